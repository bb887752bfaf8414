#!/bin/sh
# slurm_cluster.sh -- starts or stops a real Slurm cluster on this machine.
#
# A real Slurm cluster on this one machine, for tests and
# benchmarks: a private munged, one slurmctld and N slurmd, each slurmd a
# node of its own (n1 .. nN) with its own port on 127.0.0.1.  Everything
# (configuration, keys, sockets, state, logs, PIDs) lives under DIR; the
# system's /etc/slurm and /etc/munge are not used.
#
#   cluster.sh start DIR N [CPUS]   start the cluster (CPUS per node, default
#                                   2) and wait until every node is idle;
#                                   prints the SLURM_CONF to export
#   cluster.sh stop DIR             cancel every job, stop every daemon started
#                                   under DIR (by PID), remove the state; safe
#                                   to call twice or after a failed start
#   cluster.sh kill-node DIR NODE   a node lost: SIGKILL its slurmd, and the
#                                   slurmstepd and task processes it started
#                                   (killing slurmd alone leaves them running)
#   cluster.sh start-node DIR NODE  starts that node's slurmd again
#   cluster.sh pids DIR [NODE]      live processes of the cluster (or of one
#                                   node): daemons, slurmstepd, tasks
#   cluster.sh steps DIR [NODE]     the same without the daemons
#
# Ports: SLURM_TEST_PORT (controller; nodes on the next N ports), else a
# free block of 16 picked from 17000..26990.  Every Slurm client call here is
# bounded by `timeout` and given a stdin (srun/salloc hang with fd 0 closed).
# Daemons are found by their PID files, step processes as step_pids says.
# A zombie counts as dead: PID 1 on these machines reaps late.
set -u

die() {
    echo "cluster.sh: $*" >&2
    exit 1
}

# alive PID: the process exists and is not a zombie.
alive() {
    [ -r "/proc/$1/stat" ] || return 1
    st=$(sed -E 's/^[0-9]+ \(.*\) (.).*/\1/' "/proc/$1/stat" 2>/dev/null) || return 1
    [ -n "$st" ] && [ "$st" != Z ] && [ "$st" != X ]
}

# pid_of FILE NAME: the PID in FILE if that process is alive and its command
# name is NAME (a stale file whose PID was reused names someone else).
pid_of() {
    [ -r "$1" ] || return 1
    p=$(head -n 1 "$1" 2>/dev/null)
    case "$p" in '' | *[!0-9]*) return 1 ;; esac
    alive "$p" || return 1
    [ "$(cat "/proc/$p/comm" 2>/dev/null)" = "$2" ] || return 1
    echo "$p"
}

# wait_dead SECONDS PID...: true once none of the PIDs is alive.
wait_dead() {
    n=$(($1 * 10))
    shift
    while [ $n -gt 0 ]; do
        left=0
        for p in "$@"; do alive "$p" && left=1; done
        [ $left -eq 0 ] && return 0
        sleep 0.1
        n=$((n - 1))
    done
    return 1
}

# step_pids DIR [NODE]: slurmstepd and task processes of the cluster (or of
# one node).  Tasks carry SLURM_CONF and SLURMD_NODENAME in their
# environment; a slurmstepd overwrites its own, but keeps its node's log file
# (DIR/log/slurmd.NODE.log) open.  Daemons are found by PID file instead.
step_pids() {
    for p in $(pgrep -x slurmstepd); do
        for fd in /proc/$p/fd/*; do
            case "$(readlink "$fd" 2>/dev/null)" in
            "$1/log/slurmd.${2:-}"*.log) alive "$p" && echo "$p"; break ;;
            esac
        done
    done
    # One grep over every environment first: cheap, and most processes drop out.
    for f in $(grep -lzFx "SLURM_CONF=$1/slurm.conf" /proc/[0-9]*/environ 2>/dev/null); do
        d=${f%/environ}
        p=${d#/proc/}
        [ "$p" = "$$" ] && continue
        alive "$p" || continue
        node=$({ tr '\0' '\n' <"$d/environ"; } 2>/dev/null | sed -n 's/^SLURMD_NODENAME=//p')
        [ -n "$node" ] || continue
        [ -z "${2:-}" ] || [ "$node" = "$2" ] && echo "$p"
    done
}

daemon_pids() {
    pid_of "$1/munge/munged.pid" munged
    pid_of "$1/pid/slurmctld" slurmctld
    for f in "$1"/pid/slurmd.*; do
        [ -e "$f" ] || continue
        pid_of "$f" slurmd
    done
}

