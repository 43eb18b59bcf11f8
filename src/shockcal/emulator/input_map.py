"""An emulator block's inputs from design columns (`InputMap`): sums of design columns (a shot's summed
shear moduli), the powers base^column (`POWER_INPUTS`: eps^n, T*^m) and ln of the law's yield stress
(`shockcal.emulator.yield_input`), with the box each spans; per shot (`shot_input_map`) or over all shots
(`joint_input_map`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from shockcal.design.tables import ShotMapping
from shockcal.emulator.yield_input import YieldInput

# extra emulator inputs base^column: config emulator key of the base, the column's role in the strength law
# (`shockcal.hydro.laws.Law.role_column`: Johnson-Cook's n and m)
POWER_INPUTS = [("hardening_strain", "hardening_exponent"), ("homologous_temperature", "thermal_exponent")]


@dataclass
class InputMap:
    """How one emulator's inputs derive from design inputs: each is a sum of design columns, then
    one input base^column for each entry of `powers`: the Johnson-Cook factors eps^n at a plastic
    strain eps and T*^m at a homologous temperature T*. Both are steep near n = 0 and m = 0, where
    the features change fastest, and smooth and monotone everywhere. Last, with `yield_input`, ln of the
    law's yield stress (`YieldInput`), scaled by its range over the training runs (`with_yield`)."""

    names: list[str]            # emulator input names, e.g. [A, B, C, n, m, V2, G_105S]
    terms: list[list[str]]      # design columns summed into each input
    lower: np.ndarray           # box of each input (sum of the terms' bounds), the powers, then the yield last
    upper: np.ndarray
    powers: list[tuple[float, str]] = field(default_factory=list)   # (base, design column)
    yield_input: YieldInput | None = None

    def design_inputs(self) -> list[str]:
        return list(dict.fromkeys(t for terms in self.terms for t in terms))

    def raw(self, inputs) -> np.ndarray:
        """(N, d) inputs (sums of design columns, strain^n, ln yield) from a mapping or DataFrame of design columns."""
        raw = [sum(np.asarray(inputs[t], dtype=float) for t in terms) for terms in self.terms]
        raw += [base ** np.asarray(inputs[column], dtype=float) for base, column in self.powers]
        if self.yield_input is not None:
            raw.append(self.yield_input.values(inputs))
        return np.column_stack(raw)

    def with_yield(self, yield_input: YieldInput, table: pd.DataFrame) -> InputMap:
        """This map with `yield_input` last, its box the range it takes over the runs of `table`."""
        values = yield_input.values(table)
        return replace(self, lower=np.append(self.lower, values.min()), upper=np.append(self.upper, values.max()),
                       yield_input=yield_input)

    def scaled(self, inputs) -> np.ndarray:
        """(N, d) inputs scaled to [0, 1] by the box."""
        return (self.raw(inputs) - self.lower) / (self.upper - self.lower)

    def to_json(self) -> dict:
        return {"names": self.names, "terms": self.terms, "lower": self.lower.tolist(), "upper": self.upper.tolist(),
                "powers": [list(p) for p in self.powers],
                "yield_input": None if self.yield_input is None else self.yield_input.to_json()}

    @classmethod
    def from_json(cls, d: dict) -> InputMap:
        yield_input = d.get("yield_input")
        return cls(d["names"], d["terms"], np.array(d["lower"]), np.array(d["upper"]),
                   [(float(b), str(c)) for b, c in d["powers"]],
                   None if yield_input is None else YieldInput.from_json(yield_input))


def shot_input_map(shot: ShotMapping, bounds: Mapping[str, tuple[float, float]], powers=()) -> InputMap:
    """A per-shot emulator's inputs: the law's (A, B, C, n, m for Johnson-Cook), the shot's velocity, its
    summed shear modulus (when the law has no G law), then the `powers` (base, design column); `bounds`:
    the prior box by design input."""
    terms = [[k] for k in shot.strength_inputs] + [[shot.velocity_input]]
    names = [*shot.strength_inputs, shot.velocity_input]
    if shot.shear_modulus_inputs:
        terms.append(list(shot.shear_modulus_inputs))
        names.append(f"G_{shot.shot}")
    return box_map(bounds, names, terms, powers)


def joint_input_map(shots: list[ShotMapping], bounds: Mapping[str, tuple[float, float]], powers=()) -> InputMap:
    """The joint emulator's inputs: every design input the shots use, each on its own, then the `powers`."""
    used = list(dict.fromkeys(k for shot in shots for k in shot.inputs()))
    return box_map(bounds, used, [[k] for k in used], powers)


def box_map(bounds, names, terms, powers) -> InputMap:
    """The map whose inputs are the sums `terms` named `names`, then the `powers`, its box from `bounds`."""
    lower = [sum(bounds[t][0] for t in ts) for ts in terms]
    upper = [sum(bounds[t][1] for t in ts) for ts in terms]
    for base, column in powers:             # base < 1: base^column falls as the column grows
        lower.append(base ** bounds[column][1])
        upper.append(base ** bounds[column][0])
    return InputMap(names, terms, np.array(lower), np.array(upper), list(powers))
