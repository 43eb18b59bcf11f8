"""The workflow's plan: what the Snakemake rule files need to know before any job runs, as plain functions of
the validated study config, so that it is tested without snakemake (tests/test_workflow_plan.py) and the rule
files only declare rules.

`plan_workflow(config)` reads the config and the training design and returns a `WorkflowPlan`: the run sets
(their sizes, chunk sizes and chunks), the chunks' row digests, the new shots and the base study, a
sequential study's waves and steps, the files every job reads (the content-named effective config). It writes
nothing: `write_planned_files` writes the files the plan names (once, from the Snakefile), and
`plan_next_shot_check` adds the realized check's derived studies, which are written there too (they read the
training design written before).

Paths are strings under the study's results directory (`study.results_dir`); an input whose modification
time the rules do not follow (the training design and a check candidate's design, rewritten when the workflow
is read) is flagged with snakemake's `ancient`.
"""

from __future__ import annotations

import dataclasses
import hashlib
from dataclasses import dataclass, field

import pandas as pd
import yaml
from snakemake.io import ancient

from shockcal.design.tables import chunk_fingerprints, write_design
from shockcal.errors import ShockcalError
from shockcal.study.adapters import base_study_config, input_box, new_posterior_shots, shot_mapping, study_design
from shockcal.study.config import run_cost_mm_us, wave_sizes
from shockcal.study.simulator import simulator_kind
from shockcal.study.stages import stage_config
from shockcal.study.workflow import chunk_count, chunk_rows, write_if_changed

# A new shot's runs (design.new_shots, one shot alone) go in NEW_SHOT_CHUNKS chunks at most simulate.chunk_size
# rows, so that they fill the cores (150 runs in one chunk of the paper study's 150 kept one core idle)
NEW_SHOT_CHUNKS = 4
# A simulate chunk's priority: SIMULATE_PRIORITY (before the jobs that only read the records or the design:
# figures, observed) up to + PRIORITY_STEPS for its run set's longest chunk, below the joint calibration (10)
SIMULATE_PRIORITY, PRIORITY_STEPS = 5, 4
# a shot's stage -> the same stage for a next-shot candidate (`shockcal simulate/features --shot` take its name)
CANDIDATE_STAGES = {"simulate": "next_shot_simulate", "features": "next_shot_features",
                    "failure_budget": "next_shot_features"}
# a sequential study's step files (waves.smk), under {results}/waves/step{k}/
STEP_FILES = {
    "design": "design.parquet",
    "emulator": "emulator/emulator.json",
    "arrays": "emulator/emulator.npz",
    "samples": "posterior/joint.parquet",
    "summary": "posterior/joint_summary.parquet",
    "weighted": "posterior/joint_weighted.parquet",
}


def content_named_path(results: str, prefix: str, text: str) -> str:
    """{results}/config/{prefix}-<the first 12 hex digits of text's sha256>.yaml: a config file named by its
    content, so a dry run with other settings never rewrites the file running jobs read."""
    return f"{results}/config/{prefix}-{hashlib.sha256(text.encode()).hexdigest()[:12]}.yaml"


