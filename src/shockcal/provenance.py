"""Which code wrote a table: the shockcal version and the git commit of its source, once per process.

`write_table` puts `provenance()` under the key ``provenance`` of every table's metadata:
``{"shockcal_version": "0.1.0", "git_commit": "fa30d0d", "git_dirty": false}``. The commit is that of
the checkout the imported package lives in (an editable install: the repository), and `git_dirty`
says whether its tracked files differ from that commit (untracked files, such as a study's results,
do not count). When git is missing, or the package is not a tracked file of a checkout (an installed
wheel), the commit is ``"unknown"`` and the flag ``null``.

Two runs of the same checkout write the same provenance, so tables stay identical between runs.
"""

from __future__ import annotations

import functools
import subprocess
from pathlib import Path

from shockcal import __version__

UNKNOWN = "unknown"
GIT_TIMEOUT_S = 10.0   # per git call; a hung network filesystem must not hold up a job


@functools.cache
def provenance() -> dict:
    """{"shockcal_version", "git_commit" (short hash or "unknown"), "git_dirty" (bool, or None when unknown)}
    of this process's shockcal, computed on the first call."""
    return {"shockcal_version": __version__, **git_state(Path(__file__).resolve().parent)}


def git_state(source: Path) -> dict:
    """{"git_commit": short hash, "git_dirty": bool} of the checkout holding the package directory
    `source`; {"git_commit": "unknown", "git_dirty": None} when git is missing, `source` is not a
    tracked part of a checkout, or git fails."""
    unknown = {"git_commit": UNKNOWN, "git_dirty": None}
    tracked = _git(source, "ls-files", "--error-unmatch", "__init__.py")   # a site-packages copy inside some repo: no
    commit = _git(source, "rev-parse", "--short", "HEAD") if tracked is not None else None
    # --no-optional-locks: many jobs may ask at once, and none may take the index lock from a user's commit
    changes = _git(source, "--no-optional-locks", "status", "--porcelain", "--untracked-files=no") if commit else None
    if not commit or changes is None:
        return unknown
    return {"git_commit": commit, "git_dirty": bool(changes)}


def _git(cwd: Path, *args: str) -> str | None:
    """git's stripped stdout, or None when git is missing, fails or hangs."""
    try:
        done = subprocess.run(["git", "-C", str(cwd), *args], capture_output=True, text=True, timeout=GIT_TIMEOUT_S,
                              check=False)
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None
