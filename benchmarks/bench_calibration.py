"""Calibration: the default sampler (nautilus) against a long reference run, on the real data.

For each calibration (joint, then each shot) on a fitted emulator and measured features:
  reference  nautilus run long (importance nested sampling, weighted draws), kept under
             --reference-dir and reused;
  default    the configured sampler with --replicates seeds: wall and CPU seconds, likelihood
             evaluations, Kish ESS, the ESS of each parameter's mean from the spread of the
             replicate means (posterior variance / variance of the means), the worst quantile error
             against the reference as a share of the box (5/25/50/75/95%), the mass at A > 800 MPa;
  smc        (--smc) smcpy's adaptive SMC with --smc-particles and --smc-moves, the same measures;
  emcee      (--emcee) an emcee ensemble of the same length in likelihood evaluations, with
             ArviZ's R-hat and bulk ESS, as a yardstick;
  dynesty    (--dynesty N_LIVE) static nested sampling with random slices, the independent
             cross-check of the reference (--replicates 0 skips the default runs).
Goal: ESS >= 1000 per parameter, worst quantile error <= 0.02 of the box, <= 60 s wall.

    .venv/bin/python benchmarks/bench_calibration.py --emulator DIR [--observed TABLE] [--only joint]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.inference.summaries import quantile_mcse, weighted_quantiles

REPO = Path(__file__).resolve().parents[1]
QUANTILES = [0.05, 0.25, 0.5, 0.75, 0.95]
TIP_A_MBAR = 0.008           # A > 800 MPa: the thin arm of the A-m posterior
SHOTS = ["104S", "105S", "106S"]
LAMBDA_Y_SPAN = 2.33         # lambda_y's "box": the 99.5% quantile of its Gamma(5, 5) prior


def load() -> str:
    return f"load {os.getloadavg()[0]:.1f}"


def reference(problem, name: str, directory: Path, n_live: int, n_eff: int, seed: int = 1) -> pd.DataFrame:
    """nautilus's weighted draws of this posterior (columns: parameters, weight), run once and kept."""
    path = directory / f"reference_{name}.parquet"
    if path.is_file():
        return pd.read_parquet(path)
    from nautilus import Sampler

    start = time.perf_counter()
    sampler = Sampler(problem.prior_transform, problem.log_likelihood, n_dim=problem.ndim, n_live=n_live,
                      vectorized=True, seed=seed, n_networks=1)
    sampler.run(n_eff=n_eff, discard_exploration=True)
    points, log_w, _ = sampler.posterior()
    w = np.exp(log_w - log_w.max())
    frame = pd.DataFrame(points, columns=[*problem.names, "lambda_y"]).assign(weight=w / w.sum())
    directory.mkdir(parents=True, exist_ok=True)
    frame.to_parquet(path)
    print(f"  reference (nautilus, n_live {n_live}, n_eff {n_eff}, seed {seed}): {time.perf_counter() - start:.0f} s wall, "
          f"{sampler.n_like} evaluations, Kish ESS {1 / np.sum(frame['weight'] ** 2):.0f}, "
          f"log evidence {sampler.log_z:.3f} ({load()})")
    return frame


def worst_quantile_error(points: np.ndarray, ref: pd.DataFrame, names, width) -> tuple[float, str]:
    """Worst |quantile - reference quantile| / box width over parameters and QUANTILES, and where."""
    worst, where = 0.0, ""
    for j, name in enumerate(names):
        q_ref = weighted_quantiles(ref[name].to_numpy(), ref["weight"].to_numpy(), QUANTILES)
        q = np.quantile(points[:, j], QUANTILES)
        error = np.abs(q - q_ref) / width[j]
        if error.max() > worst:
            k = int(np.argmax(error))
            worst, where = float(error.max()), (f"{name} q{round(100 * QUANTILES[k]):02d} "
                                                f"{q[k]:.4g} against {q_ref[k]:.4g}")
    return worst, where


def quantile_z(draws, ref: pd.DataFrame, names) -> tuple[float, str]:
    """Worst |quantile - reference quantile| in units of the Monte Carlo standard error of that
    difference (both runs' `quantile_mcse`), and where: is the error the sampling noise of the ESS?"""
    worst, where = 0.0, ""
    w_ref = ref["weight"].to_numpy()
    for j, name in enumerate(names):
        x_ref, x = ref[name].to_numpy(), draws.points[:, j]
        difference = weighted_quantiles(x, draws.weights, QUANTILES) - weighted_quantiles(x_ref, w_ref, QUANTILES)
        error = np.hypot(quantile_mcse(x, draws.weights, QUANTILES), quantile_mcse(x_ref, w_ref, QUANTILES))
        z = np.abs(difference) / error
        if z.max() > worst:
            worst, where = float(z.max()), f"{name} q{round(100 * QUANTILES[int(np.argmax(z))]):02d}"
    return worst, where


