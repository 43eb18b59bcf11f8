"""The hydrocode's settings models: the shared settings base (`shockcal.settings_model`: frozen, fields with
their default and description once, rendered into the config schema) whose fields may also name a physical
rule of `shockcal.hydro.rules`, checked on creation and by the config schema (`x-rule`), in the same words.
"""

from __future__ import annotations

from pydantic import model_validator

from shockcal.hydro.rules import check_fields
from shockcal.settings_model import SettingsModel as BaseSettingsModel
from shockcal.settings_model import schema_extras
from shockcal.settings_model import setting as base_setting

RULE = "x-rule"


def setting(default, description: str, rule: str | None = None, unit: str | None = None):
    """A settings field: its `default`, its `description` (the config page's text), the name of its rule in
    `shockcal.hydro.rules.RULES` (None: any value of its type) and its unit when its name does not say it."""
    return base_setting(default, description, unit, extra={RULE: rule} if rule is not None else None)


class SettingsModel(BaseSettingsModel):
    """The shared settings base, with every field that names an `x-rule` checked by that rule on creation."""

    @model_validator(mode="after")
    def _check_rules(self):
        check_fields(self, {name: extra[RULE] for name, extra in schema_extras(type(self)).items() if RULE in extra})
        return self
