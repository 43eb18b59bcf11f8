"""Calibration speed: likelihood evaluations per second, where an evaluation's time goes,
and the joint calibration's wall time, each beside the figure before 2026-11-26 ("before") measured in the same run.

On the paper study's emulator and measured features (`make paper`: `results/emulator`,
`results/features/observed.parquet`; skipped without them), at points drawn from the joint posterior's weighted draws
(`results/posterior/joint_weighted.parquet`; else uniform on the prior box), in batches of 100 points
(nautilus's batch):
  likelihood  evaluations per second of the joint likelihood (12 features, 11 inputs), and per point
              its phases: mean (the components' cross-covariances and their products with K^-1 y),
              variance (the triangular solves against the 1000-run Cholesky factors), glue (the basis,
              sd factors and the error model's density); "before" is the solve of main before
              2026-11-26 (on `n_jobs` BLAS threads, `previous_predict_weights`), "now" the library's;
  joint       the joint calibration with the study's settings and seed: wall and CPU seconds, the
              evaluations and the seconds spent inside the likelihood; the wall before is the same run with
              each evaluation at its measured cost before (the sampler's path is the same: the two give the
              same posterior to the bit);
  four-shot   the same for a four-shot emulator (`--four-shot-emulator DIR`, e.g. docs/workflow.md's
              "How to add a shot" run); without one it is skipped, saying so.
The machine is shared: the load average is printed beside every figure.

    .venv/bin/python benchmarks/bench_likelihood.py [--emulator DIR] [--observed TABLE] [--no-joint]
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd

REPO = Path(__file__).resolve().parents[1]
SHOTS = ["104S", "105S", "106S"]
BATCH = 100                  # nautilus's likelihood batch


def load() -> str:
    return "load " + " ".join(Path("/proc/loadavg").read_text().split()[:3])


def previous_predict_weights(model, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The yardstick "before": `PCGPEmulator._predict_weights` of main before 2026-11-26, the
    cross-covariances on `n_jobs` Python threads, then every component's solve on `n_jobs` BLAS threads."""
    from shockcal.emulator.pcgp import _blas_threads

    threads = model.settings.n_jobs
    with ThreadPoolExecutor(threads) as pool:
        cross = list(pool.map(lambda gp: gp.prior_cov(x, gp.x), model.gps))
    with _blas_threads().limit(limits=threads, user_api="blas"):
        parts = [gp.predict_from_cross_cov(k) for gp, k in zip(model.gps, cross)]
    return np.column_stack([m for m, _ in parts]), np.column_stack([v for _, v in parts])


def per_point_us(fn, batches, repeats: int = 3) -> float:
    """Median over `repeats` of the microseconds per point of fn over all batches."""
    fn(batches[0])
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for batch in batches:
            fn(batch)
        times.append((time.perf_counter() - start) / sum(len(b) for b in batches))
    return 1e6 * float(np.median(times))


def evaluation_points(problem, posterior: Path, n: int, rng) -> tuple[np.ndarray, str]:
    """n points (theta, lambda_y): drawn from the weighted joint posterior if given, else the prior."""
    if posterior.is_file():
        table = pd.read_parquet(posterior)
        weights = np.exp(table["log_weight"] - table["log_weight"].max())
        rows = rng.choice(len(table), n, p=weights / weights.sum())
        return table[[*problem.names, "lambda_y"]].to_numpy()[rows], f"{posterior.name} draws"
    return problem.prior_transform(rng.uniform(size=(n, problem.ndim))), "the prior box"


def likelihood_costs(problem, emulator, points: np.ndarray) -> dict[str, float]:
    """Per point (us): the likelihood now and before; the basis weights' mean, and their mean and
    variance now and before (the variance is their difference)."""
    from shockcal.emulator.pcgp import PCGPEmulator

    block = emulator.blocks[0]
    model = block.model
    batches = [points[i:i + BATCH] for i in range(0, len(points), BATCH)]
    scaled = [model.scaled(block.input_map.raw(emulator._complete(dict(zip(problem.names, b[:, :-1].T)), block,
                                                                  len(b)))) for b in batches]
    costs = {"now": per_point_us(problem.log_likelihood, batches)}
    current = PCGPEmulator._predict_weights
    PCGPEmulator._predict_weights = previous_predict_weights
    try:
        costs["before"] = per_point_us(problem.log_likelihood, batches)
    finally:
        PCGPEmulator._predict_weights = current
    gp_mean = [lambda x, gp=gp: gp.hyper.mean + gp.prior_cov(x, gp.x) @ gp.alpha for gp in model.gps]
    costs["mean"] = per_point_us(lambda x: [f(x) for f in gp_mean], scaled)
    costs["weights now"] = per_point_us(lambda x: model._predict_weights(np.ascontiguousarray(x)), scaled)
    costs["weights before"] = per_point_us(lambda x: previous_predict_weights(model, np.ascontiguousarray(x)), scaled)
    return costs


