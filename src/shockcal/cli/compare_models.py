"""`shockcal compare-models`: the strength laws' evidence table from each law's study.

Reads, per `--model NAME=RESULTS_DIR`: RESULTS_DIR/posterior/joint.parquet's metadata (calibrated inputs,
log evidence and its sd, the measured features), RESULTS_DIR/posterior/joint_weighted.parquet (the
sampler's weighted draws, for the box sensitivity), RESULTS_DIR/emulator/emulator.json's input_bounds
(the prior box the calibration used), RESULTS_DIR/emulator/cv_rmse.csv (the K-fold and outer check's
RMSE over all shots and features; the outer one empty when the emulator skipped it) and, when the study
made it, RESULTS_DIR/report/emulator_heldout.csv (the emulator on the posterior's predictive runs, which no
fit saw: RMSE and 90% band coverage over all of them; empty columns without it).
The Bayes factors are against `--reference` (default: the first `--model`).
Writes `--out` (CSV; shockcal.campaign.model_comparison.COLUMNS) and, with `--figures-dir`, the log evidence per law
(evidence.png and .pdf).

The box parameters are the calibrated inputs except the shots' impact velocities (the inputs in cm/us,
the unit the config schema gives a shot's velocity_input: measured shot properties with their own error)
and lambda_y (the error scale, not an input): the law's own parameters and its shear-modulus inputs.
"""

from __future__ import annotations

from shockcal.cli import add_command

EXAMPLE_COMPARE_MODELS = """\
shockcal compare-models --model johnson-cook=results/models/johnson-cook \\
    --model steinberg-guinan=results/models/steinberg-guinan --out results/models/evidence.csv"""


def register(subparsers) -> None:
    p = add_command(subparsers, "compare-models", example=EXAMPLE_COMPARE_MODELS,
                    help="the strength laws' log evidence and Bayes factors against a reference law",
                    description=__doc__)
    p.add_argument("--model", action="append", required=True, metavar="NAME=RESULTS_DIR",
                   help="a law and its study's results_dir (repeat; the first is the reference unless --reference)")
    p.add_argument("--reference", default=None, metavar="NAME",
                   help="the law the Bayes factors are against (one of the --model names; default: the first)")
    p.add_argument("--out", required=True, help="the table (CSV), e.g. results/models/evidence.csv")
    p.add_argument("--figures-dir", default=None, help="where evidence.png and .pdf go (log Z per law with +-2 sd and "
                   "the box-halved and -doubled values), e.g. results/models/figures")
    p.set_defaults(func=run)


def model_result(name: str, results_dir: str):
    """One law's `ModelResult` from its study's results directory; InputError naming a missing file or key.
    A study whose emulator skipped the outer check (too few runs inside its inner box) gets NaN there."""
    import logging
    import math
    from pathlib import Path

    import pandas as pd

    from shockcal.campaign.model_comparison import ModelResult
    from shockcal.errors import InputError
    from shockcal.io import read_table_metadata

    posterior = Path(results_dir) / "posterior" / "joint.parquet"
    weighted = Path(results_dir) / "posterior" / "joint_weighted.parquet"
    emulator = Path(results_dir) / "emulator" / "emulator.json"
    cv = Path(results_dir) / "emulator" / "cv_rmse.csv"
    for path in (posterior, weighted, emulator, cv):
        if not path.is_file():
            raise InputError(f"--model {name}: {path} does not exist (run the law's study to its joint posterior)")
    meta = read_table_metadata(posterior)
    for key in ("parameters", "log_evidence", "log_evidence_sd", "observed"):
        if key not in meta:
            raise InputError(f"--model {name}: {posterior}: metadata has no {key}")
    rmse = pd.read_csv(cv)
    overall = rmse[(rmse["shot"] == "all") & (rmse["feature"] == "all")].set_index("scheme")["rmse_m_s"]
    if "kfold" not in overall:
        raise InputError(f"--model {name}: {cv}: no kfold row over all shots and features")
    if "outer" not in overall:       # the emulator skips it when too few runs lie inside the inner box
        logging.getLogger("shockcal.compare_models").warning(
            "%s: %s has no outer check (see the emulator's log); outer_rmse_m_s left empty", name, cv)
    observed = meta["observed"]
    observed = [float(v) for v in (observed.strip("[]").split(",") if isinstance(observed, str) else observed)]
    return ModelResult(tuple(meta["parameters"]), float(meta["log_evidence"]), float(meta["log_evidence_sd"]),
                       tuple(observed), float(overall["kfold"]), float(overall.get("outer", math.nan)),
                       box_result(name, weighted, emulator),
                       *heldout_scores(name, Path(results_dir) / "report" / "emulator_heldout.csv"))


