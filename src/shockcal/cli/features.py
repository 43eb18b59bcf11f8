"""`shockcal features` (simulated traces or a measured record) and `shockcal observed` (the measured features)."""

from __future__ import annotations

import logging

from shockcal.cli import add_config_argument

log = logging.getLogger("shockcal.features")
UNITS = {"t_*": "us", "v_*": "m/s"}


def register(subparsers) -> None:
    p = subparsers.add_parser("features", help="extract the features of simulated traces or of a measured record")
    add_config_argument(p)
    p.add_argument("--shot", required=True, help="shot name (its analysis window is in the config)")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--traces", nargs="+", help="simulation tables (Parquet or CSV) from `shockcal simulate`")
    source.add_argument("--record", help="a measured record (time us, velocity m/s)")
    p.add_argument("--time-column", help="record: time column name or index (default: detected)")
    p.add_argument("--velocity-column", help="record: velocity column name or index (default: detected)")
    p.add_argument("--out", required=True, help="output Parquet table")
    p.set_defaults(func=run)

    o = subparsers.add_parser("observed", help="write the measured features of every shot (config values or records)")
    add_config_argument(o)
    o.add_argument("--out", required=True)
    o.set_defaults(func=run_observed)


def run(args) -> int:
    import pandas as pd

    from shockcal.config import load_config, shot_config
    from shockcal.io import read_table, write_table

    config = load_config(args.config)
    shot_config(config, args.shot)
    if args.record:
        table = pd.DataFrame([{"run": 0, "status": "ok", "reason": "",
                               **record_features(config, args.shot, args.record, args.time_column,
                                                 args.velocity_column)}])
    else:
        from shockcal.features import features_table

        traces = pd.concat([read_table(path) for path in args.traces], ignore_index=True)
        table = features_table(traces, config, args.shot)
        check_failures(table, config["simulate"]["max_failed_fraction"], args.shot)
    write_table(table, args.out, {"table": "features", "shot": args.shot, "units": UNITS,
                                  "analysis": config["shots"][args.shot]["analysis"]})
    return 0


def record_features(config, shot, path, time_column=None, velocity_column=None) -> dict:
    """The ten features of a measured record, with the shot's analysis settings; InputError naming the
    record when it has none."""
    from shockcal.errors import InputError
    from shockcal.features import FeatureError, extract_features
    from shockcal.records import read_record

    t, v = read_record(path, _column(time_column), _column(velocity_column))
    try:
        return extract_features(t, v, config["shots"][shot]["analysis"], config["features"])
    except FeatureError as exc:
        raise InputError(f"record {path}: no features for shot {shot}: {exc}") from exc


def _column(value):
    return int(value) if isinstance(value, str) and value.isdigit() else value


def check_failures(table, max_fraction: float, shot: str) -> None:
    """Log the excluded count; stop when more than `max_fraction` of the runs failed."""
    from shockcal.errors import ShockcalError

    failed = table[table["status"] != "ok"]
    if failed.empty:
        log.info("shot %s: all %d runs have features", shot, len(table))
        return
    log.warning("shot %s: %d of %d runs failed and are excluded downstream", shot, len(failed), len(table))
    if len(failed) > max_fraction * len(table):
        worst = "\n".join(f"  run {r.run}: {r.reason}" for r in failed.head(10).itertuples())
        raise ShockcalError(f"shot {shot}: {len(failed)} of {len(table)} runs failed, more than the allowed "
                            f"{max_fraction:.0%} (simulate.max_failed_fraction); the first:\n{worst}")


def run_observed(args) -> int:
    import pandas as pd

    from shockcal.config import load_config
    from shockcal.features import COLUMNS
    from shockcal.io import write_table

    config = load_config(args.config)
    observed = config["observed"]
    rows = []
    for shot in config["shots"]:      # load_config checked that every shot has its source's entry
        if observed["source"] == "records":
            spec = observed["records"][shot]
            rows.append({"shot": shot, "source": f"record {spec['path']} (shockcal extractor)",
                         **record_features(config, shot, spec["path"], spec["time_column"], spec["velocity_column"])})
        else:
            rows.append({"shot": shot, "source": "published (Walters et al. 2018, LA-UR-18-20151)",
                         **observed["features"][shot]})
    table = pd.DataFrame(rows)[["shot", "source", *COLUMNS]]
    write_table(table, args.out, {"table": "observed features", "units": UNITS})
    log.info("observed features:\n%s", table.drop(columns="source").to_string(index=False))
    return 0
