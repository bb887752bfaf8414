#!/bin/sh
# motion.sh -- render cost of moving instances (motion blur) against the still scene.
#
# A floor and nine instances of the 24 k-triangle knot (scenes/meshes/knot.obj),
# each with a keyed translate and rotate, rendered at frame 5 with
# --shutter 0.5 (every knot a moving instance: each ray blends its
# transform at the sample's time) and without (the same nine instances,
# still); 240x180 at 64 spp, one process (-j 1).  Prints the CPU time
# (user + system, of franja and its workers) of each of RUNS runs
# (default 3), alternating, and the medians.  Results:
# tests/bench/README.md, "Motion blur of moving instances".
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
cd "$ROOT" || exit 1
. tests/support/bench_common.sh
make -s bin/franja bin/franja-worker >/dev/null || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
cp scenes/meshes/knot.obj scenes/meshes/gold.mtl "$T/" 2>/dev/null || cp scenes/meshes/knot.obj "$T/"
inst=""
for i in 0 1 2; do
    for j in 0 1 2; do
        x=$((i * 3 - 3)) z=$((j * 3 - 3))
        inst="$inst${inst:+, }{ \"translate\": { \"keys\": [[0, [$((x - 5)), 0.6, $z]], [10, [$((x + 5)), 0.6, $z]]] },
            \"rotate\": { \"keys\": [[0, [0, 0, 0]], [10, [0, $((400 + 40 * i)), 0]]] } }"
    done
done
cat >"$T/knots.json" <<JSON
{ "image": { "width": 240, "height": 180, "spp": 64, "max_depth": 4 },
  "camera": { "position": [0, 6, -11], "target": [0, 0.3, 0], "fov": 45 },
  "materials": { "gold": { "type": "phong", "diffuse": [0.4, 0.3, 0.1], "glossy": [0.4, 0.3, 0.1], "exponent": 40 },
                 "floor": { "type": "lambert", "albedo": [0.5, 0.5, 0.5] } },
  "lights": [ { "type": "point", "position": [0, 8, -4], "intensity": [120, 120, 120] } ],
  "shapes": [ { "type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor" },
              { "type": "mesh", "file": "knot.obj", "material": "gold", "instances": [ $inst ] } ] }
JSON
machine
cpu() { # ARGS...: CPU seconds (user + system, children included) of one render
    rm -f "$T"/o.*.pfm
    /usr/bin/time -f '%U %S' -o "$T/t" bin/franja render "$T/knots.json" --frames 5 -j 1 -o "$T/o.#.pfm" "$@" \
        >/dev/null 2>"$T/log" || { cat "$T/log" >&2; return 1; }
    awk '{ printf "%.2f", $1 + $2 }' "$T/t"
}
ls="" lm=""
for i in $(seq "$RUNS"); do
    ls="$ls $(cpu)" || exit 1
    lm="$lm $(cpu --shutter 0.5)" || exit 1
done
echo "still:  $ls s CPU, median $(median $ls)"
echo "moving: $lm s CPU, median $(median $lm)"
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
