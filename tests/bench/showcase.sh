#!/bin/sh
# showcase.sh -- measures the showcase scene's noise against Cycles 3.4.
#
# The showcase against Cycles 3.4 on this machine: tests/bench/scenes/
# showcase.json (scenes/sky-spheres.json in a form both renderers read:
# rough gold, rough glass, plastic and diffuse spheres lit only by an HDR
# sky with a small bright sun), 160x90.  Each renderer is measured against
# its own converged image (FREF_SPP samples for Franja, CREF_SPP for
# Cycles, another seed), so the RMSE is noise, not the differences between
# the two models (the plastic is not the same material in both).  The
# references take minutes: they are kept in CACHE (FRANJA_BENCH_CACHE, by
# default ~/.cache/franja-bench), named by a hash of what makes them (the
# scene, its sky, the spp, and Franja's render code or the Cycles script
# and blender's version), and made again only when one of those changes.
# Two measures of noise: the RMSE, which the sun seen through the rough
# glass rules with rare bright paths (one seed's RMSE can be 2.5x
# another's), and the RMSE after clamping both images at the reference's
# PCT-th percentile (99.9 by default), which those paths do not rule (its
# seeds agree within a few per cent).  Neither falls as 1/sqrt(spp) here
# (the caustic under the glass converges slowly), so no figure below
# scales one spp to another: equal RMSE is read off measured renders.
# Reports, medians of RUNS seeds:
#   - at equal spp (SPP): wall seconds, CPU seconds (user + system of the
#     whole process tree: Franja's workers on `nproc` row slabs; blender
#     with its start-up and scene building, and Cycles' own render time as
#     it prints it, and the CPU seconds of its render alone) and both RMSEs;
#   - at equal time: Franja at the spp that takes it as long (wall) as
#     Cycles' own render time at SPP, and both RMSEs;
#   - at equal RMSE: whether Franja's clamped RMSE at SPP is at most
#     Cycles' at SPP, and then the CPU seconds each spent for it (Franja's:
#     an upper bound of what it needs for Cycles' RMSE);
#   - at equal RMSE, measured: Franja rendered again at the spp where its
#     clamped RMSE should meet Cycles' (SPP times the square of their ratio)
#     and a sixteenth above, and the CPU ratio at the lower of the two whose
#     median clamped RMSE is at most Cycles'.
# Needs blender; without it, only Franja's figures.
cd "$(dirname "$0")/../.." || exit 1
[ -x bin/tools/imgcmp ] || { echo "$0: bin/tools/imgcmp is missing: run make bench (it builds the tools)" >&2; exit 1; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
SPP=${SPP:-64} FREF_SPP=${FREF_SPP:-8192} CREF_SPP=${CREF_SPP:-2048} RUNS=${RUNS:-3} PCT=${PCT:-99.9} N=$(nproc)
CACHE=${FRANJA_BENCH_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/franja-bench}
# SCENE: another scene both renderers read (its image size is used), such
# as tests/data/cycles-metals.json (scenes/metals.json for both).
SCENE=${SCENE:-tests/bench/scenes/showcase.json}
NAME=$(basename "$SCENE" .json)
set -- $(python3 -c 'import json, sys; i = json.load(open(sys.argv[1]))["image"]; print(i["width"], i["height"])' "$SCENE") || exit 1
W=$1 H=$2
echo "== $NAME against Cycles: ${W}x$H, RMSE against each renderer's own converged image (Franja $FREF_SPP spp, Cycles $CREF_SPP spp), medians of $RUNS seeds"
echo "machine: $N cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: SCENE=$SCENE sh tests/bench/showcase.sh   (SPP, FREF_SPP, CREF_SPP, RUNS, PCT, FRANJA_BENCH_CACHE in the environment)"
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
rmse() { bin/tools/imgcmp "$1" "$2" | sed -n 's/^rmse \([0-9.]*\).*/\1/p'; }
crmse() { bin/tools/imgcmp "$1" "$2" --clamp-pct "$PCT" | sed -n 's/^clamped rmse \([0-9.]*\).*/\1/p'; }

# franja SPP SEED OUT: N row slabs at once, stitched; "wall cpu" in $T/time.
franja() {
    sed "s/\"seed\": [0-9]*/\"seed\": $2/; s|\"\.\./\.\./\.\./scenes/|\"$(pwd)/scenes/|" $SCENE >"$T/seeded.json"
    bin/franja compile "$T/seeded.json" --allow-path scenes -o "$T/s.fbin" >/dev/null || exit 1
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

# cycles SPP SEED OUT: "wall cpu render rcpu" in $T/time (render: Cycles'
# own render time, from its last progress line; rcpu: the CPU seconds of the
# render alone, blender's start-up left out, as cycles_common.py prints them).
cycles() {
    mkdir -p "$T/cy"
    /usr/bin/time -f '%e %U %S' -o "$T/rt" blender -b --factory-startup --python tests/refs/cycles_scene.py -- \
        $SCENE "$T/cy" cy "$1" "$2" >"$T/blender.log" 2>&1 || { echo "blender failed:"; tail -5 "$T/blender.log"; exit 1; }
    r=$(grep -o 'Time: *[0-9][0-9:.]*' "$T/blender.log" | tail -n 1 | sed 's/Time: *//' | awk -F: '{ print $1 * 60 + $2 }')
    rc=$(sed -n 's/^render CPU seconds: //p' "$T/blender.log" | tail -n 1)
    awk -v r="$r" -v rc="$rc" '{ printf "%s %.2f %s %s\n", $1, $2 + $3, r, rc }' "$T/rt" >"$T/time"
    cp "$T/cy/cy.pfm" "$3"
}

# cached NAME KEY...: the path of the cached reference made from KEY
# (files and strings), in $ref; non-zero when it is not there yet.
cached() {
    name=$1
    shift
    key=$(for k in "$@"; do if [ -f "$k" ]; then sha256sum <"$k"; else echo "$k"; fi; done | sha256sum | cut -c1-16)
    ref="$CACHE/$NAME-$name-$key.pfm"
    [ -s "$ref" ]
}
# keep FILE: moves a finished reference into the cache, whole or not at all.
keep() {
    mkdir -p "$CACHE" && cp "$1" "$ref.tmp.$$" && mv -f "$ref.tmp.$$" "$ref" || exit 1
}
SKY=scenes/textures/sky.hdr
if ! cached franja "$FREF_SPP" $SCENE $SKY $(ls common/*.[ch] worker/*.[ch]); then
    echo "making Franja's $FREF_SPP-spp reference (once; kept as $ref)"
    franja "$FREF_SPP" 1000 "$T/fref.pfm"
    keep "$T/fref.pfm"
fi
FREF=$ref
have_blender=0
command -v blender >/dev/null 2>&1 && have_blender=1
if [ $have_blender = 1 ]; then
    if ! cached cycles "$CREF_SPP" $SCENE $SKY tests/refs/cycles_scene.py "$(blender --version 2>/dev/null | head -n 1)"; then
        echo "making Cycles' $CREF_SPP-spp reference (once; kept as $ref)"
        cycles "$CREF_SPP" 1000 "$T/cref.pfm"
        keep "$T/cref.pfm"
    fi
    CREF=$ref
fi
fw="" fc="" fr="" fk="" cw="" cc="" cr="" ck="" crt="" crc="" ew="" er="" ek="" es=""
for seed in $(seq "$RUNS"); do
    franja "$SPP" "$seed" "$T/f.pfm"
    set -- $(cat "$T/time")
    fw="$fw $1" fc="$fc $2" fr="$fr $(rmse "$T/f.pfm" "$FREF")" fk="$fk $(crmse "$T/f.pfm" "$FREF")"
    [ $have_blender = 1 ] || continue
    cycles "$SPP" "$seed" "$T/c.pfm"
    set -- $(cat "$T/time")
    cw="$cw $1" cc="$cc $2" crt="$crt $3" crc="$crc $4" cr="$cr $(rmse "$T/c.pfm" "$CREF")" ck="$ck $(crmse "$T/c.pfm" "$CREF")"
    # Equal time: Franja's spp scaled to Cycles' render time at SPP.
    eq=$(awk -v s="$SPP" -v tf="$(echo $fw | awk '{ print $NF }')" -v tc="$3" \
        'BEGIN { n = int(s * tc / tf + 0.5); print n < 1 ? 1 : n }')
    franja "$eq" "$seed" "$T/e.pfm"
    set -- $(cat "$T/time")
    es="$es $eq" ew="$ew $1" er="$er $(rmse "$T/e.pfm" "$FREF")" ek="$ek $(crmse "$T/e.pfm" "$FREF")"
done
m() { echo "$@" | median; }
printf 'Franja at %d spp: wall%s s, CPU%s s, RMSE%s, clamped RMSE%s; medians %s s wall, %s CPU-s, RMSE %s, clamped %s\n' \
    "$SPP" "$fw" "$fc" "$fr" "$fk" "$(m $fw)" "$(m $fc)" "$(m $fr)" "$(m $fk)"
if [ $have_blender = 1 ]; then
    printf 'Cycles at %d spp: wall%s s (blender start-up included), CPU%s s, render%s s, render CPU%s s; RMSE%s, clamped RMSE%s; medians %s s wall, %s CPU-s, %s s render, %s render CPU-s, RMSE %s, clamped %s\n' \
        "$SPP" "$cw" "$cc" "$crt" "$crc" "$cr" "$ck" "$(m $cw)" "$(m $cc)" "$(m $crt)" "$(m $crc)" "$(m $cr)" "$(m $ck)"
    printf 'Franja at equal time (Cycles render time): spp%s, wall%s s, RMSE%s, clamped RMSE%s; medians %s spp, %s s, RMSE %s, clamped %s\n' \
        "$es" "$ew" "$er" "$ek" "$(m $es)" "$(m $ew)" "$(m $er)" "$(m $ek)"
    awk -v a="$(m $fk)" -v b="$(m $ck)" -v c="$(m $ek)" -v ra="$(m $fr)" -v rb="$(m $cr)" -v fc="$(m $fc)" -v cc="$(m $cc)" \
        -v crt="$(m $crt)" -v cw="$(m $cw)" -v crc="$(m $crc)" 'BEGIN {
        printf "clamped RMSE ratio Franja/Cycles: %.2f at equal spp, %.2f at equal time (RMSE: %.2f at equal spp); CPU-s ratio at equal spp %.2f (below 1: Franja better)\n", a / b, c / b, ra / rb, fc / cc
        if (a <= b)
            printf "equal RMSE: at %s spp Franja\47s clamped RMSE is at most Cycles\47 (%.4f, %.4f): Franja spends %.2f CPU-s for it, Cycles %.1f with start-up, %.1f for the render alone (measured): Franja %.2f of the render\47s CPU-s\n", "'"$SPP"'", a, b, fc, cc, crc, fc / crc
        else
            printf "equal RMSE: at %s spp Franja\47s clamped RMSE is above Cycles\47 (%.4f, %.4f): run with a higher SPP for Franja to compare CPU-s\n", "'"$SPP"'", a, b }'
fi
# Equal RMSE, measured: Franja again at the spp that 1/spp scaling says
# matches Cycles' clamped RMSE at SPP, and one step (a sixteenth) above it,
# with the same seeds; the lowest of them whose median clamped RMSE is at
# most Cycles' gives the CPU ratio.  The scaling only picks the spp: each
# figure printed is a measured one.
if [ $have_blender = 1 ]; then
    s0=$(awk -v a="$(m $fk)" -v b="$(m $ck)" -v s="$SPP" 'BEGIN { n = int(s * (a / b) ^ 2 + 0.5); print n < 1 ? 1 : n }')
    found=""
    for q in $s0 $((s0 + (s0 + 15) / 16)); do
        qc="" qk=""
        for seed in $(seq "$RUNS"); do
            franja "$q" "$seed" "$T/q.pfm"
            set -- $(cat "$T/time")
            qc="$qc $2" qk="$qk $(crmse "$T/q.pfm" "$FREF")"
        done
        echo "Franja at $q spp: CPU$qc s, clamped RMSE$qk; medians $(m $qc) CPU-s, clamped $(m $qk)"
        if awk -v a="$(m $qk)" -v b="$(m $ck)" 'BEGIN { exit !(a <= b) }'; then
            found=1
            awk -v q="$q" -v a="$(m $qk)" -v b="$(m $ck)" -v fc="$(m $qc)" -v crc="$(m $crc)" 'BEGIN {
                printf "equal RMSE, measured: Franja at %d spp (clamped RMSE %.4f, Cycles\47 %.4f at %s spp) takes %.2f CPU-s, Cycles\47 render alone %.2f: Franja/Cycles %.3f\n", q, a, b, "'"$SPP"'", fc, crc, fc / crc }'
            break
        fi
    done
    [ -n "$found" ] || echo "equal RMSE, measured: neither spp reached Cycles' clamped RMSE; the figure at $SPP spp above stands"
fi
