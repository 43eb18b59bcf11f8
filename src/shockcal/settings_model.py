"""The base of the library's settings that are also config sections: a frozen pydantic model whose fields
carry their default, limits, unit and description once (`setting`), rendered into the config schema's
entries for the section (`schema_properties`).

A field's choices are its type (`Literal["a", "b"]`: the schema's `enum`), its limits pydantic's `ge`, `gt`,
`le`, `lt` (the schema's `minimum`, `exclusiveMinimum`, `maximum`, `exclusiveMaximum`), so the config and
the library refuse the same values. A bad value is one InputError line naming the class and the field (an
unknown one with the closest field, as the config's "did you mean"), never a pydantic traceback. It sits
beside `shockcal.errors` on the ground floor: the hydrocode's settings (`shockcal.hydro.settings_model` adds
its physical rules), the emulator's and the extractor's build on it.
"""

from __future__ import annotations

import difflib
from types import UnionType
from typing import Annotated, Literal, get_args, get_origin

import annotated_types
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator
from pydantic_core import PydanticCustomError

from shockcal.errors import InputError, shown

KEY = "x-key"            # a field the config gives by a key of its own (e.g. `study.seed`), not generated
SECTION = "x-section"    # a field that is a key of another config section than the model's own (generated there)
OPTIONAL = "x-optional"  # a field the config may leave out (None: not given), with no default and no null
TYPES = {float: "number", int: "integer", bool: "boolean", str: "string", int | float: "number"}
LIMITS = ((annotated_types.Ge, "ge", "minimum"), (annotated_types.Gt, "gt", "exclusiveMinimum"),
          (annotated_types.Le, "le", "maximum"), (annotated_types.Lt, "lt", "exclusiveMaximum"),
          (annotated_types.MinLen, "min_length", "minItems"), (annotated_types.MaxLen, "max_length", "maxItems"))


def setting(default, description: str, unit: str | None = None, key: str | None = None, section: str | None = None,
            extra: dict | None = None, optional: bool = False, **limits):
    """A settings field: its `default` (`...`: required), its `description` (the config page's text), its unit
    when its name does not say it, the config `key` that gives it when no section of the model's holds it (e.g.
    `study.seed`: not generated), the config `section` it is a key of when that is not the model's own
    (dotted, `*` for every key of a mapping: `shots.*.analysis`; generated there), further schema keywords
    `extra` (`x-...`), whether it is `optional` (default None: the config leaves it out to say "not given"; its
    schema entry has no default and no null) and its `limits` (pydantic's ge, gt, le, lt; a list's min_length,
    max_length)."""
    schema = {name: value for name, value in (("x-unit", unit), (KEY, key), (SECTION, section),
                                              (OPTIONAL, optional or None)) if value is not None}
    return Field(default, description=description, json_schema_extra=(schema | (extra or {})) or None, **limits)


class SettingsError(InputError):
    """A value a settings model refuses: the message names the class and the field; `field` and `reason` are
    those parts, for a door that names the value by its config key (`shockcal.study.validate`)."""

    def __init__(self, message: str, field: str, reason: str):
        super().__init__(message)
        self.field, self.reason = field, reason


