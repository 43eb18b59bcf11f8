"""Affine-invariant ensemble MCMC (emcee) with mode-hopping differential-evolution moves.

Moves, mixed at random each step: differential evolution (DE, gamma = 2.38/sqrt(2d)), DE with
gamma = 1 (ter Braak 2006: a walker moves by the exact difference of two others, so a walker in one
mode lands in another when the two others sit in different modes), and the stretch move. All three
keep detailed balance, so the share of walkers in each mode converges to the posterior mass of
that mode. Halfway through burn-in, walkers stranded far below the ensemble in log density
(below the lower quartile by more than 3 interquartile ranges: stuck in a poor local optimum,
never accepting) restart from copies of other walkers; this happens during burn-in only, so the
retained draws are an ordinary MCMC run. emcee is used because its ensemble moves are well tested and vectorised over walkers,
which lets one emulator call serve the whole ensemble.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

STRETCH_FRACTION = 0.2
log = logging.getLogger("shockcal.sampler")


@dataclass
class Chains:
    """Retained draws: samples (walkers, steps, d), log density (walkers, steps), step numbers."""

    samples: np.ndarray
    log_prob: np.ndarray
    steps: np.ndarray
    acceptance: float


def run_ensemble(log_density, initial: np.ndarray, n_samples: int, burn_in_steps: int, thin: int,
                 mode_hop_fraction: float, seed: int) -> Chains:
    """Sample `log_density` (vectorised: (W, d) -> (W,)) from walkers `initial` (W, d).

    Runs burn_in_steps + ceil(n_samples * thin / W) steps and keeps every `thin`-th step after
    burn-in, so at least n_samples draws are retained.
    """
    import emcee

    n_walkers, ndim = initial.shape
    moves = [(emcee.moves.DEMove(), 1.0 - mode_hop_fraction - STRETCH_FRACTION),
             (emcee.moves.DEMove(gamma0=1.0), mode_hop_fraction),
             (emcee.moves.StretchMove(), STRETCH_FRACTION)]
    sampler = emcee.EnsembleSampler(n_walkers, ndim, log_density, moves=moves, vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()
    kept_steps = int(np.ceil(n_samples * thin / n_walkers))
    first = burn_in_steps // 2
    state = initial
    if first:
        state = sampler.run_mcmc(initial, first, progress=False)
        state = restart_lost_walkers(state.coords, state.log_prob, np.random.default_rng(seed))
    sampler.run_mcmc(state, burn_in_steps - first + kept_steps, progress=False)
    samples = sampler.get_chain(discard=burn_in_steps, thin=thin).transpose(1, 0, 2)
    log_prob = sampler.get_log_prob(discard=burn_in_steps, thin=thin).T
    steps = burn_in_steps + thin * (np.arange(samples.shape[1]) + 1) - 1
    return Chains(samples, log_prob, steps, float(np.mean(sampler.acceptance_fraction)))


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
