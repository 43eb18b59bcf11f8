# shockcal workflow: a calibration study of the config's material and shots (with no --configfile, the paper's:
# config/config.yaml).
# Kept cheap at the top level (on a cluster every job re-reads it): load + validate the config,
# then include one rule file per stage. Each stage appends its finished products to ALL_TARGETS.
import re

from shockcal.study.validate import workflow_config_or_exit

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


RESULTS = config["study"]["results_dir"]
SHOTS = list(config["shots"])
CANDIDATES = list(config["next_shot"]["candidates"])  # next-shot candidates: the run set next_shot's "shots"
ALL_TARGETS = []


wildcard_constraints:
    shot="|".join(re.escape(name) for name in [*SHOTS, *CANDIDATES]),
    chunk=r"\d+",


include: "workflow/rules/common.smk"
include: "workflow/rules/design.smk"
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
        rules.next_shot_check_summary.output if CHECK_PLANS else [],
