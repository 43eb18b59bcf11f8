# shockcal: `make help` lists the targets (also what a bare `make` does); `make env` creates .venv and installs, as every target that runs shockcal does first.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
INSTALLED := $(VENV)/.installed
CORES ?= all
# constraints.txt pins the environment the documented study ran with (Python 3.11); another Python
# installs from pyproject.toml's ranges instead, with a warning
LOCKED_PYTHON := 3.11
CONSTRAINTS = $$($(PY) -c 'import sys; v = "%d.%d" % sys.version_info[:2]; ok = v == "$(LOCKED_PYTHON)"; ok or print(f"warning: Python {v}: constraints.txt is for $(LOCKED_PYTHON); installing from pyproject.toml ranges", file=sys.stderr); print("-c constraints.txt" if ok else "")')
export PATH := $(CURDIR)/$(VENV)/bin:$(PATH)

# snakemake's console: one progress line (jobs done and left, the time left) and any error in full, every line
# it would print in RESULTS_DIR/logs/snakemake/<start time>.log (the logger plugin shockcal, docs/workflow.md):
# $(call snakemake,RESULTS_DIR). VERBOSE=1 (`make quick VERBOSE=1`) prints snakemake's own output instead.
VERBOSE ?=
snakemake = snakemake$(if $(filter-out 0,$(VERBOSE)),, --logger shockcal --logger-shockcal-log-dir $(1)/logs/snakemake)

# $(call study,RESULTS_DIR,SNAKEMAKE_ARGS): a whole study, its HTML report and its time per stage
# (RESULTS_DIR/stage_times.txt), then where they are
define study
	$(call snakemake,$(1)) --cores $(CORES) $(2)
	$(call snakemake,$(1)) --report $(1)/report.html $(2)
	shockcal stage-times --benchmarks $(1)/benchmarks > $(1)/stage_times.txt
	@echo "results: $(CURDIR)/$(1)/ (time per stage: stage_times.txt; settings: config/effective.yaml)"
	@echo "report:  $(CURDIR)/$(1)/report.html"
endef

.DEFAULT_GOAL := help
.PHONY: help env study paper quick flag-archive models models-paper models-reduced models-quick check verify next-shot next-shot-check test test-workflow test-slow test-slurm bench validate lint lock clean

help:  ## these targets, one line each
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | sed -E 's/^([a-z-]+):.*## /\1\t/' | expand -t 18

env: $(INSTALLED)  ## the environment only: creates .venv and installs shockcal with its test tools, nothing else

$(INSTALLED): pyproject.toml constraints.txt
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet $(CONSTRAINTS) -e '.[test]'
	touch $@

# The study that study, check, next-shot and next-shot-check run: STUDY=sequential (the default; runs in waves
# placed where the joint posterior lives, config/sequential.yaml over config/config.yaml; docs/sequential.md)
# into results/sequential, or STUDY=paper (the paper's 1000 Latin-hypercube runs per shot, config/config.yaml)
# into results
STUDY ?= sequential
$(if $(filter sequential paper,$(STUDY)),,$(error STUDY=$(STUDY): sequential (the default) or paper))
# CONFIG=FILE: a study of one's own instead (`shockcal init`, docs/your_material.md), into its study.results_dir
CONFIG ?=
STUDY_DIR = $(if $(CONFIG),$(shell $(PY) -c 'from shockcal.study.validate import load_config; print(load_config("$(CONFIG)")["study"]["results_dir"])'),$(if $(filter paper,$(STUDY)),results,results/sequential))
STUDY_CONFIG = $(if $(CONFIG),--configfile $(CONFIG),$(if $(filter paper,$(STUDY)),,--configfile config/sequential.yaml))

study: $(INSTALLED)  ## the default study, in waves (999 hydrocode runs; STUDY=paper: the paper's design; CONFIG=FILE: your own): every figure and the HTML report into results/sequential
	$(call study,$(STUDY_DIR),all $(STUDY_CONFIG))

paper: $(INSTALLED)  ## the paper's study (config/config.yaml: 1000 Latin-hypercube runs per shot, 3,300 in all): every figure and the HTML report into results
	$(MAKE) --no-print-directory study STUDY=paper

quick: $(INSTALLED)  ## the toy-size study (config/quick.yaml) and its HTML report into results/quick
	$(call study,results/quick,all --configfile config/quick.yaml)

flag-archive: $(INSTALLED)  ## the paper's FLAG runs (the data release's design and features) through the workflow, no hydrocode, and its HTML report into results/flag-archive
	$(call study,results/flag-archive,all --configfile config/flag-archive.yaml)

