"""The quick study through workflow/profiles/slurm on a running (throwaway) SLURM, checked against a
local run; run by tests/slurm/run_slurm_test.sh (`make test-slurm`), which starts and stops the cluster.

1. local reference: `snakemake all --cores 2 --configfile config/quick.yaml <results in WORK/local>`
   (or --reference DIR: the results directory of a finished local quick study); `--overlay CONFIG`
   puts a config file over config/quick.yaml in every run (`make test-slurm SLURM_OVERLAY=...`);
2. SLURM run 1, the profile as shipped: once a simulate job is running shockcal (its log exists), it is
   cancelled with scancel; the profile's retry resubmits it; the retry is cancelled too, so the chunk
   fails for good. Checks: each cancellation is detected within the bounded time, the run finishes the
   rest (keep-going) and exits non-zero naming the chunk, no partial output of the chunk is left;
3. SLURM run 2, the same command: finishes, schedules exactly the cancelled chunk and what depends on
   it (in the cancelled chunk's run set one simulate and one features_chunk job; the run sets made
   from it, e.g. predict after a training chunk, in full; none in the others: `rerun_problems`) and
   rewrites no file run 1 finished;
4. every table (Parquet, CSV) of the SLURM study equals the local one, wall-time columns aside;
5. per-job overhead from squeue's submit/start/end times, the benchmark files and the snakemake log.

Not collected by pytest (no test_ prefix); needs SLURM_CONF pointing at the cluster.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import signal
import statistics
import subprocess
import sys
import threading
import time
from datetime import datetime
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[2]
SNAKEMAKE = str(Path(sys.executable).parent / "snakemake")
PROFILE = "workflow/profiles/slurm"
WALL_TIME_COLUMNS = re.compile(r"(^|_)(wall|elapsed|runtime)(_|$)|_time_s$|^seconds$", re.I)
DETECTION_BOUND_S = 200  # squeue polling: every 20-180 s (profile), plus one poll
RUN_TIMEOUT_S = 40 * 60  # a run that takes longer is a hang: killed, and the test fails


def log(msg: str) -> None:
    print(f"[{datetime.now():%H:%M:%S}] {msg}", flush=True)


def loadavg() -> str:
    return Path("/proc/loadavg").read_text().split(" ", 3)[:3].__str__()


ACTIVE: list[Run] = []


class Run:
    """A snakemake process whose output lines are timestamped as they arrive; stopped (SIGINT, so it
    cancels its SLURM jobs) when this script ends for any reason."""

    def __init__(self, args: list[str], logfile: Path):
        self.lines: list[tuple[float, str]] = []
        self.logfile = logfile
        self.t0 = time.time()
        self.proc = subprocess.Popen([SNAKEMAKE, *args], cwd=REPO, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True, start_new_session=True)
        ACTIVE.append(self)
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        with open(self.logfile, "w") as out:
            for line in self.proc.stdout:
                self.lines.append((time.time(), line.rstrip("\n")))
                out.write(line)
                out.flush()

    def wait(self, timeout: float = RUN_TIMEOUT_S) -> int:
        try:
            self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired as err:
            log(f"snakemake still running after {timeout:.0f} s: a hang; stopping it (pid {self.proc.pid})")
            self.stop()
            raise SystemExit(f"FAIL: hang (see {self.logfile})") from err
        self.reader.join(timeout=10)
        self.elapsed = time.time() - self.t0
        return self.proc.returncode

    def stop(self):
        """SIGINT, then SIGKILL after 20 s; by pid (the cluster's teardown cancels what is left)."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()

    def first(self, pattern: str, after: float = 0.0) -> float | None:
        rx = re.compile(pattern)
        return next((t for t, line in self.lines if t >= after and rx.search(line)), None)

    def text(self) -> str:
        return "\n".join(line for _, line in self.lines)


class Squeue:
    """Polls squeue every 2 s and keeps the last row of each job of ours: id -> fields."""

    FIELDS = ["id", "name", "comment", "state", "submit", "start", "end"]

    def __init__(self):
        self.jobs: dict[str, dict] = {}
        self.running = True
        self.thread = threading.Thread(target=self._poll, daemon=True)
        self.thread.start()

    def snapshot(self) -> dict[str, dict]:
        out = subprocess.run(["squeue", "--states=all", "-h", "-o", "%i|%j|%k|%T|%V|%S|%e"],
                             capture_output=True, text=True)
        rows = {}
        for line in out.stdout.splitlines():
            row = dict(zip(self.FIELDS, line.split("|")))
            if row.get("name", "").startswith("shockcal"):
                rows[row["id"]] = row
        return rows

    def _poll(self):
        while self.running:
            self.jobs.update(self.snapshot())
            time.sleep(2)

    def stop(self):
        self.running = False
        self.thread.join(timeout=10)


def overlay(path: Path, results: Path) -> Path:
    path.write_text(f"study:\n  results_dir: {results}\n")
    return path


OVERLAYS: list[str] = []   # --overlay: config files between config/quick.yaml and the results overlay


def snakemake_args(config: Path, *extra: str) -> list[str]:
    # targets and options first: --configfile takes every argument after it
    return ["all", *extra, "--configfile", "config/quick.yaml", *OVERLAYS, str(config)]


def tables(results: Path) -> dict[str, Path]:
    skip = ("logs", "benchmarks", "config")
    return {str(p.relative_to(results)): p for p in sorted(results.rglob("*"))
            if p.suffix in (".parquet", ".csv") and p.relative_to(results).parts[0] not in skip}


def read_table(path: Path) -> pd.DataFrame:
    return pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)


