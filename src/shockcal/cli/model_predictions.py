"""`shockcal model-predictions`: each strength law's posterior predictive runs past the analysis window: the
release's arrival per law and shot (`shockcal.campaign.release`) and one figure page per law.

Reads, per `--model NAME=RESULTS_DIR`: RESULTS_DIR/features/observed.parquet (each record's t_plastic and
v_plastic), RESULTS_DIR/predict/simulations/<shot>/chunk-*.parquet (the joint posterior's draws through the
hydrocode over the whole record, `predict.end_time_us`) and RESULTS_DIR/predict/features/<shot>.parquet;
from `--config` the shots, their records (`observed.records`) and analysis windows.
Writes `--out` (CSV; shockcal.campaign.release.RELEASE_COLUMNS) and, with `--figures-dir`, predictive_<law>.png/.pdf.
"""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument

EXAMPLE_MODEL_PREDICTIONS = """\
shockcal model-predictions --config config/config.yaml --model johnson-cook=results/models/johnson-cook \\
    --model steinberg-guinan=results/models/steinberg-guinan --out results/models/release.csv"""


def register(subparsers) -> None:
    p = add_command(subparsers, "model-predictions", example=EXAMPLE_MODEL_PREDICTIONS,
                    help="each law's posterior predictive runs: release timing and "
                    "figures", description=__doc__)
    add_config_argument(p, "study config YAML (the shots, records and analysis windows)")
    p.add_argument("--model", action="append", required=True, metavar="NAME=RESULTS_DIR",
                   help="a law and its study's results_dir (repeat)")
    p.add_argument("--out", required=True, help="the release table (CSV), e.g. results/models/release.csv")
    p.add_argument("--figures-dir", default=None, help="where predictive_<law>.png and .pdf go")
    p.add_argument("--margin-m-s", type=float, default=None,
                   help="how far below the plastic plateau a release starts (m/s; default shockcal.campaign.release's 20)")
    p.set_defaults(func=run)


def _required(path, name: str):
    from shockcal.errors import InputError

    if not path.is_file():
        raise InputError(f"--model {name}: {path} does not exist (run the law's study to its posterior "
                         f"predictive runs: results_dir/posterior/joint.nc)")
    return path


def law_predictions(name: str, results_dir: str, config: dict, margin_m_s: float):
    """([release rows], {shot: ShotPredictions}) of one law's study; InputError naming a missing file."""
    from pathlib import Path

    import pandas as pd

    from shockcal.campaign.release import predicted_releases_us, release_after_arrival_us, release_row
    from shockcal.io import read_table, require_columns
    from shockcal.plots.models import ShotPredictions
    from shockcal.velocimetry.records import read_record

    root = Path(results_dir)
    observed = read_table(_required(root / "features" / "observed.parquet", name))
    require_columns(observed, ["shot", "t_plastic", "v_plastic"], root / "features" / "observed.parquet")
    observed = observed.set_index(observed["shot"].astype(str))
    rows, pages = [], {}
    for shot, spec in config["shots"].items():
        features = read_table(_required(root / "predict" / "features" / f"{shot}.parquet", name))
        chunks = sorted((root / "predict" / "simulations" / shot).glob("chunk-*.parquet"))
        if not chunks:
            _required(root / "predict" / "simulations" / shot / "chunk-0.parquet", name)
        runs = pd.concat([read_table(c) for c in chunks], ignore_index=True)
        record_spec = config["observed"]["records"].get(shot)
        record, release_record = None, float("nan")
        if record_spec is not None and shot in observed.index:
            t, v = read_record(record_spec["path"], record_spec.get("time_column"), record_spec.get("velocity_column"))
            record = pd.DataFrame({"t_us": t, "v_m_s": v})
            release_record = release_after_arrival_us(t, v, float(observed.at[shot, "t_plastic"]),
                                                      float(observed.at[shot, "v_plastic"]), margin_m_s)
        predicted = predicted_releases_us(runs, features, margin_m_s)
        rows.append(release_row(name, shot, release_record, predicted.to_numpy()))
        pages[shot] = ShotPredictions(record, runs, float(spec["analysis"]["window_after_arrival_us"]), release_record)
    return rows, pages


def run(args) -> int:
    import logging
    from pathlib import Path

    import pandas as pd

    from shockcal.campaign.release import RELEASE_COLUMNS, RELEASE_MARGIN_M_S
    from shockcal.cli import parse_model_dirs
    from shockcal.errors import InputError
    from shockcal.study.validate import load_config

    config = load_config(args.config)
    margin = RELEASE_MARGIN_M_S if args.margin_m_s is None else args.margin_m_s
    if not margin > 0:
        raise InputError(f"--margin-m-s: {args.margin_m_s} must be positive (m/s)")
    rows, pages = [], {}
    for law, results_dir in parse_model_dirs(args.model).items():
        law_rows, pages[law] = law_predictions(law, results_dir, config, margin)
        rows += law_rows
    table = pd.DataFrame(rows, columns=RELEASE_COLUMNS)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(out, index=False, float_format="%.6g")
    logging.getLogger("shockcal.model_predictions").info("wrote %s (release %.0f m/s below the plastic plateau):\n%s",
                                                         out, margin, table.to_string(index=False))
    if args.figures_dir:
        from shockcal.plots.models import predictive_figure
        from shockcal.plots.style import save_figure

        for law, shots in pages.items():
            save_figure(predictive_figure(law, shots), Path(args.figures_dir) / f"predictive_{law}")
    return 0
