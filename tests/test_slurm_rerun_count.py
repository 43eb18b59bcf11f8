"""The rerun check of `make test-slurm` (tests/slurm/slurm_study.py), on snakemake logs: after a cancelled
training chunk, the predict run set's simulate and features jobs rerun too (they were never made) and
are not counted as the cancelled chunk, nor are a sequential study's later waves; the check run set's
must not rerun."""

from __future__ import annotations

import importlib.util
from pathlib import Path

SCRIPT = Path(__file__).resolve().parent / "slurm" / "slurm_study.py"
_spec = importlib.util.spec_from_file_location("slurm_study", SCRIPT)
slurm_study = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(slurm_study)


def _job(rule, jobid, **wildcards):
    lines = [f"rule {rule}:", "    input: results/x", f"    jobid: {jobid}"]
    if wildcards:
        lines.append("    wildcards: " + ", ".join(f"{k}={v}" for k, v in wildcards.items()))
    return "\n".join([*lines, "    resources: tmpdir=/tmp", "", "[Wed Nov 25 21:14:51 2026]"])


def _log(*jobs):
    return "\n".join(["Building DAG of jobs...", *jobs, "Finished jobid: 1"])


CANCELLED = [_job("simulate", 1, run_set="training", shot="105S", chunk="2"),
             _job("features_chunk", 2, run_set="training", shot="105S", chunk="2"),
             _job("features", 3, run_set="training", shot="105S"), _job("emulator", 4)]
PREDICT = [_job("simulate", 10 + i, run_set="predict", shot=s, chunk="0") for i, s in enumerate(["104S", "105S"])]
PREDICT += [_job("features_chunk", 20 + i, run_set="predict", shot=s, chunk="0") for i, s in enumerate(["104S", "105S"])]
PREDICT += [_job("features", 30 + i, run_set="predict", shot=s) for i, s in enumerate(["104S", "105S"])]
PER_CHUNK = ("simulate", "features_chunk", "features")


def test_jobs_are_read_with_their_wildcards_once():
    text = _log(*CANCELLED, CANCELLED[0].replace("rule simulate", "localrule simulate"))   # a restart: same jobid
    assert slurm_study.scheduled_jobs(text) == [
        ("simulate", {"run_set": "training", "shot": "105S", "chunk": "2"}),
        ("features_chunk", {"run_set": "training", "shot": "105S", "chunk": "2"}),
        ("features", {"run_set": "training", "shot": "105S"}), ("emulator", {})]


def test_the_predict_run_set_is_not_counted_as_the_cancelled_chunk():
    jobs = slurm_study.scheduled_jobs(_log(*CANCELLED, *PREDICT))
    assert slurm_study.rerun_problems(jobs, "training", "105S", "2") == []


def test_an_extra_training_chunk_or_a_check_job_is_reported():
    extra = [_job("simulate", 40, run_set="training", shot="104S", chunk="0"),
             _job("simulate", 41, run_set="check", shot="104S", chunk="0")]
    problems = slurm_study.rerun_problems(slurm_study.scheduled_jobs(_log(*CANCELLED, *PREDICT, *extra)),
                                          "training", "105S", "2")
    assert problems == [
        "run 2 scheduled simulate jobs [('104S', '0'), ('105S', '2')] (shot, chunk) in run set training, expected "
        "[('105S', '2')] (the cancelled chunk)",
        "run 2 scheduled 1 simulate jobs in run set check, which run 1 had finished"]


def test_a_missing_rerun_is_reported():
    problems = slurm_study.rerun_problems(slurm_study.scheduled_jobs(_log(*CANCELLED[1:])), "training", "105S", "2")
    assert problems == ["run 2 scheduled simulate jobs [] (shot, chunk) in run set training, expected [('105S', '2')] "
                        "(the cancelled chunk)"]


def test_a_cancelled_predict_chunk_allows_nothing_elsewhere():
    jobs = slurm_study.scheduled_jobs(_log(*PREDICT[:1], PREDICT[2], PREDICT[4]))
    assert slurm_study.rerun_problems(jobs, "predict", "104S", "0") == []
    assert slurm_study.rerun_problems(slurm_study.scheduled_jobs(_log(*CANCELLED, *PREDICT[:1], PREDICT[2],
                                                                      PREDICT[4])), "predict", "104S", "0")[0] == (
        "run 2 scheduled 1 simulate jobs in run set training, which run 1 had finished")


def test_a_sequential_studys_later_waves_are_made_from_the_cancelled_chunk():
    waves = [_job(rule, 50 + 10 * k + i, run_set=f"wave{k}", shot=s, **({} if rule == "features" else {"chunk": "0"}))
             for k in (1, 2) for i, (rule, s) in enumerate((r, s) for r in PER_CHUNK for s in ("104S", "105S"))]
    jobs = slurm_study.scheduled_jobs(_log(*CANCELLED, *waves, *PREDICT))
    assert slurm_study.rerun_problems(jobs, "training", "105S", "2") == []
    wave1_cancelled = [_job("simulate", 90, run_set="wave1", shot="105S", chunk="0"),
                       _job("features_chunk", 91, run_set="wave1", shot="105S", chunk="0"),
                       _job("features", 92, run_set="wave1", shot="105S")]
    later = slurm_study.scheduled_jobs(_log(*wave1_cancelled, *waves[6:], *PREDICT))       # wave 2's jobs
    assert slurm_study.rerun_problems(later, "wave1", "105S", "0") == []
    earlier = slurm_study.scheduled_jobs(_log(*wave1_cancelled, CANCELLED[0]))               # a training chunk
    assert slurm_study.rerun_problems(earlier, "wave1", "105S", "0") == [
        "run 2 scheduled 1 simulate jobs in run set training, which run 1 had finished"]
