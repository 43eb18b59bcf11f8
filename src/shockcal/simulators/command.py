"""Run a design through an external code for one shot, one table row per run (docs/simulators.md).

Each run has its folder, `<runs_dir>/<shot>/<run>/`: the templates rendered there with the run's
values (`shockcal.simulators.templates`), the command line run there through the shell in a process
group of its own, its stdout and stderr kept (`stdout.txt`, `stderr.txt`; an earlier attempt's as
`stderr.attempt-<k>.txt`), and `done.json` written last, atomically: the run's status, reason,
attempts and a digest of its rendered inputs. The folder is the run's checkpoint: a run with a
`done.json` of the same digest is read back, never rerun (after a killed job, or a config change that
does not change what the run is given); a run whose inputs changed is rerun from an emptied folder.

Failures are rows, never exceptions: a non-zero exit, a timeout (the whole process group is killed),
an output that is missing, empty, unparseable, non-finite, truncated or in the wrong units
(`shockcal.simulators.outputs`) is status "failed" with a reason that starts with its kind. A failed
attempt is retried `retries` times. The table has builtin's columns (`shockcal.simulators.builtin`;
diagnostics the external code does not give are NaN), plus the ten feature columns for a code that
writes a features row (its traces are then empty).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path
from typing import Annotated

import numpy as np
import pandas as pd
from pydantic import Field

from shockcal.design.tables import ShotMapping
from shockcal.errors import InputError
from shockcal.hydro import Geometry, HydroSettings, MaterialProperties
from shockcal.hydro.settings_model import SettingsModel, setting
from shockcal.io import atomic_path
from shockcal.progress import progress
from shockcal.settings_model import setting as base_setting
from shockcal.simulators.builtin import DIAGNOSTICS, simulation_columns
from shockcal.simulators.outputs import OutputError, OutputSpec, read_output
from shockcal.simulators.templates import command_values, render, run_values
from shockcal.velocimetry.columns import COLUMNS as FEATURE_COLUMNS

log = logging.getLogger("shockcal.simulators.command")
DONE = "done.json"
KILL_GRACE_S = 2.0            # SIGTERM to the process group, then SIGKILL this much later
STDERR_TAIL_CHARS = 300       # the end of stderr quoted in a failed run's reason


class CommandSettings(SettingsModel):
    """An external code (the config's `simulator.command`): each field's rule, default and description once, the
    schema's entries generated from them; checked on creation, a SettingsError naming the field."""

    templates: list[str] = base_setting(
        ..., "Input template files (relative to the working directory), each rendered into the run's folder under "
             "its own name; placeholders such as {A_MPa}, {velocity_m_s}, {flyer_mm} name their unit "
             "(docs/simulators.md lists them; an unknown one is refused).", min_length=1)
    command: str = base_setting(
        ..., "The command line, run through /bin/sh in the run's folder; the templates' placeholders and {python}, "
             "{study_dir}, {run_dir} are replaced.", min_length=1)
    output: OutputSpec = base_setting(..., "What one run writes in its folder.", key="simulator.command.output")
    timeout_s: float = setting(..., "Wall time (s) of one attempt; past it the attempt's whole process group is "
                                    "killed and the attempt failed.", "positive")
    retries: int = base_setting(0, "Further attempts of a failed run (the same folder, inputs rendered again).", ge=0)
    env: dict[str, Annotated[str, Field(description="The variable's value.")]] = base_setting(
        {}, "Environment variables set for the command, on top of shockcal's own.")


def simulate_design_command(design: pd.DataFrame, mapping: ShotMapping, geometry: Geometry,
                            material: MaterialProperties, settings: HydroSettings, command: CommandSettings,
                            runs_dir: str | Path, window_end_us: float) -> pd.DataFrame:
    """Run every row of `design` for one shot through the external code; failures become rows with a reason.

    Args:
        design: design table (`run` and the inputs `mapping` reads, Table IV units).
        mapping: how the shot reads a design row.
        geometry, material, settings: the shot's plates and simulated time, the material and the numerics,
            handed to the templates as placeholders (`shockcal.simulators.templates`).
        command: the external code (`CommandSettings`).
        runs_dir: folder of the run folders (`<runs_dir>/<shot>/<run>/`).
        window_end_us: the latest end of the shot's analysis window (us); a trace must reach it.
    """
    texts = {Path(path).name: Path(path).read_text(encoding="utf-8") for path in command.templates}
    shot_dir = Path(runs_dir) / mapping.shot
    rows = []
    with _terminate_as_exit():
        for record in progress(design.to_dict("records"), len(design), f"shot {mapping.shot}", "run", log):
            rows.append(_run(record, mapping, (geometry, material, settings), command, texts,
                             shot_dir / str(int(record["run"])), window_end_us))
    table = pd.DataFrame(rows)
    table["n_steps"] = table["n_steps"].astype("Int64")
    columns = simulation_columns(mapping.inputs())
    return table[[*columns, *(c for c in FEATURE_COLUMNS if c in table.columns)]]


def _run(record: dict, mapping: ShotMapping, physics, command: CommandSettings, texts: dict, run_dir: Path,
         window_end_us: float) -> dict:
    """One run's table row, from its folder's `done.json` when that holds these inputs, else by running it."""
    row = {"run": int(record["run"]), "shot": mapping.shot, **{k: float(record[k]) for k in mapping.inputs()},
           "impact_velocity_m_s": np.nan, "shear_modulus_GPa": np.nan,
           **dict.fromkeys(DIAGNOSTICS, np.nan), "t_us": [], "v_m_s": []}
    try:
        values = run_values(mapping, record, *physics)
    except InputError as exc:
        return {**row, "status": "failed", "reason": f"InputError: {exc}"}
    row["impact_velocity_m_s"] = values["velocity_m_s"]
    row["shear_modulus_GPa"] = values.get("shear_modulus_GPa", np.nan)
    decks = {name: render(text, values) for name, text in texts.items()}
    line = render(command.command, {**values, **command_values(run_dir)})
    digest = _digest(decks, line, command)
    done = _read_done(run_dir, digest)
    if done is None:
        done = _execute_run(run_dir, decks, line, command, digest, window_end_us, row["impact_velocity_m_s"])
    else:
        log.info("run %s of shot %s: done before (%s), not rerun", row["run"], mapping.shot, run_dir / DONE)
    result = {"status": done["status"], "reason": done["reason"], "wall_time_s": done["wall_time_s"]}
    if done["status"] == "ok":
        try:
            result.update(read_output(run_dir / command.output.file, command.output, window_end_us,
                                      row["impact_velocity_m_s"]))
        except OutputError as exc:     # the folder changed after the run finished
            result.update(status="failed", reason=f"{exc} (read back from {run_dir})")
    else:
        log.warning("run %s of shot %s failed: %s", row["run"], mapping.shot, done["reason"])
    return {**row, **result}


def _digest(decks: dict, line: str, command: CommandSettings) -> str:
    """What a run is given: its rendered decks, command line, environment and output spec."""
    content = json.dumps([sorted(decks.items()), line, sorted(command.env.items()), repr(command.output)])
    return hashlib.sha256(content.encode()).hexdigest()


def _read_done(run_dir: Path, digest: str) -> dict | None:
    """The run's finished record when it holds `digest`, else None (never run, killed, or other inputs)."""
    try:
        done = json.loads((run_dir / DONE).read_text())
    except (OSError, ValueError):
        return None
    return done if done.get("digest") == digest else None


def _execute_run(run_dir: Path, decks: dict, line: str, command: CommandSettings, digest: str,
                 window_end_us: float, impact_velocity_m_s: float) -> dict:
    """Run the command in an emptied `run_dir` with up to 1 + retries attempts; write and return `done.json`."""
    if run_dir.exists():
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True)
    for name, text in decks.items():
        (run_dir / name).write_text(text, encoding="utf-8")
    env = {**os.environ, **command.env}
    attempts = command.retries + 1
    start = time.perf_counter()
    for attempt in range(1, attempts + 1):
        if attempt > 1:
            os.replace(run_dir / "stderr.txt", run_dir / f"stderr.attempt-{attempt - 1}.txt")
            (run_dir / command.output.file).unlink(missing_ok=True)
        reason = _call(line, run_dir, command.timeout_s, env)
        if reason is None:
            try:
                read_output(run_dir / command.output.file, command.output, window_end_us, impact_velocity_m_s)
            except OutputError as exc:
                reason = str(exc)
        if reason is None:
            break
        if attempts > 1:
            reason = f"{reason} (attempt {attempt} of {attempts})"
    done = {"status": "ok" if reason is None else "failed", "reason": reason or "", "attempts": attempt,
            "wall_time_s": time.perf_counter() - start, "digest": digest}
    with atomic_path(run_dir / DONE) as tmp:
        tmp.write_text(json.dumps(done, indent=1))
    return done


