"""How a posterior is sampled and checked: the study config's `calibration` section as settings models (the
sampler's keys, `calibration.check` and the mapping form of `calibration.discrepancy`), and its `verify`. Light on purpose: the
config's schema is generated from them when any command reads a config, without loading the sampler's numerics.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator
from pydantic_core import PydanticCustomError

from shockcal.hydro.settings_model import SettingsModel as RuledSettingsModel
from shockcal.hydro.settings_model import setting as ruled_setting
from shockcal.settings_model import SettingsModel, setting

MIN_N_LIVE = 50          # the least live points of every sampler (calibration, its check, the next-shot check)
MIN_N_EFF = 100          # and the least effective sample size: below it the 5% and 95% points rest on a handful of draws
# PSIS fits the largest ceil(S / 5) weights (for S < 225); ArviZ gives k-hat = inf below 5 of them (S <= 20). At
# S = 25 the threshold 1 - 1/log10(S) is 0.28.
MIN_VERIFY_DRAWS = 25

CubePower = Annotated[float, Field(strict=True, ge=1, le=10,
                                   description="The power p of this input's unit-cube coordinate.")]


class SamplerSettings(SettingsModel):
    """How nautilus samples a posterior (`shockcal.inference.sampler.sample`): the study config's `calibration`
    keys, or keyword arguments from a notebook. Each field's default, limits and description is here once; the
    config schema's entries are generated from them (`shockcal.settings_model`). Frozen (`.replace(**changes)`
    for a changed copy); checked on creation: an InputError naming the field."""

    n_live: int = setting(500, "Live points of the sampler.", ge=MIN_N_LIVE)
    n_eff: int = setting(3000, "The sampler runs until its weighted draws reach this effective (Kish) sample size.",
                         ge=MIN_N_EFF)
    draws: int = setting(10000, "Equal-weight draws written per calibration (resampled from the weighted ones).", ge=1)
    replicates: int = setting(
        1, "Independent sampler runs per calibration, each to n_eff / replicates, pooled. 1: one run, its quantiles' "
        "Monte Carlo errors from its weights (they describe a run's scatter to within a variance ratio of 1.2 on the "
        "joint posterior: docs/calibration.md, \"Monte Carlo errors\"); 3 or more: errors from the runs' spread (5 "
        "runs: 3.5 times one run's likelihood evaluations). 2 is refused.", ge=1)
    cube_power: dict[str, CubePower] = setting(
        {}, "Inputs drawn as u^p in the sampler's unit cube, the posterior reweighted to match: where the sampler "
        "looks changes, the posterior does not, and a thin low end of the input gets live points; `{}` samples the "
        "box evenly, the start for a new study or law. The paper's config sets {m: 2} for the low-m arm of its "
        "Johnson-Cook posterior (docs/calibration.md, \"The low-m arm\"); set a power only where the synthetic-truth "
        "check finds a low end with too little mass. Each name must be an input of the study's law; Johnson-Cook's "
        "names that another law does not have are dropped for it (an overlay cannot delete them), any other name is "
        "refused.")
    max_evaluations: int = setting(
        500_000, "Likelihood evaluations per sampler run; a run short of `n_eff` then stops with an error (a check "
        "trial is recorded as failed).", ge=1000)
    seed: int = setting(0, "Seed of the sampler and of the resampling (a calibration's: its shots' `calibration` "
                           "stream of it).", key="study.seed")

    @field_validator("replicates")
    @classmethod
    def _a_spread_needs_three(cls, replicates: int) -> int:
        if replicates == 2:
            raise PydanticCustomError("replicates", "2 runs give no usable spread of their quantiles; use 1, or 3 or "
                                                    "more")
        return replicates


class CheckSettings(SettingsModel):
    """The synthetic-truth coverage checks (`shockcal.inference.coverage`, `make check`): the study config's
    `calibration.check`. Each trial's sampler is `SamplerSettings` with these n_live and n_eff (as many draws,
    one run) and the calibration's cube powers and evaluation limit (`shockcal.study.adapters`)."""

    trials: int = setting(100, "Trials per check (and hydrocode truth runs, over the box and from the posterior).",
                          ge=1)
    trials_per_job: int = setting(10, "Trials per workflow job (the batches run in parallel). A change moves every "
                                      "batch's trials, so every batch reruns.", ge=1)
    n_live: int = setting(500, "Live points of each trial's sampler.", ge=MIN_N_LIVE)
    n_eff: int = setting(1000, "Effective sample size each trial's sampler runs to.", ge=MIN_N_EFF)


class StepSamplerSettings(SettingsModel):
    """The sampler of a sequential study's steps before the last (their joint posteriors only place the next
    wave; the last step's is the study's, with `calibration`'s settings): `design.waves.step_calibration`."""

    n_live: int = setting(250, "Live points of a step's joint calibration.", ge=MIN_N_LIVE)
    n_eff: int = setting(1000, "The effective (Kish) sample size a step's joint calibration runs to.", ge=MIN_N_EFF)