class SettingsModel(BaseModel):
    """Frozen, no unknown fields; a wrong type, choice or limit is one SettingsError line naming the field."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    def __init__(self, **values):
        try:
            super().__init__(**values)
        except ValidationError as exc:
            error = exc.errors()[0]
            where = error["loc"][0]      # a field (a union's member after it: n_components.int; a mapping's key)
            if get_origin(type(self).model_fields.get(where, Field()).annotation) is dict and len(error["loc"]) > 1:
                where = f"{where}.{error['loc'][1]}"
            value = "" if error["type"] == "missing" else f" {_shown(error['input'])}"
            close = difflib.get_close_matches(str(where), list(type(self).model_fields), n=1)
            hint = f"; did you mean '{close[0]}'?" if error["type"] == "extra_forbidden" and close else ""
            reason = "missing" if error["type"] == "missing" else f"{error['msg']}{hint}"     # the config's word
            raise SettingsError(f"{type(self).__name__}.{where}{value}: {reason}", str(where), reason) from None

    @field_validator("*", mode="before")
    @classmethod
    def _config_types(cls, value, info):
        """The config's types (JSON Schema's): a flag is true or false, a number is no text and no flag (pydantic
        alone would read "2" as 2, "yes" as true and true as 1, which the config refuses)."""
        annotation = _without_none(cls.model_fields[info.field_name].annotation)
        if annotation is bool and not isinstance(value, bool):
            raise PydanticCustomError("config_type", "not true or false")
        if annotation in (int, float, int | float) and isinstance(value, bool | str):
            raise PydanticCustomError("config_type", "not a number")
        return value

    @classmethod
    def from_section(cls, values: dict, **more):
        """The model of a config section's `values`: the model's own fields the section gives (`section_fields`;
        the keys of a section nested in it are another model's), and `more` (a field a key of its own gives)."""
        return cls(**{name: values[name] for name in section_fields(cls) if name in values}, **more)

    def replace(self, **changes):
        """A copy with `changes` (field names and values), checked like a new one (pydantic's model_copy is not)."""
        return type(self)(**{**self.model_dump(), **changes})


def _without_none(annotation):
    """A value-or-null type's value type (`float | None`: float); any other type as it is."""
    if get_origin(annotation) is UnionType and type(None) in get_args(annotation):
        members = [member for member in get_args(annotation) if member is not type(None)]
        return members[0] if len(members) == 1 else annotation
    return annotation


def _shown(value) -> str:
    """A value as the config writes it: true, null, 0.5, 'text'."""
    return "null" if value is None else str(value).lower() if isinstance(value, bool) else shown(value)


def schema_extras(model: type[SettingsModel]) -> dict[str, dict]:
    """{field: its schema keywords given to `setting` (x-unit, x-key, extra)}."""
    return {name: dict(field.json_schema_extra or {}) for name, field in model.model_fields.items()}


def section_fields(model: type[SettingsModel], section: str | None = None) -> list[str]:
    """The fields of `model` that are keys of config section `section` (`setting(section=...)`); None: of the
    model's own section (the fields that name no other section and no key of their own)."""
    return [name for name, extra in schema_extras(model).items() if KEY not in extra and extra.get(SECTION) == section]


def other_sections(model: type[SettingsModel]) -> list[str]:
    """The config sections besides its own that `model`'s fields are keys of (`setting(section=...)`)."""
    return list(dict.fromkeys(extra[SECTION] for extra in schema_extras(model).values() if SECTION in extra))


def schema_properties(model: type[SettingsModel], required: list[str] = (), section: str | None = None
                      ) -> dict[str, dict]:
    """The config schema's `properties` of `model`'s fields in config `section` (None: its own), in the
    schema's own words (`type` or `enum`, the limits, the `x-` keywords but x-section, `default`,
    `description`); a key the config section `required` gets no default, nor an optional field (`setting`'s
    `optional`: left out, it is not given)."""
    properties = {}
    for name in section_fields(model, section):
        field, extras = model.model_fields[name], schema_extras(model)[name]
        entry = _value_schema(_without_none(field.annotation) if extras.get(OPTIONAL) else field.annotation,
                              field.metadata)
        entry |= {keyword: value for keyword, value in extras.items() if keyword not in (SECTION, OPTIONAL)}
        if name not in required and not extras.get(OPTIONAL):
            entry["default"] = field.default
        entry["description"] = field.description
        properties[name] = entry
    return properties


def _value_schema(annotation, metadata=()) -> dict:
    """A value's schema: `enum` for a Literal, `type` and the limits in `metadata` for a number, flag or text, a
    mapping of names to such values (`dict[str, Annotated[float, Field(ge=1, description=...)]]`) as an
    object whose `additionalProperties` is the values' schema (with their description), a list (`list[str]`) as
    an array of its items' schema, a value or null (`str | None`) as the value's with the type null beside."""
    if get_origin(annotation) is Annotated:     # a value type with its Field (limits, description)
        value, info = get_args(annotation)
        return _value_schema(value, info.metadata) | ({"description": info.description} if info.description else {})
    if get_origin(annotation) is dict:
        entry = {"type": "object", "additionalProperties": _value_schema(get_args(annotation)[1])}
    elif get_origin(annotation) is list:
        entry = {"type": "array", "items": _value_schema(get_args(annotation)[0])}
    elif get_origin(annotation) is UnionType and type(None) in get_args(annotation):   # a value or null
        entry = _value_schema(*(member for member in get_args(annotation) if member is not type(None)))
        entry |= {"type": [entry["type"], "null"]}
    elif get_origin(annotation) is Literal:
        entry = {"enum": list(get_args(annotation))}
    else:
        entry = {"type": TYPES[annotation]}
    for limit in metadata:
        entry |= {keyword: getattr(limit, attr) for kind, attr, keyword in LIMITS if isinstance(limit, kind)}
    if entry.get("type") == "string":        # a text's length limits: JSON Schema's words for a text
        entry |= {f"{end}Length": entry.pop(f"{end}Items") for end in ("min", "max") if f"{end}Items" in entry}
    return entry
