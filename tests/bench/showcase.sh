#!/bin/sh
# The showcase against Cycles 3.4 on this machine: tests/bench/scenes/
# showcase.json (scenes/sky-spheres.json in a form both renderers read:
# rough gold, rough glass, plastic and diffuse spheres lit only by an HDR
# sky with a small bright sun), 160x90.  Each renderer is measured against
# its own converged image (REF_SPP samples, another seed), so the RMSE is
# noise, not the differences between the two models (the plastic is not the
# same material in both).  Reports, medians of RUNS seeds:
#   - at equal spp (SPP): wall seconds, CPU seconds (user + system of the
#     whole process tree: Franja's workers on `nproc` row slabs; blender
#     with its start-up and scene building, and Cycles' own render time as
#     it prints it) and RMSE;
#   - at equal time: Franja at the spp that takes it as long (wall) as
#     Cycles' own render time at SPP, and its RMSE.
# Needs blender; without it, only Franja's figures.  The sun seen through the
# rough glass gives rare bright paths that the REF_SPP images hold too: the
# RMSE then falls more slowly than 1/sqrt(spp) (raise REF_SPP for firm
# ratios; the time figures do not depend on it).
cd "$(dirname "$0")/../.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
SPP=${SPP:-64} REF_SPP=${REF_SPP:-512} RUNS=${RUNS:-3} N=$(nproc)
SCENE=tests/bench/scenes/showcase.json
W=160 H=90
echo "== showcase against Cycles: 160x90, RMSE against each renderer's own ${REF_SPP}-spp image, medians of $RUNS seeds"
echo "machine: $N cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: sh tests/bench/showcase.sh   (SPP, REF_SPP, RUNS in the environment)"
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
rmse() { bin/tools/imgcmp "$1" "$2" | sed -n 's/^rmse \([0-9.]*\).*/\1/p'; }

# franja SPP SEED OUT: N row slabs at once, stitched; "wall cpu" in $T/time.
franja() {
    sed "s/\"seed\": [0-9]*/\"seed\": $2/; s|\"\.\./\.\./\.\./scenes/|\"$(pwd)/scenes/|" $SCENE >"$T/seeded.json"
    bin/franja compile "$T/seeded.json" -o "$T/s.fbin" >/dev/null || exit 1
    /usr/bin/time -f '%e %U %S' -o "$T/rt" sh -c '
        i=0
        while [ $i -lt '"$N"' ]; do
            bin/franja-worker --scene "'"$T"'/s.fbin" --spp '"$1"' --rows $((i * '"$H"' / '"$N"')):$(((i + 1) * '"$H"' / '"$N"')) \
                -o "'"$T"'/slab-$i.pfm" &
            i=$((i + 1))
        done
        wait' || exit 1
    awk '{ printf "%s %.2f\n", $1, $2 + $3 }' "$T/rt" >"$T/time"
    {
        printf 'PF\n%d %d\n-1.0\n' $W $H
        i=$((N - 1))
        while [ $i -ge 0 ]; do
            tail -c $((((i + 1) * H / N - i * H / N) * W * 12)) "$T/slab-$i.pfm"
            i=$((i - 1))
        done
    } >"$3"
}

# cycles SPP SEED OUT: "wall cpu render" in $T/time (render: Cycles' own
# render time, from its last progress line).
cycles() {
    mkdir -p "$T/cy"
    /usr/bin/time -f '%e %U %S' -o "$T/rt" blender -b --factory-startup --python tests/refs/cycles_scene.py -- \
        $SCENE "$T/cy" cy "$1" "$2" >"$T/blender.log" 2>&1 || { echo "blender failed:"; tail -5 "$T/blender.log"; exit 1; }
    r=$(grep -o 'Time: *[0-9][0-9:.]*' "$T/blender.log" | tail -n 1 | sed 's/Time: *//' | awk -F: '{ print $1 * 60 + $2 }')
    awk -v r="$r" '{ printf "%s %.2f %s\n", $1, $2 + $3, r }' "$T/rt" >"$T/time"
    cp "$T/cy/cy.pfm" "$3"
}

franja "$REF_SPP" 1000 "$T/fref.pfm"
have_blender=0
command -v blender >/dev/null 2>&1 && have_blender=1
[ $have_blender = 1 ] && cycles "$REF_SPP" 1000 "$T/cref.pfm"
fw="" fc="" fr="" cw="" cc="" cr="" crt="" ew="" er="" es=""
for seed in $(seq "$RUNS"); do
    franja "$SPP" "$seed" "$T/f.pfm"
    set -- $(cat "$T/time")
    fw="$fw $1" fc="$fc $2" fr="$fr $(rmse "$T/f.pfm" "$T/fref.pfm")"
    [ $have_blender = 1 ] || continue
    cycles "$SPP" "$seed" "$T/c.pfm"
    set -- $(cat "$T/time")
    cw="$cw $1" cc="$cc $2" crt="$crt $3" cr="$cr $(rmse "$T/c.pfm" "$T/cref.pfm")"
    # Equal time: Franja's spp scaled to Cycles' render time at SPP.
    eq=$(awk -v s="$SPP" -v tf="$(echo $fw | awk '{ print $NF }')" -v tc="$3" \
        'BEGIN { n = int(s * tc / tf + 0.5); print n < 1 ? 1 : n }')
    franja "$eq" "$seed" "$T/e.pfm"
    set -- $(cat "$T/time")
    es="$es $eq" ew="$ew $1" er="$er $(rmse "$T/e.pfm" "$T/fref.pfm")"
done
m() { echo "$@" | median; }
printf 'Franja at %d spp: wall%s s, CPU%s s, RMSE%s; medians %s s wall, %s CPU-s, RMSE %s\n' \
    "$SPP" "$fw" "$fc" "$fr" "$(m $fw)" "$(m $fc)" "$(m $fr)"
if [ $have_blender = 1 ]; then
    printf 'Cycles at %d spp: wall%s s (blender start-up included), CPU%s s, render%s s; RMSE%s; medians %s s wall, %s CPU-s, %s s render, RMSE %s\n' \
        "$SPP" "$cw" "$cc" "$crt" "$cr" "$(m $cw)" "$(m $cc)" "$(m $crt)" "$(m $cr)"
    printf 'Franja at equal time (Cycles render time): spp%s, wall%s s, RMSE%s; medians %s spp, %s s, RMSE %s\n' \
        "$es" "$ew" "$er" "$(m $es)" "$(m $ew)" "$(m $er)"
    awk -v a="$(m $fr)" -v b="$(m $cr)" -v c="$(m $er)" -v fc="$(m $fc)" -v cc="$(m $cc)" 'BEGIN {
        printf "RMSE ratio Franja/Cycles: %.2f at equal spp, %.2f at equal time; CPU-s ratio at equal spp %.2f (below 1: Franja better)\n", a / b, c / b, fc / cc
        printf "CPU-s at Cycles\47 RMSE (noise as 1/sqrt(spp)): Franja %.1f, Cycles %.1f (start-up included)\n", fc * (a / b) ^ 2, cc }'
fi
