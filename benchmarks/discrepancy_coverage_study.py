"""Known-discrepancy and null coverage on a study's emulator (issue 63), with and without `calibration.discrepancy`.

Truths: rows of the study's joint posterior draws (`--truths-from`, native units). Records: the truth's features
(`--eta`: `hydrocode`, the study's hydrocode and extractor at the truth, so the records carry the emulator's own
error as real ones do; `emulator`, its mean, which leaves that error out; `emulator-draw`, its mean plus a draw of
its Gaussian error, so that with the term the likelihood is the records' own model), plus a discrepancy, plus 1% noise
(lambda_y = 1); a truth whose run fails is reported and skipped. The discrepancy (`--records`):
- `prior`: drawn from the feature-kind term's prior (`shockcal.inference.discrepancy`, `--sd-fraction-prior`);
- `shift`: out of family, a per-shot timing error of the plastic rise: each shot's slope features (v_slope1,
  v_slope2, read at two times on the rise) move by the record's rise rate (v_slope2 - v_slope1) / (t_slope2 -
  t_slope1) times a time shift ~ N(0, (`--shift-ns` x the record's read-out half-window)^2) of that shot, from the
  observed table (`readout_half_window_ns`: 4, 8 and 4 ns on the Al-5083 records);
- `none`: the null.
Each truth is calibrated twice, `none` and `feature_kind`, with the same sampler settings and seed. Prints each
parameter's 90%-interval coverage with and without, the discrepancy's scale coverage (its mean sd fraction over
the kinds, for `prior`), for every case the median's move between the two calibrations in box units and their 90%
width ratio (the null's acceptance), and the CPU per calibration. The emulator's error must be Gaussian (a
Student-t block is refused by the discrepancy): pass an emulator fitted with `emulator.error_tails: gaussian`.

    nice -n 10 .venv/bin/python benchmarks/discrepancy_coverage_study.py --config results/config.yaml \\
        --emulator results/emulator --truths-from results/posterior/joint.parquet \\
        --observed results/features/observed.parquet --records none --eta hydrocode --truths 30 --n-live 250 --n-eff 500
"""

import argparse
import time

import numpy as np
import pandas as pd

from shockcal.emulator.study_emulator import Emulator
from shockcal.errors import InputError, SamplerError
from shockcal.inference.calibration import calibrate
from shockcal.inference.discrepancy import SD_FRACTION_PREFIX, Discrepancy
from shockcal.io import read_table
from shockcal.simulators.builtin import simulate_design
from shockcal.study.adapters import calibration_settings, extractor_settings, hydro_inputs, shot_mapping
from shockcal.study.config import prior_bounds
from shockcal.study.stages import load_stage_config
from shockcal.study.validate import load_config
from shockcal.velocimetry.feature_tables import features_table

SLOPES = ("v_slope1", "v_slope2")


def shift_sd_m_s(observed: pd.DataFrame, shots, shift_ns: float) -> np.ndarray:
    """Per shot, the slope features' sd (m/s) of a timing error of `shift_ns` read-out half-windows."""
    rows = observed.set_index("shot").loc[list(shots)]
    rate = (rows["v_slope2"] - rows["v_slope1"]) / (rows["t_slope2"] - rows["t_slope1"])      # m/s per us
    return (rate * shift_ns * rows["readout_half_window_ns"] * 1e-3).to_numpy(float)


def hydrocode_features(config: dict, theta, shots, features) -> np.ndarray | None:
    """The study's hydrocode and extractor at `theta` (native units), the calibration features shot by shot
    (F,); None (and a line saying why) when a run fails."""
    values = []
    for shot in shots:
        mapping = shot_mapping(config, shot)
        row = pd.DataFrame([{"run": 0, **{name: float(theta[name]) for name in mapping.inputs()}}])
        traces = simulate_design(row, mapping, *hydro_inputs(config, config["shots"][shot]))
        table = features_table(traces, extractor_settings(config, shot))
        if table.status.iloc[0] != "ok":
            print(f"  truth skipped: {shot}'s run failed: {table.reason.iloc[0]}", flush=True)
            return None
        values.extend(float(table[name].iloc[0]) for name in features)
    return np.array(values)


