"""`shockcal report-tables`: the study's summary tables for the Snakemake report, each as CSV (for scripts)
and as an HTML table (Snakemake 9's report shows HTML inline and offers CSV only as a download).

From the posteriors (`shockcal calibrate` output and its metadata) it writes `posterior_summary.csv`
(every calibration's weighted summary, one row per calibration and parameter, in MPa, GPa and m/s with the
unit in the parameter's name and the `unit` column) and `evidence.csv` (log evidence with its sd, Kish ESS, likelihood evaluations per
calibration); from the emulator's `cv_rmse.csv`, `cross_validation.csv`; from the synthetic-truth
checks' merged tables (`make check`), `coverage.csv` (per truth and parameter); from the Sobol table
(`shockcal sensitivity`), `sobol.html` only (its CSV is the sensitivity stage's); from the emulator and
hydrocode runs it never saw (the posterior's predictive runs), `emulator_heldout.csv` (RMSE and the share
inside each feature's 90% band, then the share of runs inside its error model's 90% region of the feature
vector: `shockcal.emulator.score_heldout`, `region_coverage`); from the posteriors with a model discrepancy
(`calibration.discrepancy`), `discrepancy.csv` (its sd per calibration, shot and feature in m/s at its
5/50/95% points: `shockcal.inference.discrepancy.implied_sd_table`); from the joint posterior, the design of its
predictive draws and the emulator, `predictive_coverage.csv` (each measured feature's place in its posterior
predictive, 95% band with the discrepancy and without it: `shockcal.inference.predictive_coverage`). Each table
is written only when its inputs are given. No config is read.
"""

from __future__ import annotations

from shockcal.cli import add_command, parse_pairs

EXAMPLE_REPORT_TABLES = """\
shockcal report-tables --posteriors joint=results/posterior/joint.parquet \\
    --cv-rmse results/emulator/cv_rmse.csv --out-dir results/report"""


def register(subparsers) -> None:
    p = add_command(subparsers, "report-tables", example=EXAMPLE_REPORT_TABLES,
                    help="summary tables (CSV) of posteriors, evidence, CV and coverage "
                                                    "for the report")
    p.add_argument("--posteriors", nargs="+", default=[], metavar="NAME=POSTERIOR",
                   help="calibrations' equal-weight draws (shockcal calibrate --out); their _summary.parquet is read")
    p.add_argument("--cv-rmse", help="the emulator's cv_rmse.csv")
    p.add_argument("--coverage", nargs="+", default=[], metavar="TRUTH=TABLE",
                   help="merged synthetic-truth tables (shockcal coverage --out) by truth")
    p.add_argument("--sobol", help="the Sobol table (shockcal sensitivity --out)")
    p.add_argument("--heldout-emulator", help="an emulator directory, scored on --heldout-design's runs")
    p.add_argument("--heldout-design", help="design table of hydrocode runs the emulator never saw (e.g. the "
                                            "posterior's predictive runs, results/predict/design.parquet)")
    p.add_argument("--heldout-features", nargs="+", default=[], metavar="SHOT=TABLE",
                   help="those runs' features per shot (shockcal features --out)")
    p.add_argument("--heldout-posterior", help="optional: a posterior (shockcal calibrate --out) whose records' sd "
                                               "the held-out error is also read in")
    p.add_argument("--discrepancy", nargs="+", default=[], metavar="NAME=POSTERIOR",
                   help="posteriors with a model discrepancy (shockcal calibrate --out): its sd in m/s per shot and "
                        "feature")
    p.add_argument("--predictive-posterior", help="the joint posterior (shockcal calibrate --out): measured features, "
                                                  "their sd, shots")
    p.add_argument("--predictive-design", help="its predictive draws (shockcal predict --out), with lambda_y and the "
                                               "discrepancy's columns")
    p.add_argument("--predictive-emulator", help="the study's emulator directory, predicting at those draws")
    p.add_argument("--out-dir", required=True, help="folder for the tables (NAME.csv and NAME.html)")
    p.set_defaults(func=run)


STYLE = ("<style>body{font-family:sans-serif;font-size:13px} table{border-collapse:collapse} "
         "th,td{border:1px solid #ccc;padding:2px 6px;text-align:right} th{background:#eef}</style>")


