"""Helpers of the Snakemake rule files (kept here so the rule files hold rules only; `snakemake
--lint` also refuses os.environ in a rule file, hence `export_to_jobs`)."""

from __future__ import annotations

from pathlib import Path


def write_if_changed(path, text: str) -> None:
    """Write `path` only when its content changes (every job re-reads the Snakefile)."""
    path = Path(path)
    if not path.exists() or path.read_text() != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)


def point_stable_name(effective_config, stable_name: str = "effective.yaml") -> Path:
    """Make `stable_name`, next to the content-named `effective_config`, a relative symlink to it (replaced
    atomically) and return the link: the path a user hands `shockcal --config` to reuse a study's settings.
    The workflow calls this when a run starts jobs (`onstart`), so a dry run with other settings leaves it."""
    import os

    target = Path(effective_config)
    link = target.with_name(stable_name)
    temporary = link.with_name(f".{stable_name}.{os.getpid()}")
    temporary.unlink(missing_ok=True)
    temporary.symlink_to(target.name)
    os.replace(temporary, link)
    return link


def chunk_rows(chunk, chunk_size: int, total: int | None = None) -> str:
    """The slice START:STOP of one chunk (design rows for `shockcal simulate --rows`, trials for
    `shockcal calibrate-check --trial-range`), cut at `total` when given."""
    start = int(chunk) * chunk_size
    stop = start + chunk_size if total is None else min(start + chunk_size, total)
    return f"{start}:{stop}"


def chunk_count(n_runs: int, chunk_size: int) -> int:
    return -(-n_runs // chunk_size)


def export_to_jobs(effective_config: str) -> None:
    """Environment every job inherits: the merged config as $SHOCKCAL_CONFIG (the default of
    `shockcal --config`), and the directory of the Python running snakemake first on PATH, so rules
    find the `shockcal` script even when that environment is not activated (`.venv/bin/snakemake`);
    a conda env, when used, is activated in front of it."""
    import os
    import sys

    os.environ["SHOCKCAL_CONFIG"] = effective_config
    os.environ["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])
