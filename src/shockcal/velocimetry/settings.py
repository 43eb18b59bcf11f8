"""How one shot's traces are read (`shockcal.velocimetry.features.extract`): the study config's `features`
section and each shot's `analysis` window, as one settings model. Light on purpose: the config's schema is
generated from it when any command reads a config, without loading the extractor's numerics.
"""

from __future__ import annotations

from shockcal.settings_model import SettingsModel, setting

ANALYSIS = "shots.*.analysis"     # the config section of a shot's analysis window


class ExtractorSettings(SettingsModel):
    """The analysis window (config `shots.<shot>.analysis`, each shot's own) and the mixture's size (config
    `features`, the study's): two config sections, one library setting; each field says its section. Each
    field's default, limits and description is here once; the config schema's entries are generated from
    them (`shockcal.settings_model`). Frozen; checked on creation: an InputError naming the field."""

    window_after_arrival_us: float = setting(
        1.2, "End of the analysis window after the arrival (with auto end time, also the simulated time).",
        section=ANALYSIS, gt=0)
    cutoff_after_arrival_us: float = setting(
        0.04, "Cut-off after the arrival that splits the mixture into its early (elastic) and late (plastic) "
        "components.", section=ANALYSIS, gt=0)
    n_components: int = setting(5, "Components of the one-dimensional Gaussian mixture fitted to a trace's samples.",
                                ge=2)
    n_samples: int = setting(10000, "Stratified samples drawn through the standardized trace, read as a CDF (no "
                                    "random numbers).", ge=100)
