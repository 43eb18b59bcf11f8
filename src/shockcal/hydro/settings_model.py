"""The base of the library's settings that are also config sections: a frozen pydantic model whose fields
carry their default, rule, unit and description once (`setting`), checked by the hydrocode's own rules
(`shockcal.hydro.rules`) and rendered into the config schema (`schema_properties`).

A bad value is one InputError line naming the class and the field, never a pydantic traceback.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from shockcal.errors import InputError
from shockcal.hydro.rules import check_fields

RULE = "x-rule"


def setting(default, description: str, rule: str | None = None, unit: str | None = None):
    """A settings field: its `default`, its `description` (the config page's text), the name of its rule in
    `shockcal.hydro.rules.RULES` (None: any value of its type) and its unit when its name does not say it."""
    extra = {key: value for key, value in ((RULE, rule), ("x-unit", unit)) if value is not None}
    return Field(default, description=description, json_schema_extra=extra or None)


class SettingsModel(BaseModel):
    """Frozen, no unknown fields; every field with an `x-rule` checked by that rule on creation."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    def __init__(self, **values):
        try:
            super().__init__(**values)
        except ValidationError as exc:
            error = exc.errors()[0]
            where = ".".join(str(part) for part in error["loc"])
            raise InputError(f"{type(self).__name__}.{where}: {error['msg']}") from None

    def replace(self, **changes):
        """A copy with `changes` (field names and values), checked like a new one (pydantic's model_copy is not)."""
        return type(self)(**{**self.model_dump(), **changes})

    @model_validator(mode="after")
    def _check_rules(self):
        check_fields(self, {name: extra[RULE] for name, extra in _extras(type(self)).items() if RULE in extra})
        return self


def _extras(model: type[SettingsModel]) -> dict[str, dict]:
    return {name: dict(field.json_schema_extra or {}) for name, field in model.model_fields.items()}


def schema_properties(model: type[SettingsModel], required: list[str] = ()) -> dict[str, dict]:
    """The config schema's `properties` of `model`'s fields, in the schema's own words (`type`, `x-rule`,
    `x-unit`, `default`, `description`); a key the config section `required` gets no default."""
    types = {float: "number", int: "integer", bool: "boolean", str: "string"}
    properties = {}
    for name, field in model.model_fields.items():
        entry = {"type": types[field.annotation], **_extras(model)[name]}
        if name not in required:
            entry["default"] = field.default
        entry["description"] = field.description
        properties[name] = entry
    return properties
