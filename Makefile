# shockcal: `make study` runs the paper's study, `make test` the tests. Both create .venv first.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
INSTALLED := $(VENV)/.installed
CORES ?= all
export PATH := $(CURDIR)/$(VENV)/bin:$(PATH)

.PHONY: study quick check test test-slow test-slurm bench validate lint clean

$(INSTALLED): pyproject.toml
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $@

study: $(INSTALLED)  ## the paper's study (config/config.yaml): every figure and the HTML report
	snakemake --cores $(CORES) all
	snakemake --report results/report.html all
	shockcal stage-times --benchmarks results/benchmarks
	@echo "report: $(CURDIR)/results/report.html"

quick: $(INSTALLED)  ## the toy-size study (config/quick.yaml) into results/quick
	snakemake --cores $(CORES) --configfile config/quick.yaml all

check: $(INSTALLED)  ## synthetic-truth coverage checks of the default study (calibration.check.trials per check)
	snakemake --cores $(CORES) check

test: $(INSTALLED)  ## fast tests (slow ones are behind the `slow` marker)
	$(VENV)/bin/pytest

test-slow: $(INSTALLED)  ## the slow checks only
	$(VENV)/bin/pytest -m slow

test-slurm: $(INSTALLED)  ## the quick study on a throwaway single-node SLURM (root: installs slurm-wlm, munge)
	tests/slurm/run_slurm_test.sh

bench: $(INSTALLED)  ## speed and memory figures (printed, never asserted); installs the reference samplers
	$(PY) -m pip install --quiet -e '.[test,bench]'
	@for b in benchmarks/bench_*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

validate: $(INSTALLED)  ## our hydrocode + extractor against the paper's FLAG features and measured features
	$(PY) benchmarks/validate_flag.py

lint: $(INSTALLED)  ## ruff on the package, tests and benchmarks; snakefmt and snakemake's own lint on the rules
	$(PY) -m pip install --quiet -e '.[test,lint]'
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/snakefmt --check Snakefile workflow/
	snakemake --lint

clean:
	rm -rf results .snakemake
