"""`shockcal simulate`: run design rows through the hydrocode for one shot into a Parquet table."""

from __future__ import annotations

from shockcal.cli import add_config_argument, parse_span


def register(subparsers) -> None:
    p = subparsers.add_parser("simulate", help="run design rows through the hydrocode for one shot")
    add_config_argument(p)
    p.add_argument("--shot", required=True, help="shot name in the config, e.g. 104S")
    p.add_argument("--design", required=True, help="design table (CSV or Parquet; Table IV units; `run` kept)")
    p.add_argument("--rows", default=":", help="slice of design row positions, e.g. 0:25 (default: all)")
    p.add_argument("--out", required=True, help="output Parquet table (one row per run; see docs/hydro.md)")
    p.add_argument("--end-time-us", type=float, default=None,
                   help="simulate to this time (us) instead of hydro.end_time_us (e.g. the history figures' runs)")
    p.set_defaults(func=run)


def run(args) -> int:
    import logging

    from shockcal.errors import InputError
    from shockcal.io import write_table
    from shockcal.simulate import UNITS, simulate_design
    from shockcal.study.adapters import hydro_inputs, load_study_design, shot_mapping
    from shockcal.study.config import shot_config
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, "simulate", args.shot)
    rows = slice(*parse_span(args.rows, "--rows"))
    if args.end_time_us is not None and args.end_time_us <= 0:
        raise InputError(f"--end-time-us: {args.end_time_us} is not a positive time")
    mapping = shot_mapping(config, args.shot)
    geometry, material, settings = hydro_inputs(config, shot_config(config, args.shot), args.end_time_us)
    design = load_study_design(args.design, config, columns=mapping.inputs()).iloc[rows]
    mapping.check_positive(design, args.design)
    table = simulate_design(design, mapping, geometry, material, settings)
    units = {**UNITS, **{k: config["inputs"][k]["unit"] for k in mapping.inputs()}}
    write_table(table, args.out, {"table": "simulations", "shot": args.shot, "units": units,
                                  "hydro": config["hydro"], "material": config["material"]})
    failed = int((table["status"] != "ok").sum()) if len(table) else 0
    logging.getLogger("shockcal.simulate").info("shot %s: %d runs, %d failed, %.1f s of hydrocode -> %s", args.shot,
                                                len(table), failed, table["wall_time_s"].sum() if len(table) else 0.0,
                                                args.out)
    return 0
