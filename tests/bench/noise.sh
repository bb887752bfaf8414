#!/bin/sh
# noise.sh -- measures noise per sample, Franja against Cycles.
#
# Noise per sample, Franja against Cycles: the Cornell box with a mirror
# and a glass sphere, and the Cornell box filled with fog lit by its area
# light (tests/bench/scenes/), 128x128 at SPP samples per pixel.  Each
# renderer is compared with its own converged image (Franja: REF_SPP
# samples with another seed, rendered here; Cycles: 1024 samples, in
# tests/data, made by `make refs`), so the RMSE measures noise, not the
# small differences between the two models.  RUNS seeds each; medians.
# Cycles (blender) is run at the same SPP when it is installed (CYCLES=0:
# not at all).  SCENES picks the cases (default: glass fog).
cd "$(dirname "$0")/../.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
SPP=${SPP:-32} REF_SPP=${REF_SPP:-1024} RUNS=${RUNS:-3} N=$(nproc) CYCLES=${CYCLES:-1} SCENES=${SCENES:-glass fog}
echo "== noise: RMSE at ${SPP} spp against each renderer's converged image, 128x128, medians of $RUNS seeds"
echo "machine: $N cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: sh tests/bench/noise.sh   (SPP, REF_SPP, RUNS, CYCLES, SCENES in the environment)"
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
rmse() { bin/tools/imgcmp "$1" "$2" | sed -n 's/^rmse \([0-9.]*\).*/\1/p'; }
# Render scene $1 at $2 spp with seed $3 into $4, in N row slabs at once.
franja() {
    sed "s/\"seed\": [0-9]*/\"seed\": $3/" "$1" >"$T/seeded.json"
    i=0
    while [ $i -lt "$N" ]; do
        bin/franja-worker --scene "$T/seeded.json" --spp "$2" --rows $((i * 128 / N)):$(((i + 1) * 128 / N)) \
            -o "$T/slab-$i.pfm" &
        i=$((i + 1))
    done
    wait
    {
        printf 'PF\n128 128\n-1.0\n'
        i=$((N - 1))
        while [ $i -ge 0 ]; do
            tail -c $((((i + 1) * 128 / N - i * 128 / N) * 128 * 12)) "$T/slab-$i.pfm"
            i=$((i - 1))
        done
    } >"$4"
}
for s in $SCENES; do
    scene=tests/bench/scenes/cornell-$s.json
    franja "$scene" "$REF_SPP" 7 "$T/ref.pfm"
    fr="" cy="" tf="" tc=""
    for seed in $(seq "$RUNS"); do
        t0=$(date +%s.%N)
        franja "$scene" "$SPP" "$seed" "$T/fr.pfm"
        t1=$(date +%s.%N)
        fr="$fr $(rmse "$T/fr.pfm" "$T/ref.pfm")"
        tf="$tf $(awk "BEGIN { print $t1 - $t0 }")"
        if [ "$CYCLES" != 0 ] && command -v blender >/dev/null 2>&1; then
            t0=$(date +%s.%N)
            blender -b --factory-startup --python tests/refs/cycles_noise.py -- "$scene" "$T/cy.pfm" "$SPP" "$seed" \
                >"$T/blender.log" 2>&1 || { echo "blender failed:"; tail -5 "$T/blender.log"; exit 1; }
            t1=$(date +%s.%N)
            cy="$cy $(rmse "$T/cy.pfm" "tests/data/cycles-noise-$s.pfm")"
            tc="$tc $(awk "BEGIN { print $t1 - $t0 }")"
        fi
    done
    mf=$(echo $fr | median) mtf=$(echo $tf | median)
    printf '%s: Franja RMSE%s; median %s (%.2f s wall, %d processes)\n' "$s" "$fr" "$mf" "$mtf" "$N"
    if [ -n "$cy" ]; then
        mc=$(echo $cy | median) mtc=$(echo $tc | median)
        printf '%s: Cycles RMSE%s; median %s (%.2f s wall, blender start-up included)\n' "$s" "$cy" "$mc" "$mtc"
        awk "BEGIN { printf \"%s: noise ratio Franja/Cycles at equal spp %.2f (below 1: Franja is less noisy)\\n\", \"$s\", $mf / $mc }"
    fi
done
