"""The discrepancy term on the measured records (issue 63, "Real data"): joint posteriors side by side and
leave-one-shot-out predictions, printed.

`--posterior NAME=POSTERIOR@EMULATOR` (repeatable; `shockcal calibrate --out` files, the emulator directory each
was sampled with): every parameter's median and posterior sd in user units, log Z with its sd, the discrepancy's
sd per shot and feature in m/s (5/50/95%), and the 12 features' posterior-predictive coverage
(`study_predictive_coverage`, at `--draws` of the equal-weight draws): inside the 95% band, PIT.

`--loso NAME=DIR@EMULATOR` (repeatable): DIR holds `no<shot>.parquet`, the calibration of the other shots; each
predicts the left-out shot's four features (`shockcal.inference.leave_one_out`), its own inputs from the prior box
of `--config`; the measured features and their sd from `--measured` (a joint posterior's metadata).

    .venv/bin/python benchmarks/discrepancy_real_data.py --config results/config.yaml \\
        --posterior a=results/posterior_a/joint.parquet@results/emulator --measured results/posterior_a/joint.parquet \\
        --loso none=results/loso/none@results/emulator_gaussian
"""

import argparse

import numpy as np
import pandas as pd

from shockcal.emulator.study_emulator import Emulator
from shockcal.inference.discrepancy import implied_sd_table
from shockcal.inference.inference_data import observed_frames
from shockcal.inference.leave_one_out import leave_one_shot_out
from shockcal.inference.posterior_files import read_posterior
from shockcal.inference.predictive_coverage import study_predictive_coverage
from shockcal.io import read_table, read_table_metadata
from shockcal.study.config import input_columns, prior_bounds
from shockcal.study.stages import load_stage_config


def pair(text: str) -> tuple[str, str, str]:
    name, rest = text.split("=", 1)
    path, emulator = rest.split("@", 1)
    return name, path, emulator


def load(path: str, config: dict | None):
    """(equal-weight draws, summary in user units with q05/q50/q95/sd, log Z, its sd, metadata) of a `shockcal
    calibrate` posterior or of `discrepancy_reweight.py`'s reweighted draws (user units from `config`)."""
    meta = read_table_metadata(path)
    if meta.get("table") != "importance-reweighted posterior draws":
        posterior = read_posterior(path)
        info = posterior.info()
        return posterior.draws, posterior.summary(), posterior.log_evidence, info["log_evidence_sd"], info
    if config is None:
        raise SystemExit(f"{path}: reweighted draws need --config for their user units")
    draws = read_table(path)
    user = input_columns(config)
    rows = []
    for name in draws.columns.drop("log_likelihood"):
        label, _, factor = user.get(name, (name, "-", 1.0))
        x = draws[name].to_numpy(float) * factor
        rows.append({"parameter": label, "q05": np.quantile(x, 0.05), "q50": np.median(x),
                     "q95": np.quantile(x, 0.95), "sd": x.std()})
    summary = pd.DataFrame(rows)
    summary.loc[summary.parameter.str.startswith("delta_"), "parameter"] = [
        n for n in draws.columns if n.startswith("delta_")]
    return draws, summary, float(meta["log_evidence"]), float("nan"), meta