def compare(local: Path, slurm: Path) -> list[str]:
    """Differences between the two studies' tables (empty: equal), wall-time columns dropped."""
    a, b = tables(local), tables(slurm)
    problems = [f"only in the local study: {k}" for k in sorted(set(a) - set(b))]
    problems += [f"only in the SLURM study: {k}" for k in sorted(set(b) - set(a))]
    dropped = set()
    for key in sorted(set(a) & set(b)):
        x, y = read_table(a[key]), read_table(b[key])
        wall = [c for c in x.columns if WALL_TIME_COLUMNS.search(str(c))]
        dropped.update(wall)
        x, y = x.drop(columns=wall), y.drop(columns=[c for c in wall if c in y.columns])
        try:
            pd.testing.assert_frame_equal(x, y, check_exact=True)
        except AssertionError as err:
            problems.append(f"{key}: {str(err).splitlines()[0:6]}")
    log(f"compared {len(set(a) & set(b))} tables; wall-time columns ignored: {sorted(dropped) or 'none'}")
    return problems


def mtimes(results: Path) -> dict[str, int]:
    """Every finished file: a command simulator's run folder ({run_set}/runs/{shot}/{run}/) counts only once its
    run has finished (its done.json, written last); a run the cancellation cut short is redone, as it should be."""
    def finished(parts: tuple[str, ...]) -> bool:
        return len(parts) < 5 or parts[1] != "runs" or (results.joinpath(*parts[:4]) / "done.json").exists()

    return {str(p.relative_to(results)): p.stat().st_mtime_ns for p in results.rglob("*")
            if p.is_file() and p.relative_to(results).parts[0] not in ("logs", "benchmarks", "config")
            and finished(p.relative_to(results).parts)}


def job_stats(text: str) -> dict[str, int]:
    """The 'Job stats' table snakemake prints first: rule -> count."""
    if "Job stats:" not in text:
        return {}
    jobs = {}
    for line in text.split("Job stats:", 1)[1].splitlines()[3:]:
        name, _, count = line.strip().rpartition(" ")
        if not name or name.strip() == "total":
            break
        jobs[name.strip()] = int(count)
    return jobs


