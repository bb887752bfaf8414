#!/bin/sh
# lighttree.sh -- noise of next-event estimation with the light tree
# against the power table, at equal samples and at equal CPU time.
#
# Scenes: a ground lit by a grid of small downward lamps 4 m up and 10 m
# apart (tests/bench/lamps.awk; the camera stands near the ground) with
# 10^2 and 10^4 lamps, and the 10^4 grid cut to the lamps within 30 m of the
# camera (the goal: the full grid within 2x of it at equal time); a cloud
# of 10^5 small emissive triangles over a ground (tests/bench/cloud.awk); a room
# with two large lights (scenes/knot.json) and one (scenes/cornell.json),
# where the tree must not lose; scenes/courtyard.glb; a building's facade at
# night, one emitter of 1024 triangles whose emission texture is black but
# for small lit windows (tests/bench/facade.awk).  Each scene renders
# with "light_sampling" "tree" and "power" (the image block; the glTF file
# inside a JSON scene that says it), SIZE x SIZE at SPP samples, with two
# seeds per run, one process; noise is the relative RMS difference of the
# two seeds over the lower half of the image (the foreground; the whole
# image for the rooms), divided by sqrt 2 (one image's relative noise),
# and "at equal time" scales it by sqrt(CPU seconds / the power table's).
# RUNS runs (seed pairs), medians.  LAMPS6=1 adds the 10^6 grid (a 150 MB
# scene file: minutes to compile).  SCENES picks among lamps, cloud, rooms,
# courtyard and facade (all by default); BIN=DIR renders with the franja
# and franja-worker of DIR (an older build: before and after).  Also prints
# the tree's compile time and the .fbin bytes per light.
cd "$(dirname "$0")/../.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
SPP=${SPP:-16} SIZE=${SIZE:-256} RUNS=${RUNS:-3} BIN=${BIN:-bin}
SCENES=${SCENES:-lamps cloud rooms courtyard facade}
want() { case " $SCENES " in *" $1 "*) return 0 ;; esac; return 1; }
echo "== light tree: relative noise over the foreground, ${SIZE}x${SIZE}, ${SPP} spp, medians of $RUNS seed pairs"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p' | head -n 1), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: sh tests/bench/lighttree.sh   (SPP, SIZE, RUNS, LAMPS6, SCENES, BIN in the environment)"
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
# seeded JSON SEED: the scene JSON with its image's seed set.
seeded() {
    if grep -q '"seed"' "$1"; then
        sed "s/\"seed\": *[0-9]*/\"seed\": $2/" "$1"
    else
        sed "s/\"image\": *{/\"image\": {\"seed\": $2, /" "$1"
    fi
}
# measure NAME JSON_TREE JSON_POWER BAND: one line of figures.
measure() {
    name=$1 band=$4
    for mode in tree power; do
        src=$2
        [ "$mode" = power ] && src=$3
        nt="" tt=""
        for r in $(seq "$RUNS"); do
            for k in 1 2; do
                seeded "$src" $((2 * r + k)) >"$T/s.json"
                t0=$(date +%s.%N)
                "$BIN"/franja compile "$T/s.json" -o "$T/s$k.fbin" >/dev/null || { echo "compile failed: $name"; exit 1; }
                t1=$(date +%s.%N)
                [ "$r$k" = 11 ] && eval "build_$mode=$(awk "BEGIN { print $t1 - $t0 }")"
                /usr/bin/time -f '%U %S' -o "$T/time" "$BIN"/franja-worker --scene "$T/s$k.fbin" --rows 0:"$SIZE" \
                    --spp "$SPP" --size "${SIZE}x$SIZE" -o "$T/i$k.pfm" || exit 1
                tt="$tt $(awk '{ print $1 + $2 }' "$T/time")"
            done
            if [ "$band" = fg ]; then
                nt="$nt $(python3 tests/bench/pfmrel.py "$T/i1.pfm" "$T/i2.pfm" | awk '{ print $1 / sqrt(2) }')"
            else
                nt="$nt $(python3 tests/bench/pfmrel.py "$T/i1.pfm" "$T/i2.pfm" 0 "$SIZE" | awk '{ print $1 / sqrt(2) }')"
            fi
        done
        eval "n_$mode=$(echo $nt | median) t_$mode=$(echo $tt | median)"
    done
    bytes=$(stat -c %s "$T/s1.fbin")
    lights=$("$BIN"/franja-worker --scene "$T/s1.fbin" --check 2>&1 | sed -n 's/.* \([0-9][0-9]*\) lights.*/\1/p')
    awk -v name="$name" -v nt="$n_tree" -v np="$n_power" -v tt="$t_tree" -v tp="$t_power" -v bt="$build_tree" \
        -v bp="$build_power" 'BEGIN {
        et = nt * sqrt(tt / tp)
        printf "%-26s tree %.4f (%.2f CPU-s)  power %.4f (%.2f CPU-s)  at equal time: tree %.4f, power/tree %.1fx;",
               name, nt, tt, np, tp, et, np / et
        printf "  compile %.2f s (power table %.2f s)\n", bt, bp
    }'
    echo "$name $n_tree $t_tree" >>"$T/results"
}
lamps() { # N RADIUS SAMPLING
    awk -v n="$1" -v radius="$2" -v sampling="$3" -v size="$SIZE" -v spp="$SPP" -f tests/bench/lamps.awk
}
if want lamps; then
for n in 10 100; do
    lamps $n "" tree >"$T/lt$n.json"
    lamps $n "" power >"$T/lp$n.json"
    measure "lamps $((n * n))" "$T/lt$n.json" "$T/lp$n.json" fg
