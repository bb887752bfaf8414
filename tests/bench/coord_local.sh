#!/bin/sh
# Parallel efficiency of local mode: the same render with -j 1 and with one
# worker per core.  efficiency = T(1) / (N * T(N)); 1.0 is perfect.
cd "$(dirname "$0")/../.." || exit 1
. tests/coord/bench_common.sh
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
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