@dataclass(frozen=True)
class WorkflowPlan:
    """What the rules are planned from (module docstring); built by `plan_workflow`."""

    config: dict
    results: str
    shots: list[str]
    candidates: list[str]  # next_shot.candidates: the run set next_shot's "shots"
    new_shots: list[str]  # design.new_shots, from the base shots' posterior (docs/workflow.md, "How to add a shot")
    base_shots: list[str]
    base_study: dict  # the study without its new shots (the config itself when there are none)
    effective_text: str  # the merged config every job reads ($SHOCKCAL_CONFIG)
    base_text: str | None  # the base study's config, with new shots only
    design: pd.DataFrame  # the training design, planned when the workflow is read
    design_source: str  # where the design came from (a hypercube, the design file), kept in its metadata
    archive: bool  # simulator.kind archive: no code to run predictive runs
    chunk_size: int
    chunk_digests: dict[str, list[str]]  # shot -> a digest per training chunk
    run_set_sizes: dict[str, int]  # run set -> runs per shot (the rules' run_set wildcard, in this order)
    run_set_chunk_size: dict[str, int]
    run_set_chunks: dict[str, list[int]]
    waves: list[str]  # wave1, wave2, ... of a sequential study (none with design.strategy: lhs)
    check_plans: dict[str, dict] = field(default_factory=dict)  # the next-shot check's derived studies
    check_digests: dict[str, list[str]] = field(default_factory=dict)

    @property
    def effective_config(self) -> str:
        """The merged config's content-named path (`content_named_path`, prefix effective)."""
        return content_named_path(self.results, "effective", self.effective_text)

    @property
    def base_config_option(self) -> str:
        """`--config <the base study's config file>` with new shots, else nothing (the study's own)."""
        return f"--config {content_named_path(self.results, 'base', self.base_text)}" if self.new_shots else ""

    @property
    def design_path(self) -> str:
        """The training design's file."""
        return self.run_set_path("training", "design.parquet")

    @property
    def wave_run_sets(self) -> list[str]:
        """The waves' run sets: wave 0 is the training run set."""
        return ["training", *self.waves]

    @property
    def last_step(self) -> int:
        """The last step of a sequential study (every wave; 0 without waves)."""
        return len(self.waves)

    def run_set_path(self, run_set: str, *parts: str) -> str:
        """A run set's file or directory: {results}/{run_set}/{parts...}."""
        return "/".join([self.results, run_set, *parts])

    def features_path(self, run_set: str, shot: str) -> str:
        """A run set's merged features of one shot (the rule `features`' output)."""
        return self.run_set_path(run_set, "features", f"{shot}.parquet")

    def step_path(self, step, *parts: str) -> str:
        """A step's file or directory: {results}/waves/step{step}/{parts...}."""
        return self.run_set_path("waves", f"step{step}", *parts)

    def step_file(self, step, name: str) -> str:
        """A step's file `name` of STEP_FILES (its design, emulator, joint posterior...)."""
        return self.step_path(step, STEP_FILES[name])

    @property
    def observed_base_path(self) -> str:
        """The base shots' observed features (the rule `observed_base`'s output)."""
        return f"{self.results}/features/observed_base.parquet"

    def training_run_set(self, shot: str) -> str:
        """The run set a shot's emulator is fitted on: its own (new_shot) for a new shot, else the training runs."""
        return "new_shot" if shot in self.new_shots else "training"

    def design_input(self, run_set: str, shot: str) -> str:
        """The design a run set's chunks of `shot` read: the training design and a compared check candidate's
        are planned when the workflow is read (`ancient`); a next-shot candidate, a new shot and a check
        candidate's truths have their own per shot; the other run sets one design made by a job."""
        if run_set == "training":
            return ancient(self.design_path)
        if run_set in ("next_shot", "new_shot"):
            return self.run_set_path(run_set, "designs", f"{shot}.parquet")
        if run_set == "next_shot_check":
            return ancient(self.check_plans[shot]["design"])
        if run_set == "next_shot_truth" and shot not in self.shots:
            return self.run_set_path("next_shot_truth", "designs", f"{shot}.parquet")
        return self.run_set_path(run_set, "design.parquet")

    def chunk_rows(self, run_set: str, chunk) -> str:
        """`shockcal simulate --rows` of one chunk: START:STOP of the run set's design (a check candidate's
        cut at next_shot.check.n_training_runs, its design being longer)."""
        total = self.run_set_sizes[run_set] if run_set == "next_shot_check" else None
        return chunk_rows(chunk, self.run_set_chunk_size[run_set], total)

    def rows_digest(self, run_set: str, shot: str, chunk) -> str:
        """The digest of a chunk's rows (run ids and the columns its shot reads) for the run sets whose design
        is planned when the workflow is read (training, next_shot_check); "" for the others."""
        if run_set == "training":
            return self.chunk_digests[shot][int(chunk)]
        return self.check_digests[shot][int(chunk)] if run_set == "next_shot_check" else ""

    def simulate_priority(self, run_set: str, shot: str, chunk) -> int:
        """A simulate chunk's priority: its hydrocode cost (rows x `run_cost_mm_us`) against the run set's
        longest chunk, scaled to SIMULATE_PRIORITY..+PRIORITY_STEPS, so the longest start first (docs/workflow.md,
        "Job order"); a next-shot candidate's chunks at SIMULATE_PRIORITY."""
        if shot not in self.shots:
            return SIMULATE_PRIORITY
        size, chunk_size = self.run_set_sizes[run_set], self.run_set_chunk_size[run_set]
        rows = min(chunk_size, size - int(chunk) * chunk_size)
        longest = min(chunk_size, size) * max(run_cost_mm_us(self.config, name, run_set) for name in self.shots)
        cost = rows * run_cost_mm_us(self.config, shot, run_set)
        return SIMULATE_PRIORITY + round(PRIORITY_STEPS * cost / longest)

    def stage_settings(self, stage: str, shot: str) -> dict:
        """A run-set rule's `settings` param: `stage`'s config slice for `shot`, or for a shot that is not the
        study's (a next-shot candidate, a check candidate) its candidate stage's (CANDIDATE_STAGES)."""
        return stage_config(self.config, stage if shot in self.shots else CANDIDATE_STAGES[stage], shot)

    def allow_empty(self, run_set: str) -> str:
        """`--allow-empty` for a sequential study's later wave (a stopped wave has no runs), else nothing."""
        return "--allow-empty" if run_set in self.waves else ""

    def wave_design_path(self, wave) -> str:
        """Wave `wave`'s design, as an input: the training design for wave 0 (`ancient`, as the training chunks
        read it), else the wave's own, made by a job."""
        return ancient(self.design_path) if int(wave) == 0 else self.run_set_path(f"wave{wave}", "design.parquet")

    def step_features(self, step) -> list[str]:
        """The features of every base shot of waves 0..`step`, wave after wave."""
        return [self.features_path(run_set, shot) for run_set in self.wave_run_sets[: int(step) + 1]
                for shot in self.base_shots]

    def wave_design_inputs(self, wave) -> dict[str, str]:
        """Wave k's design reads step k-1's posterior, runs and emulator, wave k-1's design (empty: the study
        stopped), the base shots' observed features and, from k = 2, step k-2's posterior summary (the stopping
        rule). Not `ancient` (but wave 0's design): a change upstream re-places the later waves."""
        k = int(wave)
        inputs = {
            "posterior": self.step_file(k - 1, "samples"),
            "summary": self.step_file(k - 1, "summary"),
            "previous": self.wave_design_path(k - 1),
            "runs": self.step_file(k - 1, "design"),
            "emulator": self.step_file(k - 1, "emulator"),
            "observed": self.observed_base_path,
        }
        if k >= 2:
            inputs["earlier"] = self.step_file(k - 2, "summary")
        return inputs

    def study_features(self, shot: str) -> str:
        """The features a shot's part of the study's emulator is fitted on: the last step's (every wave's) or
        the training runs' for a base shot, its own runs' for a new shot."""
        if shot in self.new_shots:
            return self.features_path("new_shot", shot)
        return self.step_path(self.last_step, "features", f"{shot}.parquet") if self.waves else \
            self.features_path("training", shot)

    def study_runs(self) -> dict[str, object]:
        """The study emulator's inputs: the design (the last step's with waves), every shot's features and
        each new shot's own design."""
        return {
            "design": self.step_file(self.last_step, "design") if self.waves else self.design_path,
            "features": [self.study_features(shot) for shot in self.shots],
            "shot_designs": [self.run_set_path("new_shot", "designs", f"{shot}.parquet") for shot in self.new_shots],
        }

    def check_models(self) -> list[str]:
        """The next-shot check's models: "baseline" (the study's shots) and each compared candidate."""
        return ["baseline", *self.check_plans]

    def check_model_shots(self, model: str) -> list[str]:
        """The shots a check model calibrates: the study's, and a candidate as one more."""
        return [*self.shots, *([model] if model in self.check_plans else [])]

    def check_model_study(self, model: str) -> dict:
        """The config a check model's jobs read: the candidate's derived study, or the study's for the baseline."""
        return self.check_plans[model]["study"] if model in self.check_plans else self.config

    def check_model_config_option(self, model: str) -> str:
        """`--config` of a check model's jobs: the derived study's file, none (the study's) for the baseline."""
        return f"--config {self.check_plans[model]['config']}" if model in self.check_plans else ""

    def check_emulator_inputs(self, model: str) -> dict[str, object]:
        """A check model's emulator inputs: its training design and features (the study's shots' training
        runs, a candidate's own from the run set next_shot_check)."""
        return {
            "design": self.check_plans[model]["design"] if model in self.check_plans else self.design_path,
            "features": [*(self.features_path("training", shot) for shot in self.shots),
                         *(self.features_path("next_shot_check", shot)
                           for shot in self.check_model_shots(model)[len(self.shots):])],
        }


