# shockcal workflow: a calibration study of the config's material and shots (with no --configfile, the paper's:
# config/config.yaml).
# Kept cheap at the top level (on a cluster every job re-reads it): load + validate the config,
# then include one rule file per stage. Each stage appends its finished products to ALL_TARGETS.
import os
import re
import sys

from shockcal.study.stages import figure_config, stage_config
from shockcal.study.validate import workflow_config_or_exit
from shockcal.study.adapters import new_shot_config
from shockcal.study.workflow import chunk_count, chunk_rows, export_to_jobs, point_stable_name
from shockcal.study.workflow_plan import (
    existing_coverage,
    figure_targets,
    pairs,
    plan_next_shot_check_or_exit,
    plan_workflow,
    record_paths,
    write_planned_files,
)

# The study: the --configfile files given, each a complete config or an overlay naming the config it
# overlays (`extends:`; src/shockcal/study/config_files.py), merged through their chains, snakemake's --config
# on top; with no --configfile, the paper's study below. Then jsonschema against the package's schema
# (src/shockcal/config.schema.yaml; defaults filled in), the cross-field rules and the design file's
# contents; a bad config ends snakemake with its message alone, naming the file that sets the key and the key path:
# "shockcal: error: config/quick.yaml: simulate.chunk_size: 0 is less than the minimum of 1"
DEFAULT_CONFIGFILE = "config/config.yaml"
workflow_config_or_exit(
    config,
    configfiles=list(map(str, workflow.overwrite_configfiles)),
    overrides=workflow.config_settings.config,
    default=DEFAULT_CONFIGFILE,
)


report: "workflow/report/workflow.rst"


# The plan (src/shockcal/study/workflow_plan.py): run sets, chunks and their digests, waves, new shots, the
# next-shot check's derived studies. Its files are written here, once, each only when its content changes: the
# merged config every job reads through $SHOCKCAL_CONFIG (named by its content, so a dry run with other settings
# never rewrites the file running jobs read; not a rule input: reruns follow each rule's `settings` param, the
# stage's slice of shockcal.study.stages), the base study's config, the training design (planned here, not by a
# job: an `ancient` input of every chunk whose producer reruns drops the jobs downstream, snakemake/snakemake#4166),
# then the check's studies (only when a ranking exists; asked for on the command line, the check stops with one line).
PLAN = plan_workflow(config)
write_planned_files(PLAN)
PLAN = plan_next_shot_check_or_exit(PLAN, sys.argv[1:])
export_to_jobs(PLAN.effective_config)


# {RESULTS}/config/effective.yaml: a symlink to the merged config of the last run that started jobs (not a
# dry run's), the stable path to reuse the study's settings with `shockcal --config`; jobs never read it
onstart:
    point_stable_name(PLAN.effective_config)


RESULTS, SHOTS, CANDIDATES = PLAN.results, PLAN.shots, PLAN.candidates
LOGS, BENCHMARKS = f"{RESULTS}/logs", f"{RESULTS}/benchmarks"
ALL_TARGETS = []


wildcard_constraints:
    shot="|".join(re.escape(name) for name in [*SHOTS, *CANDIDATES]),
    chunk=r"\d+",


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/features.smk"
include: "workflow/rules/waves.smk"
include: "workflow/rules/emulator.smk"
include: "workflow/rules/calibrate.smk"
include: "workflow/rules/predict.smk"
include: "workflow/rules/verify.smk"
include: "workflow/rules/sensitivity.smk"
include: "workflow/rules/next_shot.smk"
include: "workflow/rules/next_shot_check.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/report.smk"


rule all:
    default_target: True
    input:
        ALL_TARGETS,


rule next_shot:
    """Which shot next: the candidates' ranking and its figure; `make next-shot`, outside `all`
    (next_shot.n_draws hydrocode runs per candidate, docs/next_shot.md)."""
    input:
        rules.suggest_shot.output,
        TARGET_FIGURES.get("next_shot", []),


rule next_shot_check:
    """The realized check of the ranking: `make next-shot-check`, outside `all` (docs/next_shot.md,
    "The realized check": its cost)."""
    input:
        rules.next_shot_check_summary.output if PLAN.check_plans else [],
