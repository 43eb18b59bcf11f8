"""`shockcal design`: write the study's design table (Latin hypercube, or a checked user design)."""

from __future__ import annotations

from shockcal.cli import add_config_argument


def register(subparsers) -> None:
    p = subparsers.add_parser("design", help="write the design table (seeded Latin hypercube or the config's design file)")
    add_config_argument(p)
    p.add_argument("--out", required=True, help="output Parquet design table")
    p.add_argument("--n-runs", type=int, default=None, help="override design.n_runs")
    p.add_argument("--seed", type=int, default=None, help="override study.seed")
    p.add_argument("--stream", default="design", choices=["design", "check_design"],
                   help="the random stream of study.seed the hypercube draws from (shockcal.seeds)")
    p.add_argument("--lhs", action="store_true",
                   help="a Latin hypercube over the box even when the config names a design file")
    p.set_defaults(func=run)


def run(args) -> int:
    import logging

    from shockcal.config import input_names, load_config
    from shockcal.design import study_design
    from shockcal.io import write_table

    config = load_config(args.config)
    design, source = study_design(config, args.n_runs, args.seed, args.stream, args.lhs)
    units = {name: config["inputs"][name]["unit"] for name in input_names(config)}
    write_table(design[["run", *input_names(config)]], args.out,
                {"table": "design", "source": source, "units": units})
    logging.getLogger("shockcal.design").info("wrote %d runs (%s) to %s", len(design), source, args.out)
    return 0
