# slurm_lib.sh -- helpers sourced by the Slurm tests and benchmark.
#
# Sourced by the Slurm tests (tests/it_slurm*.sh) and benchmark:
# a private cluster from tests/support/slurm_cluster.sh, stopped on exit whatever
# happens, and Slurm clients that can neither hang nor read the test's stdin.
#
#   sl_init N [CPUS]        make $T (scratch directory), start an N-node
#                           cluster under $T/cl, export SLURM_CONF; a trap
#                           stops it and removes $T on exit
#   sl_alloc SECS ARGS...   salloc ARGS... under `timeout SECS`, stdin from
#                           /dev/null (so also srun, squeue ... inside)
#   sl_alloc_bg SECS ARGS...
#                           sl_alloc in the background; its PID (that of
#                           `timeout`, which passes a TERM on) in $SL_BG, which
#                           the exit trap stops; sl_bg_stop stops it now
#   sl_srun SECS ARGS...    the same for srun
#   sl_q CMD ARGS...        a quick query (squeue, sinfo, scontrol): 10 s at most
#   sl_steps                job steps the controller still knows (squeue -s)
#   sl_jobs                 jobs the controller still knows (squeue)
#   sl_pids [NODE]          live step and task processes of the cluster
#   sl_strays               live processes started in an allocation of the
#                           cluster (salloc's command and what it started),
#                           which outlive an salloc that is stopped
#   sl_stop                 stops the cluster now (the exit trap does it too)
#   sl_until SECS CMD...    runs CMD every 0.1 s until it succeeds
#
# The checks and the closing line are tests/support/lib.sh's (check, summary ...).

ROOT=${ROOT:-$(cd "$(dirname "$0")/.." && pwd)}
. "$ROOT/tests/support/lib.sh"
CLUSTER="$ROOT/tests/support/slurm_cluster.sh"
FRANJA="$ROOT/bin/franja"
WORKER="$ROOT/bin/franja-worker"

sl_cleanup() {
    sl_bg_stop
    sl_stop
    # salloc's command outlives a salloc stopped by a signal.
    left=$(sl_strays)
    [ -z "$left" ] || kill -KILL $left 2>/dev/null
    [ -n "${T:-}" ] && [ -z "${KEEP:-}" ] && rm -rf "$T"
}

sl_init() {
    need munged slurmctld slurmd salloc srun sbcast squeue timeout
    T=$(mktemp -d /tmp/franja-slurm.XXXXXX)
    chmod 0755 "$T" # munged wants every directory above its socket searchable
    trap sl_cleanup EXIT
    trap 'exit 130' INT TERM HUP
    if ! sh "$CLUSTER" start "$T/cl" "$1" "${2:-2}" >"$T/cluster.out" 2>&1; then
        cat "$T/cluster.out"
        bad "the test cluster did not start"
        summary
        exit 1
    fi
    export SLURM_CONF="$T/cl/slurm.conf"
    # Slurm clients would otherwise take these from the caller's own job.
    unset SLURM_JOB_ID SLURM_JOBID SLURM_JOB_NODELIST SLURM_NODELIST SLURM_JOB_CPUS_PER_NODE SLURM_STEP_ID
}

sl_alloc() {
    s=$1
    shift
    timeout -k 5 "$s" salloc "$@" </dev/null
}

sl_alloc_bg() {
    s=$1
    shift
    timeout -k 5 "$s" salloc "$@" </dev/null &
    SL_BG=$!
}

sl_bg_stop() {
    [ -n "${SL_BG:-}" ] || return 0
    kill -TERM "$SL_BG" 2>/dev/null
    wait "$SL_BG" 2>/dev/null
    SL_BG=
}

sl_srun() {
    s=$1
    shift
    timeout -k 5 "$s" srun "$@" </dev/null
}

sl_q() { timeout 10 "$@" </dev/null; }

sl_steps() { sl_q squeue -h -s -o '%i %N'; }

sl_jobs() { sl_q squeue -h -o '%i %T %N'; }

sl_pids() { sh "$CLUSTER" steps "$T/cl" "${1:-}"; }

sl_stop() { [ -n "${T:-}" ] && [ -d "$T/cl" ] && sh "$CLUSTER" stop "$T/cl"; }

sl_strays() {
    for f in $(grep -lzFx "SLURM_CONF=$T/cl/slurm.conf" /proc/[0-9]*/environ 2>/dev/null); do
        d=${f%/environ}
        p=${d#/proc/}
        [ "$p" = "$$" ] && continue
        grep -qz '^SLURM_JOB_ID=' "$f" 2>/dev/null || continue
        st=$(sed -E 's/^[0-9]+ \(.*\) (.).*/\1/' "$d/stat" 2>/dev/null)
        [ -n "$st" ] && [ "$st" != Z ] && [ "$st" != X ] && echo "$p"
    done
}

sl_until() {
    n=$(($1 * 10))
    shift
    while [ $n -gt 0 ]; do
        "$@" && return 0
        sleep 0.1
        n=$((n - 1))
    done
    return 1
}
