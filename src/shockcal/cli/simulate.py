"""`shockcal simulate`: run design rows through the hydrocode for one shot into a Parquet table."""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument, parse_span

EXAMPLE_SIMULATE = """\
shockcal simulate --config config/config.yaml --shot 104S --design results/training/design.parquet \\
    --rows 0:10 --out results/training/simulations/104S/chunk-0.parquet"""


def register(subparsers) -> None:
    p = add_command(subparsers, "simulate", example=EXAMPLE_SIMULATE,
                    help="run design rows through the hydrocode for one shot")
    add_config_argument(p)
    p.add_argument("--shot", required=True,
                   help="shot name in the config, e.g. 104S, or a next-shot candidate's (its design from next-shot-design)")
    p.add_argument("--design", required=True, help="design table (CSV or Parquet; Table IV units; `run` kept)")
    p.add_argument("--rows", default=":", help="slice of design row positions, e.g. 0:25 (default: all)")
    p.add_argument("--out", required=True, help="output Parquet table (one row per run; see docs/hydro.md)")
    p.add_argument("--end-time-us", type=float, default=None,
                   help="simulate to this time (us) instead of hydro.end_time_us (e.g. the history figures' runs)")
    p.add_argument("--allow-empty", action="store_true",
                   help="a design (or --rows slice) with no rows writes an empty table (a sequential study's stopped wave)")
    p.set_defaults(func=run)


def run(args) -> int:
    import logging

    from shockcal.design.tables import load_design
    from shockcal.errors import InputError
    from shockcal.io import write_table
    from shockcal.simulators.builtin import UNITS, simulate_design
    from shockcal.study.adapters import candidate, candidate_box, hydro_inputs, input_box, shot_mapping
    from shockcal.study.config import candidate_config, shot_config
    from shockcal.study.stages import is_candidate, load_stage_config

    name = args.shot
    is_shot = not is_candidate(args.config, name)
    config = load_stage_config(args.config, "simulate" if is_shot else "next_shot_simulate", name)
    rows = slice(*parse_span(args.rows, "--rows"))
    if args.end_time_us is not None and args.end_time_us <= 0:
        raise InputError(f"--end-time-us: {args.end_time_us} is not a positive time")
    if is_shot:
        mapping, spec, box = shot_mapping(config, name), shot_config(config, name), input_box(config)
    else:
        mapping, spec, box = candidate(config, name).mapping(), candidate_config(config, name), candidate_box(config, name)
    geometry, material, settings = hydro_inputs(config, spec, args.end_time_us)
    design = load_design(args.design, box, columns=mapping.inputs(), allow_empty=args.allow_empty).iloc[rows]
    mapping.check_positive(design, args.design)
    table = simulate_design(design, mapping, geometry, material, settings)
    units = {**UNITS, **{k: box.units[k] for k in mapping.inputs()}}
    write_table(table, args.out, {"table": "simulations", "shot": name, "units": units,
                                  "hydro": config["hydro"], "material": config["material"]})
    failed = int((table["status"] != "ok").sum()) if len(table) else 0
    logging.getLogger("shockcal.simulators.builtin").info("shot %s: %d runs, %d failed, %.1f s of hydrocode -> %s", name,
                                                len(table), failed, table["wall_time_s"].sum() if len(table) else 0.0,
                                                args.out)
    return 0