free_port() {
    ! ss -Htan 2>/dev/null | awk '{print $4}' | grep -qE ":$1\$"
}

pick_ports() {
    if [ -n "${SLURM_TEST_PORT:-}" ]; then
        echo "$SLURM_TEST_PORT"
        return
    fi
    b=$((17000 + ($$ % 1000) * 10))
    tries=0
    while [ $tries -lt 50 ]; do
        ok=1
        i=0
        while [ $i -le "$1" ]; do
            free_port $((b + i)) || { ok=0; break; }
            i=$((i + 1))
        done
        [ $ok -eq 1 ] && { echo $b; return; }
        b=$((17000 + ((b - 17000 + 170) % 10000)))
        tries=$((tries + 1))
    done
    die "no free block of ports between 17000 and 27000"
}

write_conf() {
    dir=$1 n=$2 cpus=$3 port=$4
    host=$(hostname -s)
    cat >"$dir/slurm.conf" <<CONF
# A test cluster of $n nodes on this machine (tests/support/slurm_cluster.sh).
ClusterName=franjatest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmUser=$(id -un)
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/ctld
SlurmdSpoolDir=$dir/spool/%n
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.%n.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.%n.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
SlurmdParameters=config_overrides
SlurmdTimeout=10
SlurmctldTimeout=10
MessageTimeout=5
KillWait=2
InactiveLimit=0
MailProg=/bin/true
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/filetxt
JobCompLoc=$dir/log/jobcomp.txt
NodeName=n[1-$n] NodeHostname=$host NodeAddr=127.0.0.1 Port=[$((port + 1))-$((port + n))] CPUs=$cpus RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
}

start_node() {
    dir=$1 node=$2
    mkdir -p "$dir/spool/$node" "$dir/pid"
    SLURM_CONF="$dir/slurm.conf" \
        setsid slurmd -D -N "$node" >"$dir/log/slurmd.$node.out" 2>&1 </dev/null &
    echo $! >"$dir/pid/slurmd.$node"
}

# idle_nodes: how many nodes the controller reports idle.
idle_nodes() {
    SLURM_CONF="$1/slurm.conf" timeout 5 sinfo -h -N -t idle -o %N </dev/null 2>/dev/null | sort -u | wc -l
}

