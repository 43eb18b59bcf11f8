"""Every figure function draws a valid image from small synthetic tables of the documented shapes,
and a missing or empty input gives a "no data" panel instead of an error or a blank figure."""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd
import pytest
from matplotlib.image import imread

from shockcal.plots import crossval, feature_space, histories, posterior, records, toys
from shockcal.plots.style import CALIBRATION_FEATURES, FEATURES, save_figure
from shockcal.study.adapters import shot_mapping
from shockcal.study.config import input_names

SHOTS = ["104S", "105S", "106S"]


def _texts(fig) -> str:
    """All text written in the panels and their titles."""
    return " ".join([t.get_text() for ax in fig.axes for t in ax.texts] + [ax.get_title() for ax in fig.axes])


def _save_png(fig, tmp_path, name="fig"):
    (path,) = save_figure(fig, tmp_path / name, formats=["png"], dpi=40)
    image = imread(path)
    assert image.ndim == 3 and image.shape[0] > 50 and image.shape[1] > 50
    assert image[..., :3].std() > 0.01, "image is blank"
    return path


def _posterior(config, names, n=300, seed=0):
    rng = np.random.default_rng(seed)
    lo = np.array([config["inputs"][k]["min"] for k in names])
    hi = np.array([config["inputs"][k]["max"] for k in names])
    unit = np.clip(0.5 + 0.15 * rng.standard_normal((n, len(names))), 0, 1)
    table = pd.DataFrame(lo + unit * (hi - lo), columns=names)
    return table.assign(lambda_y=1.0, log_post=-1.0, chain=0)


def _features(n, seed, shift=0.0):
    rng = np.random.default_rng(seed)
    base = {"jumpoff": (0.90, 2.0), "elastic": (0.93, 70.0), "slope1": (1.0, 85.0), "slope2": (1.15, 190.0),
            "plastic": (1.8, 200.0)}
    table = {"run": np.arange(n), "status": ["ok"] * (n - 1) + ["failed"], "reason": [""] * n}
    for key, (t, v) in base.items():
        table[f"t_{key}"] = t + shift + 0.01 * rng.standard_normal(n)
        table[f"v_{key}"] = v * (1 + 0.05 * rng.standard_normal(n))
    return pd.DataFrame(table)


def _observed():
    rows = [_features(2, i, shift=0.1).iloc[0].drop(["run", "status", "reason"]) for i in range(3)]
    return pd.DataFrame(rows).assign(shot=SHOTS, source="config")


def _sims(n, seed):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 4.0, 400)
    rows = []
    for run in range(n):
        arrival = 0.85 + 0.02 * rng.standard_normal()
        v = 70 / (1 + np.exp(-(t - arrival) / 0.005)) + 130 / (1 + np.exp(-(t - arrival - 0.2) / 0.03))
        rows.append({"run": run, "status": "ok", "reason": "", "t_us": t, "v_m_s": v})
    return pd.DataFrame(rows)


@pytest.mark.parametrize("build", [toys.fig01_toy_calibration, toys.fig03_gp_draws, toys.fig14_inadequate_model])
def test_toy_figures(build, tmp_path):
    _save_png(build(), tmp_path)


def test_inadequate_model_posterior_piles_at_the_bound():
    mean = toys.sigmoid_simulator(toys.GRID, height=0.8, steepness=4.0)
    density = toys.grid_posterior(mean, np.zeros_like(mean), datum=0.77, sd=0.02)
    assert np.argmax(density) == len(toys.GRID) - 1


def test_save_figure_writes_every_format(tmp_path):
    paths = save_figure(toys.fig03_gp_draws(), tmp_path / "sub" / "fig03", formats=["png", "pdf"], dpi=40)
    assert [p.name for p in paths] == ["fig03.png", "fig03.pdf"]
    assert paths[1].read_bytes()[:4] == b"%PDF"
    assert not list((tmp_path / "sub").glob(".*tmp*"))


@pytest.fixture
def small_config(paper_config):
    """The paper's config with only the five Johnson-Cook inputs (a 5 x 5 pairs plot is fast)."""
    config = copy.deepcopy(paper_config)
    config["inputs"] = {k: v for k, v in config["inputs"].items() if k in ("A", "B", "C", "n", "m")}
    return config


def test_marginals(paper_config, small_config, tmp_path):
    posts = {s: _posterior(paper_config, shot_mapping(paper_config, s).inputs()[:6]) for s in SHOTS}
    posts["joint"] = _posterior(paper_config, input_names(paper_config))
    small_config["inputs"]["V2"] = paper_config["inputs"]["V2"]
    fig = posterior.fig07_marginals(posts, small_config)
    text = _texts(fig)
    assert "no data" not in text and "not an input\nof 104S" in text
    _save_png(fig, tmp_path)


