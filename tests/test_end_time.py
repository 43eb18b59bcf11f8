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


@pytest.mark.parametrize("runs", [pytest.param(CORNERS, id="corners"),
                                  pytest.param(None, id="all", marks=pytest.mark.slow)])
def test_auto_end_time_keeps_every_feature(paper_config, runs):
    reference = pd.read_csv(OUT).set_index(["shot", "run"]).sort_index()
    auto = features_at(paper_config, "auto", runs).set_index(["shot", "run"]).sort_index()
    reference = reference.loc[auto.index]
    assert (auto["status"] == "ok").all(), auto.loc[auto["status"] != "ok", "reason"]
    speeds = [c for c in reference.columns if c.startswith("v_")]
    times = [c for c in reference.columns if c.startswith("t_")]
    assert np.abs(auto[speeds] - reference[speeds]).to_numpy().max() <= 0.05          # m/s
    assert np.abs(auto[times] - reference[times]).to_numpy().max() <= 0.0005          # us
