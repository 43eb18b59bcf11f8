"""Affine-invariant ensemble MCMC (emcee) with mode-hopping differential-evolution moves.

Moves, mixed at random each step: differential evolution (DE, gamma = 2.38/sqrt(2d)), DE with
gamma = 1 (ter Braak 2006: a walker moves by the exact difference of two others, so a walker in one
mode lands in another when the two others sit in different modes), and the stretch move. All three
keep detailed balance, so the share of walkers in each mode converges to the posterior mass of
that mode. emcee is used because its ensemble moves are well tested and vectorised over walkers,
which lets one emulator call serve the whole ensemble.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

STRETCH_FRACTION = 0.2


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
    sampler.run_mcmc(initial, burn_in_steps + kept_steps, progress=False)
    samples = sampler.get_chain(discard=burn_in_steps, thin=thin).transpose(1, 0, 2)
    log_prob = sampler.get_log_prob(discard=burn_in_steps, thin=thin).T
    steps = burn_in_steps + thin * (np.arange(samples.shape[1]) + 1) - 1
    return Chains(samples, log_prob, steps, float(np.mean(sampler.acceptance_fraction)))
