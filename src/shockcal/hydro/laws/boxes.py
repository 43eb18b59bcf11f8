"""Literature prior boxes of the strength laws (config/models.yaml): per law, per parameter (user
units), `low`, `high` and where known `nominal`; each value's source is a comment in the file."""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import yaml

from shockcal.errors import ConfigError
from shockcal.hydro.laws.declarations import LAWS

MODELS_YAML = Path(__file__).resolve().parents[4] / "config" / "models.yaml"


class Box(NamedTuple):
    low: float
    high: float
    nominal: float | None


def load_boxes(path: str | Path = MODELS_YAML) -> dict[str, dict[str, Box]]:
    """{law: {parameter: Box}}; ConfigError naming the key for an unknown law or parameter, a
    missing bound, low >= high or a nominal outside its box."""
    raw = yaml.safe_load(Path(path).read_text())
    boxes: dict[str, dict[str, Box]] = {}
    for law_name, entry in raw.items():
        if law_name not in LAWS:
            raise ConfigError(f"{path}: {law_name}: not a strength law ({', '.join(LAWS)})")
        known = LAWS[law_name].names()
        boxes[law_name] = {}
        for name, spec in (entry.get("parameters") or {}).items():
            where = f"{path}: {law_name}.parameters.{name}"
            if name not in known:
                raise ConfigError(f"{where}: not a parameter of {law_name} ({', '.join(known)})")
            if not isinstance(spec, dict) or "low" not in spec or "high" not in spec:
                raise ConfigError(f"{where}: needs low and high")
            box = Box(float(spec["low"]), float(spec["high"]),
                      None if spec.get("nominal") is None else float(spec["nominal"]))
            if not box.low < box.high:
                raise ConfigError(f"{where}: low {box.low} is not below high {box.high}")
            if box.nominal is not None and not box.low <= box.nominal <= box.high:
                raise ConfigError(f"{where}: nominal {box.nominal} outside [{box.low}, {box.high}]")
            boxes[law_name][name] = box
    return boxes
