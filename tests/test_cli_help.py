"""Every `shockcal` command says what it does and shows one worked example, in `shockcal --help` and in
its own --help; the example parses with the command's own options."""

from __future__ import annotations

import argparse
import shlex

import pytest

from shockcal.cli import EXAMPLE, build_parser, main

PARSER = build_parser()
COMMANDS = next(a for a in PARSER._actions if isinstance(a, argparse._SubParsersAction))


def test_every_command_has_a_line_in_the_overview():
    listed = {choice.dest: choice.help for choice in COMMANDS._choices_actions}
    assert set(listed) == set(COMMANDS.choices)
    assert all(help and len(help) > 20 for help in listed.values()), listed


@pytest.mark.parametrize("name", sorted(COMMANDS.choices))
def test_each_command_has_a_description_and_an_example_that_parses(name, capsys):
    with pytest.raises(SystemExit) as done:
        main([name, "--help"])
    assert done.value.code == 0
    text = capsys.readouterr().out
    usage, _, rest = text.partition("\n\n")
    description = rest.split("\n\n")[0]
    assert not description.startswith(("options:", "positional")) and len(description) > 20, text
    assert f"\n{EXAMPLE}\n" in text
    example = text.split(f"\n{EXAMPLE}\n", 1)[1].replace("\\\n", " ")
    for line in example.splitlines():
        argv = shlex.split(line)
        assert argv[:2] == ["shockcal", name], line
        args = PARSER.parse_args(argv[1:])                   # exits (code 2) on an option it does not know
        assert args.command == name


def test_config_reads_as_optional_and_its_absence_is_one_line(capsys, monkeypatch):
    monkeypatch.delenv("SHOCKCAL_CONFIG", raising=False)
    help_text = COMMANDS.choices["simulate"].format_usage()
    assert "[--config CONFIG]" in help_text
    assert main(["design", "--out", "design.parquet"]) == 2
    err = capsys.readouterr().err
    assert err == "shockcal design: error: --config: no study config given; pass --config FILE or set $SHOCKCAL_CONFIG\n"
