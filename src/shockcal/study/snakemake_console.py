"""Snakemake's console at one line of progress: the logger plugin `snakemake --logger shockcal` (what `make` runs).

On the console (stderr; stdout for a dry run, as snakemake), instead of a block per job:

- one line, redrawn in place on a terminal (every second) and written anew every `LINE_INTERVAL_S` seconds
  otherwise (a pipe, a CI log), e.g. ``snakemake: 37/67 jobs, 01:12 elapsed, ~01:30 left``; the time left
  is the elapsed time per finished job times the jobs left;
- a failing job's block as snakemake prints it (the rule, its input, output and log paths, the shell
  command), then the last `LOG_TAIL_LINES` lines of each of its log files (where shockcal's one-line error
  is), and every warning and error line of snakemake's in full;
- at the end, the jobs done and the time taken, and the log's path.

The log (`--logger-shockcal-log-dir DIR`: ``DIR/<start time>.log``, one file per run) holds every line
snakemake would have printed without the plugin, in the same words. A dry run (`-n`) prints as snakemake
does. Snakemake still writes its own copy to `.snakemake/log/`; its exit code is untouched.

`src/snakemake_logger_plugin_shockcal` hands this module's `LogHandler` and `LogHandlerSettings` to
Snakemake's plugin registry (a plugin is found by that package name).
"""

import datetime
import logging
import shutil
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from snakemake_interface_logger_plugins.base import LogHandlerBase
from snakemake_interface_logger_plugins.common import LogEvent
from snakemake_interface_logger_plugins.settings import LogHandlerSettingsBase

LINE_INTERVAL_S = 30.0   # a progress line this often when stderr is not a terminal
REDRAW_S = 1.0           # the line's redraw on a terminal
LOG_TAIL_LINES = 5       # the last lines of a failed job's log files shown on the console
ERROR_EVENTS = (LogEvent.JOB_ERROR, LogEvent.GROUP_ERROR)
SHOWN_INFO = ("Nothing to be done", "Terminating processes on user request")   # snakemake's info lines shown
SNAKEMAKES_LOG = "Complete log(s):"   # the path of snakemake's own log, shown when there is no log of ours


@dataclass
class LogHandlerSettings(LogHandlerSettingsBase):
    # Optional[str], not `str | None`: snakemake's argparse calls the field's type
    log_dir: Optional[str] = field(default=None, metadata={  # noqa: UP045
        "help": "folder of the full log, one file per run named by its start time (default: none; snakemake's "
                "own copy is in .snakemake/log/)"})


def clock(seconds: float) -> str:
    """`seconds` as MM:SS, or H:MM:SS from an hour on."""
    minutes, secs = divmod(int(round(seconds)), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes:02d}:{secs:02d}"


def progress_line(done: int | None, total: int, elapsed_s: float) -> str:
    """The console's line: jobs done of the total, time elapsed and the time left at the pace so far."""
    done = done or 0
    line = f"snakemake: {done}/{total} jobs, {clock(elapsed_s)} elapsed"
    if 0 < done < total:
        line += f", ~{clock(elapsed_s * (total - done) / done)} left"
    return line


def final_line(done: int | None, total: int, elapsed_s: float, failed: bool) -> str:
    """The console's last word on the run: the jobs done and the time taken, and whether it failed."""
    line = f"snakemake: {done or 0}/{total} jobs done in {clock(elapsed_s)}"
    return line + "; failed (the errors above)" if failed else line


def log_tail(paths, n_lines: int = LOG_TAIL_LINES) -> list[str]:
    """The last `n_lines` lines of each existing file in `paths`, under a header naming it."""
    lines = []
    for path in paths:
        path = Path(str(path).split(" (")[0])       # without a note snakemake may append, " (...)"
        if not path.is_file():
            continue
        text = path.read_text(errors="replace").rstrip("\n").splitlines()[-n_lines:]
        lines += [f"last lines of {path}:", *(f"    {line}" for line in text)]
    return lines


