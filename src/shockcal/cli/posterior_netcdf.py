"""`shockcal posterior-netcdf`: a calibration's posterior as ArviZ InferenceData (netCDF).

Reads the posterior written by `shockcal calibrate` (the equal-weight draws, the weighted draws beside
them, their metadata: shots, measured features and their sd, units, sampler settings, evidence) and,
for the joint posterior, the features of the hydrocode runs at its draws; writes OUT (.nc) with the
groups of `shockcal.inference.inference_data`, the inputs in the units a user reads (the posterior's
`user_units` metadata; for a posterior written without it, `shockcal.study.config.input_user_units`).
Config keys: the `calibrate` stage's (the prior box; their sha256 is the file's `config_digest`).
"""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument, parse_pairs

EXAMPLE_POSTERIOR_NETCDF = """\
shockcal posterior-netcdf --config config/config.yaml --posterior results/posterior/joint.parquet \\
    --out results/posterior/joint.nc"""


def register(subparsers) -> None:
    p = add_command(subparsers, "posterior-netcdf", example=EXAMPLE_POSTERIOR_NETCDF,
                    help="a posterior as ArviZ InferenceData (netCDF) with provenance")
    add_config_argument(p)
    p.add_argument("--posterior", required=True,
                   help="equal-weight posterior draws (shockcal calibrate --out); *_weighted.parquet is read beside it")
    p.add_argument("--predicted-features", nargs="+", default=[], metavar="SHOT=TABLE",
                   help="features of the hydrocode runs at posterior draws per shot (posterior_predictive group)")
    p.add_argument("--out", required=True, help="netCDF file, e.g. results/posterior/joint.nc")
    p.set_defaults(func=run)


def run(args) -> int:
    import logging
    from pathlib import Path

    from shockcal import __version__
    from shockcal.errors import InputError
    from shockcal.inference.inference_data import (
        config_digest,
        git_commit,
        observed_frames,
        posterior_inference_data,
        write_inference_data,
    )
    from shockcal.inference.posterior_files import companion_path
    from shockcal.io import read_table, read_table_metadata
    from shockcal.study.config import input_user_units, prior_bounds
    from shockcal.study.stages import load_stage_config

    logging.getLogger("arviz").setLevel(logging.WARNING)       # its preview notes of packages not installed
    config = load_stage_config(args.config, "calibrate")
    draws = read_table(args.posterior)
    meta = read_table_metadata(args.posterior)
    needed = ["shots", "observed", "observed_sd_m_s", "units", "log_evidence"]
    if any(key not in meta for key in needed):
        raise InputError(f"{args.posterior}: not a posterior written by `shockcal calibrate` "
                         f"(metadata {[k for k in needed if k not in meta]} missing)")
    weighted_path = companion_path(args.posterior, "weighted")
    weighted = read_table(weighted_path) if Path(weighted_path).is_file() else None
    names = [c for c in draws.columns if c != "log_likelihood"]
    observed, observed_sd = observed_frames(meta["shots"], meta["observed"], meta["observed_sd_m_s"])
    bounds = prior_bounds(config)
    predictive = {shot: read_table(path)
                  for shot, path in parse_pairs(args.predicted_features, "--predicted-features").items()}
    attrs = {"shockcal_version": __version__, "git_commit": git_commit(),
             "config_digest": config_digest(config), "config_digest_of": "the calibrate stage's config slice (JSON)",
             "posterior_file": str(args.posterior), "shots": meta["shots"],
             **{key: meta[key] for key in ("sampler", "n_live", "n_eff_target", "seed", "cube_power",
                                           "log_evidence", "log_evidence_sd", "likelihood_evaluations",
                                           "ess_kish", "weighted_draws", "retained", "distinct_draws",
                                           "discrepancy_sd_fraction_prior") if key in meta}}
    user_units = meta.get("user_units") or input_user_units(config)
    idata = posterior_inference_data(
        draws, names, units=meta["units"], user_units=user_units, lower={k: b[0] for k, b in bounds.items()},
        upper={k: b[1] for k, b in bounds.items()}, observed=observed, observed_sd=observed_sd,
        weighted=weighted, predictive=predictive, attrs=attrs)
    out = write_inference_data(idata, args.out)
    logging.getLogger("shockcal.posterior_netcdf").info(
        "wrote %s: groups %s; %d draws of %s; log evidence %.3f +- %.3f; commit %s", out, ", ".join(idata.groups()),
        len(draws), ", ".join(names), meta["log_evidence"], meta.get("log_evidence_sd", float("nan")), attrs["git_commit"])
    return 0
