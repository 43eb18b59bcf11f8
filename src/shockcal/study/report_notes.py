"""The report's captions that a study's config may add a note to (config `study.report_notes`).

Every caption of the workflow's report (workflow/report/<name>.rst) ends with the note the config gives
under its name, so that what holds of one study alone (its material, its shots, a published comparison)
lives in that study's config and no caption names a material, shot or paper.
"""

from __future__ import annotations

from shockcal.errors import ConfigError

# the report's tables with a caption (workflow/rules/report.smk), and the caption all history figures share
REPORT_TABLES = ("posterior_summary", "evidence", "cross_validation", "sobol_table", "coverage", "emulator_heldout",
                 "discrepancy", "predictive_coverage")
HISTORY_CAPTION = "history"


def caption_names(config: dict) -> list[str]:
    """The captions a note can go to: every figure's (the velocity histories share `history`; the next-shot
    figure's whether or not the config has candidates) and every table's."""
    from shockcal.study.figure_catalogue import catalogue, history_names

    figures = [name for name in catalogue(config) if name not in history_names(config)]
    return [*figures, *(["next_shot"] if "next_shot" not in figures else []), HISTORY_CAPTION, *REPORT_TABLES]


def check_report_notes(config: dict, source: str) -> None:
    """ConfigError naming the key: a note for a caption the report does not have."""
    known = caption_names(config)
    for name in (config.get("study") or {}).get("report_notes") or {}:
        if name not in known:
            raise ConfigError(f"{source}: study.report_notes.{name}: no caption of that name; captions: "
                              f"{', '.join(known)}")
