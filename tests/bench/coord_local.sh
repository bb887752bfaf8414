#!/bin/sh
# coord_local.sh -- measures local mode's parallel efficiency.
#
# Parallel efficiency of local mode: the same render with -j 1 and with one
# worker per core.  efficiency = T(1) / (N * T(N)); 1.0 is perfect.
#
# Wall time on a shared machine says little when other work takes the
# cores, so the script also splits the loss into parts that such load
# disturbs less, each a median over the -j N runs:
# - occupancy: the seconds the workers of accepted slabs ran (the summary's
#   "busy s", the seventh field of its host line), over N times the
#   render's seconds: 1.0 when no slot is ever
#   idle (start-up before the first slab, gaps between slabs, the tail);
# - CPU ratio: CPU seconds (user + system, franja and its workers) of -j 1
#   over -j N: below 1.0 when N processes at once each run slower (shared
#   caches, memory, hyper-threads, straggler copies that are thrown away).
# - machine ceiling: the same CPU ratio for N whole renders with -j 1 run
#   side by side, which share nothing but the machine: what N processes of
#   this work lose to each other on these cores whatever schedules them.
#   The efficiency over this ceiling is the part the coordinator can reach.
# - paired efficiency: each -j 1 run against the -j N run that follows it.
cd "$(dirname "$0")/../.." || exit 1
. tests/support/bench_common.sh
N=$(nproc)
SCENE=${SCENE:-scenes/cornell.json}
ARGS="--size ${SIZE:-192x192} --spp ${SPP:-64}"
T=$(mktemp -d /tmp/franja-bench.XXXXXX)
trap 'rm -rf "$T"' EXIT
machine
bin/franja render "$SCENE" -o "$T/warm.pfm" $ARGS -j "$N" >/dev/null 2>&1
compare "bin/franja render $SCENE -o $T/a.pfm $ARGS -j 1" "bin/franja render $SCENE -o $T/b.pfm $ARGS -j $N" || exit 1
cmp -s "$T/a.pfm" "$T/b.pfm" || { echo "-j 1 and -j $N images differ"; exit 1; }
echo "local -j 1: $TA s, -j $N: $TB s; speed-up $(calc "$TA / $TB"), parallel efficiency $(calc "$TA / ($N * $TB)")"
# Each -j 1 run and the -j N run right after it form a pair; a load that
# comes and goes over minutes moves both of a pair alike, so the median of
# the pairs' efficiencies is steadier than the ratio of the two medians.
pairs=$(awk -v a="$la" -v b="$lb" -v n="$N" 'BEGIN { k = split(a, A, " "); split(b, B, " ")
    for (i = 1; i <= k; i++) printf " %.3f", A[i] / (n * B[i]) }')
echo "parallel efficiency of each pair (-j 1, then -j $N):$pairs; median $(median $pairs)"

# One render: prints "CPU-s occupancy" (see above).  The shell's children
# times (fields 16 and 17 of its /proc stat, in clock ticks) hold franja's
# and, through franja's waits, its workers'.
parts() {
    sh -c "bin/franja render $SCENE -o $T/p.pfm $ARGS -j $1 2>$T/log >/dev/null; cat /proc/\$\$/stat" >"$T/stat" ||
        return 1
    hz=$(getconf CLK_TCK)
    cpu=$(awk -v hz="$hz" '{ sub(/.*\) /, ""); printf "%.3f", ($14 + $15) / hz }' "$T/stat")
    occ=$(awk -v n="$1" '/ spp in [0-9.]+ s:/ { for (i = 1; i < NF; i++) if ($i == "in") t = $(i + 1) }
        $1 == "local" { busy = $7 } END { if (t > 0) printf "%.4f", busy / (n * t) }' "$T/log")
    echo "$cpu $occ"
}
c1="" cn="" occs=""
i=0
while [ $i -lt "$RUNS" ]; do
    set -- $(parts 1) || exit 1
    c1="$c1 $1"
    set -- $(parts "$N") || exit 1
    cn="$cn $1" occs="$occs $2"
    i=$((i + 1))
done
C1=$(median $c1) CN=$(median $cn) OCC=$(median $occs)
echo "CPU seconds, -j 1:$c1 (median $C1); -j $N:$cn (median $CN); CPU ratio $(calc "$C1 / $CN")"
echo "occupancy of the $N slots (busy seconds / ($N x render seconds)):$occs; median $OCC"

# The machine ceiling: CPU seconds of one -j 1 render alone against N of
# them at once (per render), alternated RUNS times.
together() {
    sh -c "k=0; while [ \$k -lt $1 ]; do bin/franja render $SCENE -o $T/s\$k.pfm $ARGS -j 1 >/dev/null 2>&1 & k=\$((k + 1)); done; wait; cat /proc/\$\$/stat" >"$T/stat" ||
        return 1
    awk -v hz="$(getconf CLK_TCK)" -v n="$1" '{ sub(/.*\) /, ""); printf "%.3f", ($14 + $15) / hz / n }' "$T/stat"
}
s1="" sn=""
i=0
while [ $i -lt "$RUNS" ]; do
    s1="$s1 $(together 1)" sn="$sn $(together "$N")"
    i=$((i + 1))
done
S1=$(median $s1) SN=$(median $sn)
CEIL=$(calc "$S1 / $SN")
echo "machine ceiling: CPU seconds of one -j 1 render alone:$s1 (median $S1); each of $N at once:$sn (median $SN); ratio $CEIL"
echo "parallel efficiency over the machine ceiling: $(calc "$TA / ($N * $TB) / $CEIL")"
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
