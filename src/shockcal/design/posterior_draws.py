"""A design of posterior draws: rows drawn from the joint posterior, in the training design's shape, for
hydrocode runs at posterior draws (posterior predictions, sequential waves, next-shot candidates).

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

log = logging.getLogger("shockcal.design.posterior_draws")


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