def run_default(problem, settings, seed):
    """The configured nautilus run: equal-weight draws (resampled), wall and CPU seconds, evaluations."""
    from shockcal.inference.sampler import nested_sample

    start, cpu = time.perf_counter(), time.process_time()
    draws = nested_sample(problem.prior_transform, problem.log_likelihood, problem.ndim, settings["n_live"],
                          settings["n_eff"], seed, problem.cube_power(settings["cube_power"], others="ignore"))
    points = draws.points[draws.resample(20000, np.random.default_rng(seed))]
    return points, time.perf_counter() - start, time.process_time() - cpu, draws.n_likelihood, draws


def run_smc(problem, particles: int, moves: int, seed: int):
    """smcpy's adaptive SMC on the unit cube (the sampler measured and not adopted; docs/calibration.md)."""
    from scipy import stats
    from smcpy import AdaptiveSampler, VectorMCMC, VectorMCMCKernel

    evaluations = [0]

    class CubeLikelihood:
        def __init__(self, *_):
            pass

        def __call__(self, cube):
            evaluations[0] += len(cube)
            return problem.log_likelihood(problem.prior_transform(cube))[:, None]

    start, cpu = time.perf_counter(), time.process_time()
    mcmc = VectorMCMC(None, None, [stats.uniform(0.0, 1.0)] * problem.ndim, log_like_func=CubeLikelihood)
    kernel = VectorMCMCKernel(mcmc, param_order=[f"u{i}" for i in range(problem.ndim)],
                              rng=np.random.default_rng(seed))
    steps, _ = AdaptiveSampler(kernel, show_progress_bar=False).sample(particles, moves, target_ess=0.8)
    points = problem.prior_transform(steps[-1].params)
    return points, time.perf_counter() - start, time.process_time() - cpu, evaluations[0]


def run_dynesty(problem, n_live: int, seed: int, keep: Path):
    """dynesty's static nested sampling (multi-ellipsoid bounds, random slices; one point per call):
    the independent cross-check of the reference. Equal-weight draws, wall and CPU seconds, calls,
    the weighted draws (also written to `keep`, about an hour's work) and its log evidence with its error."""
    import dynesty
    from dynesty.utils import resample_equal

    from shockcal.inference.sampler import WeightedDraws

    rng = np.random.default_rng(seed)
    start, cpu = time.perf_counter(), time.process_time()
    sampler = dynesty.NestedSampler(lambda x: float(problem.log_likelihood(x[None])[0]),
                                    lambda u: problem.prior_transform(u[None])[0], problem.ndim, nlive=n_live,
                                    bound="multi", sample="rslice", rstate=rng)
    sampler.run_nested(dlogz=0.1, print_progress=False)
    result = sampler.results
    weights = np.exp(result.logwt - result.logz[-1])
    weights /= weights.sum()
    points = resample_equal(result.samples, weights, rstate=rng)
    keep.parent.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(result.samples, columns=[*problem.names, "lambda_y"]).assign(weight=weights).to_parquet(keep)
    draws = WeightedDraws(result.samples, np.log(weights), result.logl, float(result.logz[-1]),
                          int(np.sum(result.ncall)))
    return (points, time.perf_counter() - start, time.process_time() - cpu, int(np.sum(result.ncall)), draws,
            float(result.logz[-1]), float(result.logzerr[-1]))


def report(label, runs, ref, names, width):
    """Print the measures of replicate runs [(points, wall, cpu, evaluations), ...]."""
    means = np.array([points.mean(axis=0) for points, *_ in runs])
    variance = np.array([np.cov(ref[n], aweights=ref["weight"]) for n in names])
    worst = [worst_quantile_error(points, ref, names, width) for points, *_ in runs]
    errors = [error for error, _ in worst]
    tip = [np.mean(points[:, names.index("A")] > TIP_A_MBAR) for points, *_ in runs] if "A" in names else [np.nan]
    wall = np.median([r[1] for r in runs])
    weighted = [r[4] for r in runs if len(r) > 4]
    print(f"  {label} x{len(runs)}: wall {wall:.1f} s median, CPU {np.median([r[2] for r in runs]):.1f} s, "
          f"{int(np.median([r[3] for r in runs]))} evaluations ({load()})")
    if len(runs) > 1:
        ess = variance / means.var(axis=0, ddof=1)
        print(f"  {label} ESS of the mean per parameter (replicate spread): "
              + ", ".join(f"{n} {e:.0f}" for n, e in zip(names, ess)) + f"; min {ess.min():.0f}")
    print(f"  {label} worst quantile error vs reference: median {np.median(errors):.4f}, max {np.max(errors):.4f} "
          f"of the box ({worst[int(np.argmax(errors))][1]}); "
          f"mass at A > 800 MPa {np.mean(tip):.3f} (reference "
          f"{ref['weight'][ref['A'] > TIP_A_MBAR].sum() if 'A' in names else np.nan:.3f})")
    for draws in weighted:
        z, where = quantile_z(draws, ref, names)
        print(f"  {label} worst quantile error in Monte Carlo standard errors of the difference: {z:.1f} ({where})")


