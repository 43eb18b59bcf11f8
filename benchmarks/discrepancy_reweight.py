"""A joint posterior under another error model by importance reweighting a finished one (issue 63, "Real data").

The proposal is a finished posterior's equal-weight draws (`--from`: `shockcal calibrate --out`, e.g. the study's
Student-t joint posterior), each paired with `--per-draw` draws from their prior of the discrepancy's parameters
(with `--discrepancy`) and of the inputs the target's shots (`--shots`) need and the proposal lacks (a
single-shot posterior as the proposal of a two-shot calibration: leave-one-shot-out). The target is the same
prior times the likelihood of `--emulator` (e.g. the study's emulator with Gaussian error tails) with
`calibration.discrepancy` none or {kind: feature_kind, sd_fraction_prior}.
Weights: log w = log L_target(theta, lambda_y, phi) - log L_from(theta, lambda_y). ArviZ's PSIS gives k-hat (the
estimate is reliable below 0.7) and the smoothed weights; log Z_target = log Z_from + log mean(w). Writes the
target's equal-weight draws (systematic resampling of the smoothed weights) as a Parquet table with the
posterior's columns, for `study_predictive_coverage`; prints the medians and sd in user units, log Z, k-hat, ESS.

Why it holds here: a Gaussian likelihood with the same or a larger covariance is at most a bounded multiple of a
Student t's of the same scale (the t has the heavier tails), and another shot's likelihood is bounded, so the
weights are bounded above and the target's mass cannot sit where the proposal has none; k-hat checks it.

    nice -n 10 .venv/bin/python benchmarks/discrepancy_reweight.py --config results/config.yaml \\
        --from results/posterior/joint.parquet --emulator results/emulator_gaussian --observed \\
        results/features/observed.parquet --discrepancy 0.02 --out results/reweighted_c.parquet
"""

import argparse

import arviz as az
import numpy as np
import pandas as pd

from shockcal.emulator.study_emulator import Emulator
from shockcal.inference.discrepancy import from_setting
from shockcal.inference.problem import LAMBDA_Y, Problem
from shockcal.io import read_table, read_table_metadata, write_table
from shockcal.study.config import input_columns, prior_bounds
from shockcal.study.stages import load_stage_config

BATCH = 500


def weighted_quantiles(x, w, q):
    order = np.argsort(x)
    return x[order][np.searchsorted(np.cumsum(w[order]), q)]


def run(args):
    config = load_stage_config(args.config, "calibrate")
    meta = read_table_metadata(args.source)
    shots = args.shots or list(meta["shots"])
    proposal = read_table(args.source)
    emulator = Emulator.load(args.emulator)
    setting = "none" if args.discrepancy is None else {"kind": "feature_kind", "sd_fraction_prior": args.discrepancy}
    problem = Problem.for_shots(emulator, shots, read_table(args.observed), config["observed"]["sd_fraction"],
                                discrepancy=setting)
    names = [*problem.names, LAMBDA_Y]
    rng = np.random.default_rng(args.seed)
    own = [name for name in names if name not in proposal.columns]       # from the prior box
    k = args.per_draw if args.discrepancy is not None or own else 1
    points = np.repeat(proposal[[n for n in names if n not in own]].to_numpy(float), k, axis=0)
    bounds = prior_bounds(config)
    for name in own:
        points = np.insert(points, names.index(name), rng.uniform(*bounds[name], len(points)), axis=1)
    base_ll = np.repeat(proposal["log_likelihood"].to_numpy(float), k)
    phi_names = problem.discrepancy_names
    if phi_names:
        term = from_setting(setting, emulator.feature_names, len(shots))
        phi = term.prior_transform(rng.uniform(size=(len(points), len(phi_names))))
        points = np.column_stack([points, phi])
    ll = np.concatenate([problem.log_likelihood(points[i:i + BATCH]) for i in range(0, len(points), BATCH)])
    log_w = ll - base_ll
    log_z = float(meta["log_evidence"]) + np.logaddexp.reduce(log_w) - np.log(len(log_w))
    smoothed, khat = az.psislw(log_w.copy())
    w = np.exp(smoothed - np.logaddexp.reduce(smoothed))
    ess = 1.0 / np.sum(w ** 2)
    columns = [*names, *phi_names]
    table = pd.DataFrame(points, columns=columns)
    print(f"{args.out}: shots {'+'.join(shots)}, {len(points)} proposals ({k} per draw; from the prior: {own}), "
          f"PSIS k-hat {float(khat):.3f}, Kish ESS {ess:.0f}, "
          f"log Z {log_z:.3f} (from {float(meta['log_evidence']):.3f}; the proposal's log Z sd "
          f"{float(meta.get('log_evidence_sd', np.nan)):.3f}; the mean weight's MC sd "
          f"{np.std(np.exp(log_w - log_w.max())) / np.mean(np.exp(log_w - log_w.max())) / np.sqrt(len(log_w)):.3f})")
    user = input_columns(config)
    rows = []
    for name in columns:
        label, _, factor = user.get(name, (name, "-", 1.0))
        q = weighted_quantiles(table[name].to_numpy(), w, [0.05, 0.5, 0.95]) * factor
        mean = np.sum(w * table[name]) * factor
        sd = np.sqrt(np.sum(w * (table[name] * factor - mean) ** 2))
        rows.append({"parameter": label, "q05": q[0], "q50": q[1], "q95": q[2], "sd": sd})
    print(pd.DataFrame(rows).to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    positions = (rng.uniform() + np.arange(args.draws)) / args.draws          # systematic resampling
    picked = np.minimum(np.searchsorted(np.cumsum(w), positions), len(w) - 1)
    draws = table.iloc[picked].reset_index(drop=True).assign(log_likelihood=ll[picked])
    write_table(draws, args.out, {"table": "importance-reweighted posterior draws", "from": args.source,
                                  "emulator": args.emulator, "discrepancy": str(setting), "khat": float(khat),
                                  "ess_kish": float(ess), "log_evidence": float(log_z), "shots": shots,
                                  "observed": problem.observed.tolist(), "observed_sd_m_s": problem.obs_sd.tolist()})


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--config", required=True)
    parser.add_argument("--from", dest="source", required=True, help="a finished posterior (calibrate --out)")
    parser.add_argument("--emulator", required=True, help="the target's emulator directory")
    parser.add_argument("--observed", required=True, help="the measured features table")
    parser.add_argument("--discrepancy", type=float, help="the feature-kind term's sd_fraction_prior (absent: none)")
    parser.add_argument("--shots", nargs="+", help="the target's shots (default: the proposal's); inputs the proposal "
                                                  "does not have are drawn from the prior box")
    parser.add_argument("--per-draw", type=int, default=10,
                        help="prior draws (discrepancy, inputs the proposal lacks) per proposal draw")
    parser.add_argument("--draws", type=int, default=10000)
    parser.add_argument("--out", required=True)
    parser.add_argument("--seed", type=int, default=1)
    run(parser.parse_args())
