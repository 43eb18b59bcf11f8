"""How traces are read: one shot's (`shockcal.velocimetry.features.extract`; the study config's `features`
section and each shot's `analysis` window, as one settings model) and the measured ones (the config's
`observed` section). Light on purpose: the config's schema is generated from them when any command reads a
config, without loading the extractor's numerics.
"""

from __future__ import annotations

from typing import Literal

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


class ObservedSettings(SettingsModel):
    """The measured features the calibrations use and their error (`shockcal.velocimetry.feature_tables`, `shockcal
    observed`): the config's `observed` keys besides the records and the published features themselves."""

    source: Literal["records", "published", "synthetic"] = setting(
        "records", "`records`: extract the features from the VISAR records (`observed.records`) with the simulations' "
        "extractor; `published`: the paper's values (`observed.features`); `synthetic`: no measurement (a study whose "
        "calibrations read synthetic measurements only, as the next-shot check's derived studies; `shockcal observed` "
        "stops).")
    sd_fraction: float = setting(
        0.01, "Observation error, the sd of each measured feature as a fraction of its value (0.01 = 1%); the read-out "
        "sd of a record's features (`readout_error`) adds to it in quadrature.", gt=0)
    readout_error: bool = setting(
        True, "With source `records`: estimate each feature's read-out sd on its record, the spread of the extractor's "
        "value over replicates of the record's own noise (an AR model fitted to its plateau; docs/features.md, "
        "\"Noisy traces\"), seeded by the `readout` stream of study.seed. It is written with the observed features "
        "(`readout_sd_v_*`, m/s) and enters each feature's observation variance beside `sd_fraction`. false: 0 (the "
        "1% alone, as before 2026-11-26).")
    readout_replicates: int = setting(
        200, "Noise replicates of each record in the read-out bootstrap (the MAD-based sd's relative Monte Carlo error "
        "is about 1.17 / sqrt(replicates): 8% at 200); 25-100 ms each.", ge=10)