def _call(line: str, run_dir: Path, timeout_s: float, env: dict) -> str | None:
    """Run `line` in `run_dir` in its own process group; None when it exits 0, else the reason."""
    with open(run_dir / "stdout.txt", "wb") as out, open(run_dir / "stderr.txt", "wb") as err:
        process = subprocess.Popen(line, shell=True, cwd=run_dir, stdin=subprocess.DEVNULL, stdout=out, stderr=err,
                                   env=env, start_new_session=True)
        try:
            code = process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            return f"timeout: no exit within {timeout_s:g} s; its process group was killed"
        finally:
            _kill_group(process)
    if code == 0:
        return None
    what = f"killed by signal {signal.Signals(-code).name}" if code < 0 else f"exit code {code}"
    return f"nonzero exit: {what}; stderr ends: {_tail(run_dir / 'stderr.txt')}"


def _kill_group(process: subprocess.Popen) -> None:
    """End the process group of `process` (the command and whatever it started): SIGTERM, then SIGKILL."""
    for sig, grace in ((signal.SIGTERM, KILL_GRACE_S), (signal.SIGKILL, None)):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:      # the group is gone
            break
        if grace is not None:
            with contextlib.suppress(subprocess.TimeoutExpired):
                process.wait(timeout=grace)
    process.wait()


def _tail(path: Path) -> str:
    text = " | ".join(line.strip() for line in path.read_text(errors="replace").splitlines() if line.strip())
    return (text[-STDERR_TAIL_CHARS:] if text else "(empty)")


@contextlib.contextmanager
def _terminate_as_exit():
    """SIGTERM (snakemake cancelling the job, a cluster's scancel) raises SystemExit while runs go on, so the
    running command's process group is killed on the way out (`_call`'s finally), not orphaned."""
    def stop(signum, frame):
        raise SystemExit(128 + signum)

    try:
        previous = signal.signal(signal.SIGTERM, stop)
    except ValueError:            # not the main thread: leave the handler alone
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