class DiscrepancySettings(SettingsModel):
    """The model-discrepancy term (`shockcal.inference.discrepancy`): the mapping form of the study config's
    `calibration.discrepancy` (its word form, `none`, is no term)."""

    kind: Literal["none", "feature_kind"] = setting(..., "The discrepancy's form.")
    sd_fraction_prior: float = setting(0.02, "Half-normal sd of each feature kind's discrepancy sd, as a fraction of "
                                             "the feature.", gt=0, le=0.5)


class CalibrationSettings(SettingsModel):
    """What a calibration (`shockcal.inference.calibration.calibrate`) needs besides the emulator and the measured
    features: the sampler's settings, the observation error, the checks, the discrepancy term, and the units and
    box of the parameters. The fields given by config keys name them (`key`); the units, the box and the velocity
    boxes come from the config's `inputs` and `shots` (`shockcal.study.adapters.calibration_settings`). Frozen;
    checked on creation: an InputError naming the field."""

    sampler: SamplerSettings = setting(SamplerSettings(), "The nested sampler's settings.", key="calibration")
    sd_fraction: float = setting(0.01, "Observation sd as a fraction of each measured feature (0.01: 1%).",
                                 key="observed.sd_fraction", gt=0)
    check_units: bool = setting(True, "Whether the measurements must look like m/s and us (`shockcal.plausibility`).",
                                key="checks.observed_units")
    units: dict[str, str] = setting({}, "Each parameter's unit (native: the prior box's and the draws'), for the "
                                        "summary.")
    user_units: dict[str, str] = setting(
        {}, "Each parameter's unit in the summary and the InferenceData, where it differs from `units` (e.g. "
        "{\"A\": \"MPa\", \"G1\": \"GPa\", \"V1\": \"m/s\"}; `shockcal.units.user_unit`).")
    bounds: dict[str, tuple[float, float]] | None = setting(
        None, "The prior box by input (native units), or None for the emulator's box; it must lie inside the "
        "emulator's (`shockcal.inference.problem.prior_box`).")
    velocity_boxes: dict[str, tuple[float, float]] = setting(
        {}, "Shot -> its impact-velocity box (m/s), against which each shot's measured plastic plateau is checked "
        "(`shockcal.plausibility.check_plateau`); shots absent: unchecked.")
    check_plateau: bool = setting(True, "Whether a plateau outside the band stops the calibration (else a warning).",
                                  key="checks.plateau_vs_velocity")
    check_training_range: bool = setting(
        True, "Whether a measured feature outside the training runs' range (widened by "
        "`shockcal.inference.training_range.RANGE_MARGIN`) stops the calibration before it starts (else a warning).",
        key="checks.features_in_training_range")
    discrepancy: Literal["none"] | DiscrepancySettings = setting(
        "none", "The model-discrepancy term: `none`, or its settings (`DiscrepancySettings`, a mapping taken); its "
        "parameters are fractions (-).", key="calibration.discrepancy")

    @field_validator("discrepancy", mode="before")
    @classmethod
    def _discrepancy_mapping(cls, value):
        """A mapping is `DiscrepancySettings`' (its refusal names its own field)."""
        return DiscrepancySettings(**value) if isinstance(value, dict) else value

    def with_sampler(self, **changes) -> CalibrationSettings:
        """These settings with some sampler settings changed (e.g. `seed`, `n_eff`), checked."""
        return self.replace(sampler=self.sampler.replace(**changes))


class PredictSettings(RuledSettingsModel):
    """Posterior predictions (Figures 10-13): the hydrocode run at joint-posterior draws, the study config's
    `predict` section (`shockcal predict-design`; the predict run set's simulate jobs)."""

    n_posterior_runs: int = setting(100, "Joint-posterior draws run through the hydrocode for every shot.", ge=1)
    end_time_us: float = ruled_setting(
        4.0, "Simulated time of those runs, the whole record for the history figures. The workflow hands it to the "
        "predict run set's simulate jobs (`--end-time-us`): a change reruns them.", rule="positive")


class VerifySettings(SettingsModel):
    """The hydrocode's verdict on the joint posterior (`shockcal.inference.verify`, `make verify`): the study
    config's `verify` section, for a study whose `calibration.discrepancy` is `discrepancy`. A study with a
    discrepancy term is refused rather than given a wrong verdict: the verdict does not weigh the term, whose
    parameters the draws do not carry."""

    n_draws: int = setting(
        300, "Joint-posterior draws S run through the hydrocode for every shot (the run set verify). k-hat passes "
        "below min(1 - 1/log10(S), 0.7): 0.60 at S = 300, 0.28 at the fewest, 25 (ArviZ's PSIS fits the largest S/5 "
        "weights and needs 5 of them).", ge=MIN_VERIFY_DRAWS)
    discrepancy: DiscrepancySettings | Literal["none"] | None = setting(
        "none", "The study's discrepancy term; only none (or a mapping of kind none) can be verified.",
        key="calibration.discrepancy")

    @field_validator("discrepancy")
    @classmethod
    def _no_discrepancy_term(cls, discrepancy):
        if discrepancy not in (None, "none") and discrepancy.kind != "none":
            raise PydanticCustomError("discrepancy", "calibration.discrepancy is '{kind}': the hydrocode's verdict does "
                                                     "not weigh a discrepancy term yet (its draws carry none); verify "
                                                     "the study with `discrepancy: none`", {"kind": discrepancy.kind})
        return discrepancy
