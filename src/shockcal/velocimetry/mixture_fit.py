"""A Gaussian mixture fitted by EM to the exact piecewise-linear CDF of a trace (the extractor's step 4).

The extractor reads the standardized, monotone trace y(t) as a CDF. The SPEC draws probability-integral-
transform (PIT) samples from it, t = y^-1(u), with the inverse the linear interpolation of the (y, t)
pairs where y strictly increases, and fits the mixture to the samples. That distribution is known
exactly: between consecutive such pairs (t_i, y_i), (t_i+1, y_i+1) it is uniform with mass
y_i+1 - y_i (and the levels below y_0 sit at t_0). This module fits the mixture to it directly, the
fit to infinitely many PIT samples: EM on the expected log-likelihood  L = integral p(t) log f(t) dt
of the mixture f under that density p.

The E- and M-steps need integrals of r_k(t) (1, t, t^2) p(t) over each uniform piece, with the
responsibility r_k = pi_k N(t; mu_k, s_k^2) / f(t). They have no closed form (a ratio of Gaussians),
so each piece is integrated by 2-point Gauss-Legendre quadrature, exact for polynomials up to degree
3 (exact for the M-step wherever one component dominates a piece). Pieces wider than `PIECE_WIDTH`
(1/64 of the distribution's sd: 1.6-3 ns on our traces, whose grid is 0.5 ns; only the stretches
where the monotone trace is flat between two rises are that wide) are first cut into equal parts.
Against 8 nodes on parts of 1/512 sd, the features of 30 hydrocode traces agree to 1e-2 ns or m/s
(median 1e-5) with EM run to 1e-9 (docs/journal/2026-11-25-extractor-exact-cdf.md). EM then runs on
the weighted nodes: the updates of EM on samples, each sample's 1/N replaced by the node's mass.

At the extractor's tolerance (1e-5 on L) EM stops on a slope of the likelihood, 0.1-3 ns short of
its optimum: the features depend on EM's path, so the extractor keeps the old path (`kmeans_starts`,
plain `em`). `deterministic_starts` and `squarem` (SQUAREM acceleration) are 1.5-2 times faster but
take other paths (features 0.1-1 ns apart, other optima in a third of the traces); measured, not used.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit

GAUSS_LEGENDRE_NODES = 2
PIECE_WIDTH = 1.0 / 64       # longest quadrature part, in sd of the standardized distribution
VARIANCE_FLOOR = 1e-6        # added to each variance on the standardized scale (scikit-learn's reg_covar)
LLOYD_MAX_ITER = 100
SETTLED = 1e-3               # plain EM steps until one gains less than this (scikit-learn's default tol), then SQUAREM
_TINY = 10 * np.finfo(float).eps   # scikit-learn's guard against an empty component


def uniform_pieces(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The CDF's uniform pieces: (left, right, mass), between consecutive points where y strictly
    increases (the pairs the PIT inverse interpolates); flat stretches carry no piece of their own.
    A trace that starts above its minimum (a noisy record: y[0] > 0) puts the levels u < y[0] at the
    window's start (np.interp clamps): a first piece of zero width carries that mass."""
    rising = np.diff(y, prepend=-np.inf) > 0
    tr, yr = t[rising], y[rising]
    return np.r_[tr[0], tr[:-1]], np.r_[tr[0], tr[1:]], np.r_[yr[0], np.diff(yr)]