def run_emcee(problem, evaluations: int, seed: int):
    """An emcee ensemble (64 walkers from the prior, half the steps burn-in) and ArviZ diagnostics."""
    import arviz
    import emcee

    walkers = 64
    rng = np.random.default_rng(seed)
    start = problem.prior_transform(rng.uniform(size=(walkers, problem.ndim)))
    start[:, -1] = np.log(start[:, -1])
    steps = evaluations // walkers
    sampler = emcee.EnsembleSampler(walkers, problem.ndim, problem.log_posterior, vectorize=True,
                                    moves=[(emcee.moves.DEMove(), 0.8), (emcee.moves.StretchMove(), 0.2)])
    sampler.random_state = np.random.RandomState(seed).get_state()
    t0 = time.perf_counter()
    sampler.run_mcmc(start, steps, progress=False)
    chain = sampler.get_chain(discard=steps // 2).transpose(1, 0, 2)        # (walkers, draws, d)
    chain[..., -1] = np.exp(chain[..., -1])
    data = arviz.convert_to_dataset({"x": chain})
    return (chain.reshape(-1, problem.ndim), time.perf_counter() - t0,
            float(arviz.rhat(data)["x"].max()), float(arviz.ess(data, method="bulk")["x"].min()))


def main(argv=None) -> int:
    from shockcal.emulator.study_emulator import Emulator
    from shockcal.inference.problem import Problem
    from shockcal.io import read_table
    from shockcal.study.validate import load_config

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--emulator", default=str(REPO / "results" / "emulator"), help="emulator directory")
    parser.add_argument("--observed", default=str(REPO / "data" / "al5083" / "observed_features.csv"),
                        help="measured features (default: the paper's published values)")
    parser.add_argument("--config", default=str(REPO / "config" / "config.yaml"))
    parser.add_argument("--only", nargs="+", choices=[*SHOTS, "joint"], default=["joint", *SHOTS])
    parser.add_argument("--replicates", type=int, default=3)
    parser.add_argument("--reference-dir", default=str(REPO / "benchmarks" / "out" / "reference"),
                        help="where reference posteriors are kept (one per emulator: use one directory each)")
    parser.add_argument("--reference-live", type=int, default=2000)
    parser.add_argument("--reference-eff", type=int, default=20000)
    parser.add_argument("--reference-seed", type=int, default=1,
                        help="seed of a new reference run (a second seed checks the reference itself)")
    parser.add_argument("--smc", action="store_true", help="also run smcpy's adaptive SMC")
    parser.add_argument("--smc-particles", type=int, default=4000)
    parser.add_argument("--smc-moves", type=int, default=5)
    parser.add_argument("--emcee", action="store_true", help="also run the emcee yardstick (60,000 evaluations)")
    parser.add_argument("--dynesty", type=int, default=0, metavar="N_LIVE",
                        help="also run dynesty with N_LIVE live points (random slices), the independent cross-check")
    args = parser.parse_args(argv)
    if not (Path(args.emulator) / "emulator.json").is_file():
        print(f"skipped: no emulator at {args.emulator} (shockcal emulate, or the study)")
        return 0
    config = load_config(args.config)
    emulator = Emulator.load(args.emulator)
    observed = read_table(args.observed)
    settings = config["calibration"]
    print(f"emulator {args.emulator}, observed {args.observed}; nautilus {settings['n_live']} live points, "
          f"ESS {settings['n_eff']}, cube powers {settings['cube_power']}")
    for name in args.only:
        shots = SHOTS if name == "joint" else [name]
        problem = Problem.for_shots(emulator, shots, observed, config["observed"]["sd_fraction"])
        names = [*problem.names, "lambda_y"]
        ref = reference(problem, name, Path(args.reference_dir), args.reference_live, args.reference_eff,
                        args.reference_seed)
        width = np.append(problem.upper - problem.lower, LAMBDA_Y_SPAN)
        print(f"== {name}: {len(names)} parameters")
        if args.replicates:
            report("default", [run_default(problem, settings, seed) for seed in range(1, args.replicates + 1)],
                   ref, names, width)
        if args.dynesty:
            *run, log_z, log_z_error = run_dynesty(problem, args.dynesty, seed=1,
                                                   keep=Path(args.reference_dir) / f"dynesty_{name}.parquet")
            report(f"dynesty ({args.dynesty} live, slices)", [run], ref, names, width)
            print(f"  dynesty log evidence {log_z:.3f} +- {log_z_error:.3f}")
        if args.smc:
            report("smc", [run_smc(problem, args.smc_particles, args.smc_moves, seed=1)], ref, names, width)
        if args.emcee:
            evaluations = 60000
            draws, seconds, rhat, ess_bulk = run_emcee(problem, evaluations, seed=1)
            print(f"  emcee, {evaluations} evaluations: {seconds:.1f} s, max R-hat {rhat:.3f}, min bulk ESS "
                  f"{ess_bulk:.0f} (ArviZ), worst quantile error {worst_quantile_error(draws, ref, names, width)[0]:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
