"""Which inputs matter: the study config's `sensitivity` section as a settings model (its fields' defaults,
limits and descriptions once; the config schema's entries are generated from them,
`shockcal.settings_model`)."""

from __future__ import annotations

from pydantic import field_validator
from pydantic_core import PydanticCustomError

from shockcal.settings_model import SettingsModel, setting


def is_power_of_two(n: int) -> bool:
    """Whether a Saltelli base sample `n` balances a Sobol sequence: a power of 2 (2, 4, 8, ...)."""
    return n >= 2 and not n & (n - 1)


class SensitivitySettings(SettingsModel):
    """The emulator's Sobol indices (`shockcal.campaign.sensitivity.emulator_sobol`, `shockcal sensitivity`)."""

    n_base: int = setting(1024, "Saltelli base sample, a power of 2: N (d + 2) emulator predictions per shot and "
                                "domain.", ge=64)
    resamples: int = setting(100, "Bootstrap resamples of the indices' 95% intervals.", ge=10)

    @field_validator("n_base")
    @classmethod
    def _a_power_of_two(cls, n_base: int) -> int:
        if not is_power_of_two(n_base):
            raise PydanticCustomError("power_of_two", "{n_base} is not a power of 2 (Sobol sequences balance only "
                                                      "then)", {"n_base": n_base})
        return n_base
