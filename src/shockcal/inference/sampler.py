"""Posterior sampling: importance nested sampling (nautilus) from a prior transform on the unit cube.

A problem hands over a prior transform (unit cube -> parameters) and a vectorised log-likelihood
(a batch of points in, a batch of values out), so every sampler targets exactly the same density.
The default, nautilus (J. U. Lange 2023, MNRAS 525, 3181: nested sampling whose bounds are learned
by neural networks, with every likelihood evaluation kept as an importance sample), needs no
starting points, burn-in or tuning. It covers the whole box before it concentrates, so the modes of
the joint posterior and its thin A-m arm are weighted by their mass, and it returns the evidence.
It was chosen by measurement on the joint posterior of the paper's data (docs/journal/calibration.md,
"Sampler choice"): against a long nautilus reference, the default settings put every quantile
within 0.021 of the box, while smcpy's adaptive SMC put 7% or 53% of the mass in the A > 800 MPa
arm (reference 67%) depending on its settings, and our earlier hand-built ensemble sampler almost
none.

The draws are weighted; `WeightedDraws.resample` gives equal-weight rows for consumers that want
them (figures, posterior-predictive runs), and summaries use the weights. `sample(problem, settings)`
returns a `Posterior`, which keeps both, the evidence and the sampler's counts.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.special import logsumexp

from shockcal.errors import SamplerError
from shockcal.inference.problem import LAMBDA_Y
from shockcal.inference.settings import SamplerSettings
from shockcal.inference.summaries import summarize
from shockcal.progress import Every
from shockcal.seeds import stream_seed
from shockcal.units import user_columns

log = logging.getLogger("shockcal.inference.sampler")


@dataclass
class WeightedDraws:
    """Weighted posterior draws with the run's evidence and cost."""

    points: np.ndarray           # (N, d) parameters, the prior transform's units
    log_weight: np.ndarray       # (N,) normalised: logsumexp(log_weight) = 0
    log_likelihood: np.ndarray   # (N,)
    log_evidence: float          # log marginal likelihood (the likelihood's constants included)
    n_likelihood: int            # likelihood evaluations spent
    log_evidence_sd: float = float("nan")   # its Monte Carlo sd (`evidence_sd`); NaN when unknown
    replicate: np.ndarray | None = None     # (N,) which independent run each draw comes from (`pool`); None: one run

    @property
    def weights(self) -> np.ndarray:
        return np.exp(self.log_weight)

    def kish_ess(self) -> float:
        """Kish's effective sample size of the weights, (sum w)^2 / sum w^2."""
        return float(1.0 / np.sum(self.weights**2))

    def resample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """Indices of n equal-weight draws by systematic resampling: point i appears floor or
        ceil(n w_i) times, the least noise any resampling scheme adds."""
        edges = np.cumsum(self.weights)
        edges[-1] = 1.0
        return np.searchsorted(edges, (rng.uniform() + np.arange(n)) / n)


