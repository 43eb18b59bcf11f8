"""Every stage's config slice of every config in the repository, one line each: to show that a change to how
the config is read (the schema, its defaults, a settings model) leaves every stage's inputs, and so every
rerun trigger, as they were.

    python benchmarks/config_slices.py > after.txt      # on the change
    PYTHONPATH=<a checkout of the base>/src python benchmarks/config_slices.py > before.txt
    cmp before.txt after.txt

Each config (config/*.yaml but the laws' boxes, the copper example and its toy, the external-hydro example; the default study and
the quick one under each other strength law, as `make models` runs them) is merged through its `extends`
chain and validated (the flag-archive config needs the reference data, `$SHOCKCAL_REFERENCE_DATA`; the copper
example its records, `examples/copper/make_records.py`: without them, a line with the error); then a line
holds its whole validated config, and one line each its slice for
every stage of `STAGE_KEYS` (with no shot and with each shot and next-shot candidate) and every figure of the
catalogue, as `repr`: the key order counts, as in the workflow's `params:`, which Snakemake compares as
written. A slice the stage cannot take (a shot it needs, a candidate it does not read) is a line with the
error, so that those stay the same too.
"""

from __future__ import annotations

import os
from pathlib import Path

from shockcal.study.config_files import merge_config_files, merge_into
from shockcal.study.figure_catalogue import catalogue
from shockcal.study.stages import STAGE_KEYS, figure_config, stage_config
from shockcal.study.validate import validate_config

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = ["examples/copper/config.yaml", "examples/copper/toy.yaml", "examples/external_hydro/quick-command.yaml"]
OTHER_LAWS = ["steinberg-guinan", "ptw", "zerilli-armstrong"]


def _line(label: str, make) -> str:
    try:
        return f"{label} {make()!r}"
    except Exception as exc:      # noqa: BLE001 - the error is the line's content
        return f"{label} ERROR {type(exc).__name__}: {exc}"


def config_lines(path: str, law: str | None = None) -> list[str]:
    """The lines of one config file (under strength law `law`; None: its own): its validated config, then
    every stage's and figure's slice."""
    label = path if law is None else f"{path}+{law}"
    try:
        merged = merge_config_files([path])[0]
        config = validate_config(merged if law is None else merge_into(merged, {"strength": {"model": law}}), label)
    except Exception as exc:      # noqa: BLE001
        return [f"{label} ERROR {type(exc).__name__}: {exc}"]
    path = label
    lines = [f"{path} CONFIG {config!r}"]
    names = [None, *config["shots"], *config["next_shot"]["candidates"]]
    lines += [_line(f"{path} {stage} {shot}", lambda stage=stage, shot=shot: stage_config(config, stage, shot))
              for stage in STAGE_KEYS for shot in names]
    lines += [_line(f"{path} figure {name}", lambda name=name: figure_config(config, name))
              for name in catalogue(config)]
    return lines


def main() -> int:
    os.chdir(REPO)
    paths = [str(p.relative_to(REPO)) for p in sorted((REPO / "config").glob("*.yaml"))
             if p.name != "models.yaml"] + EXAMPLES     # models.yaml: the laws' prior boxes, not a study
    studies = [(path, None) for path in paths] + [(path, law) for path in ("config/sequential.yaml", "config/quick.yaml")
                                                  for law in OTHER_LAWS]
    lines = [line for path, law in studies for line in config_lines(path, law)]
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
