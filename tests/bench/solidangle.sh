#!/bin/sh
# solidangle.sh -- noise and time of area-light sampling, against BASE.
#
# Solid-angle sampling of rectangle and triangle lights against the build
# before it (BASE=path/to/franja-worker; without it, this build alone): the
# Cornell box (scenes/cornell.json, its light 130 x 105 mm, two triangles,
# 549 mm above the floor) and the same box with a light of 450 x 460 mm (near
# the upper part of every wall), at 512x512 and SPP samples per pixel, RUNS
# seeds each, the two builds alternated.  Noise: the RMSE between the render
# of seed k and that of seed 0 over sqrt(2) (no reference needed: it is
# noise alone); time: the workers' CPU seconds (user + system); medians (of
# two, the lower); the efficiency 1 / (noise^2 x CPU seconds) and its ratio.
cd "$(dirname "$0")/../.." || exit 1
[ -z "$BASE" ] || [ -x "$BASE" ] || { echo "$0: BASE=$BASE is not a program" >&2; exit 1; }
[ -x bin/tools/imgcmp ] || { echo "$0: bin/tools/imgcmp is missing: run make bench" >&2; exit 1; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
SPP=${SPP:-64} RUNS=${RUNS:-2} N=$(nproc)
echo "== solidangle: ${SPP} spp, 512x512, seeds 0..$((RUNS - 1)), this build${BASE:+ against $BASE}"
echo "machine: $N cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: ${BASE:+BASE=$BASE }sh tests/bench/solidangle.sh   (BASE, SPP, RUNS in the environment)"
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
# The big light: 450 x 460 mm instead of 130 x 105, a tenth of the radiance.
sed 's/\[343, 548.7, 227\]/[500, 548.7, 50]/; s/\[343, 548.7, 332\]/[500, 548.7, 510]/;
     s/\[213, 548.7, 332\]/[50, 548.7, 510]/; s/\[213, 548.7, 227\]/[50, 548.7, 50]/;
     s/"emission": \[17, 12, 4\]/"emission": [1.7, 1.2, 0.4]/' scenes/cornell.json >"$T/big.json"
grep -q '500, 548.7, 510' "$T/big.json" || { echo "$0: cannot enlarge the light" >&2; exit 1; }
# render WORKER SCENE SEED OUT: N row slabs at once; prints the CPU seconds.
render() {
    sed "s/\"seed\": [0-9]*/\"seed\": $3/" "$2" >"$T/seeded.json"
    i=0
    while [ $i -lt "$N" ]; do
        /usr/bin/time -f '%U %S' -o "$T/cpu-$i" "$1" --scene "$T/seeded.json" --spp "$SPP" \
            --rows $((i * 512 / N)):$(((i + 1) * 512 / N)) -o "$T/slab-$i.pfm" &
        i=$((i + 1))
    done
    wait
    { printf 'PF\n512 512\n-1.0\n'; i=$((N - 1)); while [ $i -ge 0 ]; do
        tail -c $((((i + 1) * 512 / N - i * 512 / N) * 512 * 12)) "$T/slab-$i.pfm"; i=$((i - 1)); done; } >"$4"
    cat "$T"/cpu-* | awk '{ s += $1 + $2 } END { printf "%.2f", s }'
}
for scene in scenes/cornell.json "$T/big.json"; do
    name=$(basename "$scene" .json)
    cb="" cn="" nb="" nn=""
    seed=0
    while [ $seed -lt "$RUNS" ]; do
        [ -n "$BASE" ] && cb="$cb $(render "$BASE" "$scene" $seed "$T/base-$seed.pfm")"
        cn="$cn $(render bin/franja-worker "$scene" $seed "$T/new-$seed.pfm")"
        if [ $seed -gt 0 ]; then
            [ -n "$BASE" ] &&
                nb="$nb $(bin/tools/imgcmp "$T/base-$seed.pfm" "$T/base-0.pfm" | awk '/^rmse/ { print $2 / sqrt(2) }')"
            nn="$nn $(bin/tools/imgcmp "$T/new-$seed.pfm" "$T/new-0.pfm" | awk '/^rmse/ { print $2 / sqrt(2) }')"
        fi
        seed=$((seed + 1))
    done
    tn=$(echo $cn | median) rn=$(echo $nn | median)
    echo "$name: this build CPU seconds$cn, noise$nn${BASE:+; base CPU seconds$cb, noise$nb}"
    [ -z "$BASE" ] && continue
    tb=$(echo $cb | median) rb=$(echo $nb | median)
    awk "BEGIN { eb = 1 / ($rb * $rb * $tb); en = 1 / ($rn * $rn * $tn);
        printf \"  medians: noise %.5f -> %.5f (variance x%.3f), CPU %.2f -> %.2f s (x%.3f), efficiency x%.3f\\n\",
        $rb, $rn, ($rn * $rn) / ($rb * $rb), $tb, $tn, $tn / $tb, en / eb }"
done
echo "load $(cut -d' ' -f1-3 /proc/loadavg)"
