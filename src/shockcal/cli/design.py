"""`shockcal design`: write the study's design table (Latin hypercube, or a checked user design)."""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument

EXAMPLE_DESIGN = """\
shockcal design --config config/config.yaml --out results/training/design.parquet"""


def register(subparsers) -> None:
    p = add_command(subparsers, "design", example=EXAMPLE_DESIGN,
                    help="write the design table (seeded Latin hypercube or the config's design file)")
    add_config_argument(p)
    p.add_argument("--out", required=True, help="output Parquet design table")
    p.add_argument("--n-runs", type=int, default=None, help="override design.n_runs")
    p.add_argument("--seed", type=int, default=None, help="override study.seed")
    p.add_argument("--stream", default="design", choices=["design", "check_design"],
                   help="the random stream of study.seed the hypercube draws from (shockcal.seeds); "
                        "check_design: the synthetic-truth check's runs, calibration.check.trials of them by default")
    p.add_argument("--lhs", action="store_true",
                   help="a Latin hypercube over the box even when the config names a design file")
    p.set_defaults(func=run)


def run(args) -> int:
    import logging

    from shockcal.design.tables import write_design
    from shockcal.study.adapters import input_box, study_design
    from shockcal.study.stages import load_stage_config

    config = load_stage_config(args.config, args.stream)  # the design or check_design stage
    if args.stream == "check_design":  # the check's truth runs: always a hypercube, of check.trials runs
        n_runs, lhs = args.n_runs or config["calibration"]["check"]["trials"], True
    else:
        n_runs, lhs = args.n_runs, args.lhs
    design, source = study_design(config, n_runs, args.seed, args.stream, lhs)
    write_design(design, source, input_box(config), args.out)
    logging.getLogger("shockcal.design.tables").info("wrote %d runs (%s) to %s", len(design), source, args.out)
    return 0