def pairs(shots, paths) -> str:
    """SHOT=FILE arguments of the `shockcal` commands, shot after shot."""
    return " ".join(f"{shot}={path}" for shot, path in zip(shots, paths))


def record_paths(study: dict) -> list[str]:
    """The measured records a study's observed features read (none with published features)."""
    records = study["observed"]["records"].values() if study["observed"]["source"] == "records" else []
    return [spec["path"] for spec in records]


def run_set_sizes(config: dict, training_runs: int) -> dict[str, int]:
    """Runs per shot of every run set (docs/workflow.md; simulate.smk lists them), in the rules' order."""
    sizes = {
        "training": training_runs,
        "predict": config["predict"]["n_posterior_runs"],
        "check": config["calibration"]["check"]["trials"],
        "check_posterior": config["calibration"]["check"]["trials"],
        "next_shot": config["next_shot"]["n_draws"],
        "verify": config["verify"]["n_draws"],
    }
    waves = wave_sizes(config)
    sizes.update(zip((f"wave{k}" for k in range(1, len(waves))), waves[1:]))
    sizes["next_shot_check"] = config["next_shot"]["check"]["n_training_runs"]
    sizes["next_shot_truth"] = config["next_shot"]["check"]["n_truths"]
    sizes["new_shot"] = config["design"]["new_shots"]["n_runs"]
    return sizes


