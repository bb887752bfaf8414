#!/bin/sh
# frames.sh -- times an animation's --frames render against a reference build.
#
# An animation rendered with --frames: five frames of the Cornell box with
# a sphere moving, 128x128 at 16 spp, -j 2 (FRAMES, SIZE, SPP, JOBS change
# them; OPTS adds options to both, e.g. OPTS='--progress json').  B is this build's --frames, which runs the frames together over
# one set of workers; A is the reference: REF=path/to/an/older/franja (its
# own --frames, e.g. a build of the frame-by-frame version), else the
# frames as separate renders one after another.  Every frame of B must be
# the bytes of A's.  Prints both medians and the time B saves.
cd "$(dirname "$0")/../.." || exit 1
. tests/support/bench_common.sh
FRAMES=${FRAMES:-5}
ARGS="--size ${SIZE:-128x128} --spp ${SPP:-16} -j ${JOBS:-2} ${OPTS:-}"
T=$(mktemp -d /tmp/franja-bench.XXXXXX)
trap 'rm -rf "$T"' EXIT
i=1
while [ $i -le "$FRAMES" ]; do
    sed "/\"shapes\": \[/a { \"type\": \"sphere\", \"center\": [$((40 * i + 150)), 100, 300], \"radius\": 80, \"material\": \"white\" }," \
        scenes/cornell.json >"$T/f.000$i.json"
    i=$((i + 1))
done
F="$(pwd)/bin/franja"
if [ -n "$REF" ]; then
    A="cd $T && rm -rf a && $REF render 'f.####.json' --frames 1-$FRAMES -o 'a/f.####.pfm' $ARGS"
else
    A="cd $T && rm -rf a && mkdir a && for i in \$(seq 1 $FRAMES); do $F render f.000\$i.json -o a/f.000\$i.pfm $ARGS || exit 1; done"
fi
B="cd $T && rm -rf b && $F render 'f.####.json' --frames 1-$FRAMES -o 'b/f.####.pfm' $ARGS"
machine
sh -c "$B" >/dev/null 2>&1 # warm the caches
compare "$A" "$B" || exit 1
i=1
while [ $i -le "$FRAMES" ]; do
    cmp -s "$T/a/f.000$i.pfm" "$T/b/f.000$i.pfm" || { echo "frame $i differs between A and B"; exit 1; }
    i=$((i + 1))
done
echo "$FRAMES frames ($ARGS): A $TA s, B $TB s; B takes $(calc "100 * $TB / $TA") % of A's time"
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