def quadrature_nodes(left, right, mass, width: float, order: int):
    """Nodes x, masses w (summing to the total mass) and CDF levels F(x) of Gauss-Legendre quadrature
    of the piecewise-uniform density, each piece cut into equal parts no wider than `width`."""
    parts = np.maximum(1, np.ceil((right - left) / width)).astype(int)
    piece = np.repeat(np.arange(left.size), parts)
    part = np.arange(piece.size) - np.repeat(np.cumsum(parts) - parts, parts)   # 0 .. parts-1 in each piece
    step = (right - left)[piece] / parts[piece]
    lo = left[piece] + part * step
    below = (np.cumsum(mass) - mass)[piece] + mass[piece] * part / parts[piece]   # F at each part's left end
    nodes, node_weights = np.polynomial.legendre.leggauss(order)
    fraction = (nodes + 1) / 2                                             # on [0, 1]
    x = (lo[:, None] + step[:, None] * fraction).ravel()
    w = ((mass[piece] / parts[piece])[:, None] * node_weights / 2).ravel()
    level = (below[:, None] + (mass[piece] / parts[piece])[:, None] * fraction).ravel()
    return x, w, level


@njit(cache=True)
def _component_densities(xi, log_norm, means, inverse_variances, out):
    """out_k = exp(log pi_k N(xi; mu_k, s2_k) - top) (0 below e^-50 of the largest); returns top and
    sum_k out_k, so that log f(xi) = top + log(sum)."""
    top = -np.inf
    for j in range(out.size):
        d = xi - means[j]
        out[j] = log_norm[j] - 0.5 * d * d * inverse_variances[j]
        top = max(top, out[j])
    total = 0.0
    for j in range(out.size):
        out[j] = np.exp(out[j] - top) if out[j] - top > -50.0 else 0.0
        total += out[j]
    return top, total


@njit(cache=True)
def log_likelihood(x, w, weights, means, variances):
    """The expected log-likelihood sum_i w_i log f(x_i) of the mixture f."""
    log_norm = np.log(weights) - 0.5 * np.log(2 * np.pi * variances)
    inverse_variances = 1.0 / variances
    density = np.empty(weights.size)
    total = 0.0
    for i in range(x.size):
        top, norm = _component_densities(x[i], log_norm, means, inverse_variances, density)
        total += w[i] * (top + np.log(norm))
    return total


@njit(cache=True)
def em_step(x, w, weights, means, variances, floor):
    """One EM step, in place: with the responsibilities r_ik = pi_k N(x_i; mu_k, s2_k) / f(x_i),
    pi_k = sum_i w_i r_ik, mu_k = sum_i w_i r_ik x_i / pi_k, s2_k = sum_i w_i r_ik (x_i - mu_k)^2 / pi_k
    + floor (moments taken about the previous mu_k). Returns the log-likelihood before the step."""
    k = weights.size
    log_norm = np.log(weights) - 0.5 * np.log(2 * np.pi * variances)
    inverse_variances = 1.0 / variances
    density = np.empty(k)
    mass, first, second = np.zeros(k), np.zeros(k), np.zeros(k)
    loglik = 0.0
    for i in range(x.size):
        top, norm = _component_densities(x[i], log_norm, means, inverse_variances, density)
        loglik += w[i] * (top + np.log(norm))
        scale = w[i] / norm
        for j in range(k):
            if density[j] > 0.0:
                r = scale * density[j]
                d = x[i] - means[j]
                mass[j] += r
                first[j] += r * d
                second[j] += r * d * d
    for j in range(k):
        m = mass[j] + _TINY
        shift = first[j] / m
        weights[j], means[j], variances[j] = m, means[j] + shift, second[j] / m - shift * shift + floor
    weights /= weights.sum()
    return loglik


@njit(cache=True)
def em(x, w, weights, means, variances, floor, tol, max_iter):
    """Plain EM from the given parameters (updated in place) until the expected log-likelihood gains
    less than `tol` in one step (scikit-learn's rule: the change between E-steps); returns
    (log-likelihood at the final parameters, EM steps, converged). The reference for `squarem`."""
    previous = -np.inf
    steps = 0
    converged = False
    while steps < max_iter and not converged:
        loglik = em_step(x, w, weights, means, variances, floor)
        steps += 1
        converged = abs(loglik - previous) < tol
        previous = loglik
    return log_likelihood(x, w, weights, means, variances), steps, converged


