"""Global sensitivity of the emulated features to the inputs: Sobol indices with SALib.

`sobol_indices(function, names, lower, upper, ...)` estimates, for each output of a vectorised
function on a box, the first-order index S1 (the share of the output's variance explained by one input
alone) and the total index ST (its share with every interaction it takes part in), each with a
bootstrap confidence half-width: Saltelli's sampling on a scrambled Sobol sequence, N (d + 2)
evaluations for d inputs, and the Jansen / Saltelli 2010 estimators (SALib 1.6's `sample.sobol`,
`analyze.sobol`, second-order indices off).

`emulator_sobol(emulator, shots, bounds, ...)` does it for the study's emulator: per shot, its
calibration features (the emulator's predictive mean, m/s) against the inputs that shot reads
(`Emulator.required_inputs`), on the box `bounds`.

Sobol indices are defined for independent inputs. On the prior box they are. A posterior's inputs are
not independent (the joint posterior's A-m arm), and resampled posterior draws cannot feed Saltelli's
scheme, which recombines the coordinates of independent points. `posterior_box` therefore gives the
box of a posterior's 5-95% quantiles, and the indices on it answer: "near the posterior, with each
input varied over its posterior range independently of the others, which inputs move each feature?".
That box holds points the posterior rules out (A high with m high), so these are indices of the
emulator over the posterior's neighbourhood, not variance shares of the posterior predictive.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping

import numpy as np
import pandas as pd

from shockcal.campaign.settings import is_power_of_two
from shockcal.errors import InputError

COLUMNS = ["input", "S1", "S1_conf", "ST", "ST_conf"]
log = logging.getLogger("shockcal.campaign.sensitivity")


def sobol_indices(function: Callable[[np.ndarray], np.ndarray], names: list[str], lower, upper, n_base: int,
                  seed: int, outputs: list[str] | None = None, resamples: int = 100,
                  conf_level: float = 0.95) -> pd.DataFrame:
    """First-order and total Sobol indices of each output of `function` on a box of independent uniform inputs.

    Args:
        function: (N, d) points, in the box's units, -> (N,) or (N, k) outputs.
        names: the d inputs.
        lower, upper: (d,) the box.
        n_base: Saltelli's base sample N (a power of 2); `function` sees N (d + 2) points.
        seed: the Sobol sequence's scrambling and the bootstrap's seed.
        outputs: names of the k outputs (default "y0", "y1", ...).
        resamples: bootstrap resamples of the confidence intervals.
        conf_level: their level; S1_conf and ST_conf are half-widths.

    Returns:
        One row per output and input: `output`, `input`, `S1`, `S1_conf`, `ST`, `ST_conf`. An output
        that does not vary over the box has NaN indices (logged).
    """
    from SALib.analyze import sobol as analyze
    from SALib.sample import sobol as sample

    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    if len(lower) != len(names) or len(upper) != len(names):
        raise InputError(f"Sobol indices: {len(names)} inputs but a box of {len(lower)} and {len(upper)} bounds")
    if not np.all(upper > lower):
        bad = [n for n, lo, hi in zip(names, lower, upper) if not hi > lo]
        raise InputError(f"Sobol indices: empty box for inputs {bad} (upper must exceed lower)")
    if not is_power_of_two(n_base):
        raise InputError(f"Sobol indices: n_base {n_base} is not a power of 2 (Sobol sequences balance only then)")
    problem = {"num_vars": len(names), "names": list(names), "bounds": np.column_stack([lower, upper]).tolist()}
    points = sample.sample(problem, n_base, calc_second_order=False, scramble=True, seed=seed)
    values = np.asarray(function(points), float).reshape(len(points), -1)
    outputs = outputs or [f"y{j}" for j in range(values.shape[1])]
    if len(outputs) != values.shape[1]:
        raise InputError(f"Sobol indices: {len(outputs)} output names for {values.shape[1]} outputs")
    parts = []
    for j, output in enumerate(outputs):
        y = values[:, j]
        if not np.all(np.isfinite(y)):
            raise InputError(f"Sobol indices: output {output} is not finite at {int(np.sum(~np.isfinite(y)))} points")
        if np.ptp(y) <= 1e-12 * max(1.0, np.max(np.abs(y))):
            log.info("output %s does not vary over the box: indices NaN", output)
            table = pd.DataFrame({"input": names, **{c: np.nan for c in COLUMNS[1:]}})
        else:
            result = analyze.analyze(problem, y, calc_second_order=False, num_resamples=resamples,
                                     conf_level=conf_level, seed=seed)
            table = pd.DataFrame({"input": names, "S1": result["S1"], "S1_conf": result["S1_conf"],
                                  "ST": result["ST"], "ST_conf": result["ST_conf"]})
        parts.append(table.assign(output=output))
    return pd.concat(parts, ignore_index=True)[["output", *COLUMNS]]


def posterior_box(summary: pd.DataFrame, names: list[str], columns: Mapping[str, tuple[str, str, float]] | None = None,
                  low: str = "q05", high: str = "q95") -> dict[str, tuple[float, float]]:
    """The box of a posterior's quantiles in the inputs' native units: input -> (`low`, `high`) from its
    summary table (`parameter`, and the quantile columns, e.g. `Posterior.summary()`'s weighted q05 and q95).

    Args:
        summary: the summary table, its rows in user units (`Posterior.summary()`).
        names: the inputs (native names).
        columns: input -> (its row's name, its user unit, the factor from native to user units;
            `shockcal.units.user_columns`); None: rows named and valued as the inputs.
    """
    missing = [c for c in ["parameter", low, high] if c not in summary.columns]
    if missing:
        raise InputError(f"posterior summary: columns {missing} missing")
    table = summary.set_index("parameter")
    row = {n: (n, "", 1.0) if columns is None else columns[n] for n in names}
    absent = [row[n][0] for n in names if row[n][0] not in table.index]
    if absent:
        raise InputError(f"posterior summary: no rows for inputs {absent}")
    return {n: (float(table.loc[row[n][0], low]) / row[n][2], float(table.loc[row[n][0], high]) / row[n][2])
            for n in names}


def emulator_sobol(emulator, shots: list[str], bounds: Mapping[str, tuple[float, float]], n_base: int, seed: int,
                   resamples: int = 100, conf_level: float = 0.95, batch: int = 4096) -> pd.DataFrame:
    """Sobol indices of each shot's emulated calibration features (predictive mean, m/s) with respect to
    the inputs the shot reads, on the box `bounds`.

    Args:
        emulator: the study's `shockcal.emulator.study_emulator.Emulator`.
        shots: the shots, each analysed on its own inputs.
        bounds: design input -> (lower, upper), native units; every input the shots read.
        n_base: Saltelli's base sample (power of 2); each shot costs n_base (d + 2) emulator predictions.
        seed: the sampling's and bootstrap's seed (the same for every shot).
        resamples, conf_level: the bootstrap (`sobol_indices`).
        batch: predictions per emulator call (bounds the covariance arrays' memory).

    Returns:
        `shot`, `feature`, `input`, `S1`, `S1_conf`, `ST`, `ST_conf`.
    """
    parts = []
    for shot in shots:
        names = emulator.required_inputs([shot])
        absent = [n for n in names if n not in bounds]
        if absent:
            raise InputError(f"Sobol indices of {shot}: no bounds for inputs {absent}")

        def features(points, names=names, shot=shot):
            means = [emulator.predict(dict(zip(names, chunk.T)), [shot])[0]
                     for chunk in np.array_split(points, max(1, -(-len(points) // batch)))]
            return np.concatenate(means)

        table = sobol_indices(features, names, [bounds[n][0] for n in names], [bounds[n][1] for n in names], n_base,
                              seed, outputs=list(emulator.feature_names), resamples=resamples, conf_level=conf_level)
        parts.append(table.rename(columns={"output": "feature"}).assign(shot=shot))
    return pd.concat(parts, ignore_index=True)[["shot", "feature", *COLUMNS]]