def nested_sample(prior_transform, log_likelihood, ndim: int, n_live: int, n_eff: int, seed: int,
                  cube_power=None, max_evaluations: float = np.inf) -> WeightedDraws:
    """Run nautilus until the weighted draws reach `n_eff` effective (Kish) samples, or raise
    `SamplerError` when that takes more than `max_evaluations` likelihood evaluations (a bound that
    never shrinks, seen upstream as nautilus issues #37 and #66, would otherwise run forever).

    `prior_transform` maps (N, ndim) points of the unit cube to parameters; `log_likelihood` takes
    (N, ndim) parameters to (N,). One network per bound (nautilus's default is four: on this
    problem one gives the same posterior at a quarter of the training time). The exploration
    phase is discarded, as nautilus advises for an unbiased posterior and evidence. Same seed,
    same draws.

    `cube_power` (ndim,), default all 1, changes where the sampler looks, not the posterior: unit
    coordinate j is drawn as v_j = u_j^p_j before the prior transform, and the likelihood nautilus
    sees is multiplied by the prior-to-sampling density ratio prod_j p_j u_j^(p_j - 1), so the
    weighted draws and the evidence target the same posterior. A power above 1 widens the low end
    of a coordinate in the cube: a thin posterior arm there (m near 0, docs/calibration.md "The
    low-m arm") gets as many live points as its mass needs instead of being cut off by the bounds.
    The draws' `log_likelihood` is the caller's, without the ratio.

    Progress goes to the log (logger `shockcal.inference.sampler`, INFO) at most every 30 s: evaluations spent,
    then the effective sample size against `n_eff`. nautilus's own `verbose` status is not used: it
    redraws one line with carriage returns, padded to the terminal's width, which a job's log file
    keeps as one long line.
    """
    from nautilus import Sampler

    power = np.ones(ndim) if cube_power is None else np.asarray(cube_power, dtype=float)
    warped = np.flatnonzero(power != 1.0)

    def log_density_ratio(u):
        return np.sum(np.log(power[warped]) + (power[warped] - 1.0) * np.log(u[:, warped]), axis=1)

    def to_parameters(u):
        return prior_transform(u ** power)

    every = Every()

    def sampled_log_likelihood(u):
        if every():    # reads the sampler's counters only: the draws do not change
            log.info("nautilus: %s likelihood evaluations in %.0f s, %s", f"{sampler.n_like:,}", every.elapsed_s(),
                     f"effective sample size {sampler.n_eff:.0f} of {n_eff}" if sampler.explored else "exploring")
        return log_likelihood(to_parameters(u)) + log_density_ratio(u)

    sampler = Sampler(lambda u: u, sampled_log_likelihood, n_dim=ndim, n_live=n_live, vectorized=True, seed=seed,
                      n_networks=1)
    if not sampler.run(n_eff=n_eff, n_like_max=max_evaluations, discard_exploration=True, verbose=False):
        raise SamplerError(f"nautilus stopped at its limit of {max_evaluations:,.0f} likelihood evaluations "
                           f"(max_evaluations) before the effective sample size reached {n_eff}: ESS "
                           f"{sampler.n_eff:.0f}, exploration {'done' if sampler.explored else 'not finished'}")
    cube, log_w, log_l = (np.asarray(a) for a in sampler.posterior())
    return WeightedDraws(to_parameters(cube), log_w - logsumexp(log_w), log_l - log_density_ratio(cube),
                         float(sampler.log_z), int(sampler.n_like), evidence_sd(sampler))


def pool(runs: list[WeightedDraws]) -> WeightedDraws:
    """Independent runs on one posterior as one set of weighted draws: each run's normalised weights
    divided by the number of runs (an equal mixture of their estimates), the evidence the mean of
    theirs (log Z = logsumexp(log Z_r) - log R) with the count-based sd of that mean, the evaluations
    summed, and each draw's run in `replicate` (for Monte Carlo errors from the runs' spread,
    `summaries.quantile_mcse_between`)."""
    log_r = np.log(len(runs))
    log_z = np.array([run.log_evidence for run in runs])
    share = np.exp(log_z - logsumexp(log_z))
    return WeightedDraws(np.concatenate([run.points for run in runs]),
                         np.concatenate([run.log_weight - log_r for run in runs]),
                         np.concatenate([run.log_likelihood for run in runs]),
                         float(logsumexp(log_z) - log_r), int(sum(run.n_likelihood for run in runs)),
                         float(np.sqrt(np.sum(share**2 * np.array([run.log_evidence_sd for run in runs]) ** 2))),
                         np.concatenate([np.full(len(run.log_weight), r) for r, run in enumerate(runs)]))