def _write(table, out, name: str, title: str, csv: bool = True) -> list[str]:
    """`table` as out/NAME.csv (unless `csv` is False) and out/NAME.html; the names written."""
    from shockcal.io import atomic_path

    written = []
    if csv:
        with atomic_path(out / f"{name}.csv") as tmp:
            table.to_csv(tmp, index=False, float_format="%.6g")
        written.append(f"{name}.csv")
    html = table.to_html(index=False, float_format=lambda v: f"{v:.4g}", na_rep="", border=0)
    with atomic_path(out / f"{name}.html") as tmp:
        tmp.write_text(f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{title}</title>{STYLE}</head>"
                       f"<body><h3>{title}</h3>{html}</body></html>\n")
    return [*written, f"{name}.html"]


def run(args) -> int:
    import logging
    from pathlib import Path

    import pandas as pd

    from shockcal.inference.coverage import coverage_table
    from shockcal.inference.posterior_files import companion_path
    from shockcal.io import read_table, read_table_metadata

    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    posteriors = parse_pairs(args.posteriors, "--posteriors")
    if posteriors:
        summaries, evidence = [], []
        for name, path in posteriors.items():
            summaries.append(read_table(companion_path(path)).assign(calibration=name))
            meta = read_table_metadata(path)
            evidence.append({"calibration": name, "shots": "+".join(meta.get("shots", [])),
                             "log_evidence": meta.get("log_evidence"), "log_evidence_sd": meta.get("log_evidence_sd"),
                             "ess_kish": meta.get("ess_kish"), "likelihood_evaluations": meta.get("likelihood_evaluations"),
                             "draws": meta.get("retained"), "distinct_draws": meta.get("distinct_draws")})
        summary = pd.concat(summaries, ignore_index=True)
        summary = summary[["calibration", *[c for c in summary.columns if c != "calibration"]]]
        written += _write(summary, out, "posterior_summary", "Posterior summaries (MPa, GPa, m/s: the unit in each name)")
        written += _write(pd.DataFrame(evidence), out, "evidence", "Log evidence per calibration")
    if args.cv_rmse:
        written += _write(read_table(args.cv_rmse), out, "cross_validation", "Emulator cross-validation (m/s)")
    coverage = parse_pairs(args.coverage, "--coverage")
    if coverage:
        table = pd.concat([coverage_table(read_table(path)).assign(truth=truth) for truth, path in coverage.items()],
                          ignore_index=True)
        written += _write(table[["truth", *[c for c in table.columns if c != "truth"]]], out, "coverage",
                          "Synthetic-truth coverage of the 90% intervals")
    if args.sobol:
        written += _write(read_table(args.sobol), out, "sobol", "Sobol indices of the emulated features "
                          "(95% bootstrap half-widths)", csv=False)
    if args.heldout_emulator or args.heldout_design or args.heldout_features:
        written += _write(heldout_table(args), out, "emulator_heldout",
                          "The emulator on hydrocode runs no fit saw (m/s, and in the records' sds): 90% band per "
                          "feature, 90% region per feature vector")
    discrepancy = parse_pairs(args.discrepancy, "--discrepancy")
    if discrepancy:
        written += _write(discrepancy_table(discrepancy), out, "discrepancy",
                          "Model discrepancy's sd (m/s) per shot and feature at its 5/50/95% points")
    if args.predictive_posterior or args.predictive_design or args.predictive_emulator:
        written += _write(predictive_table(args), out, "predictive_coverage",
                          "Posterior-predictive 95% bands of the measured features (m/s), with the model discrepancy "
                          "and without it")
    logging.getLogger("shockcal.report").info("wrote %s in %s", ", ".join(written) or "nothing", out)
    return 0


