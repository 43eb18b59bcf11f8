"""The figure catalogue and `shockcal figures`: every figure builds even with no inputs (toys draw,
data figures say "no data"), named inputs reach the figures, bad inputs give clear errors."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
from matplotlib.image import imread

from shockcal.cli import main
from shockcal.cli.figures import parse_inputs
from shockcal.errors import InputError
from shockcal.plots.style import save_figure
from shockcal.study.figure_catalogue import INPUT_KINDS, FigureInputs, build_figure, catalogue, history_names

CONFIG = str(Path(__file__).resolve().parents[1] / "config" / "config.yaml")
TOYS = {"fig01_toy_calibration", "fig03_gp_draws", "fig14_inadequate_model"}


@pytest.fixture(scope="module")
def jc_config(paper_config_readonly):
    """The paper's config reduced to the five Johnson-Cook inputs (fast posterior grids)."""
    config = copy.deepcopy(paper_config_readonly)
    config["inputs"] = {k: v for k, v in config["inputs"].items() if k in ("A", "B", "C", "n", "m")}
    return config


def test_fifteen_figures_in_the_papers_order(paper_config):
    names = list(catalogue(paper_config))
    assert len(names) == 18 and names[15] == "sobol_indices"          # the paper's fifteen, then the study's own
    assert names[16] == "features_vs_training" and catalogue(paper_config)["features_vs_training"].target == "all"
    assert names[17] == "next_shot" and catalogue(paper_config)["next_shot"].target == "next_shot"   # not in `all`
    assert [int(name[3:5]) for name in names[:15]] == list(range(1, 16))
    assert history_names(paper_config) == {"fig11_history_104S": "104S", "fig12_history_105S": "105S",
                                           "fig13_history_106S": "106S"}
    added_first = {**paper_config, "shots": {"107S": paper_config["shots"]["106S"], **paper_config["shots"]}}
    assert history_names(added_first) == history_names(paper_config)   # snakemake's merge put an overlay's shot first


@pytest.mark.parametrize("name", [n for n in catalogue({"shots": {"104S": {}, "105S": {}, "106S": {}}}) if n not in TOYS])
def test_data_figures_without_inputs_say_no_data(name, jc_config, tmp_path):
    fig = build_figure(name, FigureInputs(), jc_config)
    assert any("no data" in t.get_text() or "missing" in t.get_text() or "not configured" in t.get_text()
               for ax in fig.axes for t in ax.texts), name
    (png,) = save_figure(fig, tmp_path / name, ["png"], dpi=30)
    assert imread(png).shape[0] > 30


def test_needs_name_known_kinds_and_follow_the_configured_records(paper_config):
    """The workflow builds each figure's inputs from `needs`: every key is a known kind, and a shot
    without a record draws its trace figures from a simulation sample instead."""
    specs = catalogue(paper_config)
    assert {key.partition(":")[0] for spec in specs.values() for key in spec.needs} <= set(INPUT_KINDS)
    assert specs["fig04_trace_features"].needs == ("record:104S",)
    assert "record:105S" in specs["fig02_records"].needs
    assert set(specs["fig07_marginals"].needs) == {"posterior:104S", "posterior:105S", "posterior:106S",
                                                   "posterior:joint"}
    config = copy.deepcopy(paper_config)
    del config["observed"]["records"]["104S"]
    specs = catalogue(config)
    assert specs["fig04_trace_features"].needs == ("sample_simulations:104S",)
    assert "record:104S" not in specs["fig02_records"].needs + specs["fig11_history_104S"].needs
    assert "record:105S" in specs["fig12_history_105S"].needs


def test_next_shot_figure_draws_the_ranking(paper_config, tmp_path):
    import pandas as pd

    assert any("no ranking" in t.get_text() for ax in build_figure("next_shot", FigureInputs(), paper_config).axes
               for t in ax.texts)
    rows = []
    for i, name in enumerate(["104S-repeat", "hot-700K", "105S-repeat"]):
        row = {"candidate": name, "eig_nats": 2.0 - 0.5 * i, "eig_sd": 0.1, "n_draws": 200}
        row.update({f"eig_{t}_{k}": v for t in ("A", "B", "C", "n", "m") for k, v in (("nats", 0.5 + 0.1 * i), ("sd", 0.05))})
        row.update({f"{k}_{f}": v for f in ("v_elastic", "v_plastic", "v_slope1", "v_slope2")
                    for k, v in (("feature_sd", 3.0 + i), ("noise_sd", 1.0))})
        rows.append(row)
    path = tmp_path / "ranking.csv"
    pd.DataFrame(rows).to_csv(path, index=False)
    fig = build_figure("next_shot", FigureInputs({"next_shot_ranking": [str(path)]}), paper_config)
    gain = fig.axes[0]
    top_down = sorted(zip(gain.get_yticks(), (t.get_text() for t in gain.get_yticklabels())), reverse=True)
    assert [label for _, label in top_down] == ["104S-repeat", "hot-700K", "105S-repeat"]     # best on top
    (png,) = save_figure(fig, tmp_path / "next_shot", ["png"], dpi=60)
    assert imread(png).shape[0] > 100


def test_unknown_figure_is_named(paper_config):
    with pytest.raises(InputError, match="unknown figure 'fig99'.*fig01_toy_calibration"):
        build_figure("fig99", FigureInputs(), paper_config)


def test_parse_inputs():
    assert parse_inputs(["a=x", "a=y", "b:104S=z"]) == {"a": ["x", "y"], "b:104S": ["z"]}
    with pytest.raises(InputError, match="KEY=PATH"):
        parse_inputs(["nokey"])


def test_cli_draws_a_toy_in_every_format(tmp_path):
    assert main(["figures", "--config", CONFIG, "--figure", "fig03_gp_draws", "--out-dir", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig03_gp_draws.pdf", "fig03_gp_draws.png"]


def test_cli_names_a_missing_input_file(tmp_path, capsys):
    missing = tmp_path / "joint.parquet"
    assert main(["figures", "--config", CONFIG, "--figure", "fig08_pairs", "--out-dir", str(tmp_path),
                 "--input", f"posterior:joint={missing}"]) == 2
    assert f"{missing} does not exist" in capsys.readouterr().err
    assert not list(tmp_path.glob("*.png"))
