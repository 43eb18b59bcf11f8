"""Where the tests and benchmarks find the paper's data release (its design and FLAG features).

The data is never copied into the project. It is looked up in $SHOCKCAL_REFERENCE_DATA, else in
`../shared/data/al5083` beside the repository (or beside the working directory). Tests and
benchmarks that need it call `reference_dir()` and skip, saying so, when it returns None. A study
never reads this default: its archive paths' `{reference_data}` is $SHOCKCAL_REFERENCE_DATA or the
config's `simulator.archive.reference_data` (`shockcal.study.simulator.resolve_path`).
"""

from __future__ import annotations

import os
from pathlib import Path

ENV_VAR = "SHOCKCAL_REFERENCE_DATA"
_RELATIVE = Path("shared") / "data" / "al5083"


def reference_dir() -> Path | None:
    """The reference-data folder, or None when it is not on this machine."""
    candidates = []
    if os.environ.get(ENV_VAR):
        candidates.append(Path(os.environ[ENV_VAR]))
    repo_root = Path(__file__).resolve().parents[2]
    candidates += [repo_root.parent / _RELATIVE, Path.cwd().parent / _RELATIVE]
    for path in candidates:
        if (path / "design.csv").is_file():
            return path
    return None


def require_reference_dir() -> Path:
    """The reference-data folder, or a clear error saying where it was looked for."""
    from shockcal.errors import InputError

    path = reference_dir()
    if path is None:
        raise InputError(f"reference data not found: set ${ENV_VAR} or place it at ../{_RELATIVE} beside the repository")
    return path
