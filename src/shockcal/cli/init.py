"""`shockcal init`: a commented starting config for a study of one's own material and shots."""

from __future__ import annotations

from shockcal.cli import add_command

EXAMPLE_INIT = """\
shockcal init studies/copper --material copper"""


def register(subparsers) -> None:
    p = add_command(subparsers, "init", example=EXAMPLE_INIT,
                    help="write DIR/config.yaml: a complete study config, every key with its default, unit and "
                         "meaning, the keys to fill in marked <fill in>; then snakemake --cores all --configfile DIR/config.yaml")
    p.add_argument("dir", help="the study's folder (created if needed); its config.yaml must not exist yet")
    p.add_argument("--name", help="study.name (default: the folder's name); results go to results/<name>")
    p.add_argument("--material", help="a material of the library (`shockcal materials`): material.name is written "
                                      "with it, the entry's values shown commented out; default: every material key "
                                      "to fill in")
    p.set_defaults(func=run)


def run(args) -> int:
    import logging
    from pathlib import Path

    from shockcal.errors import InputError
    from shockcal.study.config_template import render_template

    folder = Path(args.dir)
    out = folder / "config.yaml"
    if out.exists():
        raise InputError(f"{out} exists; init writes a new study's config only (choose another folder, or edit it)")
    name = args.name or folder.resolve().name
    text = render_template(str(out), name, args.material)
    folder.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    logging.getLogger("shockcal.init").info("wrote %s: fill in each <fill in>, then snakemake --cores all "
                                            "--configfile %s", out, out)
    return 0
