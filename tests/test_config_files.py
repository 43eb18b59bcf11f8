"""Study config files (shockcal.study.config_files): a complete config stands alone, an overlay names the
config it overlays with `extends:`, overlays chain, and the Snakefile and `shockcal --config` merge them with
the same function. Each refusal is one line naming the file."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from shockcal.errors import ConfigError
from shockcal.study import config_files, validate
from shockcal.study.config_files import merge_config_files, read_config_file
from shockcal.study.validate import load_config, workflow_config_or_exit

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "config"


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


@pytest.fixture
def base(tmp_path) -> Path:
    """A complete config (the paper's) copied into tmp_path/base/config.yaml."""
    return write(tmp_path / "base" / "config.yaml", (CONFIG / "config.yaml").read_text())


def test_a_complete_config_stands_alone():
    config, files = merge_config_files([CONFIG / "config.yaml"])
    assert files == [CONFIG / "config.yaml"]
    assert config == read_config_file(CONFIG / "config.yaml")


def test_an_overlay_merges_over_the_config_it_extends_relative_to_itself(base, tmp_path):
    overlay = write(tmp_path / "variants" / "small.yaml",
                    "extends: ../base/config.yaml\ndesign: {n_runs: 40}\nnext_shot: {candidates: null}\n")
    config, files = merge_config_files([overlay])
    assert [f.resolve() for f in files] == [base.resolve(), overlay.resolve()]
    assert "extends" not in config
    assert config["design"] == {**read_config_file(base)["design"], "n_runs": 40}    # key by key
    assert config["next_shot"]["candidates"] is None                                  # a value replaced
    assert config["shots"] == read_config_file(base)["shots"]


def test_overlays_chain_and_each_file_merges_once():
    chained, files = merge_config_files([CONFIG / "sequential-quick.yaml"])
    assert [f.name for f in files] == ["config.yaml", "quick.yaml", "sequential-quick.yaml"]
    stacked, _ = merge_config_files([CONFIG / "quick.yaml", CONFIG / "sequential-quick.yaml"])
    listed, _ = merge_config_files([CONFIG / "config.yaml", CONFIG / "quick.yaml", CONFIG / "sequential-quick.yaml"])
    assert chained == stacked == listed


def test_a_later_file_without_extends_overlays_the_files_before_it(base, tmp_path):
    tweak = write(tmp_path / "tweak.yaml", "simulate: {chunk_size: 7}\n")
    config, files = merge_config_files([base, tweak])
    assert files == [base, tweak] and config["simulate"]["chunk_size"] == 7


def one_line_refusal(paths) -> str:
    with pytest.raises(ConfigError) as refused:
        merge_config_files(paths)
    message = str(refused.value)
    assert "\n" not in message
    return message


def test_a_partial_config_without_extends_is_refused_naming_the_file(tmp_path):
    partial = write(tmp_path / "cu.yaml", "design: {n_runs: 40}\n")
    message = one_line_refusal([partial])
    assert message.startswith(f"{partial}: no `material`, `hydro`, `shots`, `inputs`: a study config is complete")
    assert "`extends:`" in message


def test_an_extends_naming_no_file_is_refused(tmp_path):
    overlay = write(tmp_path / "o.yaml", "extends: missing.yaml\n")
    assert one_line_refusal([overlay]) == f"{overlay}: extends: missing.yaml does not exist (looked for {tmp_path / 'missing.yaml'})"


def test_a_cycle_is_refused(tmp_path):
    write(tmp_path / "a.yaml", "extends: b.yaml\n")
    write(tmp_path / "b.yaml", "extends: a.yaml\n")
    message = one_line_refusal([tmp_path / "a.yaml"])
    assert "extends: a cycle" in message and message.count(".yaml ->") == 2


def test_a_complete_config_after_another_is_refused(base, tmp_path):
    other = write(tmp_path / "copper.yaml", base.read_text())
    message = one_line_refusal([CONFIG / "quick.yaml", other])
    assert message.startswith(f"{other}: a complete study config (no `extends:`) given after")


def test_an_overlay_of_another_study_is_refused(base, tmp_path):
    overlay = write(tmp_path / "o.yaml", "extends: base/config.yaml\n")
    assert "is another study config" in one_line_refusal([CONFIG / "quick.yaml", overlay])


def test_the_cli_and_the_snakefile_read_a_study_with_the_same_function(monkeypatch):
    """`shockcal --config` (load_config) and the Snakefile (workflow_config_or_exit) both merge through
    config_files.merge_config_files, and give the same config for the same file."""
    calls = []

    def spy(paths):
        calls.append([Path(p).name for p in paths])
        return merge_config_files(paths)

    monkeypatch.setattr(validate, "merge_config_files", spy)
    cli = load_config(CONFIG / "quick.yaml")
    snakefile: dict = {"stale": "snakemake's own merge, replaced"}
    files = workflow_config_or_exit(snakefile, [str(CONFIG / "quick.yaml")], {}, default=str(CONFIG / "config.yaml"))
    assert calls == [["quick.yaml"], ["quick.yaml"]]
    assert snakefile == cli and [Path(f).name for f in files] == ["config.yaml", "quick.yaml"]
    default: dict = {}
    workflow_config_or_exit(default, [], {"design": {"n_runs": 7}}, default=str(CONFIG / "config.yaml"))
    assert default["shots"] == cli["shots"] and default["design"]["n_runs"] == 7    # --config on top


def test_the_snakefile_refuses_an_overlay_without_a_base_in_one_line(tmp_path):
    partial = write(tmp_path / "cu.yaml", "study: {results_dir: " + str(tmp_path / "results") + "}\n")
    done = subprocess.run([str(Path(sys.executable).parent / "snakemake"), "--dry-run", "--cores", "1",
                           "--configfile", str(partial)], cwd=REPO, capture_output=True, text=True)
    assert done.returncode != 0
    errors = [line for line in (done.stdout + done.stderr).splitlines() if line.startswith("shockcal: error:")]
    assert errors == [f"shockcal: error: {partial}: no `material`, `hydro`, `shots`, `inputs`: a study config is "
                      "complete, or names the config it overlays with `extends:`"]


def test_every_overlay_in_the_repository_names_its_base():
    """Each config file under config/ and examples/ is complete or extends one (config/models.yaml is the
    strength laws' box file, not a study config)."""
    studies = [p for p in [*CONFIG.glob("*.yaml"), *(REPO / "examples").rglob("*.yaml")] if p.name != "models.yaml"]
    assert len(studies) >= 9
    for path in studies:
        files = config_files.config_files([path])
        assert "shots" in read_config_file(files[0]), path


def test_an_error_in_an_overlays_chain_names_the_file_that_sets_the_key(base, tmp_path):
    overlay = write(tmp_path / "o.yaml", f"extends: {base}\nsimulate: {{chunk_size: 0}}\n")
    with pytest.raises(ConfigError, match=rf"^{overlay}: simulate.chunk_size: 0 is less than the minimum of 1"):
        load_config(overlay)
    assert yaml.safe_load(overlay.read_text())["extends"] == str(base)    # an absolute path is taken as it is
