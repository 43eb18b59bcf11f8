"""Where the training runs go: the study config's `design` section as settings models (the design itself, a
new shot's runs `design.new_shots` and a sequential study's waves `design.waves`; their steps' sampler is
`shockcal.inference.settings.StepSamplerSettings`). Each field's default, limits and description is here once; the config
schema's entries are generated from them (`shockcal.settings_model`).
"""

from __future__ import annotations

from typing import Literal

from pydantic import ValidationInfo, field_validator, model_validator
from pydantic_core import PydanticCustomError

from shockcal.errors import number
from shockcal.settings_model import SettingsError, SettingsModel, setting


class Bounds(SettingsModel):
    """A uniform prior box's ends: a strength law's parameter's (`strength.inputs.<name>`, in the unit its name
    carries) and, with its unit, a calibrated input's (`InputRange`). Checked on creation: min below max."""

    min: float = setting(..., "Lower bound of the box (below `max`).", unit="the input's unit")
    max: float = setting(..., "Upper bound of the box.", unit="the input's unit")

    @model_validator(mode="after")
    def _ordered(self):
        if not self.min < self.max:
            reason = f"{number(self.min)} is not below max ({number(self.max)})"
            raise SettingsError(f"{type(self).__name__}.min: {reason}", "min", reason)
        return self


class InputRange(Bounds):
    """One calibrated input's uniform prior box: the study config's `inputs.<name>` (paper Table IV), checked on
    creation (a SettingsError naming the field) and by `InputBox` for each of its inputs."""

    unit: str = setting(..., "Unit of the bounds and of the input's design and posterior columns, written into the "
                             "tables' metadata (`Mbar`, `cm/us`, or `-` when dimensionless).")


class DesignSettings(SettingsModel):
    """The training design (`shockcal.design.tables`): a seeded Latin hypercube over the prior box, a design
    file, or a sequential study's waves (`WaveSettings`)."""

    n_runs: int = setting(1000, "Runs of the Latin hypercube (not used with `file`). A hypercube of another size is "
                                "another design: every simulate chunk reruns.", ge=2)
    file: str | None = setting(
        None, "A CSV or Parquet design (`run` and one column per input, Table IV units) instead of the hypercube, "
        "relative to the working directory. Appending rows adds simulate chunks and leaves the finished ones alone.")
    base_shots: list[str] | None = setting(
        None, "The shots whose inputs the Latin hypercube spans (null: every shot). An input only a shot outside this "
        "list reads (a shot added to the study: its own impact velocity or modulus increment) gets a column of its "
        "own, a one-dimensional Latin hypercube over the existing rows seeded by that shot and the input, so no "
        "existing column changes and no other shot reruns.")
    strategy: Literal["lhs", "waves"] = setting(
        "lhs", "`lhs`: the paper's design, `n_runs` Latin-hypercube runs per shot (or the design file). `waves`: a "
        "sequential study (docs/sequential.md): the training run set is wave 0, a Latin hypercube of "
        "`waves.initial_runs`; each later wave adds runs where the previous wave's joint posterior lives, the emulator "
        "is refitted on every run so far and the shots recalibrated; the last wave's emulator and joint posterior are "
        "the study's.")


class NewShotSettings(SettingsModel):
    """Where the runs of a shot outside `design.base_shots` (a shot added to the study) come from
    (`shockcal.design.waves.new_shot_design`; docs/workflow.md, "How to add a shot")."""

    runs_from: Literal["posterior", "training"] = setting(
        "posterior", "`posterior`: `n_runs` runs of its own, the base shots' joint posterior thinned for space filling "
        "(as a later wave's, `design.waves.widen` and `pool_size`) with the shot's own inputs a Latin hypercube over "
        "their box; the base shots' emulator and joint posterior (a sequential study's last step, or step 0 of the "
        "training runs) are computed without it, so adding it reruns no other shot's runs, and its emulator block is "
        "its own. `training`: it runs every training row (and every wave), its own inputs drawn as new design columns.")
    n_runs: int = setting(150, "Runs of each new shot with `runs_from: posterior`.", ge=2)


class WaveSettings(SettingsModel):
    """A sequential study's waves (`design.strategy: waves`; `shockcal.design.waves.wave_design`): their sizes,
    where a later wave's runs go and when the study stops."""

    initial_runs: int = setting(
        150, "Wave 0: Latin-hypercube runs over the prior box (every shot runs every row; the study's design stream of "
        "study.seed, so the first rows are not those of `n_runs`' hypercube).", ge=1)
    runs_per_wave: int = setting(75, "Runs of each later wave (every shot runs every row); the last wave takes what "
                                     "is left of `max_runs` when that is less.", ge=1)
    max_runs: int = setting(
        300, "The budget: training runs per shot over all waves (wave 0 included). The waves are 1 + ceil((max_runs - "
        "initial_runs) / runs_per_wave); it may not be below `initial_runs`. Predictive runs "
        "(`predict.n_posterior_runs`) come on top.", ge=1)
    criterion: Literal["posterior_thinned", "max_variance"] = setting(
        "posterior_thinned", "Where a later wave's runs go. `posterior_thinned`: a pool of the previous joint "
        "posterior's draws (widened by `widen`) thinned by greedy maximin, away from every run so far; `max_variance`: "
        "the same thinning among the quarter of the pool where the previous emulator's predictive variance over the "
        "observation variance is largest.")
    widen: float = setting(1.0, "Factor the posterior pool is moved away from its mean by (in the box scaled to "
                                "[0, 1], reflected at the faces) before the thinning; 1: the posterior as it is.", ge=1.0)
    pool_size: int = setting(4000, "Candidates drawn from the previous joint posterior for each wave.", ge=100)
    stop_mcse: float = setting(
        3.0, "The stopping rule: a wave is empty (no runs; every later one too) when no 5/50/95% point of the joint "
        "posterior moved by this many combined Monte Carlo standard errors or more over the previous wave (`q*_mcse` "
        "of the posterior summaries), nor by `stop_box` of its input's box. 0 (and `stop_box` 0): never stop early.",
        ge=0)
    stop_box: float = setting(
        0.0, "The stopping rule's second allowance: a 5/50/95% point that moved by less than this fraction of its "
        "input's box width counts as settled however many Monte Carlo SE that is (the posterior-agreement tolerance "
        "of docs/sequential.md is max(3 SE, 0.02 of the box)); lambda_y, which has no box, by the Monte Carlo SE "
        "alone. 0: the Monte Carlo SE alone.", ge=0, le=1)

    @field_validator("max_runs")
    @classmethod
    def _budget_holds_wave_0(cls, max_runs: int, info: ValidationInfo) -> int:
        initial = info.data.get("initial_runs")
        if initial is not None and max_runs < initial:
            raise PydanticCustomError("budget", "{max_runs} is below wave 0's initial_runs ({initial}); the budget "
                                                "must hold wave 0", {"max_runs": max_runs, "initial": initial})
        return max_runs

    def sizes(self) -> list[int]:
        """Runs per shot of each wave: wave 0's `initial_runs`, then `runs_per_wave` until `max_runs` is spent
        (the last wave takes the rest)."""
        sizes, left = [self.initial_runs], self.max_runs - self.initial_runs
        while left > 0:
            sizes.append(min(self.runs_per_wave, left))
            left -= sizes[-1]
        return sizes