def side_by_side(specs, draws: int, seed: int, config: dict | None) -> None:
    medians, evidence, coverage = {}, [], {}
    for name, path, emulator_dir in specs:
        posterior_draws, summary, log_z, log_z_sd, info = load(path, config)
        medians[name] = summary.set_index("parameter")[["q50", "sd"]]
        evidence.append({"posterior": name, "log_Z": log_z, "log_Z_sd": log_z_sd,
                         "khat": info.get("khat", float("nan"))})
        emulator = Emulator.load(emulator_dir)
        features = list(emulator.feature_names)
        observed, _ = observed_frames(info["shots"], info["observed"], info["observed_sd_m_s"], features)
        table = implied_sd_table(summary, observed)
        if len(table):
            print(f"\n{name}: the discrepancy's sd (m/s) per shot and feature, 5/50/95%:")
            print(table[["shot", "feature", "observed_m_s", "sd_m_s_q05", "sd_m_s_q50", "sd_m_s_q95"]]
                  .to_string(index=False, float_format=lambda v: f"{v:.2f}"))
            fractions = summary[summary.parameter.str.startswith("delta_")]
            print(fractions[["parameter", "q05", "q50", "q95"]].to_string(index=False, float_format=lambda v: f"{v:.4f}"))
        design = posterior_draws.sample(min(draws, len(posterior_draws)), random_state=seed)
        coverage[name] = study_predictive_coverage(emulator, design, info["shots"], info["observed"],
                                                   info["observed_sd_m_s"], path)
    print("\nmedian (sd) in user units:")
    table = pd.concat({n: m["q50"].map(lambda v: f"{v:.4g}") + " (" + m["sd"].map(lambda v: f"{v:.3g}") + ")"
                       for n, m in medians.items()}, axis=1)
    print(table.fillna("").to_string())
    print("\nlog evidence:")
    print(pd.DataFrame(evidence).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print("\n95% posterior-predictive coverage of the measured features (inside, PIT; with the discrepancy's share "
          "where the posterior has one):")
    out = None
    for name, table in coverage.items():
        part = table[["shot", "feature", "observed_m_s", "inside", "pit"]].rename(
            columns={"inside": f"inside_{name}", "pit": f"pit_{name}"})
        if table["sd_discrepancy_m_s"].gt(0).any():
            part[f"inside_{name}_without"] = table["inside_without"]
            part[f"pit_{name}_without"] = table["pit_without"]
        out = part if out is None else out.merge(part, on=["shot", "feature", "observed_m_s"])
    print(out.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print("inside, of 12: " + ", ".join(f"{c.removeprefix('inside_')} {int(out[c].sum())}"
                                        for c in out.columns if c.startswith("inside_")))


def leave_one_out(specs, config: dict, measured: str, draws: int, seed: int) -> None:
    bounds = prior_bounds(config)
    meta = read_table_metadata(measured)
    shots = list(meta["shots"])
    rows = []
    for name, directory, emulator_dir in specs:
        emulator = Emulator.load(emulator_dir)
        for shot in shots:
            posterior_draws, _, log_z, _, _ = load(f"{directory}/no{shot}.parquet", config)
            design = posterior_draws.sample(min(draws, len(posterior_draws)), random_state=seed)
            table = leave_one_shot_out(emulator, shots, shot, design, np.asarray(meta["observed"], float),
                                       np.asarray(meta["observed_sd_m_s"], float), bounds, seed)
            rows.append(table.assign(posterior=name, log_Z=log_z))
    table = pd.concat(rows, ignore_index=True)
    print("\nleave-one-shot-out: the other two shots' posterior predicts each shot's features (its own inputs "
          "from the prior):")
    print(table[["posterior", "shot", "feature", "observed_m_s", "mean_m_s", "sd_m_s", "z", "q_low_m_s",
                 "q_high_m_s", "pit", "inside", "prior_inputs"]].to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print(table.groupby("posterior").agg(inside=("inside", "sum"), mean_abs_z=("z", lambda z: z.abs().mean()),
                                         max_abs_z=("z", lambda z: z.abs().max())).to_string(float_format=lambda v: f"{v:.2f}"))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--posterior", nargs="*", type=pair, default=[], metavar="NAME=POSTERIOR@EMULATOR")
    parser.add_argument("--loso", nargs="*", type=pair, default=[], metavar="NAME=DIR@EMULATOR")
    parser.add_argument("--config", help="the study's config (its prior box with --loso; user units of reweighted draws)")
    parser.add_argument("--measured", help="a joint posterior whose metadata holds every shot's measured features")
    parser.add_argument("--draws", type=int, default=2000, help="posterior draws the predictive bands use")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    study = load_stage_config(args.config, "calibrate") if args.config else None
    if args.posterior:
        side_by_side(args.posterior, args.draws, args.seed, study)
    if args.loso:
        leave_one_out(args.loso, study, args.measured, args.draws, args.seed)
