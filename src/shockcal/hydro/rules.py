"""The physical limits of the hydrocode's inputs: one set of rules behind both doors.

The library's inputs (`Geometry`, `ShotParameters`, `LawShotParameters`, `MaterialProperties`,
`HydroSettings`) check their fields with these rules on construction, and the study config's schema
names the same rules (`x-rule: positive` beside a key; `shockcal.study.validate` runs them), so an
impossible shot gets the same words through a notebook and through a config:

    Geometry(flyer_mm=3.95, target_mm=0.0, end_us=2.2)
        InputError: Geometry.target_mm: 0 is not a positive number
    shots: {104S: {target_mm: 0.0, ...}}
        ConfigError: config.yaml: shots.104S.target_mm: 0 is not a positive number

A rule is an interval with the reason for its ends; `problem(value, rule)` says what is wrong, or None.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shockcal.errors import InputError, number
from shockcal.settings_model import SettingsError

# The fastest plate-impact launchers: two-stage light-gas guns fire flyers at up to about 8 km/s. Above
# this the hydrocode's solid EOS (a cubic cold curve) and its strength laws are far outside their range;
# a velocity there is a unit slip (204000 for 204 m/s).
MAX_IMPACT_VELOCITY_M_S = 10000.0


@dataclass(frozen=True)
class Rule:
    """An interval of allowed values: (low, high], or [low, high] with `low_closed`; `why` tells the
    user what the upper end means."""

    low: float = 0.0
    high: float = math.inf
    low_closed: bool = False
    why: str = ""

    def problem(self, value) -> str | None:
        """What is wrong with `value` under this rule, or None when it holds."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            try:
                value = float(value)
            except (TypeError, ValueError):
                return f"{value!r} is not a number"
        if not math.isfinite(value):
            return f"{number(value)} is not a {self.describe()}"
        if value < self.low or (value == self.low and not self.low_closed):
            below = "not a positive number" if self.low == 0 and not self.low_closed else (
                "negative" if self.low == 0 else f"below {number(self.low)}")
            return f"{number(value)} is {below}"
        if value > self.high:
            return f"{number(value)} is above {number(self.high)}{self.why}"
        return None

    def describe(self) -> str:
        """The rule in words: 'positive number', 'number >= 0', 'number in (0, 1]', 'finite number'."""
        if self.low == -math.inf:
            return "finite number"
        if self.high == math.inf:
            return "number >= 0" if self.low_closed and self.low == 0 else (
                "positive number" if self.low == 0 else f"number above {number(self.low)}")
        return f"number in {self.interval()}"

    def interval(self) -> str:
        """The rule as the configuration reference writes a range: '> 0', '>= 0', '(0, 1]', '' (any finite)."""
        if self.low == -math.inf:
            return ""
        if self.high == math.inf:
            return f"{'>=' if self.low_closed else '>'} {number(self.low)}"
        return f"{'[' if self.low_closed else '('}{number(self.low)}, {number(self.high)}]"


RULES = {
    "positive": Rule(),
    "finite": Rule(low=-math.inf, low_closed=True),
    "nonnegative": Rule(low_closed=True),
    "courant": Rule(high=1.0, why=": the time step would outrun the fastest signal (a Courant number is at most 1)"),
    "impact_velocity_m_s": Rule(high=MAX_IMPACT_VELOCITY_M_S,
                                why=" m/s, faster than any plate-impact launcher (two-stage light-gas guns reach "
                                    "about 8000 m/s); is it in another unit?"),
}


def problem(value, rule: str) -> str | None:
    """What is wrong with `value` under the rule named `rule` (a key of RULES), or None."""
    return RULES[rule].problem(value)


def check(where: str, value, rule: str) -> None:
    """InputError 'where: problem' when `value` breaks the rule named `rule`."""
    found = problem(value, rule)
    if found:
        raise InputError(f"{where}: {found}")


def check_fields(owner, rules: dict[str, str]) -> None:
    """Check an object's fields by name (`rules`: field -> rule; a None value is skipped, the field's
    'not given'), the first problem a SettingsError (an InputError) naming the class and the field."""
    for name, rule in rules.items():
        value = getattr(owner, name)
        found = problem(value, rule) if value is not None else None
        if found:
            raise SettingsError(f"{type(owner).__name__}.{name}: {found}", name, found)


def melting_problem(T_ref_K: float, T_melt_K: float) -> str | None:
    """The homologous temperature T* = (T - T_ref) / (T_melt - T_ref) needs the melting temperature above
    the reference one (at or below it, T* has no meaning or the wrong sign): what is wrong, or None."""
    if not T_melt_K > T_ref_K:
        return (f"T_melt_K ({number(T_melt_K)} K) is not above T_ref_K ({number(T_ref_K)} K); the homologous "
                "temperature (T - T_ref) / (T_melt - T_ref) needs the melting point above the reference temperature")
    return None


def plate_problem(thickness_mm: float, cell_size_um: float) -> str | None:
    """A plate thinner than one cell of the mesh has no cell to compute (the hydrocode would round it up
    to one and answer for a thicker plate): what is wrong, or None."""
    if thickness_mm * 1000.0 < cell_size_um:
        return (f"{number(thickness_mm)} mm is thinner than one cell of the mesh (cell_size_um = "
                f"{number(cell_size_um)} um); take a thicker plate or a smaller cell")
    return None