def heldout_scores(name: str, path) -> tuple[float, float]:
    """(RMSE m/s, 90% band coverage) of the emulator over all of the posterior's predictive runs, from the
    study's emulator_heldout.csv (`shockcal report-tables --heldout-*`); NaN, NaN when the study has none."""
    import math

    import pandas as pd

    from shockcal.errors import InputError

    if not path.is_file():
        return math.nan, math.nan
    table = pd.read_csv(path)
    overall = table[table["feature"].astype(str).str.startswith("all (")] if "feature" in table else table.iloc[:0]
    if overall.empty:
        raise InputError(f"--model {name}: {path}: no 'all (N runs)' row")
    return float(overall["rmse_m_s"].iloc[0]), float(overall["coverage"].iloc[0])


VELOCITY_UNIT = "cm/us"      # a shot's velocity_input (config schema): excluded from the box


def box_result(name: str, weighted_path, emulator_path):
    """The evidence's sensitivity to the box of one law's study (`shockcal.campaign.box_sensitivity`) from its weighted
    draws and its emulator's input bounds; InputError naming the file and key that is missing."""
    import json
    from pathlib import Path

    import numpy as np

    from shockcal.campaign.box_sensitivity import box_sensitivity
    from shockcal.errors import InputError
    from shockcal.inference.sampler import WeightedDraws
    from shockcal.io import read_table, read_table_metadata, require_columns

    meta = read_table_metadata(weighted_path)
    for key in ("parameters", "units", "log_evidence", "log_evidence_sd"):
        if key not in meta:
            raise InputError(f"--model {name}: {weighted_path}: metadata has no {key}")
    names = [p for p in meta["parameters"] if meta["units"].get(p) != VELOCITY_UNIT]
    table = read_table(weighted_path)
    require_columns(table, [*names, "log_weight", "log_likelihood"], weighted_path)
    try:
        bounds = json.loads(Path(emulator_path).read_text()).get("input_bounds", {})
    except (ValueError, AttributeError):
        raise InputError(f"--model {name}: {emulator_path}: not an emulator's JSON description") from None
    missing = [p for p in names if p not in bounds]
    if missing:
        raise InputError(f"--model {name}: {emulator_path}: input_bounds has no {', '.join(missing)}")
    lower, upper = (np.array([bounds[p][i] for p in names], dtype=float) for i in (0, 1))
    draws = WeightedDraws(table[names].to_numpy(float), table["log_weight"].to_numpy(float),
                          table["log_likelihood"].to_numpy(float), float(meta["log_evidence"]), 0,
                          float(meta["log_evidence_sd"]))
    return box_sensitivity(draws, lower, upper, name)


def run(args) -> int:
    import logging
    from pathlib import Path

    from shockcal.campaign.model_comparison import evidence_table
    from shockcal.cli import parse_model_dirs

    results = {law: model_result(law, results_dir) for law, results_dir in parse_model_dirs(args.model).items()}
    table = evidence_table(results, args.reference)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(out, index=False, float_format="%.6g")
    logging.getLogger("shockcal.compare_models").info("wrote %s:\n%s", out, table.to_string(index=False))
    if args.figures_dir:
        from shockcal.plots.models import evidence_figure
        from shockcal.plots.style import save_figure

        save_figure(evidence_figure(table), Path(args.figures_dir) / "evidence")
    return 0