def plan_workflow(config: dict) -> WorkflowPlan:
    """The plan of the validated study `config` (module docstring); reads the design file when the config
    names one, writes nothing."""
    results, shots = config["study"]["results_dir"], list(config["shots"])
    new_shots = new_posterior_shots(config)
    base_study = base_study_config(config) if new_shots else config
    design, source = study_design(config)
    chunk_size = config["simulate"]["chunk_size"]
    sizes = run_set_sizes(config, len(design))
    chunk_sizes = {name: chunk_size for name in sizes}
    chunk_sizes["new_shot"] = min(chunk_size, chunk_count(sizes["new_shot"], NEW_SHOT_CHUNKS))
    return WorkflowPlan(
        config=config,
        results=results,
        shots=shots,
        candidates=list(config["next_shot"]["candidates"]),
        new_shots=new_shots,
        base_shots=[shot for shot in shots if shot not in new_shots],
        base_study=base_study,
        effective_text=yaml.safe_dump(config, sort_keys=True),
        base_text=yaml.safe_dump(base_study, sort_keys=True) if new_shots else None,
        design=design,
        design_source=source,
        archive=simulator_kind(config) == "archive",
        chunk_size=chunk_size,
        chunk_digests={shot: design_digests(design, config, shot, chunk_size) for shot in shots},
        run_set_sizes=sizes,
        run_set_chunk_size=chunk_sizes,
        run_set_chunks={name: list(range(chunk_count(n, chunk_sizes[name]))) for name, n in sizes.items()},
        waves=[f"wave{k}" for k in range(1, len(wave_sizes(config)))],
    )


