# Helpers shared by every rule file (the effective config, chunking, config slices, run-set paths).
import hashlib
import os
import sys

import yaml

from shockcal.design.tables import chunk_fingerprints, write_design
from shockcal.errors import ShockcalError
from shockcal.study.adapters import (
    base_study_config,
    input_box,
    new_posterior_shots,
    new_shot_config,
    shot_mapping,
    study_design,
)
from shockcal.study.candidate_studies import plan_check
from shockcal.study.config import run_cost_mm_us, wave_sizes
from shockcal.study.simulator import simulator_kind
from shockcal.study.stages import figure_config, stage_config
from shockcal.study.workflow import (
    chunk_count,
    chunk_rows,
    export_to_jobs,
    point_stable_name,
    write_if_changed,
)

# The merged config (configfile + --configfile + --config) that every shockcal call reads, named by
# its content so a dry run with other settings never rewrites the file running jobs read. Jobs get
# it through $SHOCKCAL_CONFIG (the default of every `shockcal --config`); it is not a rule input or
# param: reruns follow each rule's params slice, never this file's name or mtime. A rule's `settings`
# param is `stage_config(config, STAGE)`: the keys shockcal.study.stages declares its stage reads, the same
# slice the `shockcal` command hands the stage's code, so the two channels cannot drift apart.
_EFFECTIVE_TEXT = yaml.safe_dump(config, sort_keys=True)
EFFECTIVE_CONFIG = f"{RESULTS}/config/effective-{hashlib.sha256(_EFFECTIVE_TEXT.encode()).hexdigest()[:12]}.yaml"
write_if_changed(EFFECTIVE_CONFIG, _EFFECTIVE_TEXT)
export_to_jobs(EFFECTIVE_CONFIG)


# {RESULTS}/config/effective.yaml: a symlink to the merged config of the last run that started jobs (not a
# dry run's), the stable path to reuse the study's settings with `shockcal --config`; jobs never read it
onstart:
    point_stable_name(EFFECTIVE_CONFIG)


CHUNK_SIZE = config["simulate"]["chunk_size"]

# New shots (design.new_shots.runs_from: posterior; docs/workflow.md, "Adding a shot"): each runs design.new_shots.n_runs
# rows of its own (the run set new_shot), placed by the base shots' emulator and joint posterior (waves.smk's last
# step). The base jobs' params are the study without the new shots (BASE_STUDY), and their commands read only the
# base shots, so adding a shot reruns none of them and no base shot's runs; the base observed features are made
# under that study's config (BASE_CONFIG_OPTION).
NEW_SHOTS = new_posterior_shots(config)
BASE_SHOTS = [shot for shot in SHOTS if shot not in NEW_SHOTS]
BASE_STUDY = base_study_config(config) if NEW_SHOTS else config
if NEW_SHOTS:
    _BASE_TEXT = yaml.safe_dump(BASE_STUDY, sort_keys=True)
    _BASE_CONFIG = f"{RESULTS}/config/base-{hashlib.sha256(_BASE_TEXT.encode()).hexdigest()[:12]}.yaml"
    write_if_changed(_BASE_CONFIG, _BASE_TEXT)
BASE_CONFIG_OPTION = f"--config {_BASE_CONFIG}" if NEW_SHOTS else ""


def training_run_set(shot):
    """The run set a shot's emulator is fitted on: its own (new_shot) for a new shot, else the training runs."""
    return "new_shot" if shot in NEW_SHOTS else "training"


# an archive study (simulator.kind archive, docs/simulators.md) has its training runs and no code to run
# others: the posterior's predictive runs (the run set predict) and what reads them are left out of `all`
ARCHIVE_STUDY = simulator_kind(config) == "archive"

LOGS = f"{RESULTS}/logs"
BENCHMARKS = f"{RESULTS}/benchmarks"


# Run sets (design.smk): their paths and the rules' inputs built from them.
def run_set_path(run_set, *parts):
    """A run set's file or directory: {RESULTS}/{run_set}/{parts...}."""
    return "/".join([RESULTS, run_set, *parts])


def run_set_design(wildcards):
    """The design a run set's chunks read: the training design is planned at parse time (ancient); a
    next-shot candidate has its own (next_shot.smk), and so has a compared candidate of the next-shot check
    (its derived study's training design, planned at parse time; its truths, next_shot_check.smk)."""
    if wildcards.run_set == "training":
        return ancient(DESIGN)
    if wildcards.run_set in ("next_shot", "new_shot"):
        return run_set_path(wildcards.run_set, "designs", f"{wildcards.shot}.parquet")
    if wildcards.run_set == "next_shot_check":
        return ancient(CHECK_PLANS[wildcards.shot]["design"])
    if wildcards.run_set == "next_shot_truth" and wildcards.shot not in SHOTS:
        return run_set_path("next_shot_truth", "designs", f"{wildcards.shot}.parquet")
    return run_set_path(wildcards.run_set, "design.parquet")


# a shot's stage -> the same stage for a next-shot candidate (the run set next_shot, whose "shots" are candidates;
# `shockcal simulate/features --shot` take a candidate's name too)
CANDIDATE_STAGES = {
    "simulate": "next_shot_simulate",
    "features": "next_shot_features",
    "failure_budget": "next_shot_features",
}


def run_set_settings(stage):
    """The rule param of `stage`'s config slice for the job's shot, or its candidate's stage for a next-shot
    candidate (the run sets next_shot, next_shot_check and next_shot_truth)."""
    return lambda w: stage_config(config, stage if w.shot in SHOTS else CANDIDATE_STAGES[stage], w.shot)


