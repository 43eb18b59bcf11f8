#!/usr/bin/env bash
# `make test-slurm`: the quick study through workflow/profiles/slurm on a throwaway single-node SLURM
# (Debian slurm-wlm + munge, no accounting; installed with apt-get when missing, which needs root).
# Starts munged, slurmctld and slurmd in a temporary directory, runs tests/slurm/slurm_study.py
# (local reference run, SLURM run with two scancels, rerun, table comparison, per-job overhead) and
# always stops the daemons by pid and removes the directory (KEEP=1 keeps it for inspection).
# Cost: see the README ("What each command costs"); not run by CI (see docs/workflow.md).
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
start=$(date +%s)

tests/slurm/cluster.sh install
"$PY" -c "import snakemake_executor_plugin_slurm" 2>/dev/null || "$PY" -m pip install --quiet -c constraints.txt -e '.[slurm]'

WORK=$(mktemp -d /tmp/shockcal-slurm.XXXXXX)
cleanup() {
    local rc=$?
    tests/slurm/cluster.sh stop "$WORK/cluster" || true
    if [ "${KEEP:-0}" = 1 ] || [ "$rc" != 0 ]; then echo "kept $WORK (logs)"; else rm -rf "$WORK"; fi
    echo "make test-slurm: $(( $(date +%s) - start )) s wall, exit $rc, load $(cut -d' ' -f1-3 /proc/loadavg)"
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

eval "$(tests/slurm/cluster.sh start "$WORK/cluster")"   # exports SLURM_CONF
sinfo
# in the background, so that INT/TERM reach the trap at once; the script stops its snakemake itself
"$PY" tests/slurm/slurm_study.py --work "$WORK" "$@" &
child=$!
trap 'kill -TERM "$child" 2>/dev/null; wait "$child"; exit 130' INT TERM
wait "$child"
