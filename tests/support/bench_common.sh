# bench_common.sh -- helpers sourced by the coordinator benchmarks.
#
# Sourced by the coordinator benchmarks (tests/bench/coord_*.sh).
#
# compare "A-CMD" "B-CMD": runs the two commands alternately $RUNS times
# (alternating spreads a changing machine load over both), prints every
# time, and sets TA and TB to the medians in seconds.  machine: prints what
# the figures were measured on.
RUNS=${RUNS:-3}

calc() { awk "BEGIN { printf \"%.3f\", $1 }"; }

elapsed() {
    s=$(date +%s.%N)
    sh -c "$1" >/dev/null 2>&1 || { echo "benchmark command failed: $1" >&2; return 1; }
    calc "$(date +%s.%N) - $s"
}

median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

compare() {
    la="" lb=""
    i=0
    while [ $i -lt "$RUNS" ]; do
        a=$(elapsed "$1") || return 1
        b=$(elapsed "$2") || return 1
        la="$la $a" lb="$lb $b"
        i=$((i + 1))
    done
    TA=$(median $la)
    TB=$(median $lb)
    echo "  A:$la s (median $TA): $1"
    echo "  B:$lb s (median $TB): $2"
}

machine() {
    echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
}
