#!/usr/bin/env bash
# A single-node Slurm cluster on this machine (Debian's slurm-wlm and munge), for trying the
# templates beside this script and for tests/slurm.rs. Everything lives in DIR: the munge key
# and socket, slurm.conf, the controller's state, the logs.
#
#   scripts/slurm/local-cluster.sh up DIR [CPUS]   start it (CPUS task slots, default 4)
#   scripts/slurm/local-cluster.sh down DIR        stop it
#
# After `up`, point Slurm's commands at it: export SLURM_CONF=DIR/slurm.conf
# Ports: SLURMCTLD_PORT and SLURMD_PORT (default 16817 and 16818).
set -euo pipefail

usage() { echo "usage: $0 up DIR [CPUS] | down DIR" >&2; exit 2; }
[ $# -ge 2 ] || usage
action=$1
dir=$(realpath -m "$2")
case $dir in
    *[[:space:]]*) echo "error: slurm.conf cannot hold a path with spaces: $dir" >&2; exit 2 ;;
esac
cpus=${3:-4}
# The controller and the node: this machine under its own short name (slurmctld refuses a
# SlurmctldHost that is not its host name).
node=$(hostname -s)

need() {
    for tool in "$@"; do
        command -v "$tool" >/dev/null 2>&1 || {
            echo "error: $tool not found: install Debian's slurm-wlm and munge (scripts/install-deps.sh)" >&2
            exit 1
        }
    done
}

# Waits up to $1 seconds for the command after it to succeed.
wait_for() {
    local seconds=$1; shift
    for _ in $(seq $((seconds * 10))); do
        "$@" >/dev/null 2>&1 && return 0
        sleep 0.1
    done
    return 1
}

fail_with_logs() {
    echo "error: $1" >&2
    for log in "$dir"/log/*; do
        [ -f "$log" ] && { echo "--- $log" >&2; tail -n 20 "$log" >&2; }
    done
    exit 1
}

up() {
    need munged mungekey slurmctld slurmd sinfo
    mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
    chmod 755 "$dir/munge"
    mungekey --create --keyfile "$dir/munge/munge.key" --force
    chmod 600 "$dir/munge/munge.key"
    # The daemons' own output goes to the log folder: a caller reading this script's output
    # to its end must not wait for daemons that hold it open.
    munged --socket="$dir/munge/socket" --key-file="$dir/munge/munge.key" \
        --log-file="$dir/log/munged.log" --pid-file="$dir/munge/munged.pid" \
        --seed-file="$dir/munge/seed" --force </dev/null >>"$dir/log/daemons.out" 2>&1
    local user
    user=$(id -un)
    cat > "$dir/slurm.conf" <<CONF
ClusterName=shine-local
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=${SLURMCTLD_PORT:-16817}
SlurmdPort=${SLURMD_PORT:-16818}
AuthType=auth/munge
# cred_expire: how long a re-queued job waits before it may start again (default 120 s).
AuthInfo=socket=$dir/munge/socket,cred_expire=10
CredType=cred/munge
SlurmUser=$user
SlurmdUser=$user
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
MpiDefault=none
SwitchType=switch/none
JobRequeue=1
KillWait=2
MinJobAge=600
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=4000 State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
    export SLURM_CONF="$dir/slurm.conf"
    slurmctld </dev/null >>"$dir/log/daemons.out" 2>&1 || fail_with_logs "slurmctld did not start"
    slurmd </dev/null >>"$dir/log/daemons.out" 2>&1 || fail_with_logs "slurmd did not start"
    wait_for 60 sh -c "sinfo -h -o %T | grep -qx idle" \
        || fail_with_logs "the node did not come up idle within 60 s"
    echo "export SLURM_CONF=$dir/slurm.conf"
}

# Stops the daemon whose pid file is $1 (TERM, then KILL after 10 s).
stop_pid() {
    [ -f "$1" ] || return 0
    local pid
    pid=$(cat "$1")
    kill "$pid" 2>/dev/null || return 0
    wait_for 10 sh -c "! kill -0 $pid" || kill -9 "$pid" 2>/dev/null || true
}

down() {
    export SLURM_CONF="$dir/slurm.conf"
    if [ -f "$SLURM_CONF" ]; then
        scancel --full --quiet --user="$(id -un)" 2>/dev/null || true
    fi
    stop_pid "$dir/slurmd.pid"
    stop_pid "$dir/slurmctld.pid"
    stop_pid "$dir/munge/munged.pid"
}

case $action in
    up) up ;;
    down) down ;;
    *) usage ;;
esac