class LogHandler(LogHandlerBase):
    """One progress line and the failures on stderr, everything in the log file (module docstring)."""

    def __post_init__(self) -> None:
        self.stream = sys.stdout if self.common_settings.stdout else sys.stderr    # where snakemake would print
        self.terminal = self.stream.isatty()
        self.started = time.monotonic()
        self.done: int | None = None
        self.total: int | None = None
        self.failed = False
        self.line_shown = False        # a progress line is on a terminal (to be wiped before other lines)
        self.lock = threading.RLock()
        self.log_path = None
        self.log = None
        log_dir = getattr(self.settings, "log_dir", None)
        if log_dir and not self.common_settings.dryrun:
            stamp = datetime.datetime.now().strftime("%Y-%m-%dT%H%M%S")
            self.log_path = Path(log_dir).resolve() / f"{stamp}.log"
            self.log_path.parent.mkdir(parents=True, exist_ok=True)
            self.log = self.log_path.open("a", encoding="utf-8")
        self.closed = threading.Event()
        self.ticker = threading.Thread(target=self._tick, daemon=True)
        if not self.common_settings.dryrun:
            self.ticker.start()

    @property
    def writes_to_stream(self) -> bool:
        return True

    @property
    def writes_to_file(self) -> bool:
        return False       # snakemake asks a file writer for one baseFilename; the log is named per run

    @property
    def has_filter(self) -> bool:
        return False       # snakemake's own filter (--quiet, --printshellcmds): the log holds what it would print

    @property
    def has_formatter(self) -> bool:
        return False       # snakemake's own formatter: the log reads as its console would

    @property
    def needs_rulegraph(self) -> bool:
        return False

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = self.format(record)
        except Exception:  # a record snakemake's formatter cannot take: its bare message
            text = record.getMessage()
        event = getattr(record, "event", None)
        with self.lock:
            if self.log is not None:
                self.log.write(text + "\n")
                self.log.flush()
            if self.common_settings.dryrun:
                self._print(text)
                return
            if event == LogEvent.PROGRESS:
                self.done, self.total = record.done, record.total
                self._redraw(new_line=False)
            elif event == LogEvent.RUN_INFO and isinstance(getattr(record, "stats", None), dict):
                self.total = record.stats.get("total", self.total)
                self.done = self.done or 0
                self._redraw(new_line=False)
            elif event in ERROR_EVENTS:
                self.failed = True
                self._print(text)
                self._print("\n".join(log_tail(getattr(record, "log", None) or [])))
            elif (record.levelno >= logging.WARNING or str(record.msg).startswith(SHOWN_INFO)
                  or (self.log is None and str(record.msg).startswith(SNAKEMAKES_LOG))):
                self.failed = self.failed or record.levelno >= logging.ERROR
                self._print(text)

    def close(self) -> None:
        with self.lock:
            if not self.closed.is_set():
                self.closed.set()
                if self.total is not None and not self.common_settings.dryrun:
                    self._clear_line()
                    self._print(final_line(self.done, self.total, time.monotonic() - self.started, self.failed))
                if self.log is not None:
                    self.log.close()
                    if self.total is not None or self.failed:      # not for a report's or an idle run's log
                        self._print(f"snakemake log: {self.log_path}")
        super().close()

    def _tick(self) -> None:
        interval = REDRAW_S if self.terminal else LINE_INTERVAL_S
        while not self.closed.wait(interval):
            with self.lock:
                if not self.closed.is_set() and self.total is not None:     # not while planning, nor for --report
                    self._redraw(new_line=not self.terminal)

    def _redraw(self, new_line: bool) -> None:
        """The progress line: in place on a terminal, as a new line otherwise when `new_line`."""
        line = progress_line(self.done, self.total, time.monotonic() - self.started)
        if self.terminal:     # cut to the terminal's width: a wrapped line would not redraw in place
            self.stream.write(f"\r{line[:shutil.get_terminal_size().columns - 1]}\x1b[K")
            self.line_shown = True
        elif new_line:
            self.stream.write(line + "\n")
        self.stream.flush()

    def _clear_line(self) -> None:
        """The progress line wiped, for other lines in its place."""
        if self.line_shown:
            self.stream.write("\r\x1b[K")
            self.line_shown = False

    def _print(self, text: str) -> None:
        """Lines in the progress line's place (a terminal redraws it below them at the next tick)."""
        if not text:
            return
        self._clear_line()
        self.stream.write(text.rstrip("\n") + "\n")
        self.stream.flush()
