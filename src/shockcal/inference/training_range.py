"""Measured features against the training runs: a calibration feature far outside every run the emulator
was trained on stops the calibration before it starts (`check_training_range`).

The emulator only interpolates: a measured feature outside the training runs' range has no inputs in the
prior box that reproduce it, and the posterior comes back as the prior box with nothing saying why (a
misread record, another shot's features, a box that misses the material). The rule: each calibration
feature of each shot must lie in the training runs' [min, max] widened on each side by `RANGE_MARGIN`
of its width. The widening leaves room for a measurement's own noise and read-out error at the range's
edge (1% of a 70-500 m/s feature is 0.7-5 m/s; a 40-run design's range is 10-90 m/s wide, so the margin
is 2.5-22 m/s) and for a design of few runs, whose range is narrower than the box's; docs/calibration.md
measures it on the paper's shots.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shockcal.errors import InputError

log = logging.getLogger("shockcal.inference.training_range")
RANGE_MARGIN = 0.25           # share of the training range's width added on each side
OPT_OUT = "checks.features_in_training_range: false"


@dataclass(frozen=True)
class TrainingRange:
    """One feature's range over a shot's training runs (m/s) and the band a measurement must lie in.

    Args:
        low_m_s, high_m_s: the training runs' smallest and largest value (m/s).
        margin: share of high - low added on each side for the band (`RANGE_MARGIN`).
    """

    low_m_s: float
    high_m_s: float
    margin: float = RANGE_MARGIN

    def band(self) -> tuple[float, float]:
        """The accepted band (m/s): [low, high] widened by `margin` of its width on each side."""
        pad = self.margin * (self.high_m_s - self.low_m_s)
        return self.low_m_s - pad, self.high_m_s + pad

    def distance(self, value_m_s: float) -> float:
        """How far `value_m_s` lies outside [low, high], in units of its width (0 inside; a value beyond
        the band has a distance above `margin`)."""
        width = max(self.high_m_s - self.low_m_s, np.finfo(float).tiny)
        return max(self.low_m_s - value_m_s, value_m_s - self.high_m_s, 0.0) / width


def training_ranges(training: Mapping[str, pd.DataFrame], features, margin: float = RANGE_MARGIN
                    ) -> dict[str, dict[str, TrainingRange]]:
    """Per shot and feature, the range of the training runs' values (finite ones; m/s).

    Args:
        training: shot -> its training runs' features (a column per feature, m/s), e.g.
            `Emulator.training_features(shot)` or a features table's rows with status "ok".
        features: the feature columns to range.
        margin: the band's widening (`RANGE_MARGIN`).
    """
    ranges = {}
    for shot, table in training.items():
        ranges[shot] = {}
        for feature in features:
            values = pd.to_numeric(table[feature], errors="coerce").to_numpy(float)
            values = values[np.isfinite(values)]
            if values.size:
                ranges[shot][feature] = TrainingRange(float(values.min()), float(values.max()), margin)
    return ranges


def outside_training_range(observed: Mapping[str, Mapping[str, float]],
                           ranges: Mapping[str, Mapping[str, TrainingRange]]) -> list[tuple[str, str, float, TrainingRange]]:
    """(shot, feature, value m/s, its training range) for each measured feature outside its band."""
    found = []
    for shot, values in observed.items():
        for feature, value in values.items():
            limits = ranges.get(shot, {}).get(feature)
            if limits is None or not np.isfinite(value):
                continue
            low, high = limits.band()
            if not low <= value <= high:
                found.append((shot, feature, float(value), limits))
    return found


def describe(shot: str, feature: str, value_m_s: float, limits: TrainingRange, n_runs: int | None = None) -> str:
    """One line naming the shot, the feature, the measured value and the training range (m/s)."""
    runs = f"{n_runs} " if n_runs else ""
    return (f"shot {shot}: measured {feature} = {value_m_s:.1f} m/s is outside the range of all {runs}training runs "
            f"[{limits.low_m_s:.1f}, {limits.high_m_s:.1f}] m/s (by {limits.distance(value_m_s):.2f} of its width; "
            f"accepted up to {limits.margin:g}): the emulator cannot reproduce it, and the posterior would be the "
            "prior box")


def check_training_range(observed: Mapping[str, Mapping[str, float]], training: Mapping[str, pd.DataFrame],
                         where: str, enabled: bool = True, margin: float = RANGE_MARGIN, error=InputError) -> None:
    """Stop (raise `error`, one line naming `where`, the shot, the feature, its value and the training range)
    when a measured feature lies outside its training runs' band (`training_ranges`); with `enabled`
    False (config `checks.features_in_training_range: false`: the user says it is intended), log a
    warning for each instead.

    Args:
        observed: shot -> {feature: measured value (m/s)}.
        training: shot -> its training runs' features (a column per feature, m/s); a shot without
            training runs here is not checked.
        where: names the measurement (the observed table) in the message.
        enabled: whether a feature outside stops (True) or warns (False).
        margin: the band's widening, a share of the range's width on each side (`RANGE_MARGIN`).
        error: the exception raised (InputError; ConfigError where a config's values are checked).
    """
    features = sorted({feature for values in observed.values() for feature in values})
    shots = {shot: table for shot, table in training.items() if shot in observed}
    ranges = training_ranges(shots, features, margin)
    for shot, feature, value, limits in outside_training_range(observed, ranges):
        line = f"{where}: {describe(shot, feature, value, limits, len(shots[shot]))}"
        if enabled:
            raise error(f"{line}; a misread record or another shot's features? If it is intended, set {OPT_OUT}")
        log.warning("%s (accepted: %s)", line, OPT_OUT)
