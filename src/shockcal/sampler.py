"""Affine-invariant ensemble MCMC (emcee) with mode-hopping differential-evolution moves.

Moves, mixed at random each step: differential evolution (DE, gamma = 2.38/sqrt(2d)), DE with
gamma = 1 (ter Braak 2006: a walker moves by the exact difference of two others, so a walker in one
mode lands in another when the two others sit in different modes), and the stretch move. All three
keep detailed balance, so the share of walkers in each mode converges to the posterior mass of
that mode. Halfway through burn-in, walkers stranded far below the ensemble in log density
(below the lower quartile by more than 3 interquartile ranges: stuck in a poor local optimum,
never accepting) restart from copies of other walkers; this happens during burn-in only, so the
retained draws are an ordinary MCMC run.

Burn-in runs in thirds: ensemble moves; ensemble moves whose draws fit a Gaussian mixture
(scikit-learn, components chosen by BIC, in the logits of the box); the mixture's own moves, whose
draws refit it. The retained draws come mostly from an independence
Metropolis-Hastings move that proposes from that mixture, widened and mixed with one broad
"defensive" Gaussian (Hesterberg 1995) so that no region the burn-in missed has zero proposal
density. The proposal is fixed before the retained draws start, so they are an ordinary MCMC run
with a valid kernel; where the mixture matches the posterior (both modes of n and m, the A-m ridge)
successive draws are nearly independent, which the ensemble moves alone are not. DE moves keep a
share of the steps. emcee is used because its moves are well tested and vectorised over walkers,
which lets one emulator call serve the whole ensemble.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

STRETCH_FRACTION = 0.2
INDEPENDENCE_FRACTION = 0.8     # share of retained-phase steps that propose from the fitted mixture
PROPOSAL_WIDENING = 1.2         # mixture component sds scaled by this
DEFENSIVE_WEIGHT = 0.1          # weight of the broad Gaussian (3x the burn-in sd) in the proposal
MIXTURE_SIZES = (1, 2, 4, 8)    # component counts tried (BIC)
log = logging.getLogger("shockcal.sampler")


@dataclass
class Chains:
    """Retained draws: samples (walkers, steps, d), log density (walkers, steps), step numbers."""

    samples: np.ndarray
    log_prob: np.ndarray
    steps: np.ndarray
    acceptance: float


def run_ensemble(log_density, initial: np.ndarray, n_samples: int, burn_in_steps: int, thin: int,
                 mode_hop_fraction: float, seed: int, bounds=None) -> Chains:
    """Sample `log_density` (vectorised: (W, d) -> (W,)) from walkers `initial` (W, d).

    Runs burn_in_steps + ceil(n_samples * thin / W) steps and keeps every `thin`-th step after
    burn-in, so at least n_samples draws are retained. `bounds` = (lower, upper) of the leading
    coordinates that live in a box (the proposal mixture is fitted in their logits).
    """
    import emcee

    n_walkers, ndim = initial.shape
    random = np.random.RandomState(seed)

    def run(moves, state, steps):
        sampler = emcee.EnsembleSampler(n_walkers, ndim, log_density, moves=moves, vectorize=True)
        sampler.random_state = random.get_state()
        state = sampler.run_mcmc(state, steps, progress=False)
        random.set_state(sampler.random_state)
        return sampler, state

    ensemble = [(emcee.moves.DEMove(), 1.0 - mode_hop_fraction - STRETCH_FRACTION),
                (emcee.moves.DEMove(gamma0=1.0), mode_hop_fraction),
                (emcee.moves.StretchMove(), STRETCH_FRACTION)]
    transform = BoxLogit(*bounds) if bounds is not None else BoxLogit.none()
    moves, state, third = ensemble, initial, burn_in_steps // 3
    if third:    # burn-in in thirds: ensemble; ensemble -> fit the mixture; mixture -> refit on its own draws
        _, state = run(ensemble, state, third)
        state = restart_lost_walkers(state.coords, state.log_prob, np.random.default_rng(seed))
        sampler, state = run(ensemble, state, third)
        moves = _mixture_moves(MixtureProposal.fit(sampler.get_chain().reshape(-1, ndim), seed, transform),
                               mode_hop_fraction)
        sampler, state = run(moves, state, burn_in_steps - 2 * third)
        moves = _mixture_moves(MixtureProposal.fit(sampler.get_chain().reshape(-1, ndim), seed, transform),
                               mode_hop_fraction)
    elif burn_in_steps:
        _, state = run(ensemble, state, burn_in_steps)
    kept_steps = int(np.ceil(n_samples * thin / n_walkers))
    sampler, _ = run(moves, state, thin * kept_steps)
    samples = sampler.get_chain(thin=thin).transpose(1, 0, 2)
    log_prob = sampler.get_log_prob(thin=thin).T
    steps = burn_in_steps + thin * (np.arange(samples.shape[1]) + 1) - 1
    return Chains(samples, log_prob, steps, float(np.mean(sampler.acceptance_fraction)))


def _mixture_moves(proposal, mode_hop_fraction: float) -> list:
    """The retained-phase kernel: mostly independence proposals from the mixture, the rest DE moves."""
    import emcee

    rest = 1.0 - INDEPENDENCE_FRACTION
    return [(emcee.moves.MHMove(proposal), INDEPENDENCE_FRACTION),
            (emcee.moves.DEMove(), rest * (1.0 - mode_hop_fraction)),
            (emcee.moves.DEMove(gamma0=1.0), rest * mode_hop_fraction)]


@dataclass
class BoxLogit:
    """z = logit((x - lower) / (upper - lower)) on the leading len(lower) coordinates, identity on
    the rest: a uniform box looks Gaussian-like in z, so a Gaussian mixture fits it."""

    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def none(cls) -> "BoxLogit":
        return cls(np.zeros(0), np.zeros(0))

    def forward(self, x: np.ndarray) -> np.ndarray:
        k = len(self.lower)
        u = np.clip((x[:, :k] - self.lower) / (self.upper - self.lower), 1e-12, 1 - 1e-12)
        return np.hstack([np.log(u) - np.log1p(-u), x[:, k:]])

    def inverse(self, z: np.ndarray) -> np.ndarray:
        k = len(self.lower)
        return np.hstack([self.lower + (self.upper - self.lower) / (1.0 + np.exp(-z[:, :k])), z[:, k:]])

    def log_jacobian(self, x: np.ndarray) -> np.ndarray:
        """log |dz/dx| at x."""
        k = len(self.lower)
        width = self.upper - self.lower
        return np.sum(np.log(width) - np.log(x[:, :k] - self.lower) - np.log(self.upper - x[:, :k]), axis=1)


@dataclass
class MixtureProposal:
    """Independence proposal, in z = transform(x): q_z = (1 - w) GMM(widened) + w N(mean, (3 sd)^2);
    as an emcee MHMove proposal function: (coords, random) -> (proposed coords, log q(x) - log q(x'))."""

    weights: np.ndarray       # (K + 1,) the last is the defensive component
    means: np.ndarray         # (K + 1, d)
    covariances: np.ndarray   # (K + 1, d, d)
    transform: BoxLogit

    @classmethod
    def fit(cls, draws: np.ndarray, seed: int, transform: BoxLogit) -> "MixtureProposal":
        from sklearn.mixture import GaussianMixture

        draws = transform.forward(draws)
        center, scale = draws.mean(axis=0), draws.std(axis=0)
        scale = np.where(scale > 0, scale, 1.0)
        z = (draws - center) / scale
        z = z[np.random.default_rng(seed).permutation(len(z))[:20000]]
        fits = [GaussianMixture(k, covariance_type="full", reg_covar=1e-6, random_state=seed).fit(z)
                for k in MIXTURE_SIZES if k < len(z) // (4 * z.shape[1])]
        best = min(fits, key=lambda g: g.bic(z))
        means = np.vstack([center + scale * best.means_, center])
        widen = PROPOSAL_WIDENING**2 * best.covariances_
        broad = 9.0 * np.eye(z.shape[1])[None]
        covariances = np.concatenate([widen, broad]) * np.outer(scale, scale)
        weights = np.append((1.0 - DEFENSIVE_WEIGHT) * best.weights_, DEFENSIVE_WEIGHT)
        log.info("independence proposal: %d mixture components (BIC) + a defensive Gaussian", best.n_components)
        return cls(weights, means, covariances, transform)

    def log_density(self, x: np.ndarray) -> np.ndarray:
        """log q(x) in the sampled coordinates x (the mixture density of z times |dz/dx|)."""
        from scipy.special import logsumexp
        from scipy.stats import multivariate_normal

        z = self.transform.forward(x)
        terms = [np.log(w) + multivariate_normal.logpdf(z, m, c, allow_singular=True)
                 for w, m, c in zip(self.weights, self.means, self.covariances)]
        log_qz = logsumexp(np.array(terms).reshape(len(self.weights), -1), axis=0)
        return log_qz + self.transform.log_jacobian(x)

    def __call__(self, coords: np.ndarray, random) -> tuple[np.ndarray, np.ndarray]:
        n, d = coords.shape
        component = random.choice(len(self.weights), size=n, p=self.weights)
        z = np.empty_like(coords)
        for k in np.unique(component):
            rows = component == k
            z[rows] = random.multivariate_normal(self.means[k], self.covariances[k], size=rows.sum())
        proposed = self.transform.inverse(z)
        return proposed, self.log_density(coords) - self.log_density(proposed)


def restart_lost_walkers(coords: np.ndarray, log_prob: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Walkers below Q1 - 3 IQR of the ensemble's log density move onto (jittered) copies of the others."""
    finite = np.where(np.isfinite(log_prob), log_prob, -np.inf)
    q1, q3 = np.quantile(finite[np.isfinite(finite)], [0.25, 0.75])
    lost = finite < q1 - 3.0 * (q3 - q1)
    if not lost.any() or lost.all():
        return coords
    good = np.flatnonzero(~lost)
    coords = coords.copy()
    jitter = 1e-3 * coords[good].std(axis=0)
    coords[lost] = coords[rng.choice(good, lost.sum())] + jitter * rng.normal(size=(lost.sum(), coords.shape[1]))
    log.info("burn-in: %d of %d walkers were stranded (log density below %.1f) and restarted from others",
             lost.sum(), len(coords), q1 - 3.0 * (q3 - q1))
    return coords