def timed_calibration(emulator, shots, observed, config, label: str) -> dict:
    """The study's calibration of `shots` (settings and seed), with the seconds spent in the likelihood."""
    from shockcal.inference.problem import Problem
    from shockcal.inference.sampler import sample
    from shockcal.study.adapters import calibration_settings

    settings = calibration_settings(config, shots)
    problem = Problem.for_shots(emulator, shots, observed, settings.sd_fraction, bounds=settings.bounds)
    inside = [0.0]
    likelihood = problem.log_likelihood

    def timed_likelihood(points):
        start = time.perf_counter()
        value = likelihood(points)
        inside[0] += time.perf_counter() - start
        return value

    problem.log_likelihood = timed_likelihood
    start, cpu = time.perf_counter(), time.process_time()
    posterior = sample(problem, settings.sampler, other_powers="ignore")
    wall = time.perf_counter() - start
    out = {"wall": wall, "cpu": time.process_time() - cpu, "inside": inside[0],
           "evaluations": posterior.weighted.n_likelihood, "problem": problem}
    print(f"  {label}: {wall:.0f} s wall, {out['cpu']:.0f} CPU-s, {out['evaluations']:,} evaluations, "
          f"{out['inside']:.0f} s inside the likelihood ({load()}); log Z {posterior.log_evidence:.3f}")
    return out


def main(argv=None) -> int:
    from shockcal.emulator.study_emulator import Emulator
    from shockcal.inference.problem import Problem
    from shockcal.io import read_table
    from shockcal.study.validate import load_config

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--emulator", default=str(REPO / "results" / "emulator"))
    parser.add_argument("--observed", default=str(REPO / "results" / "features" / "observed.parquet"))
    parser.add_argument("--posterior", default=str(REPO / "results" / "posterior" / "joint_weighted.parquet"))
    parser.add_argument("--config", default=str(REPO / "config" / "config.yaml"))
    parser.add_argument("--points", type=int, default=2000, help="likelihood points timed (in batches of 100)")
    parser.add_argument("--no-joint", action="store_true", help="skip the joint calibration (about 2 min)")
    parser.add_argument("--four-shot-emulator", help="a four-shot emulator directory (with --four-shot-observed)")
    parser.add_argument("--four-shot-observed", help="its measured features (four shots)")
    parser.add_argument("--four-shot-config", help="the config of the four-shot study")
    args = parser.parse_args(argv)
    if not (Path(args.emulator) / "emulator.json").is_file() or not Path(args.observed).is_file():
        print(f"skipped: no emulator at {args.emulator} or no measured features at {args.observed} (the study)")
        return 0
    config = load_config(args.config)
    emulator = Emulator.load(args.emulator)
    observed = read_table(args.observed)
    problem = Problem.for_shots(emulator, SHOTS, observed, config["observed"]["sd_fraction"])
    model = emulator.blocks[0].model
    points, source = evaluation_points(problem, Path(args.posterior), args.points, np.random.default_rng(1))
    print(f"joint likelihood: {len(model.x_train)} runs, {len(model.gps)} components, {len(problem.observed)} "
          f"features; {len(points)} points from {source}, batches of {BATCH}, {model.settings.n_jobs} threads")
    costs = likelihood_costs(problem, emulator, points)
    print(f"  likelihood evaluations per second: now {1e6 / costs['now']:.0f}, before {1e6 / costs['before']:.0f} "
          f"({costs['now']:.0f} / {costs['before']:.0f} us a point; {load()})")
    variance_now = costs["weights now"] - costs["mean"]
    variance_before = costs["weights before"] - costs["mean"]
    print(f"  per point now (us): mean {costs['mean']:.0f}, variance {variance_now:.0f}, glue "
          f"{costs['now'] - costs['weights now']:.0f}; the variance before {variance_before:.0f} ({load()})")
    if not args.no_joint:
        run = timed_calibration(emulator, SHOTS, observed, config, "joint now")
        before = run["wall"] + run["evaluations"] * (costs["before"] - costs["now"]) * 1e-6
        print(f"  joint wall: now {run['wall']:.0f} s, before {before:.0f} s (the same run at the "
              f"{costs['before']:.0f} us an evaluation before); outside the likelihood (nautilus): "
              f"{run['wall'] - run['inside']:.0f} s")
    if args.four_shot_emulator and args.four_shot_observed:
        four = Emulator.load(args.four_shot_emulator)
        four_config = load_config(args.four_shot_config or args.config)
        shots = list(four.shots)
        run = timed_calibration(four, shots, read_table(args.four_shot_observed), four_config, "four-shot joint now")
        per_eval = run["inside"] / run["evaluations"]
        print(f"  four-shot joint: now {run['wall']:.0f} s; {1e6 * per_eval:.0f} us an evaluation in the run")
    else:
        print("  four-shot joint: skipped (no four-shot emulator: --four-shot-emulator DIR --four-shot-observed "
              "TABLE --four-shot-config CONFIG)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
