"""`shockcal figures`: draw one of the paper's figures (or list them) from named input tables."""

from __future__ import annotations

from shockcal.cli import add_command, add_config_argument

EXAMPLE_FIGURES = """\
shockcal figures --config config/config.yaml --list
shockcal figures --config config/config.yaml --figure fig07_marginals --out-dir results/figures"""


def register(subparsers) -> None:
    p = add_command(subparsers, "figures", example=EXAMPLE_FIGURES,
                    help="draw one figure of the study as PNG/PDF (see --list)")
    add_config_argument(p, "study config YAML (figures.formats, figures.dpi)")
    p.add_argument("--figure", help="figure name, e.g. fig07_marginals")
    p.add_argument("--out-dir", default="results/figures", help="folder for <figure>.<format>")
    p.add_argument("--input", action="append", default=[], metavar="KEY=PATH",
                   help="a named input, e.g. posterior:joint=results/posterior/joint.parquet (repeat a key for chunks)")
    p.add_argument("--list", action="store_true", help="print the figure names and exit")
    p.set_defaults(func=run)


def parse_inputs(pairs: list[str]) -> dict[str, list[str]]:
    """['k=a', 'k=b', 'j=c'] -> {'k': ['a', 'b'], 'j': ['c']}; a pair without '=' is an InputError."""
    from shockcal.errors import InputError

    files: dict[str, list[str]] = {}
    for pair in pairs:
        key, sep, path = pair.partition("=")
        if not sep or not key or not path:
            raise InputError(f"--input '{pair}': expected KEY=PATH")
        files.setdefault(key, []).append(path)
    return files


def run(args) -> int:
    import logging
    from pathlib import Path

    from shockcal.errors import InputError
    from shockcal.plots.style import save_figure
    from shockcal.study.figure_catalogue import FigureInputs, catalogue, figure_spec
    from shockcal.study.read_log import recorded
    from shockcal.study.stages import figure_config
    from shockcal.study.validate import load_config

    config = load_config(args.config)
    if args.list:
        for spec in catalogue(config).values():
            print(f"{spec.name}\t{spec.category}")
        return 0
    if not args.figure:
        raise InputError("give --figure NAME (or --list)")
    spec = figure_spec(args.figure, config)
    config = recorded(figure_config(config, args.figure), f"figure {args.figure}")  # only the keys it declares
    fig = spec.build(FigureInputs(parse_inputs(args.input)), config)
    paths = save_figure(fig, Path(args.out_dir) / args.figure, config["figures"]["formats"], config["figures"]["dpi"])
    logging.getLogger("shockcal.figures").info("wrote %s", ", ".join(map(str, paths)))
    return 0
