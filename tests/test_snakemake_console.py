"""`snakemake --logger shockcal` (what `make` runs): one progress line on the console, every line snakemake would
print in the log, a failing job shown in full with the end of its log, and snakemake's exit code untouched.

A toy workflow of seconds (six one-line jobs and one that fails, or not), not a study."""

from __future__ import annotations

import io
import logging
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest
from snakemake_interface_logger_plugins.common import LogEvent

from shockcal.study import snakemake_console
from shockcal.study.snakemake_console import LogHandler, LogHandlerSettings, clock, final_line, progress_line

SNAKEMAKE = str(Path(sys.executable).parent / "snakemake")
TOY = """
rule all:
    input: expand("out/{{i}}.txt", i=range(6)), "out/last.txt"

rule make:
    output: "out/{{i}}.txt"
    log: "logs/{{i}}.log"
    wildcard_constraints: i=r"\\d+"
    shell: "echo {{wildcards.i}} > {{output}} 2> {{log}}"

rule last:
    input: "out/0.txt"
    output: "out/last.txt"
    log: "logs/last.log"
    shell: "(echo reading; echo 'shockcal features: error: out/0.txt: no column t_us'; exit {exit_code}) > {{log}} 2>&1; touch {{output}}"
"""


def run_toy(tmp_path: Path, exit_code: int, *options: str) -> subprocess.CompletedProcess:
    (tmp_path / "Snakefile").write_text(TOY.format(exit_code=exit_code))
    return subprocess.run([SNAKEMAKE, "--cores", "2", "--logger", "shockcal", "--logger-shockcal-log-dir",
                           "results/logs/snakemake", *options], cwd=tmp_path, capture_output=True, text=True)


def console_lines(done: subprocess.CompletedProcess) -> list[str]:
    return (done.stdout + done.stderr).splitlines()


def the_log(tmp_path: Path) -> str:
    (log,) = (tmp_path / "results" / "logs" / "snakemake").glob("*.log")
    return log.read_text()


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """The toy workflow run once to the end: (its folder, the run)."""
    folder = tmp_path_factory.mktemp("toy")
    return folder, run_toy(folder, 0)


def test_a_run_shows_its_progress_on_a_line_and_every_job_block_in_the_log(finished):
    folder, done = finished
    lines = console_lines(done)
    assert done.returncode == 0, lines
    assert lines[-2].startswith("snakemake: 8/8 jobs done in ") and "failed" not in lines[-2], lines
    (log_path,) = (folder / "results" / "logs" / "snakemake").glob("*.log")
    assert lines[-1] == f"snakemake log: {log_path}"
    assert len(lines) == 2, lines                               # piped, a run of seconds: no 30 s line
    log = log_path.read_text()
    assert log.count("localrule make:") == 6 and "8 of 8 steps (100%) done" in log   # snakemake's own words


def test_a_failure_shows_the_rule_its_log_and_snakemakes_error_and_keeps_the_exit_code(tmp_path):
    done = run_toy(tmp_path, 3)
    console = "\n".join(console_lines(done))
    assert done.returncode == 1, console                      # snakemake's own exit code
    assert "Error in rule last:" in console and "log: logs/last.log" in console
    assert "last lines of logs/last.log:" in console
    assert "    shockcal features: error: out/0.txt: no column t_us" in console        # the job's own message
    assert "At least one job did not complete successfully." in console               # snakemake's error line
    assert "failed (the errors above)" in console_lines(done)[-2]
    assert "localrule make:" not in console and "localrule make:" in the_log(tmp_path)


def test_nothing_to_do_says_so_and_a_dry_run_prints_as_snakemake_does(finished):
    folder, _ = finished
    again = console_lines(run_toy(folder, 0))
    assert len(again) == 1 and again[0].startswith("Nothing to be done"), again
    dry = "\n".join(console_lines(run_toy(folder, 0, "--dry-run", "--forceall")))
    assert dry.count("rule make:") == 6 and "This was a dry-run" in dry


def recorded(event=None, level=logging.INFO, msg="", **fields) -> logging.LogRecord:
    """A record as snakemake logs it (`logger.info(msg, extra=dict(event=..., ...))`)."""
    record = logging.LogRecord("snakemake", level, __file__, 0, msg, None, None)
    record.__dict__.update(fields, **({"event": event} if event else {}))
    return record


def test_off_a_terminal_a_line_comes_every_interval_with_the_time_left(monkeypatch):
    """Records of a run (its job table, then jobs finishing) through the handler on a pipe: the line
    comes from the clock, with the jobs done so far and the time left at their pace."""
    now = [100.0]
    monkeypatch.setattr(snakemake_console.time, "monotonic", lambda: now[0])
    stream = io.StringIO()
    monkeypatch.setattr(snakemake_console.sys, "stderr", stream)
    handler = LogHandler(SimpleNamespace(dryrun=False, stdout=False), LogHandlerSettings())
    handler.closed.set()                                        # no ticker thread: the test calls its step
    handler.setFormatter(logging.Formatter("%(message)s"))
    handler.handle(recorded(LogEvent.RUN_INFO, msg="Job stats: ...", stats={"make": 66, "all": 1, "total": 67}))
    now[0] += 72.0
    for done in range(1, 38):
        handler.handle(recorded(LogEvent.PROGRESS, msg="", done=done, total=67))
    assert stream.getvalue() == ""                               # nothing between the ticks off a terminal
    handler._redraw(new_line=True)
    assert stream.getvalue() == "snakemake: 37/67 jobs, 01:12 elapsed, ~00:58 left\n"


def test_the_line_reads_in_minutes_and_hours():
    assert clock(59.6) == "01:00" and clock(3725) == "1:02:05"
    assert progress_line(0, 67, 5) == "snakemake: 0/67 jobs, 00:05 elapsed"
    assert progress_line(10, 40, 60) == "snakemake: 10/40 jobs, 01:00 elapsed, ~03:00 left"
    assert final_line(12, 67, 30, failed=True) == "snakemake: 12/67 jobs done in 00:30; failed (the errors above)"


