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


def setting(default, description: str, rule: str | None = None, unit: str | None = None, section: str | None = None,
            optional: bool = False):
    """A settings field: its `default` (`...`: required), its `description` (the config page's text), the name of
    its rule in `shockcal.hydro.rules.RULES` (None: any value of its type), its unit when its name does not say
    it, the config `section` it is a key of when that is not the model's own and whether the config may leave it
    out to say "not given" (`optional`, default None; `shockcal.settings_model.setting`)."""
    return base_setting(default, description, unit, section=section, optional=optional,
                        extra={RULE: rule} if rule is not None else None)


class SettingsModel(BaseSettingsModel):
    """The shared settings base, with every field that names an `x-rule` checked by that rule on creation."""

    @model_validator(mode="after")
    def _check_rules(self):
        """The first field (not None) that breaks its rule: a SettingsError naming the class and the field."""
        check_fields(self, {name: extra[RULE] for name, extra in schema_extras(type(self)).items() if RULE in extra})
        return self