def records(args, eta, features, shots, disc, shift_sd, rng):
    """(synthetic features (F,), the truth's mean sd fraction: 0 for none, NaN for shift): eta + discrepancy +
    1% noise."""
    scale = 0.0 if args.records == "none" else float("nan")
    y = eta.copy()
    if args.records == "prior":
        phi = disc.prior_transform(rng.uniform(size=(1, len(features) + 1)))
        y = y + rng.multivariate_normal(np.zeros(len(y)), disc.covariance(phi, eta)[0])
        scale = float(phi[0, :-1].mean())
    elif args.records == "shift":
        for s, sd in enumerate(shift_sd):
            dt = rng.normal()
            for name in SLOPES:
                y[s * len(features) + features.index(name)] += sd * dt
    return y + rng.normal(0.0, 0.01 * np.abs(y)), scale


def run(args):
    config = load_stage_config(args.config, "calibrate")
    shots = list(config["shots"])
    emulator = Emulator.load(args.emulator)
    features = list(emulator.feature_names)
    names = emulator.required_inputs(shots)
    bounds = prior_bounds(config)
    width = np.array([bounds[n][1] - bounds[n][0] for n in names])
    truths = read_table(args.truths_from)
    shift_sd = shift_sd_m_s(read_table(args.observed), shots, args.shift_ns)
    disc = Discrepancy(tuple(features), len(shots), args.sd_fraction_prior)
    base = calibration_settings(config, shots).replace(check_training_range=False, check_plateau=False,
                   velocity_boxes={}, check_units=False)
    rng = np.random.default_rng(args.seed)
    runs = {"none": "none", "feature_kind": {"kind": "feature_kind", "sd_fraction_prior": args.sd_fraction_prior}}
    rows, cost = [], {k: 0.0 for k in runs}
    if args.records == "shift":
        print("shift: the slope features' sd per shot (m/s):", {s: round(float(v), 2) for s, v in zip(shots, shift_sd)})
    full = load_config(args.config) if args.eta == "hydrocode" else None
    failed = []
    for trial in range(args.truths):
        theta = truths.iloc[int(rng.integers(len(truths)))]
        mean, covariance = emulator.predict({n: np.array([theta[n]]) for n in names}, shots)[:2]
        eta = mean[0]
        if args.eta == "emulator-draw":        # the emulator's error drawn too: the likelihood is then exact
            eta = eta + rng.multivariate_normal(np.zeros(len(eta)), covariance[0])
        if full is not None and trial >= args.skip:
            eta = hydrocode_features(full, theta, shots, features)
            if eta is None:
                continue
        y, scale = records(args, eta, features, shots, disc, shift_sd, rng)
        observed = pd.DataFrame(y.reshape(len(shots), -1), columns=features).assign(shot=shots)
        seed = int(rng.integers(2**31))
        if trial < args.skip:           # its draws taken, so the later truths are the same as in a full run
            continue
        done = []
        for kind, setting in runs.items():
            settings = base.replace(discrepancy=setting).with_sampler(n_live=args.n_live, n_eff=args.n_eff,
                                                                        draws=args.n_eff, seed=seed,
                                                                        max_evaluations=args.max_evaluations)
            start = time.process_time()
            try:
                posterior = calibrate(emulator, shots, observed, settings, f"trial {trial}")
            except (SamplerError, InputError) as exc:     # the sampler's limit, or records the library refuses
                failed.append((trial, kind, str(exc)))
                print(f"  truth {trial + 1} left out: the {kind} calibration failed: {exc}", flush=True)
                break
            finally:
                cost[kind] += time.process_time() - start
            done.append((kind, posterior))
        if len(done) < len(runs):
            continue
        for kind, posterior in done:
            summary = posterior.summary(native=True).set_index("parameter")
            for j, name in enumerate(names):
                q05, q50, q95 = summary.loc[name, ["q05", "q50", "q95"]]
                rows.append({"trial": trial, "run": kind, "parameter": name, "inside": q05 <= theta[name] <= q95,
                             "q50_box": q50 / width[j], "width_box": (q95 - q05) / width[j]})
            if kind == "feature_kind":
                mean_fraction = posterior.draws[[f"{SD_FRACTION_PREFIX}{f}" for f in features]].mean(axis=1)
                q05, q50, q95 = np.quantile(mean_fraction, [0.05, 0.5, 0.95])
                rows.append({"trial": trial, "run": kind, "parameter": "scale", "truth": scale, "q50_box": q50,
                             "inside": q05 <= scale <= q95 if args.records == "prior" else None})
        table = pd.DataFrame(rows)
        table = table[table.parameter != "scale"]
        print(f"truth {trial + 1}: 90% coverage over the inputs, none "
              f"{table[table.run == 'none'].inside.mean():.2f}, feature_kind "
              f"{table[table.run == 'feature_kind'].inside.mean():.2f}; CPU so far {cost}", flush=True)
        report(pd.DataFrame(rows), args, cost, names)     # after every truth: a run stopped early keeps its table
        if args.rows_out:
            pd.DataFrame(rows).to_csv(args.rows_out, index=False)
    print(f"{len(failed)} truths left out (a calibration failed): {failed}", flush=True)