def scheduled_jobs(text: str) -> list[tuple[str, dict[str, str]]]:
    """(rule, wildcards) of each job a snakemake log announces (its `rule NAME:` / `localrule NAME:`
    block with a `wildcards:` line; none for a rule without wildcards), each job once (a restarted job
    is announced again with the same jobid)."""
    jobs, seen = [], set()
    rule = jobid = None
    wildcards: dict[str, str] = {}

    def close():
        if rule is not None and (rule, jobid, tuple(sorted(wildcards.items()))) not in seen:
            seen.add((rule, jobid, tuple(sorted(wildcards.items()))))
            jobs.append((rule, dict(wildcards)))

    for line in text.splitlines():
        m = re.match(r"^(?:local)?rule (\w+):\s*$", line.strip()) if not line.startswith(" ") else None
        if m:
            close()
            rule, jobid, wildcards = m.group(1), None, {}
        elif rule is not None and line.startswith("    "):
            key, _, value = line.strip().partition(": ")
            if key == "jobid":
                jobid = value.strip()
            elif key == "wildcards":
                wildcards = dict(pair.split("=", 1) for pair in value.split(", ") if "=" in pair)
        elif rule is not None:
            close()
            rule = None
    close()
    return jobs


PER_CHUNK_RULES = ("simulate", "features_chunk", "features")


def made_from(run_set: str, other: str) -> bool:
    """Whether run set `other` is made from `run_set`'s results, so that a cancelled chunk of `run_set`
    leaves every job of `other` unmade in run 1: the predict design is drawn from the joint posterior of
    the training runs and every wave; a sequential study's wave k (wave1, wave2, ...) from the runs of
    waves 0..k-1 (wave 0 is the training run set)."""
    def wave(name: str) -> int | None:
        later = re.fullmatch(r"wave(\d+)", name)
        return 0 if name == "training" else int(later.group(1)) if later else None

    if wave(run_set) is None:
        return False
    return other == "predict" or (wave(other) is not None and wave(other) > wave(run_set))


def rerun_problems(jobs: list[tuple[str, dict[str, str]]], run_set: str, shot: str, chunk: str) -> list[str]:
    """What is wrong with run 2's schedule after chunk `chunk` of `shot` in `run_set` was cancelled for
    good in run 1, rule by rule of PER_CHUNK_RULES and run set by run set: in the cancelled run set,
    exactly that chunk (simulate, features_chunk) and that shot's merge (features); in the run sets
    made from it (`made_from`, never made in run 1), any; in the others (finished), none."""
    problems = []
    for rule in PER_CHUNK_RULES:
        by_set: dict[str, list] = {}
        for name, wildcards in jobs:
            if name == rule:
                by_set.setdefault(wildcards.get("run_set", "?"), []).append((wildcards.get("shot"),
                                                                             wildcards.get("chunk")))
        expected = [(shot, None if rule == "features" else chunk)]
        got = sorted(by_set.pop(run_set, []), key=str)
        if got != expected:
            problems.append(f"run 2 scheduled {rule} jobs {got} (shot, chunk) in run set {run_set}, expected "
                            f"{expected} (the cancelled chunk)")
        for other, found in sorted(by_set.items()):
            if not made_from(run_set, other):
                problems.append(f"run 2 scheduled {len(found)} {rule} jobs in run set {other}, which run 1 had "
                                "finished")
    return problems


def simulate_wildcards(comment: str) -> tuple[str, str, str]:
    """(run set, shot, chunk) of a simulate job from its SLURM comment."""
    run_set, shot, chunk = comment.removeprefix("rule_simulate_wildcards_").split("_")
    return run_set, shot, chunk


