"""`hydro.end_time_us: auto`: runs stop just past the latest end of the analysis window, and their
features equal those of the full 4 us runs (stored reference, tests/data/make_end_time_reference.py)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from shockcal.study.config import AUTO_END_MARGIN_US, end_time_us

DATA = Path(__file__).with_name("data")
sys.path.insert(0, str(DATA))
from make_end_time_reference import OUT, features_at  # noqa: E402


def test_auto_end_time_is_the_window_end_bound(paper_config):
    c0 = math.sqrt(paper_config["material"]["eos"]["c1_Mbar"] / paper_config["material"]["rho0_g_cc"])
    for name, shot in paper_config["shots"].items():
        expected = shot["target_mm"] * 0.1 / c0 + shot["analysis"]["window_after_arrival_us"] + AUTO_END_MARGIN_US
        assert end_time_us(paper_config, shot) == pytest.approx(expected), name
        assert end_time_us(paper_config, shot) < 3.1                 # the paper's runs went to 4 us
    paper_config["hydro"]["end_time_us"] = 3.5
    assert end_time_us(paper_config, paper_config["shots"]["104S"]) == 3.5


CORNERS = [3, 4]    # the runs of reference_design whose free surface moves latest
EARLY = [0]         # the hypercube run the fast suite's `per_run` check compares


@pytest.fixture(scope="module")
def auto_fast_runs(paper_config_readonly) -> pd.DataFrame:
    """`auto`'s features of the corners and the early run, simulated once for the two fast tests that read them
    (each run is simulated and read on its own: the same rows as a batch of its runs alone)."""
    return features_at(paper_config_readonly, "auto", EARLY + CORNERS).set_index(["shot", "run"]).sort_index()


def _auto_features(config, runs, request) -> pd.DataFrame:
    """`auto`'s features of `runs` (None: all), by shot and run: the module's shared runs where they hold them."""
    if runs is None:
        return features_at(config, "auto", runs).set_index(["shot", "run"]).sort_index()
    shared = request.getfixturevalue("auto_fast_runs")
    return shared[shared.index.get_level_values("run").isin(runs)]


@pytest.mark.parametrize("runs", [pytest.param(CORNERS, id="corners"),
                                  pytest.param(None, id="all", marks=pytest.mark.slow)])
def test_auto_end_time_keeps_every_feature(paper_config, runs, request):
    reference = pd.read_csv(OUT).set_index(["shot", "run"]).sort_index()
    auto = _auto_features(paper_config, runs, request)
    reference = reference.loc[auto.index]
    assert (auto["status"] == "ok").all(), auto.loc[auto["status"] != "ok", "reason"]
    speeds = [c for c in reference.columns if c.startswith("v_")]
    times = [c for c in reference.columns if c.startswith("t_")]
    assert np.abs(auto[speeds] - reference[speeds]).to_numpy().max() <= 0.05          # m/s
    assert np.abs(auto[times] - reference[times]).to_numpy().max() <= 0.0005          # us


# --- `per_run`: each run ends after its own rise -------------------------------------------------------------

def test_a_run_that_ends_after_its_rise_is_the_longer_runs_prefix():
    """The kernel stops `stop_after_rise_us` after the first output above rise_fraction x the impact velocity:
    the same steps as the longer run up to there, so the same outputs bit for bit, and fewer of them."""
    from shockcal.hydro import Geometry, HydroSettings, ShotParameters, run_shot
    from shockcal.hydro.material_library import load_material

    params = ShotParameters(A_MPa=170, B_MPa=425, C=0.0335, n=0.42, m=1.225, velocity_m_s=204, shear_modulus_GPa=26.9)
    coarse, al5083 = HydroSettings(cell_size_um=20.0), load_material("al5083")
    full = run_shot(params, Geometry(flyer_mm=3.95, target_mm=5.965, end_us=2.30), al5083, coarse)
    short = run_shot(params, Geometry(flyer_mm=3.95, target_mm=5.965, end_us=2.30, stop_after_rise_us=1.2, rise_fraction=0.003), al5083,
                     coarse)
    n = len(short.t_us)
    # bit for bit: one code path in one process, the same steps and arithmetic, only stopped sooner
    rise = full.t_us[np.argmax(full.v_m_s > 0.003 * 204)]
    assert short.status == full.status == "ok" and n < len(full.t_us)
    assert short.t_us[-1] <= rise + 1.2 < full.t_us[n]                       # the last output within rise + 1.2 us
    np.testing.assert_array_equal(short.v_m_s, full.v_m_s[:n])
    np.testing.assert_array_equal(short.energy_history, full.energy_history[:n])
    assert short.n_steps < full.n_steps
    late = run_shot(params, Geometry(flyer_mm=3.95, target_mm=5.965, end_us=2.30, stop_after_rise_us=5.0, rise_fraction=0.003),
                    al5083, coarse)
    np.testing.assert_array_equal(late.v_m_s, full.v_m_s)                   # end_us comes first


def test_a_stop_after_the_rise_needs_both_settings():
    from shockcal.errors import InputError
    from shockcal.hydro import Geometry

    with pytest.raises(InputError, match="Geometry.stop_after_rise_us and Geometry.rise_fraction: give both"):
        Geometry(flyer_mm=3.95, target_mm=5.965, end_us=2.3, stop_after_rise_us=1.2)
    with pytest.raises(InputError, match="Geometry.rise_fraction"):
        Geometry(flyer_mm=3.95, target_mm=5.965, end_us=2.3, stop_after_rise_us=1.2, rise_fraction=-0.1)


@pytest.mark.parametrize("runs", [pytest.param(EARLY, id="early"),
                                  pytest.param(None, id="all", marks=pytest.mark.slow)])
def test_per_run_end_keeps_the_auto_runs_features(paper_config, runs, request):
    """`per_run` ends each run the window plus 0.1 us after its free surface passes 0.3% of its impact velocity,
    no later than the extractor's arrival (its threshold on a trace at rest is 0.2% of the rise, and the rise
    stays below 1.5x the impact velocity): the features equal `auto`'s bit for bit, on a hypercube run (cut
    most; with the late-arrival corners in `make test-slow`). Not a law: the extractor reads the rise from the trace's maximum, so a
    trace still creeping up past the cut can move its arrival by a sample (one PTW run in 900, docs/hydro.md)."""
    from shockcal.study.config import PER_RUN_RISE_FRACTION
    from shockcal.velocimetry.features import QUIET_ARRIVAL_FRACTION

    assert PER_RUN_RISE_FRACTION == pytest.approx(1.5 * QUIET_ARRIVAL_FRACTION)
    auto = _auto_features(paper_config, runs, request)
    per_run = features_at(paper_config, "per_run", runs).set_index(["shot", "run"]).sort_index()
    assert (per_run["status"] == "ok").all(), per_run.loc[per_run["status"] != "ok", "reason"]
    columns = [c for c in auto.columns if c.startswith(("t_", "v_"))]
    pd.testing.assert_frame_equal(per_run[columns], auto[columns], check_exact=True)
