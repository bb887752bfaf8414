#!/bin/sh
# bvh.sh -- measures the BVH and binary scene against Embree 3.
#
# BVH and binary scene against Embree 3 on the same triangles and rays:
# build time (one thread each; Embree at its default and at its high,
# spatial-split build quality), closest-hit and any-hit Mrays/s for primary
# and diffuse-bounce rays (one thread), worker start-up (process start to
# first pixel) and binary scene bytes per triangle, on a torus knot, a
# terrain and a sheet of long thin diagonal slivers, each at 100 k and 1 M
# triangles.  Medians of REPS runs (default 5); MESHES and SIZES pick a
# subset.  RAYS (default 1024x1024) is the grid of primary rays, one per
# pixel of the scene's camera; the bounce rays start where they hit, so a
# bounce pass holds 0.3-0.5 M rays and lasts 0.07-1.2 s on a 2-core AMD EPYC
# VM, long enough for two runs' ratios to agree within about 0.01 there
# (512x512 gave passes of 20-350 ms whose ratios moved by 0.1).  Each
# `walks` line times every BVH walk the processor runs (portable, AVX2,
# AVX-512) in the same rounds, with the AVX-512 walk's rate over the AVX2
# walk's.  Ratios of rays/s are Franja / Embree (higher is better for
# Franja), of build times Franja / Embree (lower is better).
cd "$(dirname "$0")/../.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
REPS=${REPS:-5}
RAYS=${RAYS:-1024x1024}
MESHES=${MESHES:-knot terrain thin}
SIZES=${SIZES:-100000 1000000}
echo "== bvh: Franja BVH vs Embree 3 (single thread), binary scene"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: REPS=$REPS RAYS=$RAYS MESHES='$MESHES' SIZES='$SIZES' sh tests/bench/bvh.sh"
for mesh in $MESHES; do
    for n in $SIZES; do
        bin/gen/genmesh "$mesh" --tris "$n" -o "$T/mesh.obj" || exit 1
        cat >"$T/mesh.json" <<JSON
{"image": {"width": 512, "height": 512, "spp": 1},
 "camera": {"position": [0, 1.2, -2.6], "target": [0, 0, 0], "fov": 45},
 "materials": {"m": {"type": "lambert", "albedo": [0.7, 0.7, 0.7]}},
 "lights": [{"type": "point", "position": [2, 4, -3], "intensity": [20, 20, 20]}],
 "shapes": [{"type": "mesh", "file": "mesh.obj", "material": "m"}]}
JSON
        echo "-- $mesh, $n triangles requested (load $(cut -d' ' -f1 /proc/loadavg))"
        echo "\$ bin/gen/genmesh $mesh --tris $n -o mesh.obj && bin/franja compile mesh.json -o mesh.fbin"
        bin/franja compile "$T/mesh.json" -o "$T/mesh.fbin" || exit 1
        echo "\$ bin/bench/bvhbench mesh.fbin --reps $REPS --size $RAYS --worker bin/franja-worker"
        bin/bench/bvhbench "$T/mesh.fbin" --reps "$REPS" --size "$RAYS" --worker bin/franja-worker || exit 1
        rm -f "$T/mesh.obj" "$T/mesh.fbin"
    done
done
