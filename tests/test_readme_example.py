"""The README's notebook example runs as written and finds the known answer."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from shockcal.study.adapters import extractor_settings

README = Path(__file__).resolve().parents[1] / "README.md"


def _run_block(index: int) -> dict:
    """Execute the `index`-th python block of the README's notebook section; its variables."""
    section = README.read_text().split("## From a notebook", 1)[1].split("\n## ", 1)[0]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[index]
    scope: dict = {}
    exec(compile(code, str(README), "exec"), scope)
    return scope


def test_readme_notebook_example_recovers_the_inputs_that_made_the_measurement():
    scope = _run_block(0)
    posterior = scope["posterior"]
    summary = posterior.summary().set_index("parameter")
    for name, truth in {"a": 0.4, "b": 0.5}.items():
        assert summary.loc[name, "q05"] < truth < summary.loc[name, "q95"], summary
    assert summary.loc["a", "q95"] - summary.loc["a", "q05"] < 0.25     # the data do inform a
    assert len(posterior.draws) == 10000 and posterior.info()["ess_kish"] >= 1500


def test_readme_hydrocode_shot_is_the_study_configs_run(paper_config):
    """The two-line shot runs, its plateau is near the impact velocity (symmetric impact), and its defaults
    (Al-5083, the numerics) are the study config's: the same run through the config adapter is
    bit-identical, and so are its features read with the config's 104S settings."""
    from shockcal.hydro import run_shot
    from shockcal.study.adapters import hydro_inputs
    from shockcal.velocimetry.features import extract_features

    scope = _run_block(1)
    result = scope["result"]
    assert result.status == "ok", result.reason
    t, v = result.t_us, result.v_m_s
    plateau = np.median(v[(t > 1.6) & (t < 2.0)])          # m/s; strength holds it a few % below 204
    assert 0.95 * 204.0 < plateau < 204.0
    spec = {"flyer_mm": 3.95, "target_mm": 5.965}
    from_config = run_shot(scope["params"], *hydro_inputs(paper_config, spec, end_us=2.2))
    assert np.array_equal(from_config.v_m_s, v)
    assert scope["features"] == extract_features(t, v, extractor_settings(paper_config, "104S"))
    assert scope["features"]["v_elastic"] < scope["features"]["v_plastic"] <= v.max()
