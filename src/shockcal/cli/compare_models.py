"""`shockcal compare-models`: the strength laws' evidence table from each law's study.

Reads, per `--model NAME=RESULTS_DIR`: RESULTS_DIR/posterior/joint.parquet's metadata (calibrated inputs,
log evidence and its sd, the measured features) and RESULTS_DIR/emulator/cv_rmse.csv (the K-fold and
outer check's RMSE over all shots and features; the outer one empty when the emulator skipped it).
Writes `--out` (CSV; shockcal.model_comparison.COLUMNS).
"""

from __future__ import annotations


def register(subparsers) -> None:
    p = subparsers.add_parser("compare-models", help="the strength laws' log evidence and Bayes factors vs Johnson-Cook",
                              description=__doc__)
    p.add_argument("--model", action="append", required=True, metavar="NAME=RESULTS_DIR",
                   help="a law and its study's results_dir (repeat; johnson-cook required)")
    p.add_argument("--out", required=True, help="the table (CSV), e.g. results/models/evidence.csv")
    p.set_defaults(func=run)


def model_result(name: str, results_dir: str):
    """One law's `ModelResult` from its study's results directory; InputError naming a missing file or key.
    A study whose emulator skipped the outer check (too few runs inside its inner box) gets NaN there."""
    import logging
    import math
    from pathlib import Path

    import pandas as pd

    from shockcal.errors import InputError
    from shockcal.io import read_table_metadata
    from shockcal.model_comparison import ModelResult

    posterior = Path(results_dir) / "posterior" / "joint.parquet"
    cv = Path(results_dir) / "emulator" / "cv_rmse.csv"
    for path in (posterior, cv):
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
                       tuple(observed), float(overall["kfold"]), float(overall.get("outer", math.nan)))


def run(args) -> int:
    import logging
    from pathlib import Path

    from shockcal.errors import InputError
    from shockcal.hydro.laws import get_law
    from shockcal.model_comparison import evidence_table

    results = {}
    for pair in args.model:
        name, sep, results_dir = pair.partition("=")
        if not sep or not results_dir:
            raise InputError(f"--model: '{pair}' is not NAME=RESULTS_DIR")
        law = get_law(name).name
        if law in results:
            raise InputError(f"--model: {law} given twice")
        results[law] = model_result(law, results_dir)
    table = evidence_table(results)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(out, index=False, float_format="%.6g")
    logging.getLogger("shockcal.compare_models").info("wrote %s:\n%s", out, table.to_string(index=False))
    return 0