def allow_empty(wildcards):
    """`--allow-empty` for a sequential study's later wave (a stopped wave has no runs), else nothing."""
    return "--allow-empty" if wildcards.run_set in WAVES else ""


# A run set's simulate chunks start longest first (their hydrocode cost: rows x `run_cost_mm_us`): a wave has a
# chunk or two per shot, and with 2 cores the slowest shot's chunk starting last left a core idle for a minute
# (docs/workflow.md, "Job order"). Priority SIMULATE_PRIORITY (the fan-out before the jobs that only read the
# records or the design: figures, observed) up to + PRIORITY_STEPS for the run set's longest chunk, below the
# joint calibration (10); a next-shot candidate's chunks at the base.
SIMULATE_PRIORITY, PRIORITY_STEPS = 5, 4


def simulate_priority(wildcards):
    if wildcards.shot not in SHOTS:
        return SIMULATE_PRIORITY
    size = RUN_SET_SIZES[wildcards.run_set]
    chunk_size = RUN_SET_CHUNK_SIZE[wildcards.run_set]
    rows = min(chunk_size, size - int(wildcards.chunk) * chunk_size)
    longest = min(chunk_size, size) * max(run_cost_mm_us(config, shot, wildcards.run_set) for shot in SHOTS)
    cost = rows * run_cost_mm_us(config, wildcards.shot, wildcards.run_set)
    return SIMULATE_PRIORITY + round(PRIORITY_STEPS * cost / longest)


def simulations(run_set, shot):
    """Every simulation chunk of one run set's shot."""
    return expand(rules.simulate.output[0], run_set=run_set, shot=shot, chunk=RUN_SET_CHUNKS[run_set])


# The next-shot check (next_shot_check.smk): a model is "baseline" (the three shots) or a compared candidate
# (design.smk's CHECK_PLANS: the four).
def check_model_config(model):
    """`--config` of a check job: the derived study's for a candidate, none (the study's) for the baseline."""
    return f"--config {CHECK_PLANS[model]['config']}" if model in CHECK_PLANS else ""


def check_model_shots(model):
    """The shots a check model calibrates: the study's, and the candidate as the fourth."""
    return [*SHOTS, *([model] if model in CHECK_PLANS else [])]


def check_model_settings(stage):
    """The rule param of `stage`'s config slice in the model's study."""
    return lambda w: stage_config(CHECK_PLANS[w.model]["study"] if w.model in CHECK_PLANS else config, stage)


# A sequential study's waves (waves.smk): wave 0 is the training run set, step k every run of waves 0..k.
def step_path(step, *parts):
    """A step's file or directory: {RESULTS}/waves/step{step}/{parts...}."""
    return run_set_path("waves", f"step{step}", *parts)


def wave_design_path(wave):
    """Wave `wave`'s design, as an input: the training design for wave 0, `ancient` as the training chunks
    read it (run_set_design). It is rewritten when the workflow is read, also when a new shot adds its input
    column, which changes no base shot's runs; a change to the base shots' rows reruns their chunks, and so
    everything that reads their features."""
    return ancient(DESIGN) if int(wave) == 0 else run_set_path(f"wave{wave}", "design.parquet")


def step_features(step):
    """The features of every base shot of waves 0..`step`, wave after wave."""
    return [
        rules.features.output[0].format(run_set=run_set, shot=shot)
        for run_set in WAVE_RUN_SETS[: int(step) + 1]
        for shot in BASE_SHOTS
    ]


def pairs(shots, paths):
    """SHOT=FILE arguments of the `shockcal` commands, shot after shot."""
    return " ".join(f"{shot}={path}" for shot, path in zip(shots, paths))


def wave_design_inputs(wildcards):
    """Wave k's design reads step k-1's posterior, runs and (max_variance) emulator, wave k-1's design
    (empty: the study stopped) and step k-2's posterior summary (the stopping rule). Not `ancient`: a
    change upstream (the extractor, the emulator or sampler settings) moves the posterior and so
    re-places the later waves, as a fresh study with that config would (docs/sequential.md)."""
    k = int(wildcards.wave)
    inputs = {
        "posterior": rules.wave_calibrate.output.samples.format(step=k - 1),
        "summary": rules.wave_calibrate.output.summary.format(step=k - 1),
        "previous": wave_design_path(k - 1),
        "runs": rules.merge_runs.output.design.format(step=k - 1),
        "emulator": rules.wave_emulator.output.emulator.format(step=k - 1),
        "observed": rules.observed_base.output[0],
    }
    if k >= 2:
        inputs["earlier"] = rules.wave_calibrate.output.summary.format(step=k - 2)
    return inputs


def record_paths(study):
    """The measured records a study's observed features read (none with published features)."""
    records = study["observed"]["records"].values() if study["observed"]["source"] == "records" else []
    return [spec["path"] for spec in records]


def study_features(shot):
    """The features a shot's part of the study's emulator is fitted on: the last step's (every wave's) or the
    training runs' for a base shot, its own runs' for a new shot."""
    if shot in NEW_SHOTS:
        return rules.features.output[0].format(run_set="new_shot", shot=shot)
    if WAVES:
        return step_path(LAST_STEP, "features", f"{shot}.parquet")
    return rules.features.output[0].format(run_set="training", shot=shot)
