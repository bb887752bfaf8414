# bench_common.sh -- sourced by the coordinator benchmarks (tests/bench/coord_*.sh).
# median_time VAR CMD...: runs CMD $RUNS times, sets VAR to the median wall
# seconds.  machine: prints what the figures were measured on.
RUNS=${RUNS:-3}

calc() { awk "BEGIN { printf \"%.3f\", $1 }"; }

median_time() {
    var=$1
    shift
    times=""
    i=0
    while [ $i -lt "$RUNS" ]; do
        s=$(date +%s.%N)
        "$@" >/dev/null 2>&1 || { echo "benchmark command failed: $*"; return 1; }
        e=$(date +%s.%N)
        times="$times $(calc "$e - $s")"
        i=$((i + 1))
    done
    m=$(printf '%s\n' $times | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    eval "$var=$m"
    echo "  $(printf '%s ' $times| sed 's/ $//') s -> median $m s: $*"
}

machine() {
    echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
}
