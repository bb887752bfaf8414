#!/bin/sh
# it_gltf_anim_instances.sh -- tests that a glTF mesh placed by moving instances reuses its compiled mesh.
#
# tests/support/genanim.py's anim.gltf (a box on a node whose translation,
# rotation and scale are keyed over frames 0 to 3, a floor, an animated
# light and camera) with a second node drawing the box's mesh: the mesh
# is placed by two instances (scene_hooks.h's mesh_bounds).  Frames 1 to 3
# are made of the frame before's mesh sections and a skeleton's
# placements, and every frame's scene and image are byte for byte those
# of the frame alone, without and with a shutter (the moving instance
# blurred).  With the floor (a mesh on one node, in the world's
# triangles without a shutter) moved by the box's keys too and no shutter,
# every frame compiles whole.
# The box on one node is an instance when it moves across the
# shutter, made of the frame before's too; without a shutter it is
# flattened into the world's triangles where it stands: every frame
# compiles whole.
. "$(dirname "$0")/support/lib.sh"
T=$(mktemp -d) || exit 1
trap 'rm -rf "$T"' EXIT
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$T" || exit 1
python3 "$ROOT/tests/support/genanim.py" . >/dev/null || bad "genanim.py"
python3 - <<'PY' || bad "twin.gltf"
import json
d = json.load(open('anim.gltf'))
d['nodes'].append({"name": "box2", "mesh": 0, "translation": [1.5, 0.6, -1.0], "scale": [0.5, 0.5, 0.5]})
d['scenes'][0]['nodes'].append(len(d['nodes']) - 1)
json.dump(d, open('twin.gltf', 'w'))
d['animations'][0]['channels'].append({"sampler": 0, "target": {"node": 0, "path": "translation"}})
json.dump(d, open('floor.gltf', 'w'))
PY

# anim NAME SCENE SHUTTER: frames 0-3 of SCENE, then each alone; every
# frame's scene and image must be those of the frame alone.
anim() {
    "$ROOT/bin/franja" render "$2" --frames 0-3 --shutter "$3" -o "$1/f.#.pfm" --size 32x16 --spp 1 \
        --keep-job 2>"log-$1" || bad "$1: $(cat "log-$1")"
    for f in 0 1 2 3; do
        "$ROOT/bin/franja" render "$2" --frames $f --shutter "$3" -o "$1-$f/f.#.pfm" --size 32x16 --spp 1 \
            --keep-job 2>/dev/null || bad "$1: frame $f alone"
        check "$1: frame $f's scene is the full compile's" \
            cmp -s "$1/f.$f.pfm.franja-job/scene.fbin" "$1-$f/f.$f.pfm.franja-job/scene.fbin"
        check "$1: frame $f's image is the frame's alone" cmp -s "$1/f.$f.pfm" "$1-$f/f.$f.pfm"
    done
}
# made NAME N WHAT: frames of NAME's log made of the frame before's (N)
# or compiled whole (4 - N).
made() {
    check "$1: $3" test "$(grep -c "scene made of the frame before's" "log-$1")" -eq "$2"
    check "$1: the other frames compiled whole" test "$(grep -c "scene compiled" "log-$1")" -eq $((4 - $2))
}
anim twin-0 twin.gltf 0
anim twin-0.5 twin.gltf 0.5
made twin-0 3 "frames 1 to 3 made of the frame before's"
made twin-0.5 3 "frames 1 to 3 made of the frame before's, blurred"
check "twin: the shutter changes frame 1's scene (the instance blurred)" \
    sh -c "! cmp -s twin-0/f.1.pfm.franja-job/scene.fbin twin-0.5/f.1.pfm.franja-job/scene.fbin"
anim floor floor.gltf 0
made floor 0 "a flattened mesh moving: no frame made of the frame before's"
anim one-0.5 anim.gltf 0.5
made one-0.5 3 "one moving node blurred (an instance): frames 1 to 3 made of the frame before's"
anim one-0 anim.gltf 0
made one-0 0 "one moving node, sharp (flattened): no frame made of the frame before's"
summary
