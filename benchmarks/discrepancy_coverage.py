"""Known-discrepancy coverage on a linear toy emulator (issue 63), with and without `calibration.discrepancy`.

Three shots x four feature kinds (m/s), three inputs on [0, 1]; records = the toy's mean at a truth plus a
discrepancy drawn from the term's prior (`--records prior`) or none (`--records none`), plus 1% noise.
Each truth is calibrated with `none` and with `feature_kind` (nautilus); prints the 90%-interval coverage
of every input and of the discrepancy's scale, and the cost. A provisional toy: the study's check is `make check`.

    nice -n 10 .venv/bin/python benchmarks/discrepancy_coverage.py --truths 30 --records prior
"""

import argparse
import time

import numpy as np

from shockcal.inference.discrepancy import Discrepancy
from shockcal.inference.problem import Problem
from shockcal.inference.sampler import nested_sample

KINDS = ("v_a", "v_b", "v_c", "v_d")


def toy(seed: int = 0):
    """Base features (12,) m/s and a sensitivity (12, 3): the box moves each feature by up to ~6%."""
    rng = np.random.default_rng(seed)
    base = np.tile([300.0, 150.0, 500.0, 250.0], 3) * rng.uniform(0.9, 1.1, 12)
    jac = base[:, None] * rng.uniform(-0.06, 0.06, (12, 3))
    return base, jac


def run(args):
    base, jac = toy()
    cov = np.diag((0.001 * base) ** 2)

    def predict(theta):
        return base + theta @ jac.T, np.broadcast_to(cov, (len(theta), 12, 12)).copy()

    disc = Discrepancy(KINDS, 3, args.sd_fraction_prior)
    rng = np.random.default_rng(args.seed)
    hits = {"none": [], "feature_kind": []}
    scale_hits, cost = [], {"none": 0.0, "feature_kind": 0.0}
    for trial in range(args.truths):
        truth = rng.uniform(size=3)
        y = base + jac @ truth
        phi = disc.prior_transform(rng.uniform(size=(1, 5)))
        if args.records == "prior":
            y = y + rng.multivariate_normal(np.zeros(12), disc.covariance(phi, y)[0])
        y = y + rng.normal(0, 0.01 * np.abs(y))
        for kind, term in (("none", None), ("feature_kind", disc)):
            problem = Problem(predict, y, 0.01 * np.abs(y), ["x0", "x1", "x2"], np.zeros(3), np.ones(3), "toy",
                              None, term)
            start = time.process_time()
            draws = nested_sample(problem.prior_transform, problem.log_likelihood, problem.ndim, args.n_live,
                                  args.n_eff, seed=trial)
            cost[kind] += time.process_time() - start
            w = draws.weights
            covered = []
            for j in range(3):
                order = np.argsort(draws.points[:, j])
                cdf = np.cumsum(w[order])
                lo, hi = draws.points[order, j][np.searchsorted(cdf, [0.05, 0.95])]
                covered.append(lo <= truth[j] <= hi)
            hits[kind].append(covered)
            if term is not None and args.records == "prior":
                scale = draws.points[:, 4:8].mean(1)          # the kinds' mean sd fraction
                order = np.argsort(scale)
                lo, hi = scale[order][np.searchsorted(np.cumsum(w[order]), [0.05, 0.95])]
                scale_hits.append(lo <= phi[0, :4].mean() <= hi)
        print(f"truth {trial + 1}: none {np.mean(hits['none'], 0).round(2)}, feature_kind "
              f"{np.mean(hits['feature_kind'], 0).round(2)}", flush=True)
    print(f"records {args.records}, {args.truths} truths, n_live {args.n_live}, n_eff {args.n_eff}")
    for kind in hits:
        print(f"  {kind:13s} 90% coverage by input {np.mean(hits[kind], 0).round(2)}; CPU {cost[kind]:.0f} s")
    if scale_hits:
        print(f"  discrepancy scale (mean sd fraction) 90% coverage {np.mean(scale_hits):.2f}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--truths", type=int, default=30)
    parser.add_argument("--records", choices=["prior", "none"], default="prior")
    parser.add_argument("--sd-fraction-prior", type=float, default=0.02)
    parser.add_argument("--n-live", type=int, default=200)
    parser.add_argument("--n-eff", type=int, default=500)
    parser.add_argument("--seed", type=int, default=1)
    run(parser.parse_args())