done
lamps 100 30 tree >"$T/ltn.json"
lamps 100 30 power >"$T/lpn.json"
measure "lamps within 30 m" "$T/ltn.json" "$T/lpn.json" fg
awk 'BEGIN { while ((getline l < ARGV[1]) > 0) { split(l, f, " "); if (l ~ /^lamps 10000 /) { a = f[3] * sqrt(f[4]) }
             if (l ~ /^lamps within/) { b = f[5] * sqrt(f[6]) } }
             if (b > 0) printf "10^4 lamps against the lamps within 30 m alone, tree, at equal time: %.2fx the noise\n", a / b }' \
    "$T/results"
fi
if [ "${LAMPS6:-0}" = 1 ]; then
    lamps 1000 "" tree >"$T/lt1000.json"
    lamps 1000 "" power >"$T/lp1000.json"
    measure "lamps 1000000" "$T/lt1000.json" "$T/lp1000.json" fg
fi
if want cloud; then
awk -v n=100000 -v size="$SIZE" -v spp="$SPP" -f tests/bench/cloud.awk >"$T/ct.json"
awk -v n=100000 -v size="$SIZE" -v spp="$SPP" -v sampling=power -f tests/bench/cloud.awk >"$T/cp.json"
measure "cloud of 10^5 triangles" "$T/ct.json" "$T/cp.json" fg
fi
want rooms && for s in knot cornell; do
    sed 's/"image": {/"image": {"light_sampling": "power", /' scenes/$s.json >"$T/p-$s.json"
    cp scenes/$s.json "$T/t-$s.json"
    cp -r scenes/meshes scenes/textures "$T/" 2>/dev/null
    measure "$s" "$T/t-$s.json" "$T/p-$s.json" all
done
# A scene reads only files in its own folder: the glTF file goes beside it.
want courtyard && cp scenes/courtyard.glb "$T/" && for mode in tree power; do
    printf '{"image": {"width": %d, "height": %d, "spp": %d, "light_sampling": "%s"}, "materials": {},\n "shapes": [{"type": "gltf", "file": "courtyard.glb", "camera": "camera"}]}\n' \
        "$SIZE" "$SIZE" "$SPP" "$mode" >"$T/c-$mode.json"
done
want courtyard && measure "courtyard.glb" "$T/c-tree.json" "$T/c-power.json" all
if want facade; then
    awk -v dir="$T" -v size="$SIZE" -v spp="$SPP" -f tests/bench/facade.awk >"$T/ft.json"
    awk -v dir="$T" -v size="$SIZE" -v spp="$SPP" -v sampling=power -f tests/bench/facade.awk >"$T/fp.json"
    measure "facade, lit windows" "$T/ft.json" "$T/fp.json" fg
fi
