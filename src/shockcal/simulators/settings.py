"""How a run set's hydrocode runs are split into jobs and how many may fail: the study config's `simulate`
section as a settings model (its fields' defaults, limits and descriptions once; the config schema's
entries are generated from them, `shockcal.settings_model`)."""

from __future__ import annotations

from shockcal.settings_model import SettingsModel, setting


class SimulateSettings(SettingsModel):
    """The simulate jobs' size (`shockcal.design.tables.chunk_fingerprints`) and a shot's failed-run budget
    (`shockcal.velocimetry.feature_tables.check_failures`)."""

    chunk_size: int = setting(150, "Design rows per simulate job (1: a job per run; docs/workflow.md, \"Per-job "
                                   "overhead\"). A change moves every chunk's rows, so every simulate job reruns.", ge=1)
    max_failed_fraction: float = setting(0.05, "Largest share of a shot's runs that may fail in the hydrocode; more "
                                               "stops the shot's features merge with an error.", ge=0, le=1)
