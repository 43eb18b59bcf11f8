"""Sequential design in waves: a later wave's runs placed where the current joint posterior lives.

Wave 0 is a Latin hypercube over the prior box (`shockcal.design.tables.latin_hypercube`). Each later
wave draws a pool of candidates from the previous wave's joint posterior (equal-weight draws, every
input of the study, Table IV units), optionally widened about the posterior mean, and keeps the
candidates that are farthest from every run made so far and from each other (greedy maximin in the
prior box scaled to [0, 1]): the posterior thinned for space filling. With the `max_variance`
criterion only the candidates where the emulator's predictive variance, relative to the observation
error, is highest enter the thinning. A design row has every input, so each shot reads its own
velocity and modulus inputs from it (`ShotMapping`), as in the training design.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from shockcal.design.posterior_draws import draw_posterior_design
from shockcal.design.tables import extend_design
from shockcal.errors import InputError

CRITERIA = ("posterior_thinned", "max_variance")


def scaled_inputs(design: pd.DataFrame, bounds: Mapping[str, tuple[float, float]]) -> np.ndarray:
    """(N, d) design inputs scaled to [0, 1] by the prior box `bounds` (input -> (min, max), native units)."""
    lower, upper = np.array(list(bounds.values()), dtype=float).T
    return (design[list(bounds)].to_numpy(dtype=float) - lower) / (upper - lower)


def widened(unit: np.ndarray, factor: float) -> np.ndarray:
    """Points in [0, 1]^d moved away from their mean by `factor` (1: unchanged), reflected at the box's
    faces, so the widened cloud stays inside the prior box."""
    moved = unit.mean(axis=0) + factor * (unit - unit.mean(axis=0))
    moved = np.abs(moved)                       # reflect below 0
    moved = 1.0 - np.abs(1.0 - moved)           # reflect above 1
    return np.clip(moved, 0.0, 1.0)


def maximin_subset(candidates: np.ndarray, existing: np.ndarray, n: int) -> np.ndarray:
    """Indices of `n` rows of `candidates` (M, d) picked greedily, each the candidate farthest from the
    `existing` points (K, d; K may be 0) and from those picked before it (Euclidean)."""
    if n > len(candidates):
        raise InputError(f"{n} runs asked of a pool of {len(candidates)} candidates")
    nearest = np.full(len(candidates), np.inf)
    for point in existing:
        nearest = np.minimum(nearest, np.sum((candidates - point) ** 2, axis=1))
    picked = []
    for _ in range(n):
        i = int(np.argmax(nearest))
        picked.append(i)
        nearest = np.minimum(nearest, np.sum((candidates - candidates[i]) ** 2, axis=1))
        nearest[i] = -1.0
    return np.array(picked, dtype=np.int64)


def relative_variance(emulator, pool: pd.DataFrame, shots, observed_sd_m_s: np.ndarray) -> np.ndarray:
    """Per pool row: the emulator's predictive variance of every calibrated feature of `shots` over the
    observation variance, summed (what the emulator adds to the likelihood's error there).

    Args:
        emulator: the study's `Emulator`.
        pool: candidate design rows (every input the shots read, native units).
        shots: the calibrated shots.
        observed_sd_m_s: the observation sd of each feature, shot after shot (m/s; 4 per shot).
    """
    _, cov = emulator.predict({name: pool[name].to_numpy(float) for name in pool.columns if name != "run"}, shots)
    return np.sum(np.diagonal(cov, axis1=1, axis2=2) / np.asarray(observed_sd_m_s) ** 2, axis=1)


def wave_design(posterior: pd.DataFrame, bounds: Mapping[str, tuple[float, float]], n_runs: int, first_run: int,
                seed: int, existing: pd.DataFrame | None = None, widen: float = 1.0, pool_size: int = 4000,
                criterion: str = "posterior_thinned", variance=None, variance_share: float = 0.25,
                source: str = "posterior") -> pd.DataFrame:
    """One later wave's design: `n_runs` rows, run ids from `first_run`, every input of `bounds`.

    Args:
        posterior: the previous wave's joint posterior, equal-weight draws (native units).
        bounds: the prior box by input, in the design's column order (native units).
        n_runs: runs in the wave (0: an empty design).
        first_run: the first run id (one past the largest id so far: ids stay unique over the waves).
        seed: the pool's seed.
        existing: the runs made so far (design rows); the wave keeps away from them.
        widen: the factor the posterior pool is widened by about its mean (1: the posterior as it is).
        pool_size: candidates drawn from the posterior (with replacement when it has fewer draws).
        criterion: "posterior_thinned" (maximin over the whole pool) or "max_variance" (maximin over
            the `variance_share` of the pool where `variance` is largest).
        variance: with max_variance, a function of a candidate table returning one score per row
            (`relative_variance` with the emulator bound).
        variance_share: the share of the pool max_variance keeps, in (0, 1].
        source: names `posterior` in errors.
    """
    if criterion not in CRITERIA:
        raise InputError(f"wave criterion {criterion!r}: one of {', '.join(CRITERIA)}")
    names = list(bounds)
    if n_runs == 0:
        return pd.DataFrame({"run": np.array([], dtype=np.int64), **{name: np.array([], dtype=float) for name in names}})
    pool = draw_posterior_design(posterior, names, max(pool_size, n_runs), seed, source, bounds)
    lower, upper = np.array(list(bounds.values()), dtype=float).T
    unit = widened(scaled_inputs(pool, bounds), widen)
    pool[names] = lower + unit * (upper - lower)
    if criterion == "max_variance":
        if variance is None:
            raise InputError("the max_variance criterion needs the emulator's variance at the candidates")
        score = np.asarray(variance(pool))
        keep = np.argsort(score)[::-1][:max(n_runs, int(round(variance_share * len(pool))))]
        pool, unit = pool.iloc[np.sort(keep)].reset_index(drop=True), unit[np.sort(keep)]
    previous = np.empty((0, len(names))) if existing is None or existing.empty else scaled_inputs(existing, bounds)
    rows = maximin_subset(unit, previous, n_runs)
    design = pool.iloc[rows][names].reset_index(drop=True)
    design.insert(0, "run", np.arange(first_run, first_run + n_runs, dtype=np.int64))
    return design


def new_shot_design(posterior: pd.DataFrame, bounds: Mapping[str, tuple[float, float]],
                    own_bounds: Mapping[str, tuple[float, float]], n_runs: int, first_run: int, seed: int,
                    own_seeds: Mapping[str, int], existing: pd.DataFrame | None = None, widen: float = 1.0,
                    pool_size: int = 4000, source: str = "posterior") -> pd.DataFrame:
    """A shot added to a study: `n_runs` rows where the other shots' joint posterior lives, with the
    shot's own inputs drawn fresh over their box.

    The inputs of `bounds` (those the posterior has: the base shots') are the posterior thinned for
    space filling away from `existing` (`wave_design`, criterion posterior_thinned); each input of
    `own_bounds` (the new shot's impact velocity, a modulus increment only it reads) is a
    one-dimensional Latin hypercube over the rows from its seed in `own_seeds` (`extend_design`).

    Args:
        posterior: the base shots' joint posterior, equal-weight draws (native units).
        bounds: the prior box of the inputs drawn from it (native units), in column order.
        own_bounds: the prior box of the shot's own inputs.
        n_runs: rows; first_run: the first run id (ids unique over the study's runs).
        seed: the posterior pool's seed; own_seeds: input -> its column's seed.
        existing, widen, pool_size, source: as `wave_design`.
    """
    design = wave_design(posterior, bounds, n_runs, first_run, seed, existing=existing, widen=widen,
                         pool_size=pool_size, source=source)
    return extend_design(design, own_bounds, own_seeds)
