"""The report's text and figures come from the config: a copper-like study's captions, opening and figures
name no material, shot or paper of the paper's study; the paper's config brings its own text back."""

from __future__ import annotations

import copy
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
import yaml

from shockcal.study.figure_catalogue import FigureInputs, catalogue, figure_spec, history_names
from shockcal.study.references import drawn_sets
from shockcal.study.report_notes import caption_names
from shockcal.study.stages import figure_config
from shockcal.study.validate import validate_config

REPO = Path(__file__).resolve().parents[1]
REPORT = REPO / "workflow" / "report"
# what the paper's study is made of: its material, shots, paper and reference sets
FORBIDDEN = ("Al-5083", "5083", "104S", "105S", "106S", "Walters", "Gray", "Boteler", "Dandekar", "Table IV")


@pytest.fixture(scope="module")
def copper_config() -> dict:
    """The paper's config with its shots renamed (CU1-CU3), its study text and reference sets left out and
    its published features as the observations (no record files): a study of another material, as a user
    who starts from it would write it."""
    text = (REPO / "config" / "config.yaml").read_text()
    for old, new in (("104S", "CU1"), ("105S", "CU2"), ("106S", "CU3")):
        text = text.replace(old, new)
    raw = yaml.safe_load(text)
    raw["study"] = {"name": "ofhc-copper", "seed": 1,
                    "description": "a Bayesian calibration of Johnson-Cook for OFHC copper from three shots."}
    raw["observed"]["source"] = "published"
    raw["observed"].pop("records")
    return validate_config(raw, "copper.yaml")


def _forbidden_in(text: str) -> list[str]:
    return [word for word in FORBIDDEN if word.lower() in text.lower()]


def render_caption(path: Path, config: dict, shot: str = "") -> str:
    """A caption rendered as `snakemake --report` renders it (Jinja2 with its settings, `snakemake.config`,
    `.params`), then checked as reStructuredText (a docutils warning raises)."""
    from docutils.core import publish_parts
    from jinja2 import Environment, StrictUndefined

    env = Environment(trim_blocks=True, lstrip_blocks=True, undefined=StrictUndefined)
    snakemake = SimpleNamespace(config=config, params=SimpleNamespace(shot=shot))
    text = env.from_string(path.read_text()).render(snakemake=snakemake)
    publish_parts(text, writer_name="html", settings_overrides={"halt_level": 2, "report_level": 2})
    return text


def test_every_caption_can_take_a_note():
    """The captions `study.report_notes` accepts are the report's caption files, and each file ends with its note."""
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    files = {path.stem for path in REPORT.glob("*.rst")} - {"workflow"}
    assert set(caption_names(config)) == files
    for name in files:
        assert f'report_notes"].get("{name}", "")' in (REPORT / f"{name}.rst").read_text(), name


def test_a_copper_report_names_nothing_of_the_papers_study(copper_config):
    shots = list(copper_config["shots"])
    for path in sorted(REPORT.glob("*.rst")):
        text = render_caption(path, copper_config, shots[0])
        assert not _forbidden_in(text), f"{path.name}: {_forbidden_in(text)}"
    opening = render_caption(REPORT / "workflow.rst", copper_config)
    assert "ofhc-copper" in opening and "OFHC copper" in opening and "Reference:" not in opening
    assert "CU1, CU2, CU3" in render_caption(REPORT / "fig02_records.rst", copper_config)


def test_an_opening_without_a_description_names_the_law_and_shots(copper_config):
    config = copy.deepcopy(copper_config)
    config["study"]["description"] = ""
    opening = render_caption(REPORT / "workflow.rst", config)
    assert "johnson-cook strength model from\n3 plate-impact shots (CU1, CU2, CU3)" in opening


def test_the_papers_config_brings_its_text_back(paper_config_readonly):
    opening = render_caption(REPORT / "workflow.rst", paper_config_readonly)
    assert "Al-5083 from three plate-impact shots (104S, 105S, 106S), reproducing Walters et al. 2018." in opening
    assert "Reference: Walters et al. 2018, J. Appl. Phys. 124, 205105." in opening
    marginals = render_caption(REPORT / "fig07_marginals.rst", paper_config_readonly)
    assert "Gray et al.: high rate, T > RT" in marginals and "highest C lies outside the prior box" in marginals
    assert "0.08, 0.45 and 2.75" in render_caption(REPORT / "history.rst", paper_config_readonly, "104S")


def _posteriors(config: dict, names) -> dict[str, pd.DataFrame]:
    rng = np.random.default_rng(3)
    return {name: pd.DataFrame({k: rng.uniform(b["min"], b["max"], 200) for k, b in config["inputs"].items()})
            for name in names}


def _build(name: str, inputs: FigureInputs, config: dict):
    """Figure `name` as `shockcal figures` builds it: from the keys its catalogue entry reads."""
    return figure_spec(name, config).build(inputs, figure_config(config, name))


def _texts(fig) -> str:
    from matplotlib.text import Text

    return "\n".join(t.get_text() for t in fig.findobj(Text))


def test_a_copper_studys_figures_name_nothing_of_the_papers_study(copper_config, tmp_path):
    """Every figure that reads the config, built with no inputs (data figures say "no data"; the toys read
    none), and the marginals with draws."""
    import matplotlib.pyplot as plt

    shots = sorted(copper_config["shots"])
    for name, spec in catalogue(copper_config).items():
        if not spec.reads:
            continue
        fig = _build(name, FigureInputs(), copper_config)
        assert not _forbidden_in(_texts(fig)), f"{name}: {_forbidden_in(_texts(fig))}"
        plt.close(fig)
    files = {}
    for name, table in _posteriors(copper_config, [*shots, "joint"]).items():
        files[f"posterior:{name}"] = [str(tmp_path / f"{name}.parquet")]
        table.to_parquet(files[f"posterior:{name}"][0])
    fig = _build("fig07_marginals", FigureInputs(files), copper_config)    # the one that draws reference sets
    assert not _forbidden_in(_texts(fig)), _forbidden_in(_texts(fig))
    assert not [line for ax in fig.axes for line in ax.get_lines() if line.get_label().startswith("Gray")]
    plt.close(fig)
    assert set(history_names(copper_config).values()) == set(shots)


def test_the_papers_marginals_draw_grays_sets_at_their_values(paper_config_readonly):
    """Figure 7 of the paper's config draws its four reference sets where Gray et al. put them (MPa for A, B)."""
    import matplotlib.pyplot as plt

    from shockcal.plots.posterior import fig07_marginals

    config = figure_config(paper_config_readonly, "fig07_marginals")
    fig = fig07_marginals(_posteriors(config, ["joint"]), config, drawn_sets(config))
    names = list(config["inputs"])
    drawn = {}
    for ax, name in zip(fig.axes[:len(names)], names):
        for line in ax.get_lines():
            drawn.setdefault(line.get_label(), {})[name] = line.get_xdata()[0]
    assert drawn["Gray et al.: all rates, all T"] == {"A": 210.0, "B": 620.0, "C": 0.0125, "n": 0.375, "m": 1.525}
    assert drawn["Gray et al.: high rate, T > RT"]["C"] == 0.0335
    assert len(drawn) == 4 and all(re.match(r"Gray et al\.: ", label) for label in drawn)
    plt.close(fig)
