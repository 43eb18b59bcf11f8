"""Progress and time left of long loops (a simulate chunk's runs, a batch of synthetic-truth trials), with tqdm.

Where it goes depends on stderr:

- a terminal: tqdm's bar, redrawn in place, with the log lines printed above it;
- anything else (a Snakemake job's log file, `> log 2>&1`; a pipe; a notebook): the bar's text as an
  ordinary log line of the caller's logger, at most once every `LOG_INTERVAL_S` seconds, plus one
  line when the loop starts and one when it ends, e.g.

      2026-11-26 10:00:31,402 shockcal.simulators.builtin INFO: shot 104S: 60/150 runs (40%), 01:02 elapsed, 01:33 left, 1.55s/run

  A simulate job of 150 runs (1.5-3.5 min) gets 5 to 9 such lines, a job of 10 check trials (~16 min)
  one per trial; without logging configured at INFO (a notebook) nothing is shown.

tqdm's own output is not used in log files: it redraws the line with carriage returns, which a log
file keeps as one long line of every update. Progress never changes what a loop computes.
"""

from __future__ import annotations

import functools
import logging
import sys
import time
from collections.abc import Iterable, Iterator

LOG_INTERVAL_S = 30.0   # at most one progress line per this many seconds in a log file
LOG_FORMAT = "{desc}: {n_fmt}/{total_fmt} {unit}s ({percentage:.0f}%), {elapsed} elapsed, {remaining} left, {rate_fmt}"


def progress(items: Iterable, total: int | None, what: str, unit: str, logger: logging.Logger,
             interval_s: float | None = None, stream=None) -> Iterator:
    """Yield `items` unchanged while showing how many of `total` are done and the time left.

    `what` labels the line (e.g. "shot 104S"), `unit` names one item ("run", "trial"); in a log file
    the line goes to `logger` at INFO every `interval_s` seconds at most (default `LOG_INTERVAL_S`); `stream` (default
    sys.stderr) decides terminal or log: the bar is drawn on it when it is a terminal."""
    from tqdm import tqdm

    stream = sys.stderr if stream is None else stream
    interval_s = LOG_INTERVAL_S if interval_s is None else interval_s
    if _is_terminal(stream):
        from tqdm.contrib.logging import logging_redirect_tqdm

        with logging_redirect_tqdm():
            yield from tqdm(items, total=total, desc=what, unit=unit, file=stream, dynamic_ncols=True)
        return
    bar = _log_bar()(items, total=total, desc=what, unit=unit, file=_LogLines(logger), mininterval=interval_s,
                     miniters=1, bar_format=LOG_FORMAT if total else None, disable=not logger.isEnabledFor(logging.INFO))
    try:
        yield from bar
    finally:
        bar.close()


class Every:
    """True at most once every `interval_s` seconds (default `LOG_INTERVAL_S`; monotonic clock): `if every(): log...`."""

    def __init__(self, interval_s: float | None = None):
        self.interval_s = LOG_INTERVAL_S if interval_s is None else interval_s
        self.started = self.last = time.monotonic()

    def __call__(self) -> bool:
        now = time.monotonic()
        if now - self.last < self.interval_s:
            return False
        self.last = now
        return True

    def elapsed_s(self) -> float:
        return time.monotonic() - self.started


class _LogLines:
    """A file for tqdm that turns each redraw ('\\r' + the bar's text) into one log line."""

    def __init__(self, logger: logging.Logger):
        self.logger = logger

    def write(self, text: str) -> None:
        for line in text.replace("\r", "\n").split("\n"):
            if line.strip():
                self.logger.info("%s", line.rstrip())

    def flush(self) -> None:
        pass


@functools.cache
def _log_bar():
    """tqdm that draws each count once: the end of a loop whose last item was just shown adds no line."""
    from tqdm import tqdm

    class LogBar(tqdm):
        def display(self, msg=None, pos=None):
            if msg is None and self.n == getattr(self, "_shown_n", None):
                return True
            self._shown_n = self.n
            return super().display(msg, pos)

    return LogBar


def _is_terminal(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):   # no isatty, or a closed stream
        return False
