"""A posterior on disk, as `shockcal calibrate` writes it, and back.

`write_posterior(posterior, out)` writes three Parquet tables, each with the posterior's `info()` as
metadata (shots, parameters, `units` and `user_units`, measured features, sampler settings, evidence):

- OUT: the equal-weight draws (`Posterior.draws`), the inputs in their native units (`units`, the
  design's: the paper's Mbar and cm/us for Johnson-Cook), lambda_y and, with `calibration.discrepancy`,
  its parameters (named in the metadata's `discrepancy_parameters`, dimensionless);
- OUT_summary.parquet: `Posterior.summary()`, in the units a user reads (MPa, GPa, m/s; the unit in
  each parameter's name);
- OUT_weighted.parquet: the sampler's weighted draws (`Posterior.weighted_table()`, native units).

`read_posterior(out)` gives the `Posterior` back from the draws and the weighted draws (the summary is
recomputed from them), refusing a file that is not such a posterior in one line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from shockcal.errors import InputError
from shockcal.inference.problem import LAMBDA_Y
from shockcal.inference.sampler import Posterior, SamplerSettings, WeightedDraws
from shockcal.io import read_table, read_table_metadata, write_table

# what read_posterior needs of the metadata
NEEDED_METADATA = ("shots", "parameters", "units", "log_evidence", "likelihood_evaluations", "n_live",
                   "n_eff_target", "seed", "cube_power", "distinct_draws")


def companion_path(out, kind: str = "summary") -> Path:
    """The table of `kind` ("summary", "weighted") beside the posterior samples `out`."""
    out = Path(out)
    return out.with_name(f"{out.stem}_{kind}.parquet")


def write_posterior(posterior: Posterior, out) -> dict:
    """Write `posterior`'s three tables (module docstring) at `out` and beside it; returns its `info()`."""
    info = posterior.info()
    meta = {"table": "posterior samples", **info,
            "columns": "equal-weight draws resampled from nautilus's weighted ones: inputs in `units`; lambda_y (-); "
                       "log_likelihood (at the draw)"}
    write_table(posterior.draws, out, meta)
    write_table(posterior.summary(), companion_path(out),
                {"table": "posterior summary", "shots": info.get("shots"), "units": info.get("user_units"),
                 "columns": "weighted mean, sd, 5/50/95% quantiles and their Monte Carlo errors, Kish ESS; each "
                            "parameter in the unit of its name and of the `unit` column (MPa, GPa, m/s or -)"})
    write_table(posterior.weighted_table(), companion_path(out, "weighted"),
                {**meta, "table": "posterior weighted draws",
                 "columns": "nautilus's weighted draws (the exact result): inputs in `units`; lambda_y (-); log_weight "
                            "(normalised, logsumexp = 0); log_likelihood"})
    return info


def read_posterior(path) -> Posterior:
    """The `Posterior` written by `write_posterior` (`shockcal calibrate --out`) at `path`: its equal-weight
    draws, its weighted draws (OUT_weighted.parquet), evidence, settings and units; InputError naming the
    file when it is not such a posterior or its weighted draws are missing or do not match."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such posterior (shockcal calibrate --out)")
    meta = read_table_metadata(path)
    missing = [key for key in NEEDED_METADATA if key not in meta]
    if missing:
        raise InputError(f"{path}: not a posterior written by `shockcal calibrate` (metadata {missing} missing)")
    names = [*meta["parameters"], LAMBDA_Y, *meta.get("discrepancy_parameters", [])]
    weighted_path = companion_path(path, "weighted")
    if not weighted_path.is_file():
        raise InputError(f"{weighted_path}: missing; the weighted draws of {path} are written beside it by "
                         "`shockcal calibrate`")
    draws, table = read_table(path), read_table(weighted_path)
    for source, frame, needed in ((path, draws, [*names, "log_likelihood"]),
                                  (weighted_path, table, [*names, "log_weight", "log_likelihood"])):
        absent = [c for c in needed if c not in frame.columns]
        if absent:
            raise InputError(f"{source}: columns {absent} missing (columns: {list(frame.columns)})")
    weighted = WeightedDraws(table[names].to_numpy(float), table["log_weight"].to_numpy(float),
                             table["log_likelihood"].to_numpy(float), float(meta["log_evidence"]),
                             int(meta["likelihood_evaluations"]), float(meta.get("log_evidence_sd", np.nan)),
                             table["replicate"].to_numpy() if "replicate" in table.columns else None)
    settings = SamplerSettings(n_live=meta["n_live"], n_eff=meta["n_eff_target"], draws=len(draws), seed=meta["seed"],
                               cube_power=meta["cube_power"], replicates=meta.get("replicates", 1))
    context = {key: meta[key] for key in ("shots", "parameters", "units", "user_units", "observed", "observed_sd_m_s",
                                          "discrepancy_parameters", "discrepancy_sd_fraction_prior") if key in meta}
    return Posterior(names, weighted, draws[[*names, "log_likelihood"]], settings, dict(meta["cube_power"]),
                     int(meta["distinct_draws"]), units=dict(meta["units"]), user_units=dict(meta.get("user_units") or {}),
                     context=context)