def cancel_running_simulate(run: Run, squeue: Squeue, results: Path, exclude: set[str], wait_for_log: bool,
                            comment: str | None = None, timeout: float = 600) -> tuple[str, str, float]:
    """scancel the first simulate job seen RUNNING (with its shockcal log written when wait_for_log;
    only the job with this SLURM comment, i.e. this chunk, when given); returns (slurm id, comment,
    time of the scancel)."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        if run.proc.poll() is not None:
            raise SystemExit("FAIL: snakemake ended before a simulate job ran")
        for job in squeue.snapshot().values():
            if job["id"] in exclude or job["state"] != "RUNNING" or not job["comment"].startswith("rule_simulate_"):
                continue
            if comment is not None and job["comment"] != comment:
                continue
            run_set, shot, chunk = simulate_wildcards(job["comment"])
            if wait_for_log and not (results / "logs" / run_set / "simulate" / shot / f"chunk-{chunk}.log").exists():
                continue
            subprocess.run(["scancel", job["id"]], check=True)
            t = time.time()
            log(f"scancel {job['id']} ({job['comment']}, running for {elapsed_since(job['start']):.0f} s)")
            return job["id"], job["comment"], t
        time.sleep(0.2)
    raise SystemExit("FAIL: no running simulate job to cancel")


def elapsed_since(stamp: str) -> float:
    try:
        return time.time() - datetime.fromisoformat(stamp).timestamp()
    except ValueError:
        return float("nan")


def seconds(a: str, b: str) -> float | None:
    try:
        return (datetime.fromisoformat(b) - datetime.fromisoformat(a)).total_seconds()
    except ValueError:
        return None


def rule_start_on_node(slurm_logs: Path, slurm_id: str) -> float | None:
    """When the shell command of the job started on the node: the last `[date]` line followed by
    `rule ...:` in its SLURM log (kept with --slurm-keep-successful-logs). The log holds two snakemake
    start-ups: the job step executor's, then, under srun, the one that runs the rule."""
    stamp = None
    for path in slurm_logs.rglob(f"{slurm_id}.log"):
        lines = path.read_text(errors="replace").splitlines()
        for line, following in zip(lines, lines[1:]):
            m = re.match(r"^\[(\w{3} \w{3} +\d+ \d\d:\d\d:\d\d \d{4})\]$", line.strip())
            if m and following.startswith(("rule ", "localrule ")):
                stamp = datetime.strptime(m.group(1), "%a %b %d %H:%M:%S %Y").timestamp()
    return stamp


def overhead(run: Run, squeue: Squeue, results: Path, slurm_logs: Path) -> dict[str, list[float]]:
    """Per completed job: queue wait (submit -> start), snakemake start-up on the node (start -> the
    rule's start in the job's log), submission -> rule start on the node, time on the node outside
    shockcal (start -> end minus the benchmark's wall time: snakemake start-up, srun, teardown), and
    end -> snakemake noticing it (status polling). squeue's times have a resolution of 1 s."""
    submitted = {}  # snakemake jobid -> slurm id
    for _, line in run.lines:
        m = re.search(r"Job (\d+) has been submitted with SLURM jobid (\d+)", line)
        if m:
            submitted[m.group(1)] = m.group(2)
    finished = {}
    for t, line in run.lines:
        m = re.search(r"Finished jobid: (\d+)", line)
        if m:
            finished[m.group(1)] = t
    out = {"queue": [], "startup": [], "to_rule": [], "node": [], "detect": [], "shockcal": []}
    for sm_id, slurm_id in submitted.items():
        job = squeue.jobs.get(slurm_id)
        if not job or job["state"] != "COMPLETED":
            continue
        bench = benchmark_file(results, job["comment"])
        if bench is None:
            continue
        s = float(pd.read_csv(bench, sep="\t")["s"].iloc[0])
        queue, on_node = seconds(job["submit"], job["start"]), seconds(job["start"], job["end"])
        if queue is None or on_node is None:
            continue
        out["queue"].append(queue)
        out["node"].append(on_node - s)
        out["shockcal"].append(s)
        rule_start = rule_start_on_node(slurm_logs, slurm_id)
        if rule_start is not None:
            out["startup"].append(rule_start - datetime.fromisoformat(job["start"]).timestamp())
            out["to_rule"].append(rule_start - datetime.fromisoformat(job["submit"]).timestamp())
        if sm_id in finished:
            out["detect"].append(finished[sm_id] - datetime.fromisoformat(job["end"]).timestamp())
    return out


