"""The config's `simulator` section read: its kind, and the archive's paths, runs and design (docs/simulators.md).

`simulator_kind` is "builtin" when the section is left out. An archive path may start with
`{reference_data}`: $SHOCKCAL_REFERENCE_DATA, else the folder `simulator.archive.reference_data` names
(`resolve_path`). The section's rules
are in `shockcal.study.simulator_rules`.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from shockcal.errors import ConfigError

REFERENCE_DATA = "{reference_data}"


def simulator_kind(config: dict) -> str:
    """builtin, command or archive."""
    return (config.get("simulator") or {}).get("kind", "builtin")


def resolve_path(path: str, where: str, section: dict) -> Path:
    """`path` with a leading {reference_data} replaced by $SHOCKCAL_REFERENCE_DATA, else by the archive
    `section`'s `reference_data` folder; a ConfigError naming `where` when neither names one, or the folder
    does not exist."""
    if not path.startswith(REFERENCE_DATA):
        return Path(path)
    import os

    from shockcal.reference import ENV_VAR

    folder = os.environ.get(ENV_VAR) or section.get("reference_data")
    if not folder:
        raise ConfigError(f"{where}: {path}: {REFERENCE_DATA} names no folder; set simulator.archive.reference_data "
                          f"or ${ENV_VAR}")
    if not Path(folder).is_dir():
        raise ConfigError(f"{where}: {path}: the reference-data folder {folder} does not exist here; set "
                          f"${ENV_VAR} or simulator.archive.reference_data to the folder holding the data")
    return Path(folder) / path[len(REFERENCE_DATA):].lstrip("/")


def archive_runs(config: dict) -> list[int]:
    """The archive's run ids: those of its features tables (the same for every shot, all in its design),
    else every run of its design (traces)."""
    from shockcal.io import integer_ids, read_table, require_columns

    section = config["simulator"]["archive"]
    design_path = resolve_path(section["design"], "simulator.archive.design", section)
    design = read_table(design_path)
    require_columns(design, ["run"], f"simulator.archive.design ({design_path})")
    design_runs = set(integer_ids(design, "run", design_path)["run"])
    runs, first = None, None
    for shot, path in section.get("features", {}).items():
        key = f"simulator.archive.features.{shot}"
        table = read_table(resolve_path(path, key, section))
        require_columns(table, ["run"], f"{key} ({path})")
        ids = set(integer_ids(table, "run", path)["run"])
        outside = sorted(ids - design_runs)
        if outside:
            raise ConfigError(f"{key}: runs {outside[:5]} ({len(outside)} in all) are not in simulator.archive.design "
                              f"({design_path}); the design and the features disagree in their run ids")
        if runs is not None and ids != runs:
            odd = sorted(ids ^ runs)
            raise ConfigError(f"{key}: its run ids differ from simulator.archive.features.{first}'s (runs {odd[:5]}, "
                              f"{len(odd)} in all, are in one and not the other); every shot needs the same runs")
        if runs is None:
            runs, first = ids, shot
    return sorted(design_runs if runs is None else runs)


def archive_design(config: dict, load) -> tuple[pd.DataFrame, str]:
    """(the training design, where it came from): the archive's design rows that have runs, read by
    `load(path)` (the study's design loader, which checks the box)."""
    section = config["simulator"]["archive"]
    path = resolve_path(section["design"], "simulator.archive.design", section)
    design = load(path)
    runs = archive_runs(config)
    return design[design["run"].isin(runs)].reset_index(drop=True), f"archive {path} ({len(runs)} runs)"
