"""`shockcal config-doc`: docs/configuration.md, every config key on one page, from the config schema."""

from __future__ import annotations

from shockcal.cli import add_command

EXAMPLE_CONFIG_DOC = """\
shockcal config-doc --out docs/configuration.md"""


def register(subparsers) -> None:
    p = add_command(subparsers, "config-doc", example=EXAMPLE_CONFIG_DOC,
                    help="render the configuration reference (docs/configuration.md) "
                                                 "from the config schema")
    p.add_argument("--out", help="write the page here (default: print it), e.g. docs/configuration.md")
    p.add_argument("--check", action="store_true",
                   help="write nothing; fail when --out differs from the schema's page (it needs regenerating)")
    p.set_defaults(func=run)


def run(args) -> int:
    import logging
    from pathlib import Path

    from shockcal.errors import InputError
    from shockcal.study.config_doc import render

    page = render()
    if args.out is None:
        if args.check:
            raise InputError("config-doc: --check needs --out (the page to compare)")
        print(page, end="")
        return 0
    out = Path(args.out)
    if args.check:
        if not out.is_file() or out.read_text() != page:
            raise InputError(f"{out} is not the schema's page: run shockcal config-doc --out {out}")
        return 0
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(page)
    logging.getLogger("shockcal.study.config_doc").info("wrote %s (%d lines)", out, page.count("\n"))
    return 0
