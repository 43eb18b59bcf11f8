# shockcal: `make study` runs the paper's study, `make test` the tests. Both create .venv first.
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

.PHONY: study sequential quick models models-reduced models-quick check next-shot next-shot-check test test-slow test-slurm bench validate lint lock clean

$(INSTALLED): pyproject.toml constraints.txt
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet $(CONSTRAINTS) -e '.[test]'
	touch $@

study: $(INSTALLED)  ## the paper's study (config/config.yaml): every figure and the HTML report
	snakemake --cores $(CORES) all
	snakemake --report results/report.html all
	shockcal stage-times --benchmarks results/benchmarks
	@echo "report: $(CURDIR)/results/report.html"

sequential: $(INSTALLED)  ## the study in waves placed from the joint posterior (config/sequential.yaml; docs/sequential.md) into results/sequential
	snakemake --cores $(CORES) all --configfile config/sequential.yaml

quick: $(INSTALLED)  ## the toy-size study (config/quick.yaml) into results/quick
	snakemake --cores $(CORES) all --configfile config/quick.yaml

# the strength laws compared by `make models` (docs/models.md): one study each, to its joint posterior and its
# posterior predictive runs (the run set predict, through posterior/joint.nc); MODELS_CONFIG: the config files
# in order, the paper's config/config.yaml first (compare-models and model-predictions read the shots and records from it)
MODELS ?= johnson-cook steinberg-guinan ptw zerilli-armstrong
MODELS_CONFIG ?= config/config.yaml
MODELS_DIR ?= results/models

models: $(INSTALLED)  ## every law's study (strength.model) into results/models/<law>, then evidence.csv, release.csv and figures/
	for model in $(MODELS); do \
	  snakemake --cores $(CORES) --configfile $(MODELS_CONFIG) --config "strength={model: $$model}" \
	    "study={results_dir: $(MODELS_DIR)/$$model}" -- $(MODELS_DIR)/$$model/posterior/joint.nc || exit 1; \
	done
	shockcal compare-models $(foreach m,$(MODELS),--model $(m)=$(MODELS_DIR)/$(m)) --out $(MODELS_DIR)/evidence.csv \
	  --figures-dir $(MODELS_DIR)/figures
	shockcal model-predictions --config $(firstword $(MODELS_CONFIG)) $(foreach m,$(MODELS),--model $(m)=$(MODELS_DIR)/$(m)) \
	  --out $(MODELS_DIR)/release.csv --figures-dir $(MODELS_DIR)/figures

models-reduced: $(INSTALLED)  ## the same at 150 training and 30 predictive runs per shot (config/models-reduced.yaml) into results/models-reduced
	$(MAKE) models MODELS_CONFIG="config/config.yaml config/models-reduced.yaml" MODELS_DIR=$(if $(filter command line,$(origin MODELS_DIR)),$(MODELS_DIR),results/models-reduced)

models-quick: $(INSTALLED)  ## the same at toy size (config/quick.yaml) into results/models-quick
	$(MAKE) models MODELS_CONFIG="config/config.yaml config/quick.yaml" MODELS_DIR=results/models-quick

check: $(INSTALLED)  ## synthetic-truth coverage checks of the default study (calibration.check.trials per check)
	snakemake --cores $(CORES) check

next-shot: $(INSTALLED)  ## which shot next: rank next_shot.candidates by expected information gain
	snakemake --cores $(CORES) next_shot
	@echo "ranking: $(CURDIR)/results/next_shot/ranking.csv"

next-shot-check: $(INSTALLED)  ## the realized check of the next-shot ranking: its best and worst candidates on truths from the posterior
	snakemake --cores $(CORES) next_shot_check
	@echo "check: $(CURDIR)/results/next_shot/check_summary.csv"

test: $(INSTALLED)  ## fast tests (slow ones are behind the `slow` marker)
	$(VENV)/bin/pytest

test-slow: $(INSTALLED)  ## the slow checks only
	$(VENV)/bin/pytest -m slow

test-slurm: $(INSTALLED)  ## the quick study on a throwaway single-node SLURM (root: installs slurm-wlm, munge)
	tests/slurm/run_slurm_test.sh

bench: $(INSTALLED)  ## speed and memory figures (printed, never asserted); installs the reference samplers
	$(PY) -m pip install --quiet $(CONSTRAINTS) -e '.[test,bench]'
	$(PY) benchmarks/run_all.py

validate: $(INSTALLED)  ## our hydrocode + extractor against the paper's FLAG features and measured features
	$(PY) benchmarks/validate_flag.py

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

clean:
	rm -rf results .snakemake