def heldout_table(args):
    """`score_heldout`'s rows (per feature, then all), then one row per error block with the share of runs in
    its 90% region (`feature` "region: SHOTS (F features)", `coverage`, `n_values` = runs)."""
    import pandas as pd

    from shockcal.emulator import Emulator, region_coverage, score_heldout
    from shockcal.errors import InputError
    from shockcal.io import read_table

    if not (args.heldout_emulator and args.heldout_design and args.heldout_features):
        raise InputError("report-tables: --heldout-emulator, --heldout-design and --heldout-features go together")
    emulator = Emulator.load(args.heldout_emulator)
    design = read_table(args.heldout_design)
    features = {shot: read_table(path)
                for shot, path in parse_pairs(args.heldout_features, "--heldout-features").items()}
    records_sd = None if args.heldout_posterior is None else posterior_records_sd(
        args.heldout_posterior, list(features), emulator.feature_names)
    regions = region_coverage(emulator, design, features)
    region_rows = pd.DataFrame({"feature": [f"region: {b} ({f} features)" for b, f in
                                            zip(regions["block"], regions["n_features"])],
                                "coverage": regions["coverage"], "n_values": regions["n_runs"]})
    return pd.concat([score_heldout(emulator, design, features, records_sd_m_s=records_sd), region_rows],
                     ignore_index=True)


def posterior_records_sd(path: str, shots: list[str], feature_names: list[str]):
    """The records' sd (m/s) a posterior was calibrated with (its metadata), shot-major for `shots`."""
    from shockcal.errors import InputError
    from shockcal.inference.inference_data import observed_frames
    from shockcal.io import read_table_metadata

    meta = read_table_metadata(path)
    if not {"shots", "observed", "observed_sd_m_s"} <= set(meta):
        raise InputError(f"{path}: not a posterior written by `shockcal calibrate` (no observed sd in its metadata)")
    sd = observed_frames(meta["shots"], meta["observed"], meta["observed_sd_m_s"], feature_names)[1]
    missing = [shot for shot in shots if shot not in sd.index]
    if missing:
        raise InputError(f"{path}: a posterior of shots {meta['shots']}, without {', '.join(missing)}")
    return sd.loc[shots].to_numpy(float).ravel()


def discrepancy_table(posteriors: dict):
    """`implied_sd_table` of each posterior (name -> path), one block per calibration; a posterior without
    a discrepancy is an InputError naming it."""
    import pandas as pd

    from shockcal.errors import InputError
    from shockcal.inference.discrepancy import SD_FRACTION_PREFIX, implied_sd_table
    from shockcal.inference.inference_data import observed_frames
    from shockcal.inference.posterior_files import companion_path
    from shockcal.io import read_table, read_table_metadata

    tables = []
    for name, path in posteriors.items():
        meta = read_table_metadata(path)
        if "discrepancy_parameters" not in meta:
            raise InputError(f"--discrepancy {name}={path}: a posterior without a model discrepancy "
                             "(calibration.discrepancy: none)")
        features = [p.removeprefix(SD_FRACTION_PREFIX) for p in meta["discrepancy_parameters"]
                    if p.startswith(SD_FRACTION_PREFIX)]          # one per feature kind, in the emulator's order
        observed, _ = observed_frames(meta["shots"], meta["observed"], meta["observed_sd_m_s"], features)
        tables.append(implied_sd_table(read_table(companion_path(path)), observed).assign(calibration=name))
    table = pd.concat(tables, ignore_index=True)
    return table[["calibration", *[c for c in table.columns if c != "calibration"]]]


def predictive_table(args):
    """`study_predictive_coverage` of --predictive-posterior's measured features at --predictive-design's draws."""
    from shockcal.emulator import Emulator
    from shockcal.errors import InputError
    from shockcal.inference.predictive_coverage import study_predictive_coverage
    from shockcal.io import read_table, read_table_metadata

    if not (args.predictive_posterior and args.predictive_design and args.predictive_emulator):
        raise InputError("report-tables: --predictive-posterior, --predictive-design and --predictive-emulator go "
                         "together")
    meta = read_table_metadata(args.predictive_posterior)
    missing = [key for key in ("shots", "observed", "observed_sd_m_s") if key not in meta]
    if missing:
        raise InputError(f"{args.predictive_posterior}: not a posterior written by `shockcal calibrate` (metadata "
                         f"{missing} missing)")
    return study_predictive_coverage(Emulator.load(args.predictive_emulator), read_table(args.predictive_design),
                                     meta["shots"], meta["observed"], meta["observed_sd_m_s"], args.predictive_design)