cmd_start() {
    [ $# -ge 2 ] || die "usage: cluster.sh start DIR N [CPUS]"
    dir=$1 n=$2 cpus=${3:-2}
    case "$n" in '' | *[!0-9]* | 0) die "N must be a number of nodes (1-9)" ;; esac
    [ "$n" -le 9 ] || die "at most 9 nodes"
    for t in munged slurmctld slurmd sinfo scancel squeue setsid timeout ss; do
        command -v "$t" >/dev/null 2>&1 || die "$t is missing (run tests/install-deps.sh)"
    done
    [ -z "$(daemon_pids "$dir")" ] || die "$dir: a cluster is already running there"
    rm -rf "$dir/ctld" "$dir/spool" "$dir/pid" "$dir/munge" "$dir/log"
    mkdir -p "$dir/log" "$dir/ctld" "$dir/munge" "$dir/spool" "$dir/pid" || die "cannot create $dir"
    # munged refuses a socket directory others cannot search.
    chmod 0755 "$dir" "$dir/munge"
    port=$(pick_ports "$n") || exit 1
    echo "$port" >"$dir/port"
    echo "$n" >"$dir/nodes"
    write_conf "$dir" "$n" "$cpus" "$port"
    dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 2>/dev/null
    chmod 0400 "$dir/munge/munge.key"
    timeout 10 munged --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
        --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" \
        --seed-file="$dir/munge/munged.seed" </dev/null >"$dir/log/munged.out" 2>&1 ||
        die "munged did not start: $(cat "$dir/log/munged.out" "$dir/log/munged.log" 2>/dev/null | tail -n 3)"
    SLURM_CONF="$dir/slurm.conf" setsid slurmctld -D -i >"$dir/log/slurmctld.out" 2>&1 </dev/null &
    echo $! >"$dir/pid/slurmctld"
    i=1
    while [ $i -le "$n" ]; do
        start_node "$dir" "n$i"
        i=$((i + 1))
    done
    k=0
    while [ "$(idle_nodes "$dir")" -lt "$n" ]; do
        k=$((k + 1))
        if [ $k -ge 300 ]; then
            echo "cluster.sh: the nodes did not become idle within 30 s:" >&2
            tail -n 5 "$dir"/log/*.log "$dir"/log/*.out >&2 2>/dev/null
            cmd_stop "$dir"
            exit 1
        fi
        pid_of "$dir/pid/slurmctld" slurmctld >/dev/null || {
            echo "cluster.sh: slurmctld exited: $(tail -n 5 "$dir/log/slurmctld.out" "$dir/log/slurmctld.log" 2>/dev/null)" >&2
            cmd_stop "$dir"
            exit 1
        }
        sleep 0.1
    done
    echo "export SLURM_CONF=$dir/slurm.conf"
}

cmd_stop() {
    [ $# -ge 1 ] || die "usage: cluster.sh stop DIR"
    dir=$1
    [ -d "$dir" ] || return 0
    if pid_of "$dir/pid/slurmctld" slurmctld >/dev/null; then
        export SLURM_CONF="$dir/slurm.conf"
        timeout 10 scancel --user="$(id -un)" </dev/null >/dev/null 2>&1
        k=0
        while [ $k -lt 50 ] && [ -n "$(timeout 5 squeue -h -o %i </dev/null 2>/dev/null)" ]; do
            sleep 0.1
            k=$((k + 1))
        done
    fi
    # Daemons by PID, nodes first, then the controller, then munged.
    pids=""
    for f in "$dir"/pid/slurmd.*; do
        [ -e "$f" ] || continue
        p=$(pid_of "$f" slurmd) && pids="$pids $p"
    done
    [ -z "$pids" ] || { kill -TERM $pids 2>/dev/null; wait_dead 5 $pids || kill -KILL $pids 2>/dev/null; }
    p=$(pid_of "$dir/pid/slurmctld" slurmctld) &&
        { kill -TERM "$p" 2>/dev/null; wait_dead 5 "$p" || kill -KILL "$p" 2>/dev/null; }
    # What a lost node or a cancelled job may have left behind.
    left=$(step_pids "$dir")
    [ -z "$left" ] || { kill -KILL $left 2>/dev/null; wait_dead 3 $left; }
    p=$(pid_of "$dir/munge/munged.pid" munged) &&
        { kill -TERM "$p" 2>/dev/null; wait_dead 5 "$p" || kill -KILL "$p" 2>/dev/null; }
    rm -rf "$dir/ctld" "$dir/spool" "$dir/munge/munge.socket" "$dir/munge/munge.socket.lock"
    return 0
}

cmd_kill_node() {
    [ $# -eq 2 ] || die "usage: cluster.sh kill-node DIR NODE"
    dir=$1 node=$2
    p=$(pid_of "$dir/pid/slurmd.$node" slurmd) && kill -KILL "$p" 2>/dev/null
    left=$(step_pids "$dir" "$node")
    [ -z "$left" ] || kill -KILL $left 2>/dev/null
    wait_dead 3 ${p:-} $left
}

# Every command takes DIR second; the PID files and logs hold absolute paths.
if [ $# -ge 2 ]; then
    case "$2" in
    /*) ;;
    *) a=$1 d=$(pwd)/$2; shift 2; set -- "$a" "$d" "$@" ;;
    esac
fi
case "${1:-}" in
start) shift; cmd_start "$@" ;;
stop) shift; cmd_stop "$@" ;;
kill-node) shift; cmd_kill_node "$@" ;;
start-node)
    [ $# -eq 3 ] || die "usage: cluster.sh start-node DIR NODE"
    pid_of "$2/pid/slurmd.$3" slurmd >/dev/null && die "$3 is running"
    start_node "$2" "$3"
    ;;
pids)
    [ $# -ge 2 ] || die "usage: cluster.sh pids DIR [NODE]"
    if [ -n "${3:-}" ]; then
        pid_of "$2/pid/slurmd.$3" slurmd
    else
        daemon_pids "$2"
    fi
    step_pids "$2" "${3:-}"
    ;;
steps)
    [ $# -ge 2 ] || die "usage: cluster.sh steps DIR [NODE]"
    step_pids "$2" "${3:-}"
    ;;
*) die "usage: cluster.sh start DIR N [CPUS] | stop DIR | kill-node DIR NODE | start-node DIR NODE | pids|steps DIR [NODE]" ;;
esac
