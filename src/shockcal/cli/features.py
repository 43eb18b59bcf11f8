"""`shockcal features` (simulated traces or a measured record) and `shockcal observed` (the measured features)."""

from __future__ import annotations

import logging

from shockcal.cli import add_command, add_config_argument

log = logging.getLogger("shockcal.velocimetry.features")
UNITS = {"t_*": "us", "v_*": "m/s", "readout_sd_v_*": "m/s", "noise_sd_m_s": "m/s", "readout_half_window_ns": "ns"}

EXAMPLE_FEATURES = """\
shockcal features --config config/config.yaml --shot 104S --record Data_S104S.txt --out 104S_measured.parquet"""
EXAMPLE_OBSERVED = """\
shockcal observed --config config/config.yaml --out results/features/observed.parquet"""


def register(subparsers) -> None:
    p = add_command(subparsers, "features", example=EXAMPLE_FEATURES,
                    help="extract the features of simulated traces or of a measured record")
    add_config_argument(p)
    p.add_argument("--shot", required=True, help="shot name (its analysis window is in the config), or a next-shot "
                   "candidate's (its window derived from its reference shot's; no failed-run budget)")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--traces", nargs="+", help="simulation tables (Parquet or CSV) from `shockcal simulate`")
    source.add_argument("--record", help="a measured record (time us, velocity m/s)")
    source.add_argument("--tables", nargs="+",
                        help="features tables of chunks of one shot's runs (--traces ... --no-failure-budget): merged")
    p.add_argument("--no-failure-budget", action="store_true",
                   help="--traces of one chunk: leave the failed-run budget (simulate.max_failed_fraction) to the merge")
    p.add_argument("--allow-empty", action="store_true",
                   help="--traces or --tables with no runs give an empty table (a sequential study's stopped wave)")
    p.add_argument("--time-column", help="record: time column name or index (default: detected)")
    p.add_argument("--velocity-column", help="record: velocity column name or index (default: detected)")
    p.add_argument("--out", required=True, help="output Parquet table")
    p.set_defaults(func=run)

    o = add_command(subparsers, "observed", example=EXAMPLE_OBSERVED,
                    help="write the measured features of every shot (config values or records)")
    add_config_argument(o)
    o.add_argument("--out", required=True)
    o.set_defaults(func=run_observed)


def run(args) -> int:
    import pandas as pd

    from shockcal.io import write_table
    from shockcal.study.adapters import candidate_extractor_settings, extractor_settings
    from shockcal.study.config import candidate_config
    from shockcal.study.stages import is_candidate, load_stage_config
    from shockcal.velocimetry.feature_tables import check_failures, record_features

    name = args.shot
    candidate = is_candidate(args.config, name)
    config = load_stage_config(args.config, feature_stages(args, candidate), name)
    analysis = (candidate_config(config, name) if candidate else config["shots"][name])["analysis"]
    settings = None if args.tables else (candidate_extractor_settings if candidate else extractor_settings)(config, name)
    if args.record:
        table = pd.DataFrame([{"run": 0, "status": "ok", "reason": "",
                               **record_features(args.record, settings, name, args.time_column,
                                                 args.velocity_column)}])
    else:
        from shockcal.io import read_tables
        from shockcal.velocimetry.feature_tables import features_table

        if args.tables:
            table = read_tables(args.tables, ["run"], "features")
        else:
            traces = read_tables(args.traces, ["run"], "simulations")
            table = features_table(traces, settings, ", ".join(args.traces), args.allow_empty)
        if not args.no_failure_budget and not candidate:
            check_failures(table, config["simulate"]["max_failed_fraction"], name, args.allow_empty)
    write_table(table, args.out, {"table": "features", "shot": name, "units": UNITS, "analysis": analysis})
    return 0


def feature_stages(args, candidate: bool = False) -> list[str]:
    """The stages (shockcal.study.stages) a `features` call is: extraction, the failed-run budget, or both;
    a next-shot candidate's: its window (its failed runs are counted by suggest-shot, not budgeted)."""
    if candidate:
        return ["next_shot_features"]
    extracts = not args.tables
    budget = not args.record and not args.no_failure_budget
    return [stage for stage, used in (("features", extracts), ("failure_budget", budget)) if used]


def run_observed(args) -> int:
    from shockcal.io import write_table
    from shockcal.study.adapters import observed_table
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "observed")
    table = observed_table(config)
    write_table(table, args.out, {"table": "observed features", "units": UNITS})
    log.info("observed features:\n%s", table.drop(columns="source").to_string(index=False))
    return 0