def evidence_sd(sampler) -> float:
    """Monte Carlo sd of a finished nautilus run's log Z, from its own counts (delta method).

    nautilus estimates Z = sum_k V_k / N_k sum_{i in shell k} L_i: V_k the volume of bound k, N_k the
    points drawn from it in the sampling phase, of which those outside the next bound make shell k.
    Given the bounds, the shells are independent strata, and each contributes its share s_k of Z
    times a relative error with variance
      1 / ESS_k - 1 / N_k   (the points drawn: which land in the shell and their likelihoods), plus
      var log V_k           (V_k is itself a count: the accepted share of points drawn from the bound's
                             outer ellipsoids, and of the ellipsoids' union; binomial, r / (s (s - r))).
    The second term is what the weights' Kish ESS cannot see: the shared volume error of all the
    points of a shell. The bounds' own randomness is left out. Measured on the study's 104S posterior
    (docs/posteriors.md, "Monte Carlo errors"): 0.0156 (mean over 8 runs) against 0.0155 over 12
    seeds, where the weights' Kish formula gives 0.0119.
    """
    log_z_k = sampler.shell_log_l + sampler.shell_log_v
    used = np.isfinite(log_z_k) & (sampler.shell_n > 0)
    share = np.exp(log_z_k[used] - logsumexp(log_z_k[used]))
    drawn = (sampler.shell_n_sample - sampler.shell_n_sample_exp)[used]
    strata = 1.0 / sampler.shell_n_eff[used] - 1.0 / np.maximum(drawn, 1)
    volumes = np.array([log_volume_variance(bound) for bound in sampler.bounds])[used]
    return float(np.sqrt(np.sum(share**2 * (np.maximum(strata, 0.0) + volumes))))


def log_volume_variance(bound) -> float:
    """Variance of a nautilus bound's estimated log volume: the binomial variance of the log of its
    accepted share, r / (s (s - r)) for s points drawn and r rejected, for the bound and its outer
    union of ellipsoids (the unit cube's volume is exact: 0)."""
    total = 0.0
    for level in (bound, getattr(bound, "outer_bound", None)):
        drawn, rejected = getattr(level, "n_sample", 0), getattr(level, "n_reject", 0)
        if drawn > rejected:
            total += rejected / (drawn * (drawn - rejected))
    return total