@njit(cache=True)
def _pack(weights, means, variances):
    return np.concatenate((np.log(weights), means, np.log(variances)))


@njit(cache=True)
def _unpack(theta, weights, means, variances):
    k = weights.size
    weights[:] = np.exp(theta[:k] - theta[:k].max())
    weights /= weights.sum()
    means[:] = theta[k:2 * k]
    variances[:] = np.exp(theta[2 * k:])


@njit(cache=True)
def squarem(x, w, weights, means, variances, floor, tol, max_iter, settle=SETTLED):
    """EM accelerated by SQUAREM (Varadhan and Roland 2008, scheme SqS3), parameters updated in place.

    A cycle takes two EM steps theta0 -> theta1 -> theta2 and stops, as plain EM does, when the
    second gains less than `tol` (the change between the two E-steps' log-likelihoods). Otherwise it
    extrapolates theta0 - 2 a r + a^2 v with r = theta1 - theta0, v = theta2 - 2 theta1 + theta0,
    a = -|r| / |v| (in log-weights, means, log-variances), and keeps the EM step from there when its
    log-likelihood is at least theta1's, else theta2. Returns (log-likelihood at the final parameters,
    EM steps, converged); `max_iter` counts EM steps."""
    trial_weights, trial_means, trial_variances = np.empty_like(weights), np.empty_like(means), np.empty_like(variances)
    steps = 0
    converged = False
    previous = -np.inf
    while steps < max_iter:                      # plain EM until it has settled in its basin
        loglik = em_step(x, w, weights, means, variances, floor)
        steps += 1
        if abs(loglik - previous) < settle:
            converged = abs(loglik - previous) < tol
            break
        previous = loglik
    while steps < max_iter and not converged:
        theta0 = _pack(weights, means, variances)
        first = em_step(x, w, weights, means, variances, floor)
        theta1 = _pack(weights, means, variances)
        second = em_step(x, w, weights, means, variances, floor)
        steps += 2
        if abs(second - first) < tol:
            converged = True
            break
        r = theta1 - theta0
        v = _pack(weights, means, variances) - theta1 - r
        if not np.dot(v, v) > 0:
            continue
        a = min(-np.sqrt(np.dot(r, r) / np.dot(v, v)), -1.0)
        if a == -1.0:
            continue
        _unpack(theta0 - 2 * a * r + a * a * v, trial_weights, trial_means, trial_variances)
        at_trial = em_step(x, w, trial_weights, trial_means, trial_variances, floor)
        steps += 1
        if np.isfinite(at_trial) and at_trial >= second:
            weights[:], means[:], variances[:] = trial_weights, trial_means, trial_variances
    return log_likelihood(x, w, weights, means, variances), steps, converged


def hard_start(x, w, labels, k: int):
    """The M-step of a hard assignment of the nodes to k components: (weights, means, variances)."""
    mass = np.bincount(labels, w, k) + _TINY
    means = np.bincount(labels, w * x, k) / mass
    variances = np.bincount(labels, w * (x - means[labels]) ** 2, k) / mass + VARIANCE_FLOOR
    return mass / mass.sum(), means, variances


def lloyd_labels(x, w, centres):
    """Weighted 1-D k-means (Lloyd's iterations) from `centres`: the nodes' cluster labels."""
    k = centres.size
    centres = np.sort(centres)
    for _ in range(LLOYD_MAX_ITER):
        labels = np.searchsorted((centres[1:] + centres[:-1]) / 2, x)
        mass = np.bincount(labels, w, k)
        new = np.where(mass > 0, np.bincount(labels, w * x, k) / np.where(mass > 0, mass, 1.0), centres)
        if np.array_equal(new, centres):
            break
        centres = new
    return labels