def benchmark_file(results: Path, comment: str) -> Path | None:
    """The benchmark file of a job from its SLURM comment (rule_<rule>[_wildcards_<values>])."""
    m = re.match(r"rule_(.+?)(?:_wildcards_(.*))?$", comment)
    rule, wildcards = m.group(1), (m.group(2) or "").split("_") if m.group(2) else []
    bench = results / "benchmarks"
    candidates = {
        "simulate": lambda: bench / wildcards[0] / "simulate" / wildcards[1] / f"chunk-{wildcards[2]}.tsv",
        "features_chunk": lambda: bench / wildcards[0] / "features" / wildcards[1] / f"chunk-{wildcards[2]}.tsv",
        "features": lambda: bench / wildcards[0] / "features" / f"{wildcards[1]}.tsv",
        "calibrate": lambda: bench / "calibrate" / f"{wildcards[0]}.tsv",
        "emulator": lambda: bench / "emulator.tsv",
        "check_design": lambda: bench / "check" / "design.tsv",
        "predict_design": lambda: bench / "predict" / "design.tsv",
    }
    if rule in candidates:
        path = candidates[rule]()
    elif rule.startswith("figure_"):
        path = bench / "figures" / f"{rule.removeprefix('figure_')}.tsv"
    else:
        matches = [p for p in bench.rglob("*.tsv") if p.stem in (rule, *wildcards[-1:])]
        path = matches[0] if len(matches) == 1 else None
    return path if path is not None and path.exists() else None


