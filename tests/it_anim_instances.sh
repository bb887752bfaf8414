#!/bin/sh
# it_anim_instances.sh -- tests that a rigid instance moving reuses its compiled mesh.
#
# A JSON mesh placed by two instances, one keyed (translate and rotate),
# beside a plane and a sphere, four frames (coordinator/reuse_placed.h):
# frames 2 to 4 are made of the frame before's mesh sections and a
# skeleton's placements, and every frame's scene is byte for byte the full
# compile of that frame alone, without and with a shutter (the moving
# instance blurred: inst_motions).  A mesh of its file's materials (the
# skeleton cannot make them), a mesh of an interior medium that moves
# around the camera and a mesh whose own transform is keyed compile every
# frame whole, to the bytes of the frame alone.
. "$(dirname "$0")/support/lib.sh"
T=$(mktemp -d) || exit 1
trap 'rm -rf "$T"' EXIT
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$T" || exit 1
"$ROOT/bin/gen/genmesh" knot --tris 6000 -o knot.obj >/dev/null || bad "genmesh"
cat >inst.json <<'JSON'
{ "image": { "width": 16, "height": 12, "spp": 1 },
  "camera": { "position": [0, 1, -4.4], "target": [0, 0.3, 0], "fov": 40 },
  "materials": { "gold": { "type": "phong", "diffuse": [0.4, 0.3, 0.1], "glossy": [0.4, 0.3, 0.1], "exponent": 40 },
                 "w": { "type": "lambert", "albedo": [0.6, 0.6, 0.6] } },
  "lights": [ { "type": "point", "position": [0, 4, -3], "intensity": [20, 20, 20] } ],
  "shapes": [ { "type": "sphere", "center": [1.5, 0, 1], "radius": 0.4, "material": "w" },
              { "type": "mesh", "file": "knot.obj", "material": "gold", "instances": [
                  { "translate": { "keys": [[1, [0, 0, 0]], [4, [1, 0.5, 0]]] },
                    "rotate": { "keys": [[1, [0, 0, 0]], [4, [0, 60, 0]]] } },
                  { "translate": [-1.5, 0, 1] } ] },
              { "type": "plane", "point": [0, -1, 0], "normal": [0, 1, 0], "material": "w" } ] }
JSON
sed 's|"material": "gold", "instances"|"instances"|' inst.json >mtl.json
sed 's|"file": "knot.obj", "material": "gold", "instances": \[|"file": "knot.obj", "material": "gold", "translate": { "keys": [[1, [0, 0, 0]], [4, [0, 1, 0]]] }, "instances": [|' \
    inst.json >own.json

# anim NAME SCENE SHUTTER: frames 1-4 of SCENE, then each alone; every
# frame's scene must be the one of the frame alone.
anim() {
    "$ROOT/bin/franja" render "$2" --frames 1-4 --shutter "$3" -o "$1/f.#.pfm" --keep-job 2>"log-$1" ||
        bad "$1: $(cat "log-$1")"
    for f in 1 2 3 4; do
        "$ROOT/bin/franja" render "$2" --frames $f --shutter "$3" -o "$1-$f/f.#.pfm" --keep-job 2>/dev/null ||
            bad "$1: frame $f alone"
        check "$1: frame $f's scene is the full compile's" \
            cmp -s "$1/f.$f.pfm.franja-job/scene.fbin" "$1-$f/f.$f.pfm.franja-job/scene.fbin"
    done
}
for sh in 0 0.5; do
    anim "inst-$sh" inst.json $sh
    check "inst (shutter $sh): frames 2 to 4 made of the frame before's" \
        test "$(grep -c "scene made of the frame before's" "log-inst-$sh")" -eq 3
done
check "inst: the shutter changes frame 2's scene (the instance blurred)" \
    sh -c "! cmp -s inst-0/f.2.pfm.franja-job/scene.fbin inst-0.5/f.2.pfm.franja-job/scene.fbin"
anim mtl mtl.json 0.5
check "mtl: the file's materials compile every frame whole" test "$(grep -c "scene compiled" log-mtl)" -eq 4
"$ROOT/bin/gen/genmesh" sphere --tris 2000 -o ball.obj >/dev/null || bad "genmesh sphere"
cat >medium.json <<'JSON'
{ "image": { "width": 16, "height": 12, "spp": 1 },
  "camera": { "position": [0, 0, -4], "target": [0, 0, 1], "fov": 40 },
  "media": { "cloud": { "sigma_a": 0.1, "sigma_s": 0.5 } },
  "materials": { "cloud": { "type": "interface", "medium": "cloud" },
                 "w": { "type": "lambert", "albedo": [0.6, 0.6, 0.6] } },
  "lights": [ { "type": "point", "position": [0, 0, 0.5], "intensity": [5, 5, 5] } ],
  "shapes": [ { "type": "mesh", "file": "ball.obj", "material": "cloud",
                "instances": [ { "translate": { "keys": [[1, [0, 0, 0]], [4, [0, 0, -4.5]]] } } ] },
              { "type": "plane", "point": [0, -3, 0], "normal": [0, 1, 0], "material": "w" } ] }
JSON
anim medium medium.json 0
check "medium: a mesh that may hold the camera compiles every frame whole" \
    test "$(grep -c "scene compiled" log-medium)" -eq 4
anim own own.json 0
check "own: a mesh moving itself compiles every frame whole" test "$(grep -c "scene compiled" log-own)" -eq 4
summary