def deterministic_starts(x, w, level, k: int, count: int):
    """`count` starts, in order: the k equal-mass (quantile) bins; k-means from the bins' means;
    k-means from k equally spaced centres over the support; then k-means from centres equally spaced
    in CDF level at shifted offsets."""
    bins = np.minimum((level * k).astype(int), k - 1)
    quantile = hard_start(x, w, bins, k)
    starts = [quantile]
    centres = [quantile[1], x.min() + (x.max() - x.min()) * (np.arange(k) + 0.5) / k]
    for extra in range(max(0, count - 3)):
        levels = (np.arange(k) + (extra + 1) / (count - 1)) / k
        centres.append(np.interp(levels, level, x))
    for c in centres[: count - 1]:
        starts.append(hard_start(x, w, lloyd_labels(x, w, c), k))
    return starts


@functools.cache
def _threadpools():
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()      # 3 ms to find the thread pools: once a process


def _one_openmp_thread():
    return _threadpools().limit(limits=1, user_api="openmp")


def kmeans_starts(z, k: int, count: int):
    """scikit-learn's starts of the old fit on the (standardized) PIT samples z, as `GaussianMixture`
    makes them: the M-step of k-means labels (n_init 1, random_state 0, 1, ...), the first with its
    means replaced by the samples' quantiles (i + 1/2)/k. Seeded, so deterministic."""
    from sklearn.cluster import KMeans

    starts = []
    with _one_openmp_thread():     # k-means in 1-D: OpenMP threads cost more than they save (5-10x, loaded)
        for seed in range(max(count - 1, 1)):
            labels = KMeans(n_clusters=k, n_init=1, random_state=seed).fit(z[:, None]).labels_
            starts.append(hard_start(z, np.full(z.size, 1.0 / z.size), labels, k))
    weights, _, variances = starts[0]
    return [(weights, np.quantile(z, (np.arange(k) + 0.5) / k), variances), *starts][:count]


def fit_piecewise_linear_cdf(t, y, n_components: int, n_starts: int, tol: float, max_iter: int, starts=None,
                             accelerate: bool = False):
    """The Gaussian mixture of highest expected log-likelihood under the CDF y(t) (monotone, 0 to 1)
    over `n_starts` starts: `deterministic_starts` when `starts` is None, `kmeans_starts` when it is an
    array of PIT samples (in t's units), or the given list of (weights, means, variances) on the
    standardized scale; each run to convergence on the standardized scale by plain `em` (by `squarem`
    when `accelerate`: the same stopping rule, about 0.6 times the EM steps, another path).

    Returns (weights, means, sds) in t's units and a dict of diagnostics (standardization, nodes,
    per-start log-likelihood and iterations)."""
    left, right, mass = uniform_pieces(np.asarray(t, float), np.asarray(y, float))
    keep = mass > 0
    left, right, mass = left[keep], right[keep], mass[keep] / mass[keep].sum()
    centre = float(np.sum(mass * (left + right) / 2))                      # exact moments of the density
    spread = float(np.sqrt(np.sum(mass * (left**2 + left * right + right**2) / 3) - centre**2))
    x, w, level = quadrature_nodes((left - centre) / spread, (right - centre) / spread, mass, PIECE_WIDTH,
                                        GAUSS_LEGENDRE_NODES)
    if starts is None:
        starts = deterministic_starts(x, w, level, n_components, n_starts)
    elif not isinstance(starts, list):             # PIT samples: scikit-learn's k-means starts
        starts = kmeans_starts((np.asarray(starts, float) - centre) / spread, n_components, n_starts)
    best, best_score, runs = None, -np.inf, []
    for start in starts:
        weights, means, variances = (np.array(p, dtype=float) for p in start)
        run = squarem if accelerate else em
        score, iterations, converged = run(x, w, weights, means, variances, VARIANCE_FLOOR, tol, max_iter)
        runs.append((score, iterations, converged))
        if score > best_score:
            best, best_score = (weights, means, variances), score
    weights, means, variances = best
    info = {"centre": centre, "spread": spread, "nodes": x.size, "runs": runs}
    return (weights, centre + spread * means, spread * np.sqrt(variances)), info