def stats(values: list[float]) -> str:
    if not values:
        return "n/a"
    return (f"median {statistics.median(values):.1f} s, mean {statistics.mean(values):.1f} s, "
            f"min {min(values):.1f} s, max {max(values):.1f} s (n={len(values)})")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--work", type=Path, required=True, help="scratch directory (results, logs)")
    parser.add_argument("--reference", type=Path, help="results of a finished local quick study to compare with")
    parser.add_argument("--overlay", action="append", default=[], metavar="CONFIG",
                        help="a config file over config/quick.yaml for every run, local and SLURM (e.g. "
                             "examples/external_hydro/quick-command.yaml: the example external code)")
    args = parser.parse_args()
    OVERLAYS.extend(args.overlay)
    work = args.work.resolve()
    failures: list[str] = []
    t_start = time.time()
    log(f"load {loadavg()}, {os.cpu_count()} cores; work directory {work}")

    # 1. local reference
    if args.reference:
        local = args.reference.resolve()
        log(f"local reference: {local} (given)")
    else:
        local = work / "local" / "results"
        log("local run of the quick study (reference) ...")
        ref = Run(snakemake_args(overlay(work / "local.yaml", local), "--cores", "2"), work / "local.log")
        if ref.wait() != 0:
            raise SystemExit(f"FAIL: the local quick study failed (see {work / 'local.log'})")
        log(f"local run: {ref.elapsed:.0f} s, load {loadavg()}")

    results = work / "slurm" / "results"
    config = overlay(work / "slurm.yaml", results)
    # The profile as shipped; the test only moves the SLURM logs out of the repository and keeps them.
    extra = ["--profile", PROFILE, "--slurm-logdir", str(work / "slurm_logs"), "--slurm-keep-successful-logs"]
    squeue = Squeue()

    # 2. run 1: cancel a running simulate job, then its retry
    log("SLURM run 1 (cancels one simulate job and its retry) ...")
    run1 = Run(snakemake_args(config, *extra), work / "slurm-run1.log")
    first_id, comment, t_cancel1 = cancel_running_simulate(run1, squeue, results, set(), wait_for_log=True)
    run_set, shot, chunk = simulate_wildcards(comment)
    t_retry = None
    deadline = time.time() + DETECTION_BOUND_S
    while time.time() < deadline and t_retry is None:
        t_retry = run1.first(r"Trying to restart job|Restarting job", after=t_cancel1)
        time.sleep(0.5)
    if t_retry is None:
        failures.append(f"cancelled job {first_id} not detected and retried within {DETECTION_BOUND_S} s")
    else:
        log(f"cancellation detected and the job resubmitted after {t_retry - t_cancel1:.0f} s")
        _, _, t_cancel2 = cancel_running_simulate(run1, squeue, results, {first_id}, wait_for_log=False,
                                                  comment=comment)
    rc1 = run1.wait()
    log(f"run 1: exit {rc1} after {run1.elapsed:.0f} s, load {loadavg()}")
    if t_retry is not None:
        t_error = run1.first(r"Error in rule simulate", after=t_cancel2)
        if t_error is None:
            failures.append("the cancelled retry was not reported as an error")
        else:
            log(f"cancelled retry reported as failed after {t_error - t_cancel2:.0f} s")
            if t_error - t_cancel2 > DETECTION_BOUND_S:
                failures.append(f"the failed retry was reported only after {t_error - t_cancel2:.0f} s")
    if rc1 == 0:
        failures.append("run 1 exited 0 although a chunk was cancelled twice")
    chunk_file = results / run_set / "simulations" / shot / f"chunk-{chunk}.parquet"
    if chunk_file.exists():
        failures.append(f"{chunk_file} exists after its job was cancelled")
    leftovers = [p for p in chunk_file.parent.glob(f"*chunk-{chunk}*") if p != chunk_file] if chunk_file.parent.exists() else []
    if leftovers:
        failures.append(f"partial files of the cancelled chunk left: {leftovers}")
    before = mtimes(results)
    log(f"run 1 left {len(before)} files; {shot} chunk {chunk} missing as expected: {not chunk_file.exists()}")

    # 3. run 2: the same command finishes and recomputes only what is missing
    log("SLURM run 2 (rerun) ...")
    run2 = Run(snakemake_args(config, *extra), work / "slurm-run2.log")
    rc2 = run2.wait()
    log(f"run 2: exit {rc2} after {run2.elapsed:.0f} s, load {loadavg()}")
    squeue.stop()
    if rc2 != 0:
        failures.append(f"run 2 failed (exit {rc2}, see {run2.logfile})")
    planned = job_stats(run2.text())
    log(f"run 2 scheduled: {planned}")
    for rule in ("design", "observed", "check_design"):
        if planned.get(rule):
            failures.append(f"run 2 reran {rule}, which run 1 had finished")
    failures += rerun_problems(scheduled_jobs(run2.text()), run_set, shot, chunk)   # per run set (rerun_problems)
    after = mtimes(results)
    rewritten = sorted(k for k, t in before.items() if after.get(k) != t)
    if rewritten:
        failures.append(f"run 2 rewrote files run 1 had finished: {rewritten[:10]}")

    # 4. the SLURM study's tables equal the local ones
    if rc2 == 0:
        problems = compare(local, results)
        failures += [f"tables differ: {p}" for p in problems]
        if not problems:
            log("every table of the SLURM study equals the local run's")

    # 5. overhead per job (from both runs)
    slurm_logs = work / "slurm_logs"
    per_job = {k: a + b for (k, a), b in zip(overhead(run1, squeue, results, slurm_logs).items(),
                                            overhead(run2, squeue, results, slurm_logs).values())}
    (work / "squeue.json").write_text(json.dumps(squeue.jobs, indent=1))
    total = time.time() - t_start
    print()
    print("== make test-slurm summary")
    print(f"load at the end: {loadavg()} ({os.cpu_count()} cores)")
    if not args.reference:
        print(f"local quick study:                 {ref.elapsed:6.0f} s")
    print(f"SLURM run 1 (with 2 cancellations): {run1.elapsed:6.0f} s, exit {rc1}")
    print(f"SLURM run 2 (rerun):               {run2.elapsed:6.0f} s, exit {rc2}, jobs {sum(planned.values())}")
    print(f"total (this script):               {total:6.0f} s")
    print("per SLURM job (completed jobs of both runs):")
    print(f"  queue wait (submit -> start):             {stats(per_job['queue'])}")
    print(f"  job start -> shockcal starts (2 snakemake start-ups): {stats(per_job['startup'])}")
    print(f"  submission -> shockcal starts:            {stats(per_job['to_rule'])}")
    print(f"  on the node outside shockcal (all):       {stats(per_job['node'])}")
    print(f"  end -> snakemake notices (squeue polls):  {stats(per_job['detect'])}")
    print(f"  shockcal itself (benchmark s):            {stats(per_job['shockcal'])}")
    if t_retry is not None:
        print(f"cancelled job detected + resubmitted after {t_retry - t_cancel1:.0f} s")
    for f in failures:
        print(f"FAIL: {f}")
    print("PASS" if not failures else f"FAILED ({len(failures)})")
    return 0 if not failures else 1


def _terminate(signum, frame):
    raise SystemExit(f"stopped by signal {signum}")


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, _terminate)
    try:
        sys.exit(main())
    finally:
        for active in ACTIVE:
            active.stop()
