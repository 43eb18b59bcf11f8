#!/usr/bin/env bash
# A throwaway single-node SLURM (Debian slurm-wlm + munge, no accounting) in a directory of its own.
#   tests/slurm/cluster.sh install        install slurm-wlm and munge with apt-get when missing (root)
#   tests/slurm/cluster.sh start DIR      write DIR/slurm.conf + a munge key, start munged, slurmctld and
#                                         slurmd (pids in DIR/*.pid); prints `export SLURM_CONF=...`
#   tests/slurm/cluster.sh stop DIR       stop the three daemons by pid (TERM, then KILL after 10 s)
#   tests/slurm/cluster.sh clean          remove a configuration link a killed run left behind (see below)
# The daemons run as root in the foreground of background jobs; nothing is started through init
# scripts. Everything is written under DIR except one symlink, /run/slurm/conf/slurm.conf -> DIR/slurm.conf
# (removed by `stop`): the job step inside each job runs `srun` with every SLURM_* variable stripped,
# SLURM_CONF included, and that is where Slurm 22.05 clients look after /etc/slurm/slurm.conf.
# Used by tests/slurm/run_slurm_test.sh, which always stops the cluster.
set -euo pipefail

install() {
    local missing=()
    for exe in munged slurmctld slurmd sbatch squeue scontrol; do command -v "$exe" >/dev/null || missing+=("$exe"); done
    [ ${#missing[@]} -eq 0 ] && return 0
    [ "$(id -u)" = 0 ] || { echo "cluster.sh: ${missing[*]} missing and not root: apt-get install slurm-wlm munge" >&2; exit 1; }
    echo "cluster.sh: installing slurm-wlm and munge (missing: ${missing[*]})" >&2
    # keep the packages' init scripts from starting daemons of their own
    local policy=/usr/sbin/policy-rc.d added=0
    if [ ! -e "$policy" ]; then printf '#!/bin/sh\nexit 101\n' > "$policy"; chmod +x "$policy"; added=1; fi
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
    [ "$added" = 1 ] && rm -f "$policy"
    return 0
}

RUN_CONF=/run/slurm/conf/slurm.conf

# A run killed outright (SIGKILL, a machine shut down) leaves RUN_CONF pointing at a cluster whose controller
# is gone. Every Slurm client then waits for it: `scontrol show config` takes 9 s, and snakemake's SLURM plugin
# runs it each time snakemake starts (`make test` went from 6 to 19 min that way). Remove such a link.
remove_stale_link() {
    [ -L "$RUN_CONF" ] || return 0
    local target cluster pid
    target=$(readlink "$RUN_CONF")
    case $target in /tmp/shockcal-slurm.*/cluster/slurm.conf) ;; *) return 0 ;; esac
    cluster=$(dirname "$target")
    pid=$(cat "$cluster/slurmctld.pid" 2>/dev/null || true)
    if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then return 0; fi
    echo "cluster.sh: removing $RUN_CONF -> $target, left by a run that did not stop (no controller runs there)" >&2
    rm -f "$RUN_CONF"
}

free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }

start() {
    local dir=$1
    mkdir -p "$dir"/{state,spool,log}
    chmod 700 "$dir"
    dir=$(cd "$dir" && pwd)
    local node cpus mem port
    node=$(hostname -s)
    cpus=$(nproc)
    mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 9 / 10 ))
    port=$(free_port)
    dd if=/dev/urandom of="$dir/munge.key" bs=1024 count=1 status=none
    chmod 600 "$dir/munge.key"
    cat > "$dir/slurm.conf" <<CONF
# throwaway single-node cluster of tests/slurm (no accounting: sacct has nothing to report)
ClusterName=shockcal-test
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid.conf
SlurmdPidFile=$dir/slurmd.pid.conf
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
# finished jobs stay visible to squeue for 5 min (the Slurm default; snakemake polls at most every 180 s)
MinJobAge=300
SlurmdTimeout=30
InactiveLimit=0
KillWait=5
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=60 State=UP
CONF
    export SLURM_CONF=$dir/slurm.conf
    remove_stale_link
    if [ -e /etc/slurm/slurm.conf ] || { [ -e "$RUN_CONF" ] && [ "$(readlink "$RUN_CONF")" != "$dir/slurm.conf" ]; }; then
        echo "cluster.sh: a Slurm configuration exists already (/etc/slurm/slurm.conf or $RUN_CONF):" \
             "this machine has a Slurm of its own; not starting a throwaway one" >&2
        exit 1
    fi
    mkdir -p "$(dirname "$RUN_CONF")"
    ln -sfn "$dir/slurm.conf" "$RUN_CONF"
    munged -F --force --key-file="$dir/munge.key" --socket="$dir/munge.socket" --pid-file="$dir/munged.pid.own" \
        --log-file="$dir/log/munged.log" --seed-file="$dir/munged.seed" >>"$dir/log/munged.out" 2>&1 &
    echo $! > "$dir/munged.pid"
    for _ in $(seq 50); do [ -S "$dir/munge.socket" ] && break; sleep 0.1; done
    [ -S "$dir/munge.socket" ] || { echo "cluster.sh: munged did not start:" >&2; cat "$dir/log/"munged* >&2; exit 1; }
    slurmctld -D -i -f "$dir/slurm.conf" >>"$dir/log/slurmctld.out" 2>&1 &
    echo $! > "$dir/slurmctld.pid"
    slurmd -D -f "$dir/slurm.conf" >>"$dir/log/slurmd.out" 2>&1 &
    echo $! > "$dir/slurmd.pid"
    for _ in $(seq 60); do
        if sinfo -h -o %t 2>/dev/null | grep -qx idle; then echo "export SLURM_CONF=$dir/slurm.conf"; return 0; fi
        sleep 0.5
    done
    echo "cluster.sh: the node did not come up idle within 30 s:" >&2
    sinfo >&2 || true
    tail -n 20 "$dir"/log/*.log >&2 || true
    exit 1
}

stop() {
    local dir=$1 pid name
    # jobs first (their slurmstepd would outlive slurmd), while the controller still answers
    if [ -f "$dir/slurmctld.pid" ] && kill -0 "$(cat "$dir/slurmctld.pid")" 2>/dev/null; then
        SLURM_CONF=$dir/slurm.conf scancel --user="$(id -un)" 2>/dev/null || true
        for _ in $(seq 30); do
            [ -z "$(SLURM_CONF=$dir/slurm.conf squeue -h -t RUNNING,COMPLETING,PENDING 2>/dev/null)" ] && break
            sleep 0.5
        done
    fi
    for name in slurmd slurmctld munged; do
        [ -f "$dir/$name.pid" ] || continue
        pid=$(cat "$dir/$name.pid")
        kill -TERM "$pid" 2>/dev/null || { rm -f "$dir/$name.pid"; continue; }
        for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null
        rm -f "$dir/$name.pid"
    done
    if [ -L "$RUN_CONF" ] && [ "$(readlink "$RUN_CONF")" = "$(cd "$dir" && pwd)/slurm.conf" ]; then rm -f "$RUN_CONF"; fi
    return 0
}

case ${1:-} in
    install) install ;;
    start) start "${2:?cluster.sh start DIR}" ;;
    stop) stop "${2:?cluster.sh stop DIR}" ;;
    clean) remove_stale_link ;;
    *) echo "usage: $0 install | start DIR | stop DIR | clean" >&2; exit 2 ;;
esac