# the strength laws compared by `make models` (docs/models.md): one study each, to its joint posterior and its
# posterior predictive runs (the run set predict, through posterior/joint.nc); MODELS_CONFIG: the config files
# in order, the paper's config/config.yaml first (compare-models and model-predictions read the shots and records from it)
# The laws' studies run side by side, MODEL_JOBS at a time, each snakemake with --cores MODEL_CORES, the costliest
# first (MODEL_ORDER). By default the machine's cores (CORES, or nproc's count for `all`) are split between up to
# four laws (no more than MODELS has): on 2 cores two laws at a time, one job each, so every core runs one job from
# start to end (no core idles while a law calibrates, none runs two jobs); on 8 cores four laws with 2 cores each.
# Each line of a study's console starts with its law. MODEL_JOBS=1 runs them one after another.
MODELS ?= johnson-cook steinberg-guinan ptw zerilli-armstrong
MODELS_CONFIG ?= config/config.yaml config/sequential.yaml
MODELS_DIR ?= results/models
MACHINE_CORES := $(if $(filter all,$(CORES)),$(shell nproc 2>/dev/null || getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1),$(CORES))
MODEL_JOBS ?= $(shell n=$(MACHINE_CORES); l=$(words $(MODELS)); n=$$(( n < l ? n : l )); echo $$(( n < 4 ? n : 4 )))
MODEL_CORES ?= $(shell echo $$(( $(MACHINE_CORES) / $(MODEL_JOBS) > 1 ? $(MACHINE_CORES) / $(MODEL_JOBS) : 1 )))
MODEL_ORDER := ptw steinberg-guinan johnson-cook zerilli-armstrong

models: $(INSTALLED)  ## every law's study in waves (strength.model; config/sequential.yaml) into results/models/<law>, then evidence.csv, release.csv and figures/
	$(MAKE) --no-print-directory -j $(MODEL_JOBS) \
	  $(addprefix model-study-,$(filter $(MODELS),$(MODEL_ORDER)) $(filter-out $(MODEL_ORDER),$(MODELS)))
	shockcal compare-models $(foreach m,$(MODELS),--model $(m)=$(MODELS_DIR)/$(m)) --out $(MODELS_DIR)/evidence.csv \
	  --figures-dir $(MODELS_DIR)/figures
	shockcal model-predictions --config $(firstword $(MODELS_CONFIG)) $(foreach m,$(MODELS),--model $(m)=$(MODELS_DIR)/$(m)) \
	  --out $(MODELS_DIR)/release.csv --figures-dir $(MODELS_DIR)/figures
	@echo "results: $(CURDIR)/$(MODELS_DIR)/ (one study per law: $(MODELS))"
	@echo "tables:  $(CURDIR)/$(MODELS_DIR)/evidence.csv and release.csv; figures: $(CURDIR)/$(MODELS_DIR)/figures/"

model-study-%: $(INSTALLED)
	set -o pipefail; $(call snakemake,$(MODELS_DIR)/$*) --cores $(MODEL_CORES) --configfile $(MODELS_CONFIG) \
	  --config "strength={model: $*}" "study={results_dir: $(MODELS_DIR)/$*}" -- $(MODELS_DIR)/$*/posterior/joint.nc \
	  $(MODELS_DIR)/$*/report/emulator_heldout.csv 2>&1 | sed -u 's/^/[$*] /'

models-paper: $(INSTALLED)  ## the same on the paper's design (1000 training and 100 predictive runs per shot) into results/models-paper
	$(MAKE) models MODELS_CONFIG=config/config.yaml MODELS_DIR=$(if $(filter command line,$(origin MODELS_DIR)),$(MODELS_DIR),results/models-paper)

models-reduced: $(INSTALLED)  ## the paper's design at 150 training and 30 predictive runs per shot (config/models-reduced.yaml) into results/models-reduced
	$(MAKE) models MODELS_CONFIG="config/config.yaml config/models-reduced.yaml" MODELS_DIR=$(if $(filter command line,$(origin MODELS_DIR)),$(MODELS_DIR),results/models-reduced)

models-quick: $(INSTALLED)  ## the paper's design at toy size (config/quick.yaml) into results/models-quick
	$(MAKE) models MODELS_CONFIG="config/config.yaml config/quick.yaml" MODELS_DIR=results/models-quick

