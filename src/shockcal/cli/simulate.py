"""`shockcal simulate`: run design rows for one shot into a Parquet simulations table.

The run source is the config's `simulator.kind` (docs/simulators.md): the built-in hydrocode, an
external code (each run in `--runs-dir`/<shot>/<run>/, its checkpoint) or an archive of finished runs.
Reads the config keys of the stage `simulate` (shockcal.study.stages); writes `--out` (docs/hydro.md).
"""

from __future__ import annotations

from pathlib import Path

from shockcal.cli import add_command, add_config_argument, parse_span

EXAMPLE_SIMULATE = """\
shockcal simulate --config config/config.yaml --shot 104S --design results/training/design.parquet \\
    --rows 0:10 --out results/training/simulations/104S/chunk-0.parquet"""


def register(subparsers) -> None:
    p = add_command(subparsers, "simulate", example=EXAMPLE_SIMULATE,
                    help="run design rows for one shot (hydrocode, external code or archive)")
    add_config_argument(p)
    p.add_argument("--shot", required=True,
                   help="shot name in the config, e.g. 104S, or a next-shot candidate's (its design from next-shot-design)")
    p.add_argument("--design", required=True, help="design table (CSV or Parquet; Table IV units; `run` kept)")
    p.add_argument("--rows", default=":", help="slice of design row positions, e.g. 0:25 (default: all)")
    p.add_argument("--out", required=True, help="output Parquet table (one row per run; see docs/hydro.md)")
    p.add_argument("--runs-dir", default=None,
                   help="simulator.kind command: folder of the run folders <shot>/<run>/ (default: runs/ beside "
                        "--out's simulations/ folder, e.g. results/training/runs)")
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
    from shockcal.simulators.builtin import UNITS
    from shockcal.study.adapters import candidate, candidate_box, hydro_inputs, input_box, shot_mapping
    from shockcal.study.config import candidate_config, shot_config
    from shockcal.study.simulator import simulator_kind
    from shockcal.study.stages import is_candidate, load_stage_config
    from shockcal.velocimetry.columns import COLUMNS as FEATURE_COLUMNS

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
    table = run_design(config, design, mapping, spec, (geometry, material, settings), runs_dir(args))
    units = {**UNITS, **dict.fromkeys(FEATURE_COLUMNS, "us or m/s (t_*, v_*)"), **{k: box.units[k] for k in mapping.inputs()}}
    write_table(table, args.out, {"table": "simulations", "shot": name, "units": units, "hydro": config["hydro"],
                                  "material": config["material"], "simulator": simulator_kind(config)})
    failed = int((table["status"] != "ok").sum()) if len(table) else 0
    logging.getLogger("shockcal.simulators").info("shot %s: %d runs, %d failed, %.1f s of simulation -> %s", name,
                                                len(table), failed, table["wall_time_s"].sum() if len(table) else 0.0,
                                                args.out)
    return 0


def runs_dir(args) -> Path:
    """`--runs-dir`, or runs/ in --out's run set (the folder above simulations/<shot>/)."""
    if args.runs_dir:
        return Path(args.runs_dir)
    out = Path(args.out).resolve()
    return out.parents[2] / "runs" if out.parent.parent.name == "simulations" else out.parent / "runs"


def run_design(config: dict, design, mapping, spec: dict, physics, runs: Path):
    """The simulations table of `design` from the config's run source (`simulator.kind`)."""
    from shockcal.study.config import analysis_end_us
    from shockcal.study.simulator import simulator_kind

    kind = simulator_kind(config)
    if kind == "command":
        from shockcal.simulators.command import simulate_design_command
        from shockcal.study.adapters import command_settings

        return simulate_design_command(design, mapping, *physics, command_settings(config), runs,
                                       analysis_end_us(config, spec))
    if kind == "archive":
        from shockcal.simulators.archive import archive_design
        from shockcal.study.adapters import archive_source

        return archive_design(design, mapping, archive_source(config, mapping.shot), analysis_end_us(config, spec))
    from shockcal.simulators.builtin import simulate_design

    return simulate_design(design, mapping, *physics)
