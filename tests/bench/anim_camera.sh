#!/bin/sh
# anim_camera.sh -- compile time and bytes sent per frame of a camera move.
#
# A camera-only animation of a large scene: a knot of TRIS triangles
# (default 1 M, bin/gen/genmesh) in a JSON scene whose camera position is
# keyed (json_keys.h), FRAMES frames (default 3) rendered with --frames
# over one fake SSH host (tests/support/fakehosts.sh: sshd on loopback),
# 64x64 at 1 spp.  Prints the median of three `franja compile` times of
# the scene (a full compile: what the first frame costs), the .fbin's
# size, then RUNS renders of the animation (default 3; the host's scene
# cache emptied before each) and per frame the medians of what the
# coordinator says: the frame's compile time (a full compile, or the
# frame made of the frame before's sections: coordinator/reuse.h) and the
# bytes it sent the host (the packed scene, or a patch: common/fpatch.h).
# MOVE=instance keeps the camera still and keys instead the translation
# of one of two instances of the knot (a rigid object moving); MOVE=gltf
# is that scene as glTF (tests/bench/anim_gltf.py: one mesh drawn by two
# nodes, one node's translation animated), rendered at 64x64, 1 spp.
# Results: tests/bench/README.md, "A camera move through a large scene".
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
. "$ROOT/tests/support/fakehosts.sh"
fh_init
cd "$ROOT" || exit 1
TRIS=${TRIS:-1000000}
FRAMES=${FRAMES:-3}
. tests/support/bench_common.sh
make -s bin/franja bin/franja-worker bin/gen/genmesh >/dev/null || exit 1
T=$FH
bin/gen/genmesh knot --tris "$TRIS" -o "$T/knot.obj" >/dev/null || exit 1
CAM='"position": { "keys": [[1, [0, 1, -3.4]], [24, [2.4, 1, -2.4]]] }'
INST=''
if [ "${MOVE:-camera}" = instance ]; then
    CAM='"position": [0, 1, -3.4]'
    INST=', "instances": [ { "translate": { "keys": [[1, [0, 0, 0]], [24, [1, 0, 0]]] } }, { "translate": [-1.5, 0, 1] } ]'
fi
cat >"$T/move.json" <<JSON
{ "image": { "width": 64, "height": 64, "spp": 1 },
  "camera": { $CAM, "target": [0, 0.3, 0], "fov": 34 },
  "materials": { "gold": { "type": "phong", "diffuse": [0.4, 0.3, 0.1], "glossy": [0.4, 0.3, 0.1], "exponent": 40 } },
  "lights": [ { "type": "point", "position": [0, 4, -3], "intensity": [20, 20, 20] } ],
  "shapes": [ { "type": "mesh", "file": "knot.obj", "material": "gold"$INST } ] }
JSON
SCENE=$T/move.json
SIZE=""
if [ "${MOVE:-camera}" = gltf ]; then
    SCENE=$T/move.gltf
    SIZE="--size 64x64 --spp 1"
    python3 tests/bench/anim_gltf.py "$T/knot.obj" "$SCENE" || exit 1
fi
machine
times=""
for i in 1 2 3; do
    times="$times $(elapsed "bin/franja compile '$SCENE' -o '$T/move.fbin'")" || exit 1
done
echo "compile of one frame ($TRIS triangles): $times s, median $(median $times) s; .fbin $(stat -c %s "$T/move.fbin") bytes"
fh_start a 2 2
: >"$T/logs"
r=1
while [ $r -le "$RUNS" ]; do
    rm -rf "$T/out" "$FH/a/work/scenes"/*
    s=$(date +%s.%N)
    fr render "$SCENE" $SIZE --frames 1-"$FRAMES" -o "$T/out/f.#.pfm" --hosts "$FH/hosts" 2>"$T/log" ||
        { cat "$T/log"; exit 1; }
    echo "run $r: render of $FRAMES frames over one SSH host: $(calc "$(date +%s.%N) - $s") s"
    sed "s/^/run $r: /" "$T/log" >>"$T/logs"
    r=$((r + 1))
done
f=1
while [ $f -le "$FRAMES" ]; do
    c=$(sed -n "s/^run [0-9]*: franja: frame $f: scene .* in \([0-9.]*\) s.*/\1/p" "$T/logs")
    how=$(sed -n "s/^run 1: franja: frame $f: scene \(compiled\|made of the frame before's\) in.*/\1/p" "$T/logs")
    b=$(sed -n "s/^run [0-9]*: franja: host a: frame $f: scene .*, \([0-9]*\) bytes sent).*/\1/p" "$T/logs")
    echo "frame $f: $how; compile s:" $c "(median $(median $c)); bytes sent:" $b "(median $(median $b))"
    f=$((f + 1))
done
grep -E "^run [0-9]*: +a " "$T/logs"
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
