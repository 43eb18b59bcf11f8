"""Which shot next: the expected information gain of a candidate shot, from the features of
the current posterior's draws at the candidate's conditions (docs/next_shot.md).

The current joint posterior is the next shot's prior. Its draws theta_i (i = 1..N, equal weights)
run through the hydrocode at a candidate's conditions give features g_i = g(theta_i) (N, F); a
measurement of them is y = g(theta) + eps, eps ~ N(0, diag(s(theta)^2)), s the per-feature noise sd
the caller computes (`noise_sd`: the observation error sd_fraction |g| / sqrt(lambda_y) and the
extractor's read-out sd in quadrature). The expected information gain about theta is

    EIG = I(theta; y) = E_{theta, y}[log p(y | theta) - log p(y)]   (nats).

Everything the draws carry (the inputs, lambda_y when `noise_sd` uses each draw's lambda_y) is theta.

Estimators (`expected_information_gain`):

- All of theta (`targets=None`): nested Monte Carlo reusing the draws (Rainforth et al. 2018; Foster
  et al. 2020, "A unified stochastic gradient approach to designing Bayesian-optimal experiments"):
  outer samples y_k ~ p(y | theta_i(k)), p(y_k) the mean of p(y_k | theta_j) over the *other* draws
  (leave-one-out; a draw's exact duplicates, as a resampled posterior has, are left out with it), in
  log-sum-exp. The inner draws are then independent of y_k, the inner mean is unbiased for p(y_k), and
  by Jensen the estimator is biased *upward* by about Var[p(y|theta)] / (2 N p(y)^2), O(1/N)
  (`eig`). The same matrix with the outer draw's own term put back into the inner mean is the prior
  contrastive estimate (PCE), a lower bound in expectation that can never exceed log N (`eig_lower`).
  The two bracket the truth; a bracket wider than the Monte Carlo noise (`resolved` false) says the
  draws are too few for this candidate's information (EIG near log N).
- A subset theta_T (e.g. m alone): p(y | theta_T) needs draws sharing theta_T, which posterior draws
  never do, so no nested estimator is consistent without new hydrocode runs. We use the Gaussian
  (maximum-entropy) bound on rank normal scores: z_T = Phi^-1(rank(theta_T)) over the draws (mutual
  information is invariant under a monotone map of each coordinate, and one z's marginal is N(0, 1)
  by construction, so its entropy is known); since no density of a given covariance has more entropy
  than the Gaussian, H(z_T | y) <= 0.5 log det(2 pi e Cov(z_T | y)), and

      I(theta_T; y) >= 0.5 log det C - 0.5 E_y log det Cov(z_T | y),

  Cov(z_T | y_k) the importance-weighted (weights p(y_k | theta_j), leave-one-out) covariance of the
  draws' scores, floored at N^(-2/|T|) C (a posterior finer than the draws' spacing cannot be seen).
  Exact for a linear-Gaussian problem; the gap is the expected non-Gaussianity of the posterior of
  z_T (bias *downward*: 0.09 nats of 0.46 on the nonlinear toy); the weights' noise lowers it a
  little more (-0.02 nats on the linear-Gaussian check with 200 draws). For several targets C is the
  normal scores' covariance and their entropy is taken as Gaussian, which overstates it by their
  copula's non-Gaussianity: the bound can then lean upward by that much. I(theta_T; y) <= I(theta; y)
  bounds it from above (`eig_full`). This is the Gaussian approximation of the posterior covariance
  reduction, made a bound by the normal scores and the maximum-entropy argument.

Monte Carlo error (`eig_sd`): bootstrap over the draws (resampled with replacement, each draw's outer
samples and its place in every inner mean or weight together; a draw's copies leave one out together).
With one outer sample per draw this is the bootstrap over the outer samples, each carrying its inner
role. On the linear-Gaussian check (20 seeds) the z-scores have sd 1.04 for the full EIG, 1.35 for
the marginal (its sd is about 25% low); on the nonlinear toy the full EIG's sd is about twice its
spread over seeds (conservative).

Expected posterior sd of each parameter: for each outer y_k, the importance-weighted (leave-one-out)
variance over the draws, divided by 1 - sum w^2; reported as the root mean over the outer samples (the
expected posterior variance, Bayes risk under squared loss). With few effective draws per y
(`inner_ess`) it is biased low.

Cost: n_outer x N likelihood evaluations of F features, and the bootstrap n_boot times the n_outer x N
log-sum-exp (N = 200: 40,000 pairs, well under a second).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import special, stats

from shockcal.errors import InputError

OUTER_BLOCK = 256       # outer samples per block of the (block, N, F) likelihood array


@dataclass(frozen=True)
class InformationGain:
    """The expected information gain of one candidate shot (nats) and what goes with it.

    `eig`, `eig_sd`: the estimate for the targets and its bootstrap sd; `method` names the estimator
    ("nmc-loo" for all of theta, "gaussian-entropy-bound" for a subset). `eig_full`, `eig_full_sd`,
    `eig_full_lower`: the leave-one-out nested estimate of I(theta; y) (biased up) and the PCE lower
    bound from the same matrix; for a subset, `eig_full` bounds `eig` from above. `resolved`: the
    bracket [eig_full_lower, eig_full] is no wider than its noise (false: too few draws for this
    candidate). `posterior_sd`, `prior_sd`: per target (or per theta column when `targets` is None and
    theta was given), native units; `inner_ess`: median Kish ESS of the inner importance weights.
    """

    eig: float
    eig_sd: float
    method: str
    eig_full: float
    eig_full_sd: float
    eig_full_lower: float
    resolved: bool
    targets: tuple
    posterior_sd: np.ndarray | None
    prior_sd: np.ndarray | None
    inner_ess: float
    n_draws: int
    n_outer: int


def noise_sd(features, sd_fraction: float = 0.01, readout_sd=0.0, lambda_y=None) -> np.ndarray:
    """The measurement noise sd of each draw's features: the observation error sd_fraction |g| / sqrt(lambda_y)
    (`shockcal.inference.problem`'s, with the draw's feature in place of the measured one) and the extractor's
    read-out sd, in quadrature.

    Args:
        features: g(theta_i), (N, F), m/s.
        sd_fraction: observation sd as a fraction of each feature (0.01: 1%).
        readout_sd: the extractor's read-out error sd, m/s, a number or (F,).
        lambda_y: each draw's observation precision scale (N,), or None for 1.

    Returns (N, F) sd, m/s.
    """
    g = _matrix(features, "features")
    lam = np.ones(len(g)) if lambda_y is None else np.asarray(lambda_y, dtype=float)
    if lam.shape != (len(g),) or not np.all(np.isfinite(lam) & (lam > 0)):
        raise InputError(f"noise_sd: lambda_y must be {len(g)} positive numbers, one per draw (got shape {lam.shape})")
    readout = np.broadcast_to(np.asarray(readout_sd, dtype=float), (g.shape[1],)) if np.ndim(readout_sd) < 2 else None
    if readout is None or not np.all(np.isfinite(readout) & (readout >= 0)) or not sd_fraction >= 0:
        raise InputError("noise_sd: sd_fraction and readout_sd must be non-negative (readout_sd a number or one per "
                         "feature)")
    return np.sqrt((sd_fraction * g) ** 2 / lam[:, None] + readout**2)


def expected_information_gain(features, noise_sd, rng: np.random.Generator, targets: Sequence | None = None,
                              theta=None, names: Sequence[str] | None = None, n_outer: int | None = None,
                              n_boot: int = 200) -> InformationGain:
    """Expected information gain (nats) of measuring a candidate shot's features, about all of theta or a
    subset, with its bootstrap sd and the expected posterior sd of each target.

    Args:
        features: g(theta_i) at the N equal-weight draws of the current posterior (the next shot's
            prior), (N, F), m/s.
        noise_sd: the measurement noise sd, m/s: (F,) for all draws, or (N, F) per draw (relative noise,
            a per-draw lambda_y; `noise_sd()` builds it).
        rng: the random stream of the outer samples and the bootstrap.
        targets: None (everything the draws carry), or the parameters of interest, as column indices of
            `theta` or names from `names`.
        theta: the draws (N, d), native units: needed for `targets` and for the posterior sds.
        names: theta's column names (for targets given by name, and messages).
        n_outer: outer samples (default N; above N each draw gets several, cycling).
        n_boot: bootstrap replicates of `eig_sd`.

    Returns an `InformationGain`. Bad input (shapes, non-finite values, non-positive sd, an unknown
    target, too few draws) is an InputError naming it.
    """
    g = _matrix(features, "features")
    n, f = g.shape
    if n < 10:
        raise InputError(f"features: {n} draws; at least 10 are needed (200 is the default)")
    sd = np.asarray(noise_sd, dtype=float)
    if sd.shape not in ((f,), (n, f)):
        raise InputError(f"noise_sd has shape {sd.shape}; features {g.shape} need ({f},) or ({n}, {f})")
    if not np.all(np.isfinite(sd) & (sd > 0)):
        raise InputError(f"noise_sd: every sd must be finite and positive (smallest {np.nanmin(sd):g} m/s)")
    sd = np.broadcast_to(sd, (n, f))
    th = None if theta is None else _matrix(theta, "theta")
    if th is not None and len(th) != n:
        raise InputError(f"theta has {len(th)} rows but features has {n}: one row per draw in both")
    names = None if names is None else [str(name) for name in names]
    if names is not None and th is not None and len(names) != th.shape[1]:
        raise InputError(f"names has {len(names)} entries but theta has {th.shape[1]} columns")
    cols = _target_columns(targets, th, names)
    n_outer = n if n_outer is None else int(n_outer)
    if n_outer < 10:
        raise InputError(f"n_outer = {n_outer}; at least 10 outer samples are needed")
    if n_boot < 20:
        raise InputError(f"n_boot = {n_boot}; at least 20 bootstrap replicates are needed for eig_sd")

    draw = np.resize(rng.permutation(n), n_outer)                 # outer sample k measures draw draw[k]
    y = g[draw] + sd[draw] * rng.standard_normal((n_outer, f))
    log_lik = _log_likelihood(y, g, sd)                           # (n_outer, N)
    group = np.unique(np.hstack([g, sd]), axis=0, return_inverse=True)[1].ravel()
    other = group[draw][:, None] != group[None, :]                # inner draws independent of outer k
    if not other.any(axis=1).all():
        raise InputError("features: every draw is a copy of one; the information gain needs distinct draws")
    own = log_lik[np.arange(n_outer), draw]

    counts = rng.multinomial(n, np.full(n, 1.0 / n), size=n_boot).astype(float)
    full, full_boot = _nmc(log_lik, own, other, draw, counts)
    contrast = np.logaddexp(own, special.logsumexp(np.where(other, log_lik, -np.inf), axis=1))
    lower = float(np.mean(own - (contrast - np.log(1.0 + other.sum(axis=1)))))
    full_sd = float(np.std(full_boot, ddof=1))

    weights = _weights(log_lik, other)
    ess = float(np.median(1.0 / np.sum(weights**2, axis=1)))
    post_sd = prior_sd = None
    if th is not None:
        shown = th if cols is None else th[:, cols]
        post_sd = np.sqrt(np.mean(np.diagonal(_posterior_cov(weights, shown), axis1=1, axis2=2), axis=0))
        prior_sd = shown.std(axis=0)

    if cols is None or len(cols) == th.shape[1]:
        eig, eig_sd, method = full, full_sd, "nmc-loo"
    else:
        z = normal_scores(th[:, cols], th[:, cols])
        eig = float(np.mean(_entropy_bound_terms(z, weights)))
        boot = [np.sum(c[draw] * _entropy_bound_terms(z, _weights(log_lik, other, c))) / np.sum(c[draw])
                for c in counts]
        eig_sd, method = float(np.std(boot, ddof=1)), "gaussian-entropy-bound"
    label = None if cols is None else tuple(names[c] if names else c for c in cols)
    return InformationGain(eig, eig_sd, method, full, full_sd, lower, bool(full - lower <= max(2 * full_sd, 0.05)),
                           label, post_sd, prior_sd, ess, n, n_outer)


def _matrix(values, what: str) -> np.ndarray:
    a = np.asarray(values, dtype=float)
    if a.ndim != 2 or 0 in a.shape:
        raise InputError(f"{what} must be a non-empty 2-D array (draws x columns), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{what}: row {int(np.argmax(~np.isfinite(a).all(axis=1)))} has a value that is not finite")
    return a


def _target_columns(targets, theta, names) -> list[int] | None:
    if targets is None:
        return None
    if theta is None:
        raise InputError(f"targets {list(targets)} need theta, the draws' parameters")
    targets = [targets] if isinstance(targets, (str, int)) else list(targets)
    cols = []
    for target in targets:
        if isinstance(target, (int, np.integer)) and not isinstance(target, bool) and 0 <= target < theta.shape[1]:
            cols.append(int(target))
        elif isinstance(target, str) and names is not None and target in names:
            cols.append(names.index(target))
        else:
            known = names if names is not None else f"column indices 0..{theta.shape[1] - 1}"
            raise InputError(f"unknown target {target!r}: the targets are among {known}")
    if not cols or len(set(cols)) != len(cols):
        raise InputError(f"targets {targets}: give each target once, and at least one")
    return cols


def _log_likelihood(y: np.ndarray, g: np.ndarray, sd: np.ndarray) -> np.ndarray:
    """log N(y_k; g_j, diag(sd_j^2)) for every outer k and draw j, (n_outer, N)."""
    norm = -np.log(sd).sum(axis=1) - 0.5 * g.shape[1] * np.log(2 * np.pi)
    out = np.empty((len(y), len(g)))
    for start in range(0, len(y), OUTER_BLOCK):
        block = y[start:start + OUTER_BLOCK, None, :]
        out[start:start + OUTER_BLOCK] = norm - 0.5 * np.sum(((block - g) / sd) ** 2, axis=2)
    return out


def _nmc(log_lik, own, other, draw, counts) -> tuple[float, np.ndarray]:
    """The leave-one-out nested estimate and its bootstrap replicates (draws resampled by `counts`)."""
    masked = np.where(other, log_lik, -np.inf)
    estimate = float(np.mean(own - special.logsumexp(masked, axis=1) + np.log(other.sum(axis=1))))
    boot = np.empty(len(counts))
    for b, c in enumerate(counts):
        inner_w = other * c
        total = inner_w.sum(axis=1)
        keep = (c[draw] > 0) & (total > 0)
        inner = special.logsumexp(log_lik[keep], b=inner_w[keep], axis=1) - np.log(total[keep])
        boot[b] = np.sum(c[draw][keep] * (own[keep] - inner)) / np.sum(c[draw][keep])
    return estimate, boot


def normal_scores(reference: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Normal scores of `values` (M, d) by the marginal empirical CDFs of `reference` (N, d):
    Phi^-1(F(x)), F the mid-rank CDF (a value equal to k reference draws sits in the middle of them),
    clipped to [1/(2N), 1 - 1/(2N)]: the reference's own scores are rank normal scores."""
    reference, values = np.atleast_2d(reference), np.atleast_2d(values)
    n = len(reference)
    scores = np.empty(values.shape)
    for j in range(reference.shape[1]):
        ordered = np.sort(reference[:, j])
        below = np.searchsorted(ordered, values[:, j], side="left")
        upto = np.searchsorted(ordered, values[:, j], side="right")
        cdf = np.clip(0.5 * (below + upto) / n, 0.5 / n, 1 - 0.5 / n)
        scores[:, j] = stats.norm.ppf(cdf)
    return scores


