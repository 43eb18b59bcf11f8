"""`shockcal stage-times`: where a study's time went, per stage (Snakemake benchmark files)."""

from __future__ import annotations

from shockcal.cli import add_command

EXAMPLE_STAGE_TIMES = """\
shockcal stage-times --benchmarks results/quick/benchmarks"""


def register(subparsers) -> None:
    p = add_command(subparsers, "stage-times", example=EXAMPLE_STAGE_TIMES,
                    help="wall and CPU seconds per workflow stage of a finished study")
    p.add_argument("--benchmarks", default="results/benchmarks", help="the study's benchmark folder")
    p.set_defaults(func=run)


def run(args) -> int:
    from pathlib import Path

    from shockcal.errors import InputError
    from shockcal.study.stage_times import simulate_overhead, stage_table

    if not Path(args.benchmarks).is_dir():
        raise InputError(f"{args.benchmarks}: no such folder (run the study first)")
    print(stage_table(Path(args.benchmarks)).to_string(index=False))
    overhead = simulate_overhead(Path(args.benchmarks))
    if len(overhead):
        print("\nsimulate jobs: start-up and write-out (job wall s minus its runs' hydrocode s), median and range:")
        print(overhead.to_string(index=False))
    return 0