def test_marginals_without_posteriors_say_so(small_config, tmp_path):
    posts = {"104S": None, "joint": _posterior(small_config, input_names(small_config)).iloc[:0]}
    fig = posterior.fig07_marginals(posts, small_config)
    assert "posterior missing" in _texts(fig) and "posterior empty" in _texts(fig)
    _save_png(fig, tmp_path)


def test_gray_values_outside_the_box_widen_the_axis(paper_config):
    from shockcal.study.references import drawn_sets

    lo, hi = posterior.display_limits("C", paper_config, drawn_sets(paper_config))
    assert hi > 0.0335 > paper_config["inputs"]["C"]["max"]


def test_pairs(small_config, tmp_path):
    fig = posterior.fig08_pairs(_posterior(small_config, input_names(small_config)), small_config)
    _save_png(fig, tmp_path)


@pytest.mark.parametrize("samples", [None, "empty"])
def test_pairs_without_posterior_says_so(small_config, samples, tmp_path):
    table = None if samples is None else _posterior(small_config, input_names(small_config)).iloc[:0]
    fig = posterior.fig08_pairs(table, small_config)
    assert "no data" in _texts(fig)
    _save_png(fig, tmp_path)


def test_crossval(tmp_path):
    rows = [{"run": r, "shot": s, "feature": f, "simulated": 100.0 + r, "predicted": 100.0 + r + (-1) ** r}
            for s in SHOTS for f in CALIBRATION_FEATURES for r in range(20)]
    fig = crossval.fig06_crossval(pd.DataFrame(rows), SHOTS)
    assert "RMSE 1.0 m/s" in _texts(fig)
    _save_png(fig, tmp_path)


def test_crossval_missing(tmp_path):
    assert "no data" in _texts(crossval.fig06_crossval(None, SHOTS))


@pytest.mark.parametrize("source", ["emulator", "hydrocode"])
def test_feature_space(source, tmp_path):
    training = {s: _features(60, i) for i, s in enumerate(SHOTS)}
    predicted = {s: _features(30, 10 + i) for i, s in enumerate(SHOTS[:2])}
    fig = feature_space.feature_space(training, predicted, _observed(), SHOTS, 0.01, source)
    assert "missing: predictions" in _texts(fig)  # 106S has none
    _save_png(fig, tmp_path)


def test_the_measured_band_is_the_likelihoods_observation_sd():
    """1% of the value and the record's read-out sd in quadrature; 1% alone without a read-out column."""
    row = pd.Series({"v_slope1": 80.0, "readout_sd_v_slope1": 0.6, "v_plastic": 200.0})
    assert feature_space.observation_sd(row, "v_slope1", 0.01) == pytest.approx(1.0)
    assert feature_space.observation_sd(row, "v_plastic", 0.01) == pytest.approx(2.0)


def test_failed_runs_are_left_out():
    table = _features(5, 0)
    assert len(feature_space.usable(table)) == 4


def test_time_shift_is_estimated_from_feature_times():
    simulated = _features(50, 0)
    observed = simulated.iloc[0].copy()
    for key in FEATURES:
        observed[f"t_{key}"] = simulated[f"t_{key}"].iloc[:-1].median() + 2.75  # the last run failed
    assert histories.estimate_time_shift(observed, simulated) == pytest.approx(-2.75)
    assert histories.estimate_time_shift(None, simulated) is None


def test_history(tmp_path):
    observed = _observed().iloc[0]
    record = pd.DataFrame({"t_us": np.linspace(0, 3, 300), "v_m_s": np.linspace(0, 200, 300)})
    fig = histories.fig_history("104S", _sims(8, 0), _sims(5, 1), observed, record, -0.1, n_training=5)
    assert "shifted by -0.100 µs" in _texts(fig)
    _save_png(fig, tmp_path)


def test_history_without_anything_says_so(tmp_path):
    fig = histories.fig_history("104S", None, None, None, None, None)
    assert "no data" in _texts(fig)
    _save_png(fig, tmp_path)


def test_records(tmp_path):
    record = pd.DataFrame({"t_us": np.linspace(0, 3, 300), "v_m_s": np.linspace(0, 200, 300)})
    fig = records.fig02_records({"104S": record}, _observed().iloc[:2], SHOTS)
    text = _texts(fig)
    assert "measured features only" in text and "106S: no record" in text
    _save_png(fig, tmp_path)