def report(table, args, cost, names):
    """Print the coverage by parameter with and without the term, the moves and width ratios, the cost."""
    params = table[table.parameter != "scale"]
    pivot = params.pivot_table(index="parameter", columns="run", values="inside", aggfunc="mean").loc[names]
    both = params.pivot_table(index=["trial", "parameter"], columns="run", values=["q50_box", "width_box"])
    move = (both["q50_box"]["feature_kind"] - both["q50_box"]["none"]).abs().groupby("parameter").agg(["mean", "max"])
    ratio = (both["width_box"]["feature_kind"] / both["width_box"]["none"]).groupby("parameter").agg(["mean", "max"])
    out = pivot.join(move.add_prefix("median_move_box_")).join(ratio.add_prefix("width_ratio_")).loc[names]
    n = table.trial.nunique()
    print(f"\nrecords {args.records} on the {args.eta}'s features, {n} truths, n_live {args.n_live}, n_eff {args.n_eff}, sd_fraction_prior "
          f"{args.sd_fraction_prior}; 90% coverage (none / feature_kind), |median with - without| in box units and the "
          "90% width ratio with / without (mean, max over truths):")
    print(out.to_string(float_format=lambda v: f"{v:.3f}"))
    scale = table[table.parameter == "scale"]
    if len(scale):
        covered = scale.inside.dropna()
        print(f"discrepancy scale (the kinds' mean sd fraction): 90% coverage "
              f"{covered.mean() if len(covered) else float('nan'):.2f}; truths' median "
              f"{scale.truth.median():.4f}, posterior medians' median {scale.q50_box.median():.4f}")
    print(f"CPU: none {cost['none'] / n:.0f} s, feature_kind {cost['feature_kind'] / n:.0f} s per truth", flush=True)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--config", required=True, help="the study's config (its calibration, inputs, observed)")
    parser.add_argument("--emulator", required=True, help="the study's emulator directory, Gaussian error tails")
    parser.add_argument("--truths-from", required=True, help="the joint posterior's draws (Parquet, native units)")
    parser.add_argument("--observed", required=True, help="the measured features table (rise times, read-out)")
    parser.add_argument("--records", choices=["prior", "shift", "none"], default="prior")
    parser.add_argument("--eta", choices=["hydrocode", "emulator", "emulator-draw"], default="hydrocode",
                        help="the truth's features: the hydrocode's run, the emulator's mean, or its mean plus a draw of its error")
    parser.add_argument("--truths", type=int, default=30)
    parser.add_argument("--sd-fraction-prior", type=float, default=0.02)
    parser.add_argument("--shift-ns", type=float, default=1.0, help="timing sd in read-out half-windows")
    parser.add_argument("--n-live", type=int, default=250)
    parser.add_argument("--n-eff", type=int, default=500)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--skip", type=int, default=0, help="truths of a run stopped early: drawn, not calibrated")
    parser.add_argument("--max-evaluations", type=int, default=150_000, help="the sampler's limit per calibration")
    parser.add_argument("--rows-out", help="CSV of every truth's rows (to join runs)")
    run(parser.parse_args())
