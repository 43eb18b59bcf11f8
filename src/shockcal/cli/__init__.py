"""The `shockcal` command: one subcommand per workflow stage, each usable without Snakemake.

Each stage lives in its own module under shockcal.cli with `register(subparsers)`, which adds
its parser and sets `func`. Modules import heavy libraries (numba, scikit-learn, matplotlib)
inside their handlers so that `shockcal --help` and argument errors stay fast.
Exit codes: 0 success, 2 a user error (bad config, table or record: the message says which).
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys

from shockcal import __version__
from shockcal.errors import InputError, ShockcalError

STAGE_MODULES = [
    "shockcal.cli.design",
    "shockcal.cli.simulate",
    "shockcal.cli.features",
    "shockcal.cli.emulate",
    "shockcal.cli.calibrate",
    "shockcal.cli.posterior_netcdf",
    "shockcal.cli.predict",
    "shockcal.cli.verify",
    "shockcal.cli.waves",
    "shockcal.cli.next_shot",
    "shockcal.cli.next_shot_check",
    "shockcal.cli.sensitivity",
    "shockcal.cli.figures",
    "shockcal.cli.report",
    "shockcal.cli.stage_times",
    "shockcal.cli.config_doc",
    "shockcal.cli.init",
    "shockcal.cli.flow_stress",
    "shockcal.cli.compare_models",
    "shockcal.cli.model_predictions",
    "shockcal.cli.materials",
]


class HelpFormatter(argparse.HelpFormatter):
    """argparse's wrapping of a command's description, paragraph by paragraph, and its example (the
    epilog) kept line for line as written."""

    def _fill_text(self, text, width, indent):
        if text.startswith(EXAMPLE):
            return "".join(indent + line for line in text.splitlines(keepends=True))
        return "\n\n".join(super(HelpFormatter, self)._fill_text(part, width, indent)
                           for part in text.strip().split("\n\n"))


EXAMPLE = "example:"


def add_command(subparsers, name: str, help: str, example: str, description: str | None = None):
    """A subcommand's parser: `help` is its line in `shockcal --help` and, unless a longer
    `description` is given, the top of its own --help; `example` (a command line, or a few) is shown
    below its options, as written. Returns the parser (add its arguments and `func`)."""
    return subparsers.add_parser(name, help=help, description=description or _sentence(help),
                                 epilog=f"{EXAMPLE}\n" + "\n".join(f"  {line}" for line in example.strip().splitlines()),
                                 formatter_class=HelpFormatter)


def _sentence(help: str) -> str:
    """A parser's one-line help as the sentence that opens its own --help ('%%' is argparse's escaped '%')."""
    text = help.replace("%%", "%")
    return f"{text[0].upper()}{text[1:]}."


def add_config_argument(parser, help: str = "study config YAML") -> None:
    """`--config`, optional on the command line: it defaults to $SHOCKCAL_CONFIG (the workflow sets it to
    the merged config); `main` stops with one line when neither is given."""
    parser.add_argument("--config", default=os.environ.get("SHOCKCAL_CONFIG"),
                        help=f"{help} (default: $SHOCKCAL_CONFIG)")
    parser.set_defaults(needs_config=True)


def parse_pairs(pairs: list[str], option: str) -> dict[str, str]:
    """['104S=a.parquet', ...] -> {'104S': 'a.parquet', ...}; a malformed pair, a shot given twice or one
    file given for two shots is an InputError."""
    parsed = {}
    for pair in pairs:
        key, sep, path = pair.partition("=")
        if not sep or not key or not path:
            raise InputError(f"{option}: '{pair}' is not SHOT=FILE")
        if key in parsed:
            raise InputError(f"{option}: shot {key} is given twice ({key}={parsed[key]} and {pair}); give each shot once")
        same = [shot for shot, other in parsed.items() if os.path.realpath(other) == os.path.realpath(path)]
        if same:
            raise InputError(f"{option}: {path} is given for shots {same[0]} and {key}; each shot has its own table")
        parsed[key] = path
    return parsed


def parse_model_dirs(pairs: list[str], option: str = "--model") -> dict[str, str]:
    """['johnson-cook=results/models/johnson-cook', ...] -> {law name: results directory}, the name
    resolved through the law registry (aliases allowed); a malformed pair, an unknown law or a law given
    twice is an InputError."""
    from shockcal.hydro.laws import get_law

    parsed = {}
    for pair in pairs:
        name, sep, results_dir = pair.partition("=")
        if not sep or not results_dir:
            raise InputError(f"{option}: '{pair}' is not NAME=RESULTS_DIR")
        law = get_law(name).name
        if law in parsed:
            raise InputError(f"{option}: {law} given twice")
        parsed[law] = results_dir
    return parsed


def unique_shots(shots: list[str], option: str = "--shots") -> list[str]:
    """The shots of a command line, each once; a shot given twice is an InputError naming it."""
    twice = sorted({shot for shot in shots if shots.count(shot) > 1})
    if twice:
        raise InputError(f"{option}: {', '.join(twice)} given more than once ({' '.join(shots)}); name each shot once")
    return shots


def parse_span(text: str, option: str) -> tuple[int | None, int | None]:
    """'START:STOP' -> (start, stop), either side may be empty (None); anything else is an InputError."""
    parts = text.split(":")
    if len(parts) != 2:
        raise InputError(f"{option}: '{text}' is not START:STOP")
    try:
        start, stop = (int(p) if p else None for p in parts)
    except ValueError:
        raise InputError(f"{option}: '{text}' is not START:STOP with integers") from None
    return start, stop


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="shockcal", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"shockcal {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in STAGE_MODULES:
        importlib.import_module(name).register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.DEBUG if args.verbose else logging.INFO,
                        format="%(asctime)s %(name)s %(levelname)s: %(message)s", stream=sys.stderr)
    try:
        if getattr(args, "needs_config", False) and not args.config:
            raise InputError("--config: no study config given; pass --config FILE or set $SHOCKCAL_CONFIG")
        return int(args.func(args) or 0)
    except ShockcalError as exc:
        print(f"shockcal {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:                                    # the machine's, not shockcal's: disk full, read-only
        print(f"shockcal {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
