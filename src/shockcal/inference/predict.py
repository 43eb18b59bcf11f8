"""Posterior predictions: draws from the joint posterior as a design table for hydrocode runs, and
emulator predictions of the calibration features at those draws.

The drawn design has the training design's shape (`run`, then one column per input, Table IV
units), so the workflow runs it through `shockcal simulate` and `shockcal features` unchanged.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

import numpy as np
import pandas as pd

from shockcal.errors import InputError, shown
from shockcal.io import require_columns
from shockcal.plausibility import outside_box

log = logging.getLogger(__name__)


def draw_posterior_design(posterior: pd.DataFrame, names: list[str], n: int, seed: int,
                          source: str = "posterior", bounds: Mapping[str, tuple[float, float]] | None = None,
                          carried: tuple[str, ...] = ()) -> pd.DataFrame:
    """`n` rows drawn (seeded, without replacement when possible) from the posterior samples.

    Args:
        posterior: equal-weight posterior draws (one column per input, native units).
        names: the design's inputs, in order (every input of the study: a joint posterior).
        n: rows to draw.
        seed: the draw's seed.
        source: names `posterior` in errors.
        bounds: the study's prior box by input (native units): every sample must lie in it.
        carried: posterior columns that are not inputs, kept after them when the posterior has them
            (`lambda_y`: a check that takes the draws as truths needs each one's observation precision;
            the hydrocode reads only the inputs).

    Returns a design table: `run` 0..n-1, the inputs `names` and the `carried` columns present. An empty table, a missing input, a
    value that is not a finite number, or a sample outside `bounds` (a posterior of another study or
    box) is an InputError naming `source`, the row and the input.
    """
    if posterior.empty:
        raise InputError(f"{source}: posterior has no samples; cannot draw {n} posterior runs")
    require_columns(posterior, names, source)
    for name in names:
        values = pd.to_numeric(posterior[name], errors="coerce").to_numpy(dtype=float)
        bad = ~np.isfinite(values)
        if bad.any():
            row = int(np.argmax(bad))
            raise InputError(f"{source}: row {row}: {name} = {shown(posterior[name].iloc[row])} is not a finite number")
        if bounds is not None and name in bounds:
            low, high = bounds[name]
            outside = outside_box(values, low, high)
            if outside.any():
                row = int(np.argmax(outside))
                raise InputError(f"{source}: row {row}: {name} = {values[row]:g} is outside the prior box inputs.{name} "
                                 f"[{low:g}, {high:g}] ({int(outside.sum())} of {len(values)} samples): a posterior "
                                 "of another box or study?")
    replace = len(posterior) < n
    if replace:
        log.warning("%s: only %d samples for %d posterior runs; drawing with replacement", source, len(posterior), n)
    rows = np.random.default_rng(seed).choice(len(posterior), size=n, replace=replace)
    columns = [*names, *(name for name in carried if name in posterior.columns)]
    design = posterior.iloc[np.sort(rows)][columns].reset_index(drop=True).astype(float)
    design.insert(0, "run", np.arange(n, dtype=np.int64))
    return design


def emulator_predictions(emulator, design: pd.DataFrame, shots: list[str]) -> pd.DataFrame:
    """Emulator mean and sd (m/s) of the calibration features at every design row, for each shot.

    One row per (run, shot): `run`, `shot`, the features (e.g. `v_elastic`, the predictive mean)
    and their predictive sd (`v_elastic_sd`, emulator uncertainty, no observation error).
    """
    inputs = {name: design[name].to_numpy(float) for name in design.columns if name != "run"}
    mean, cov = emulator.predict(inputs, shots)
    sd = np.sqrt(np.clip(np.diagonal(cov, axis1=1, axis2=2), 0.0, None))
    names = list(emulator.feature_names)
    parts = []
    for i, shot in enumerate(shots):
        cols = slice(len(names) * i, len(names) * (i + 1))
        part = pd.DataFrame(mean[:, cols], columns=names)
        part[[f"{n}_sd" for n in names]] = sd[:, cols]
        part.insert(0, "shot", shot)
        part.insert(0, "run", design["run"].to_numpy())
        parts.append(part)
    return pd.concat(parts, ignore_index=True)
