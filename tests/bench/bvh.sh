#!/bin/sh
# BVH and binary scene against Embree 3 on the same triangles and rays:
# build time (100 k and 1 M triangles, one thread each), closest-hit and
# any-hit Mrays/s for primary and diffuse-bounce rays (one thread), worker
# start-up on the 1 M-triangle binary scene (process start to first pixel)
# and binary scene bytes per triangle.  Medians of REPS runs (default 5);
# ratios are Franja / Embree (higher is better for Franja).
cd "$(dirname "$0")/../.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
REPS=${REPS:-5}
echo "== bvh: Franja BVH vs Embree 3 (single thread), binary scene"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: REPS=$REPS sh tests/bench/bvh.sh"
for n in 100000 1000000; do
    bin/tools/genmesh knot --tris $n -o "$T/knot.obj" || exit 1
    cat >"$T/knot.json" <<JSON
{"image": {"width": 512, "height": 512, "spp": 1},
 "camera": {"position": [0, 1.2, -2.6], "target": [0, 0, 0], "fov": 45},
 "materials": {"m": {"type": "lambert", "albedo": [0.7, 0.7, 0.7]}},
 "lights": [{"type": "point", "position": [2, 4, -3], "intensity": [20, 20, 20]}],
 "shapes": [{"type": "mesh", "file": "knot.obj", "material": "m"}]}
JSON
    echo "-- torus knot, $n triangles requested"
    echo "\$ bin/franja compile knot.json -o knot.fbin"
    bin/franja compile "$T/knot.json" -o "$T/knot.fbin" || exit 1
    echo "\$ bin/bench/bvhbench knot.fbin --reps $REPS --worker bin/franja-worker"
    bin/bench/bvhbench "$T/knot.fbin" --reps "$REPS" --worker bin/franja-worker || exit 1
    rm -f "$T/knot.obj" "$T/knot.fbin"
done