def design_digests(design: pd.DataFrame, config: dict, shot: str, chunk_size: int) -> list[str]:
    """A digest per chunk of `design` over its run ids and the columns `shot` reads in `config`: a column added
    for another shot leaves this shot's chunks alone."""
    return chunk_fingerprints(design[["run", *shot_mapping(config, shot).inputs()]], chunk_size)


def write_planned_files(plan: WorkflowPlan) -> None:
    """Write the files the plan names, each only when its content changes (every job re-reads the Snakefile):
    the effective config, the base study's config (with new shots) and the training design."""
    write_if_changed(plan.effective_config, plan.effective_text)
    if plan.new_shots:
        write_if_changed(plan.base_config_option.removeprefix("--config "), plan.base_text)
    write_design(plan.design, plan.design_source, input_box(plan.config), plan.design_path)


def check_requested(arguments: list[str]) -> bool:
    """Whether snakemake's command line (`sys.argv[1:]`) asks for the next-shot check: its rule, or a file of
    its own (snakemake has not read its targets yet when it reads the workflow)."""
    return any("next_shot_check" in word or "next_shot/check" in word for word in arguments)


def plan_next_shot_check(plan: WorkflowPlan, required: bool) -> WorkflowPlan:
    """`plan` with the next-shot check's derived studies (`candidate_studies.plan_check`: their config and
    training design written under the run set next_shot_check) and their chunks' digests. Without a ranking
    yet, or with settings that do not fit the study, there is none, unless `required`: then the
    ShockcalError goes up. Call after `write_planned_files` (the derived designs extend the training design)."""
    from shockcal.study.candidate_studies import plan_check

    plans = plan_check(plan.config, f"{plan.results}/next_shot/ranking.csv", plan.design_path,
                       plan.run_set_path("next_shot_check"), required=required)
    digests = {name: design_digests(study["table"], study["study"], name, plan.chunk_size)
               for name, study in plans.items()}
    return dataclasses.replace(plan, check_plans=plans, check_digests=digests)


def plan_next_shot_check_or_exit(plan: WorkflowPlan, arguments: list[str]) -> WorkflowPlan:
    """`plan_next_shot_check`, required when the command line asks for the check (`check_requested`); an
    error ends snakemake with its one line."""
    try:
        return plan_next_shot_check(plan, check_requested(arguments))
    except ShockcalError as exc:
        raise SystemExit(f"shockcal: error: {exc}") from None


# the figure input kinds an archive study cannot make (hydrocode traces, posterior predictive runs)
RUN_INPUT_KINDS = {"sample_simulations", "simulations", "predicted_simulations", "predicted_features"}


def figure_targets(plan: WorkflowPlan, specs: dict, formats: list[str]) -> tuple[list[str], dict[str, list[str]]]:
    """The figure files of the target `all` (every format of each catalogue figure whose target is all, but
    those an archive study cannot make: RUN_INPUT_KINDS), and the other targets' figure files, by target."""
    def files(name):
        return [f"{plan.results}/figures/{name}.{fmt}" for fmt in formats]

    in_all = [path for name, spec in specs.items() if spec.target == "all"
              and not (plan.archive and any(key.partition(":")[0] in RUN_INPUT_KINDS for key in spec.needs))
              for path in files(name)]
    by_target = {}
    for name, spec in specs.items():
        if spec.target != "all":
            by_target.setdefault(spec.target, []).extend(files(name))
    return in_all, by_target


def existing_coverage(truths: list[str], paths: list[str]) -> dict[str, object]:
    """The coverage tables of `make check` that exist (read by the report, not rule inputs: as inputs they would
    send `all` through the checks again): `pairs`, TRUTH=PATH of each; `modified`, each path's modification time
    (s, None when missing), a param that reruns the report's table when a check is redone."""
    import os

    return {"pairs": " ".join(f"{t}={p}" for t, p in zip(truths, paths) if os.path.exists(p)),
            "modified": [int(os.path.getmtime(p)) if os.path.exists(p) else None for p in paths]}
