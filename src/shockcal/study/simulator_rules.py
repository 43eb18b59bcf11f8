"""The config's `simulator` section checked: a bad one is refused in one line naming the key, before any
run starts (docs/simulators.md): a command without its template files, a placeholder the run does not
have, a trace output without its columns, an archive whose features and design disagree in their run ids.
"""

from __future__ import annotations

from pathlib import Path

from shockcal.errors import ConfigError, ShockcalError
from shockcal.study.adapters import shot_mapping
from shockcal.study.simulator import archive_runs, resolve_path, simulator_kind


def check_simulator(config: dict, source: str = "config") -> None:
    """The simulator section's rules beyond the schema (module docstring)."""
    section, kind = config.get("simulator") or {}, simulator_kind(config)
    if kind != "builtin" and kind not in section:
        raise ConfigError(f"{source}: simulator.{kind}: missing; simulator.kind is {kind!r}")
    if kind == "command":
        check_command(config, source)
    elif kind == "archive":
        check_archive(config, source)


def check_command(config: dict, source: str) -> None:
    """Templates exist and name only known placeholders; so does the command line (its output, a model, is
    checked with the other model sections: `config_checks.check_model_sections`)."""
    from shockcal.simulators.templates import COMMAND_ONLY, check_template, placeholder_units

    section = config["simulator"]["command"]
    known = {}
    for shot in config["shots"]:
        known.update(placeholder_units(shot_mapping(config, shot)))
    for i, path in enumerate(section["templates"]):
        where = f"{source}: simulator.command.templates[{i}]"
        if not Path(path).is_file():
            raise ConfigError(f"{where}: {path} does not exist")
        try:
            text = Path(path).read_text(encoding="utf-8")
        except UnicodeDecodeError:
            raise ConfigError(f"{where}: {path} is not UTF-8 text") from None
        check_template(text, known, f"{where} ({path})")
    check_template(section["command"], {**known, **COMMAND_ONLY}, f"{source}: simulator.command.command")


def check_output(output: dict, where: str) -> None:
    """The output spec through the library's own model (`shockcal.simulators.outputs.OutputSpec`)."""
    from shockcal.settings_model import SettingsError
    from shockcal.simulators.outputs import OutputSpec

    try:
        OutputSpec(**output)
    except SettingsError as exc:
        raise ConfigError(f"{where}.{exc.field}: {exc.reason}") from None


def check_archive(config: dict, source: str) -> None:
    """The archive's design exists; every shot has features or traces; the features' run ids are the
    same for every shot and all in the design; a traces pattern holds {run}."""
    section, where = config["simulator"]["archive"], f"{source}: simulator.archive"
    if config["design"].get("file"):
        raise ConfigError(f"{source}: design.file: the archive's design (simulator.archive.design) is the training "
                          "design; leave design.file out")
    design_path = resolve_path(section["design"], f"{where}.design", section)
    if not design_path.is_file():
        raise ConfigError(f"{where}.design: {design_path} does not exist")
    for shot in config["shots"]:
        given = [key for key in ("features", "traces") if shot in section.get(key, {})]
        if len(given) != 1:
            raise ConfigError(f"{where}: shot {shot}: give its runs as features or as traces (simulator.archive."
                              f"features.{shot} or .traces.{shot}); {'both are' if given else 'neither is'} given")
    for shot, pattern in section.get("traces", {}).items():
        if "{run}" not in pattern:
            raise ConfigError(f"{where}.traces.{shot}: {pattern} has no {{run}}; each run's trace is a file of its own")
    if section.get("traces"):
        check_output({**section.get("trace", {}), "kind": "trace"}, f"{where}.trace")
    try:
        archive_runs(config)
    except ShockcalError as exc:
        raise ConfigError(f"{source}: {exc}") from None
