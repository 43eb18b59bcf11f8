"""How a principal-component GP emulator is fitted (`shockcal.emulator.pcgp.PCGPEmulator`): the study
config's `emulator` section as a settings model. Light on purpose: the config's schema is generated from it
when any command reads a config, without loading the emulator's numerics.
"""

from __future__ import annotations

from typing import Literal

from shockcal.settings_model import SettingsModel, setting

FAMILIES = ("gaussian", "matern52", "matern32")     # the GP's correlation families (`shockcal.emulator.correlation`)


class EmulatorSettings(SettingsModel):
    """How a PCGPEmulator is fitted: the study config's `emulator` section (its other keys are the study
    emulator's, `shockcal.emulator.study_emulator.EmulatorSpec`), or keyword arguments from a notebook. Each
    field's default, choices, limits and description is here once; the config schema's entries are generated
    from them (`shockcal.settings_model`). Frozen (`.replace(**changes)` for a changed copy); checked on
    creation: an InputError naming the field."""

    n_components: int | float = setting(0.999, "Principal components kept, as a count (an integer) or the fraction "
                                               "of the variance to explain (below 1).", gt=0)
    n_starts: int = setting(2, "L-BFGS-B starts per GP for its MAP hyperparameters.", ge=1)
    max_fit_runs: int = setting(500, "The hyperparameters are fitted on at most this many runs (a seeded subset); "
                                     "all runs condition the GP.", ge=10)
    family: Literal[FAMILIES] = setting("matern52", "Correlation family (`gaussian` is the paper's).")
    fit_mean: bool = setting(True, "A constant mean per component (GLS); false for a zero mean.")
    n_jobs: int = setting(2, "Processes for the GP fits, one BLAS thread each; also the threads of the jobs that "
                             "predict with the emulator.", ge=1)
    cv_folds: int = setting(10, "Folds of the K-fold cross-validation (everything refitted per fold).", ge=2)
    calibrate_sd: bool = setting(True, "Scale each feature's predictive sd from the K-fold, so that 90% bands hold "
                                       "90% of held-out runs.")
    cv_warm_start: bool = setting(True, "K-fold and outer refits start from the full fit's hyperparameters (one "
                                        "start).")
    switch_ratio: float = setting(0.9, "Predicted v_elastic / v_plastic past which (single-wave traces) a shot's "
                                       "features get their own sd factors; 0 turns it off.", ge=0)
    sd_model: Literal["smooth", "constant"] = setting(
        "smooth", "How the K-fold scales the predictive sd (with `calibrate_sd`): `smooth`, a variance model over "
        "the box (additive splines per input and the log raw sd, fitted to the K-fold's log z^2; bands widen where "
        "the emulator is weak) times a factor per feature, or `constant`, a factor per feature. `smooth` brings "
        "the study's K-fold coverage into 0.88-0.92 in 54 of 55 input fifths (constant: 49) and n's "
        "hydrocode-truth coverage from 0.82 to 0.85 (docs/emulator.md, docs/calibration.md); the default since "
        "2026-11-26.")
    error_tails: Literal["student_t", "gaussian"] = setting(
        "student_t", "Error distribution around the emulator's mean and covariance: `student_t` (degrees of "
        "freedom and scale fitted to the K-fold errors) or `gaussian`.")
    seed: int = setting(0, "Seed of the fit's subset of runs, its starts and its K-fold folds.", key="study.seed")