@dataclass
class Posterior:
    """A sampled posterior: the sampler's weighted draws (the exact result), an equal-weight resample,
    the log evidence with its uncertainty and the sampler's counts.

    `names` are the parameters: the calibrated inputs (native units: `units`, e.g. the paper's Mbar and
    cm/us), then lambda_y. `draws` has one row per equal-weight draw (the parameters and
    `log_likelihood`, native units); `weighted_table()` the weighted draws with their log weights
    (native units); `summary()` the weighted mean, sd and quantiles with their Monte Carlo errors, in
    `user_units` (name -> the unit a user reads, e.g. {"A": "MPa", "G1": "GPa", "V1": "m/s"};
    `shockcal.units.user_unit`); `info()` everything else (evidence, counts, settings) as a plain dict.
    """

    names: list[str]
    weighted: WeightedDraws
    draws: pd.DataFrame
    settings: SamplerSettings
    cube_power: dict
    distinct_draws: int
    units: dict = field(default_factory=dict)
    user_units: dict = field(default_factory=dict)
    context: dict = field(default_factory=dict)    # what the caller adds to info() (shots, measured features)

    @property
    def log_evidence(self) -> float:
        """log Z, the likelihood's normalising constants included."""
        return self.weighted.log_evidence

    @property
    def log_evidence_sd(self) -> float:
        """log Z's Monte Carlo sd from the sampler's counts (`evidence_sd`); for draws that do not carry
        it, the weights' delta-method sd sqrt(1 / ESS - 1 / N) (ESS their Kish ESS, N the draws), which
        leaves out the shells' volume errors and so is too small (by 1.5-1.7x on the study's posteriors)."""
        if np.isfinite(self.weighted.log_evidence_sd):
            return self.weighted.log_evidence_sd
        n = len(self.weighted.log_weight)
        return float(np.sqrt(max(1.0 / self.weighted.kish_ess() - 1.0 / n, 0.0)))

    def summary(self, native: bool = False) -> pd.DataFrame:
        """Per parameter: weighted mean, sd, 5/50/95% quantiles with their Monte Carlo standard errors,
        the Kish ESS, and the unit where known. The values are in the user units (`user_units`), the
        unit in the parameter's name (`A_MPa`, `G1_GPa`, `V1_m_s`; C, n, m, lambda_y as they are) and in
        the `unit` column; `native`: in the parameters' own units and names (`units`), as sampled."""
        table = summarize(self.weighted, self.names)
        if not self.units:
            return table
        if native:
            table.insert(1, "unit", table["parameter"].map(self.units))
            return table
        columns = user_columns(self.units, self.user_units)
        factor = table["parameter"].map(lambda name: columns[name][2] if name in columns else 1.0)
        scaled = [c for c in table.columns if c not in ("parameter", "ess")]
        table[scaled] = table[scaled].mul(factor, axis=0)
        table.insert(1, "unit", table["parameter"].map(lambda name: columns[name][1] if name in columns else "-"))
        table["parameter"] = table["parameter"].map(lambda name: columns[name][0] if name in columns else name)
        return table

    def weighted_table(self) -> pd.DataFrame:
        """The weighted draws: the parameters, `log_weight` (normalised: logsumexp = 0), `log_likelihood`
        and, for pooled runs, `replicate`."""
        table = pd.DataFrame(self.weighted.points, columns=self.names)
        table["log_weight"] = self.weighted.log_weight
        table["log_likelihood"] = self.weighted.log_likelihood
        if self.weighted.replicate is not None:
            table["replicate"] = self.weighted.replicate
        return table

    def info(self) -> dict:
        """The run: sampler settings, log evidence and its sd, likelihood evaluations, Kish ESS, draws."""
        return {"sampler": "nautilus", "n_live": self.settings.n_live, "n_eff_target": self.settings.n_eff,
                "seed": self.settings.seed, "log_evidence": self.log_evidence,
                "log_evidence_sd": self.log_evidence_sd, "likelihood_evaluations": self.weighted.n_likelihood,
                "cube_power": self.cube_power, "weighted_draws": len(self.weighted.points),
                "ess_kish": self.weighted.kish_ess(), "replicates": self.settings.replicates,
                "retained": len(self.draws),
                "distinct_draws": self.distinct_draws, **self.context}

    def __repr__(self) -> str:
        return (f"Posterior({len(self.names)} parameters {self.names}, {len(self.weighted.points)} weighted draws, "
                f"Kish ESS {self.weighted.kish_ess():.0f}, {len(self.draws)} equal-weight draws, "
                f"log Z {self.log_evidence:.3f} +- {self.log_evidence_sd:.3f}, "
                f"{self.weighted.n_likelihood} likelihood evaluations)")


def sample(problem, settings: SamplerSettings, other_powers: str = "error") -> Posterior:
    """Sample a problem's posterior with nautilus.

    Args:
        problem: a `shockcal.inference.problem.Problem` (prior transform, batch log-likelihood, names; a
            stand-in without a discrepancy need not have `discrepancy_names`).
        settings: the sampler's settings.
        other_powers: `Problem.cube_power`'s `others` ("error": a power of an input the problem does
            not calibrate is an error; "ignore": skipped).

    Returns:
        The `Posterior`: weighted draws, `settings.draws` equal-weight draws resampled from them, evidence.
    """
    power = problem.cube_power(settings.cube_power, other_powers)
    n_eff = int(np.ceil(settings.n_eff / settings.replicates))
    runs = [nested_sample(problem.prior_transform, problem.log_likelihood, problem.ndim, settings.n_live, n_eff,
                          settings.seed if r == 0 else stream_seed(settings.seed, "replicate", r), power,
                          settings.max_evaluations)
            for r in range(settings.replicates)]
    weighted = runs[0] if len(runs) == 1 else pool(runs)
    names = [*problem.names, LAMBDA_Y, *getattr(problem, "discrepancy_names", ())]
    rows = weighted.resample(settings.draws, np.random.default_rng(settings.seed))
    draws = pd.DataFrame(weighted.points[rows], columns=names)
    draws["log_likelihood"] = weighted.log_likelihood[rows]
    return Posterior(names, weighted, draws, settings, {k: float(p) for k, p in zip(problem.names, power) if p != 1.0},
                     int(len(np.unique(rows))))
