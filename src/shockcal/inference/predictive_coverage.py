"""Posterior-predictive coverage of the measured features, with the model discrepancy's share in the
predictive sd and without it, side by side (issue 63).

At each of S posterior draws s, feature i's predictive distribution is Gaussian with the emulator's
mean m_si and variance v_si = emulator_si + noise_si (+ discrepancy_si): the emulator's variance (its
error model's scale times its predictive variance), the observation noise (obs_sd^2 / lambda_y) and
the discrepancy's (the sd fraction times the measured feature, squared). Over the draws, the posterior
predictive is the equal mixture of those S Gaussians. Its CDF at the measured value (the PIT) says
where the measurement falls; it is inside the central 95% band when the PIT lies in [0.025, 0.975].
The band's edges are the mixture's quantiles (bisection on its CDF). The emulator's error is treated
as Gaussian here (a Student-t error model's tails are not in the band).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.errors import InputError
from shockcal.inference.discrepancy import SD_FRACTION_PREFIX
from shockcal.inference.problem import LAMBDA_Y

BISECTION_STEPS = 60     # halvings of the bracket: its width times 2^-60, far below any feature's resolution


def mixture_cdf(x: np.ndarray, mean: np.ndarray, var: np.ndarray) -> np.ndarray:
    """CDF at x (F,) of the equal mixture over S draws of N(mean, var), both (S, F): shape (F,)."""
    return stats.norm.cdf((x[None, :] - mean) / np.sqrt(var)).mean(axis=0)


def mixture_quantile(p: float, mean: np.ndarray, var: np.ndarray) -> np.ndarray:
    """The p-quantile (F,) of the equal mixture over S draws of N(mean, var), both (S, F), by bisection
    between the smallest and largest component quantile (the mixture's lies between them)."""
    z = stats.norm.ppf(p)
    low = (mean + z * np.sqrt(var)).min(axis=0)
    high = (mean + z * np.sqrt(var)).max(axis=0)
    for _ in range(BISECTION_STEPS):
        middle = 0.5 * (low + high)
        below = mixture_cdf(middle, mean, var) < p
        low, high = np.where(below, middle, low), np.where(below, high, middle)
    return 0.5 * (low + high)


def predictive_coverage(observed, mean, emulator_var, noise_var, discrepancy_var=None, shots=None, features=None,
                        level: float = 0.95) -> pd.DataFrame:
    """Where each measured feature falls in its posterior predictive, with and without the discrepancy.

    Args:
        observed: measured features (F,), m/s, shot-major (`features` per shot).
        mean: the emulator's predictive mean at S posterior draws (S, F), m/s.
        emulator_var: its variance there (S, F), (m/s)^2 (the error model's scale applied).
        noise_var: the observation noise's variance at each draw (S, F), (m/s)^2: obs_sd^2 / lambda_y.
        discrepancy_var: the discrepancy's variance at each draw (S, F), (m/s)^2, or None (none: the two
            sides of the table agree).
        shots, features: label the rows (F = len(shots) * len(features)); default "0", "1", ... and "feature".
        level: the central band's probability (0.95).

    Returns:
        One row per shot and feature: `observed_m_s`; with the discrepancy `q_low_m_s`, `q50_m_s`,
        `q_high_m_s` (the band's edges and the median), `pit`, `inside`; the same without it, suffixed
        `_without`; the predictive sd's parts at the draws' root mean variance, `sd_emulator_m_s`,
        `sd_noise_m_s`, `sd_discrepancy_m_s`, and `discrepancy_share`, the discrepancy's share of the
        mean predictive variance.
    """
    y = np.asarray(observed, dtype=float)
    parts = {"mean": mean, "emulator_var": emulator_var, "noise_var": noise_var,
             "discrepancy_var": np.zeros_like(np.asarray(mean, float)) if discrepancy_var is None else discrepancy_var}
    parts = {k: np.atleast_2d(np.asarray(v, dtype=float)) for k, v in parts.items()}
    for name, value in parts.items():
        if value.shape != parts["mean"].shape or value.shape[1:] != y.shape:
            raise InputError(f"predictive coverage: {name} has shape {value.shape}; every part needs (draws, "
                             f"{len(y)}) like the {len(y)} measured features")
        if not np.all(np.isfinite(value)) or (name != "mean" and np.any(value < 0)):
            raise InputError(f"predictive coverage: {name} has a value that is not finite"
                             + ("" if name == "mean" else " or is negative"))
    if not 0 < level < 1:
        raise InputError(f"predictive coverage: level {level!r} is not a probability between 0 and 1")
    mean = parts["mean"]
    base = parts["emulator_var"] + parts["noise_var"]
    if np.any(base <= 0):
        raise InputError("predictive coverage: a draw has zero emulator and noise variance; the band is undefined")
    tail = 0.5 * (1.0 - level)
    shots = [str(s) for s in (shots if shots is not None else range(len(y)))]
    features = list(features) if features is not None else ["feature"]
    if len(shots) * len(features) != len(y):
        raise InputError(f"predictive coverage: {len(shots)} shots x {len(features)} features for {len(y)} values")
    table = pd.DataFrame({"shot": np.repeat(shots, len(features)), "feature": np.tile(features, len(shots)),
                          "observed_m_s": y})
    for suffix, var in (("", base + parts["discrepancy_var"]), ("_without", base)):
        table[f"q_low_m_s{suffix}"] = mixture_quantile(tail, mean, var)
        if not suffix:
            table["q50_m_s"] = mixture_quantile(0.5, mean, var)
        table[f"q_high_m_s{suffix}"] = mixture_quantile(1.0 - tail, mean, var)
        table[f"pit{suffix}"] = mixture_cdf(y, mean, var)
        table[f"inside{suffix}"] = table[f"pit{suffix}"].between(tail, 1.0 - tail)
    table["sd_emulator_m_s"] = np.sqrt(parts["emulator_var"].mean(axis=0))
    table["sd_noise_m_s"] = np.sqrt(parts["noise_var"].mean(axis=0))
    table["sd_discrepancy_m_s"] = np.sqrt(parts["discrepancy_var"].mean(axis=0))
    table["discrepancy_share"] = parts["discrepancy_var"].mean(axis=0) / (base + parts["discrepancy_var"]).mean(axis=0)
    return table


def study_predictive_coverage(emulator, design: pd.DataFrame, shots, observed, obs_sd, source: str = "design",
                              level: float = 0.95) -> pd.DataFrame:
    """`predictive_coverage` of a study's measured features at a design of posterior draws.

    Args:
        emulator: the study's `Emulator` (its predictive mean and covariance, its blocks' error scales).
        design: posterior draws (`shockcal predict`'s design): the inputs `shots` need (native units),
            `lambda_y` and, for a posterior with a discrepancy, its `delta_sd_fraction_<feature>` columns.
        shots: the calibrated shots, in the order of `observed`.
        observed, obs_sd: the measured features and their observation sd (F,), m/s, shot-major (the
            posterior's `observed` and `observed_sd_m_s` metadata).
        source: names `design` in errors.
        level: the central band's probability.
    """
    from shockcal.io import require_columns

    shots = list(shots)
    features = list(emulator.feature_names)
    names = emulator.required_inputs(shots)
    require_columns(design, [*names, LAMBDA_Y], source)
    emulator.check_inside(design, source)
    y, sd = np.asarray(observed, dtype=float), np.asarray(obs_sd, dtype=float)
    mean, cov = emulator.predict({name: design[name].to_numpy(float) for name in names}, shots)
    variance = np.diagonal(cov, axis1=1, axis2=2).copy()
    for cols, error in emulator.error_groups(shots):
        variance[:, cols] *= error.scale
    noise = sd[None, :] ** 2 / design[LAMBDA_Y].to_numpy(float)[:, None]
    fractions = [f"{SD_FRACTION_PREFIX}{feature}" for feature in features]
    discrepancy = None
    if any(name in design.columns for name in fractions):
        require_columns(design, fractions, source)
        discrepancy = (np.tile(design[fractions].to_numpy(float), len(shots)) * np.abs(y)[None, :]) ** 2
    return predictive_coverage(y, mean, variance, noise, discrepancy, shots, features, level)