check: $(INSTALLED)  ## synthetic-truth coverage checks of the study (calibration.check.trials per check; STUDY=paper: the paper's)
	$(call snakemake,$(STUDY_DIR)) --cores $(CORES) check $(STUDY_CONFIG)
	@echo "results: $(CURDIR)/$(STUDY_DIR)/posterior/coverage_emulator.parquet, coverage_hydrocode.parquet and coverage_posterior.parquet"
	@echo "report:  their table joins $(CURDIR)/$(STUDY_DIR)/report.html at the next make study$(if $(filter paper,$(STUDY)), STUDY=paper)"

verify: $(INSTALLED)  ## the hydrocode's verdict on the joint posterior: verify.n_draws draws run, PSIS k-hat, corrected quantiles, the emulator's error there (STUDY=paper: the paper's)
	$(call snakemake,$(STUDY_DIR)) --cores $(CORES) verify $(STUDY_CONFIG)
	@echo "results: $(CURDIR)/$(STUDY_DIR)/verify/summary.csv and emulator_error.csv (the verdict: $(STUDY_DIR)/logs/verify/summary.log)"

next-shot: $(INSTALLED)  ## which shot next: rank next_shot.candidates by expected information gain (STUDY=paper: on the paper's study)
	$(call snakemake,$(STUDY_DIR)) --cores $(CORES) next_shot $(STUDY_CONFIG)
	@echo "results: $(CURDIR)/$(STUDY_DIR)/next_shot/ranking.csv"
	@echo "figure:  $(CURDIR)/$(STUDY_DIR)/figures/next_shot.png"

next-shot-check: $(INSTALLED)  ## the realized check of the next-shot ranking: its best and worst candidates on truths from the posterior (STUDY=paper: the paper's)
	$(call snakemake,$(STUDY_DIR)) --cores $(CORES) next_shot_check $(STUDY_CONFIG)
	@echo "results: $(CURDIR)/$(STUDY_DIR)/next_shot/check_summary.csv (per trial: check.csv)"

# TEST_WORKERS: pytest-xdist workers for make test (auto: one per core), each taking a whole test file at a time
TEST_WORKERS ?= auto
test: $(INSTALLED)  ## fast tests on TEST_WORKERS workers: all but the `slow` and `workflow` markers (CI: make lint test test-workflow)
	$(VENV)/bin/pytest -m "not slow and not workflow" -n $(TEST_WORKERS) --dist loadfile

test-workflow: $(INSTALLED)  ## the tests that read the quick study, which they run end to end by snakemake first (the `workflow` marker)
	$(VENV)/bin/pytest -m "workflow and not slow"

test-slow: $(INSTALLED)  ## the slow checks only
	$(VENV)/bin/pytest -m slow

# SLURM_OVERLAY: config files over config/quick.yaml for test-slurm's runs, e.g. the example external code:
# make test-slurm SLURM_OVERLAY=examples/external_hydro/quick-command.yaml
SLURM_OVERLAY ?=
test-slurm: $(INSTALLED)  ## the quick study on a throwaway single-node SLURM (root: installs slurm-wlm, munge); SLURM_OVERLAY=config for another run source
	tests/slurm/run_slurm_test.sh $(foreach f,$(SLURM_OVERLAY),--overlay $(f))

bench: $(INSTALLED)  ## speed and memory figures (printed, never asserted); installs the reference samplers
	$(PY) -m pip install --quiet $(CONSTRAINTS) -e '.[test,bench]'
	$(PY) benchmarks/run_all.py
	@echo "results: printed above (never written); the cached reference runs: $(CURDIR)/benchmarks/out/reference/"

validate: $(INSTALLED)  ## our hydrocode + extractor against the paper's FLAG features and measured features
	$(PY) benchmarks/validate_flag.py
	@echo "results: printed above; our features: $(CURDIR)/benchmarks/out/validate_flag_features.parquet"

lint: $(INSTALLED)  ## ruff on the package, tests and benchmarks; snakefmt and snakemake's own lint on the rules
	$(PY) -m pip install --quiet $(CONSTRAINTS) -e '.[test,lint]'
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/snakefmt --check Snakefile workflow/
	snakemake --lint

lock:  ## refresh constraints.txt: the newest releases pyproject.toml allows, resolved in a throwaway venv
	rm -rf .lock-venv && python3 -m venv .lock-venv
	.lock-venv/bin/pip install --quiet -e '.[test,lint,bench]'
	{ sed -n '/^#/p' constraints.txt; .lock-venv/bin/pip freeze --exclude-editable | grep -v -i '^shockcal'; } > constraints.new
	mv constraints.new constraints.txt && rm -rf .lock-venv

clean:  ## removes results/ and .snakemake/ (the .venv stays)
	rm -rf results .snakemake