def _weights(log_lik, other, counts=None) -> np.ndarray:
    """Importance weights of the draws given each outer y_k (rows sum to 1), over the other draws, each
    counted `counts` times (a bootstrap resample; None: once)."""
    masked = np.where(other, log_lik, -np.inf)
    if counts is not None:
        with np.errstate(divide="ignore"):
            masked = masked + np.log(counts)
    return np.exp(masked - special.logsumexp(masked, axis=1, keepdims=True))


def _posterior_cov(weights, values) -> np.ndarray:
    """Per outer sample, the weighted covariance of values (N, d) -> (n_outer, d, d), divided by
    1 - sum w^2 (unbiased for reliability weights)."""
    mean = weights @ values
    second = np.einsum("kj,ja,jb->kab", weights, values, values)
    reliability = np.maximum(1.0 - np.sum(weights**2, axis=1), 1e-12)[:, None, None]
    return (second - mean[:, :, None] * mean[:, None, :]) / reliability


def _entropy_bound_terms(z, weights) -> np.ndarray:
    """Per outer sample k, 0.5 log det C - 0.5 log det Cov(z | y_k): z the targets' normal scores (C their
    covariance), Cov(z | y_k) their importance-weighted posterior covariance, floored at N^(-2/d) C (the
    draws cannot resolve finer: one target's term is at most about log N)."""
    n, d = z.shape
    prior = np.atleast_2d(np.cov(z, rowvar=False, bias=True))
    post = _posterior_cov(weights, z) + n ** (-2.0 / d) * prior
    return 0.5 * (np.linalg.slogdet(prior)[1] - np.linalg.slogdet(post)[1])
