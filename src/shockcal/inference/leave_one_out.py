"""Leave-one-shot-out prediction (issue 63): the posterior of the other shots predicts a left-out shot's
measured features.

The posterior predictive of the left-out shot's features y_L given the others' y_O is, at each posterior
draw s of p(theta, lambda_y, phi | y_O), the Gaussian conditional of the joint model over all shots,

    y ~ N(m_s, S_s),   S_s = C_eta,s + Sigma_y / lambda_y,s (+ Sigma_delta(phi_s)),
    y_L | y_O, s ~ N(m_L + S_LO S_OO^-1 (y_O - m_O), S_LL - S_LO S_OO^-1 S_OL),

so the emulator's cross-shot covariance and the discrepancy's cross-shot correlation (rho) carry what the
other shots' residuals say about the left-out one. Over the draws it is the equal mixture of those
Gaussians (`predictive_coverage.mixture_cdf`). The left-out shot's own inputs (those the other shots do not
need: its impact velocity, its modulus increment) are not in the others' posterior: they are drawn from their
prior, uniform on the study's box, as the calibration's prior has them. The emulator's error is treated as
Gaussian (its error model's scale applied, as in `predictive_coverage`). The discrepancy's sd is a fraction of
each measured feature, the left-out shot's too (`Discrepancy.covariance`): its value sets that scale only.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from shockcal.errors import InputError
from shockcal.inference.discrepancy import RHO_NAME, SD_FRACTION_PREFIX, Discrepancy
from shockcal.inference.predictive_coverage import mixture_cdf, mixture_quantile
from shockcal.inference.problem import LAMBDA_Y


def conditional_prediction(observed, mean, cov, left) -> tuple[np.ndarray, np.ndarray]:
    """The Gaussian conditional of features `left` given the others, at each draw.

    Args:
        observed: the measured features (F,), m/s (only the others' values are read).
        mean: the joint model's mean at S draws (S, F), m/s.
        cov: its covariance there (S, F, F), (m/s)^2: emulator + noise (+ discrepancy).
        left: indices of the left-out features (L,).

    Returns:
        Conditional means (S, L), m/s, and variances (S, L), (m/s)^2.
    """
    y, mean, cov = np.asarray(observed, float), np.atleast_2d(np.asarray(mean, float)), np.asarray(cov, float)
    left = np.asarray(left, dtype=int)
    others = np.setdiff1d(np.arange(len(y)), left)
    s_oo = cov[:, others[:, None], others[None, :]]
    s_lo = cov[:, left[:, None], others[None, :]]
    try:
        chol = np.linalg.cholesky(s_oo)
    except np.linalg.LinAlgError:
        raise InputError("leave-one-shot-out: a draw's covariance of the other shots' features is not positive "
                         "definite") from None
    solve = np.linalg.solve
    a = solve(chol, s_lo.transpose(0, 2, 1))                        # L^-1 S_OL, (S, O, L)
    r = solve(chol, (y[others][None, :] - mean[:, others])[:, :, None])[:, :, 0]     # L^-1 (y_O - m_O)
    cond_mean = mean[:, left] + np.einsum("sol,so->sl", a, r)
    cond_var = np.diagonal(cov[:, left[:, None], left[None, :]], axis1=1, axis2=2) - (a ** 2).sum(axis=1)
    return cond_mean, cond_var


def mixture_table(observed, cond_mean, cond_var, level: float = 0.95) -> pd.DataFrame:
    """Where each left-out feature falls in the mixture over draws of N(cond_mean, cond_var), (S, L).

    Returns one row per feature: `observed_m_s`, the mixture's `mean_m_s` and `sd_m_s` (total variance),
    `z` = (observed - mean) / sd, the central band's edges `q_low_m_s`, `q_high_m_s`, `pit` (the mixture's
    CDF at the observed value) and `inside` (the PIT within the band)."""
    y = np.asarray(observed, dtype=float)
    if np.any(cond_var <= 0) or not np.all(np.isfinite(cond_var)):
        raise InputError("leave-one-shot-out: a conditional variance is not positive")
    tail = 0.5 * (1.0 - level)
    mean = cond_mean.mean(axis=0)
    sd = np.sqrt(cond_var.mean(axis=0) + cond_mean.var(axis=0))
    pit = mixture_cdf(y, cond_mean, cond_var)
    return pd.DataFrame({"observed_m_s": y, "mean_m_s": mean, "sd_m_s": sd, "z": (y - mean) / sd,
                         "q_low_m_s": mixture_quantile(tail, cond_mean, cond_var),
                         "q_high_m_s": mixture_quantile(1.0 - tail, cond_mean, cond_var),
                         "pit": pit, "inside": (pit >= tail) & (pit <= 1.0 - tail)})


def leave_one_shot_out(emulator, shots, left_out: str, draws: pd.DataFrame, observed, obs_sd, bounds, seed: int,
                       level: float = 0.95) -> pd.DataFrame:
    """The other shots' posterior predicting shot `left_out`'s features (module docstring).

    Args:
        emulator: the study's `Emulator` (predict, required_inputs, error_groups, feature_names).
        shots: all shots, in the order of `observed` (the left-out one among them).
        left_out: the shot predicted.
        draws: equal-weight posterior draws of the calibration of the other shots (native units; `lambda_y`;
            with a discrepancy its `delta_sd_fraction_<feature>` and `delta_rho_shots` columns).
        observed, obs_sd: every shot's measured features and observation sd (F,), m/s, shot-major.
        bounds: the prior box by input (native units): the left-out shot's own inputs are drawn from it.
        seed: the seed of those prior draws.
        level: the central band's probability.

    Returns:
        One row per left-out feature (`shot`, `feature`, then `mixture_table`'s columns) and
        `prior_inputs`, the inputs drawn from the prior.
    """
    shots = [str(s) for s in shots]
    if left_out not in shots:
        raise InputError(f"leave-one-shot-out: shot {left_out!r} is not one of {shots}")
    features = list(emulator.feature_names)
    y, sd = np.asarray(observed, dtype=float), np.asarray(obs_sd, dtype=float)
    if y.shape != (len(shots) * len(features),) or sd.shape != y.shape:
        raise InputError(f"leave-one-shot-out: {len(y)} measured features for {len(shots)} shots x {len(features)}")
    fitted = emulator.required_inputs([s for s in shots if s != left_out])
    missing = [name for name in fitted + [LAMBDA_Y] if name not in draws.columns]
    if missing:
        raise InputError(f"leave-one-shot-out: the posterior draws have no column {missing[0]!r}")
    own = [name for name in emulator.required_inputs(shots) if name not in fitted]
    rng = np.random.default_rng(seed)
    n = len(draws)
    inputs = {name: draws[name].to_numpy(float) for name in fitted}
    for name in own:
        if name not in bounds:
            raise InputError(f"leave-one-shot-out: input {name!r} has no prior box")
        low, high = bounds[name]
        inputs[name] = rng.uniform(low, high, n)
    mean, cov = emulator.predict(inputs, shots)
    for cols, error in emulator.error_groups(shots):
        cov[:, cols[:, None], cols[None, :]] *= error.scale
    cov = cov + (sd ** 2 / draws[LAMBDA_Y].to_numpy(float)[:, None])[:, :, None] * np.eye(len(y))
    fractions = [f"{SD_FRACTION_PREFIX}{feature}" for feature in features]
    if fractions[0] in draws.columns:
        phi = draws[[*fractions, RHO_NAME]].to_numpy(float)
        cov = cov + Discrepancy(tuple(features), len(shots)).covariance(phi, y)
    position = shots.index(left_out)
    left = np.arange(len(features)) + position * len(features)
    table = mixture_table(y[left], *conditional_prediction(y, mean, cov, left), level)
    table.insert(0, "feature", features)
    table.insert(0, "shot", left_out)
    table["prior_inputs"] = " ".join(own)
    return table
