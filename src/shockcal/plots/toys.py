"""Toy figures of the method: 1 (calibration with an emulator), 3 (GP draws), 14 (inadequate model).

One scalar input theta in [0, 1], a sigmoid "simulator" seen at four points, a Gaussian-process
emulator of it, one noisy measurement, and the posterior of theta on a grid. Nothing here reads the
study's data; the figures explain the method.
"""

from __future__ import annotations

import numpy as np

from shockcal.emulator.gp import GaussianProcess, Hyper, correlation
from shockcal.emulator.held_out import Z90
from shockcal.plots.style import COLORS, no_data, styled, subplots

THETA_RUNS = np.array([0.05, 0.35, 0.65, 0.95])
GRID = np.linspace(0.0, 1.0, 401)
# Fixed toy hyperparameters for the project's GP (shockcal.emulator.gp): correlation rho^(4 d^2) with
# rho = 0.2, marginal sd 0.5 of the centred outputs, a negligible nugget.
TOY_HYPER = Hyper(lambda_w=4.0, beta=np.array([-4.0 * np.log(0.2)]), lambda_n=1e8)


def gp_prior_cov(x):
    """Prior covariance of the toy GP at points `x` in [0, 1]."""
    x = np.asarray(x, dtype=float)[:, None]
    return correlation(x, x, TOY_HYPER.beta) / TOY_HYPER.lambda_w


def gp_condition(x, y, x_new):
    """Mean and covariance at `x_new` of the toy GP (constant mean = mean of `y`) conditioned on y(x)."""
    y = np.asarray(y, dtype=float)
    gp = GaussianProcess(np.asarray(x, dtype=float)[:, None], y - y.mean(), TOY_HYPER)
    mean, cov = gp.predict_joint(np.asarray(x_new, dtype=float)[:, None])
    return y.mean() + mean, cov


def sigmoid_simulator(theta, height: float = 1.0, centre: float = 0.5, steepness: float = 10.0):
    """The toy simulator: a logistic rise of `height` centred at `centre`."""
    return height / (1.0 + np.exp(-steepness * (np.asarray(theta, dtype=float) - centre)))


def grid_posterior(mean, var, datum: float, sd: float):
    """Posterior density of theta on GRID: uniform prior, datum ~ N(emulator mean, emulator var + sd^2)."""
    total = var + sd**2
    logp = -0.5 * (datum - mean) ** 2 / total - 0.5 * np.log(total)
    dens = np.exp(logp - logp.max())
    return dens / np.trapezoid(dens, GRID)


@styled
def toy_calibration(height: float = 1.0, steepness: float = 10.0, datum: float = 0.62, sd: float = 0.03,
                    theta_runs=THETA_RUNS, title: str = ""):
    """Emulator of the sigmoid from a few runs, a noisy datum, and the posterior of theta (Figs 1 and 14)."""
    runs = sigmoid_simulator(theta_runs, height, steepness=steepness)
    mean, cov = gp_condition(theta_runs, runs, GRID)
    var = np.clip(np.diag(cov), 0.0, None)
    dens = grid_posterior(mean, var, datum, sd)

    fig, axes = subplots(2, 1, width=5.0, height=5.2, sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    top, bottom = axes[:, 0]
    top.plot(GRID, sigmoid_simulator(GRID, height, steepness=steepness), color="black", ls="--", lw=1, label="simulator (unknown)")
    band = Z90 * np.sqrt(var)
    top.fill_between(GRID, mean - band, mean + band, color=COLORS["model"], alpha=0.25, lw=0,
                     label="emulator 90% band")
    top.plot(GRID, mean, color=COLORS["model"], lw=1.5, label="emulator mean")
    top.plot(theta_runs, runs, "o", color=COLORS["training"], mec="black", ms=6, label="simulator runs")
    top.axhspan(datum - Z90 * sd, datum + Z90 * sd, color=COLORS["measurement"], alpha=0.15, lw=0)
    top.axhline(datum, color=COLORS["measurement"], lw=1.5, label="measurement ± 90%")
    top.set_ylabel("output η(θ)")
    top.legend(loc="lower right")
    if title:
        top.set_title(title)

    bottom.fill_between(GRID, dens, color=COLORS["posterior"], alpha=0.35, lw=0)
    bottom.plot(GRID, dens, color=COLORS["posterior"], lw=1.5, label="posterior of θ")
    bottom.axhline(1.0, color="0.5", ls=":", lw=1, label="uniform prior")
    bottom.set_xlim(0, 1)
    bottom.set_ylim(0, None)
    bottom.set_xlabel("input θ (scaled to [0, 1])")
    bottom.set_ylabel("density")
    bottom.legend(loc="upper left")
    return fig


def fig01_toy_calibration():
    """Fig 1: an adequate model seen at four runs; the posterior is a clear bump inside the prior range."""
    return toy_calibration(title="Toy calibration: emulator built from four runs")


def fig14_inadequate_model():
    """Fig 14: the model cannot reach the datum; the posterior piles up at the prior's upper bound."""
    return toy_calibration(height=0.8, steepness=4.0, datum=0.77, sd=0.02, theta_runs=np.linspace(0, 1, 9),
                           title="Inadequate model: the datum lies above every output")


@styled
def fig03_gp_draws(n_draws: int = 5, seed: int = 3):
    """Fig 3: draws from the GP prior (left) and from the GP conditioned on the four runs (right)."""
    rng = np.random.default_rng(seed)
    runs = sigmoid_simulator(THETA_RUNS)
    fig, axes = subplots(1, 2, width=8.0, height=3.4, sharey=True)
    panels = (
        ("unconditioned (prior)", np.zeros_like(GRID), gp_prior_cov(GRID)),
        ("conditioned on four runs", *gp_condition(THETA_RUNS, runs, GRID)),
    )
    for ax, (title, mean, cov) in zip(axes[0], panels):
        if not np.all(np.isfinite(cov)):
            no_data(ax, "GP covariance not finite")
            continue
        draws = _draw(mean, cov, n_draws, rng)
        band = Z90 * np.sqrt(np.clip(np.diag(cov), 0.0, None))
        ax.fill_between(GRID, mean - band, mean + band, color=COLORS["model"], alpha=0.2, lw=0, label="90% band")
        ax.plot(GRID, draws.T, color=COLORS["model"], lw=0.9, alpha=0.9)
        ax.plot([], [], color=COLORS["model"], lw=0.9, label=f"{n_draws} draws")
        ax.set_title(title)
        ax.set_xlabel("input θ (scaled to [0, 1])")
        ax.set_xlim(0, 1)
    axes[0, 1].plot(THETA_RUNS, runs, "o", color=COLORS["training"], mec="black", ms=6, label="simulator runs")
    axes[0, 0].set_ylabel("output η(θ)")
    axes[0, 0].legend(loc="lower left")
    axes[0, 1].legend(loc="lower right")
    return fig


def _draw(mean, cov, n: int, rng):
    """`n` joint draws from N(mean, cov) on a fine grid (eigen-decomposition copes with near-singularity)."""
    vals, vecs = np.linalg.eigh(0.5 * (cov + cov.T))
    root = vecs * np.sqrt(np.clip(vals, 0.0, None))
    return mean + rng.standard_normal((n, len(mean))) @ root.T
