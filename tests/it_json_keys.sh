#!/bin/sh
# it_json_keys.sh -- tests keyframed values of JSON scenes over --frames.
#
# A JSON scene whose camera, sphere and mesh instance have keyed fields
# (json_keys.h) rendered with --frames (no # in its name: the one file is
# posed per frame): each frame is byte-identical to a still scene written
# with that frame's values (linear between keys, step, held before the
# first key and after the last); a keyed camera with a shutter (the
# camera's `shutter` key, or --shutter) is blurred like a moving glTF
# camera, identically across -j 1 and -j 2 --slab-rows 5; without
# --frames the scene is posed at frame 0 with a warning; malformed keys are
# refused naming the JSON path.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need cmp
F=bin/franja
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

cat >"$T/tet.obj" <<'OBJ'
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
OBJ
# scene CAMERA SPHERE_CENTRE INSTANCE_TRANSLATE: a scene with those fields
scene() {
    cat <<JSON
{
  "image": { "width": 48, "height": 32, "spp": 4, "max_depth": 3 },
  "camera": { "position": $1, "target": [0, 0.5, 0], "fov": 50 },
  "materials": { "white": { "type": "lambert", "albedo": [0.7, 0.7, 0.7] },
                 "red": { "type": "lambert", "albedo": [0.8, 0.2, 0.1] } },
  "lights": [ { "type": "point", "position": [2, 4, 3], "intensity": [40, 40, 40] } ],
  "shapes": [
    { "type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "white" },
    { "type": "sphere", "center": $2, "radius": 0.5, "material": "red" },
    { "type": "mesh", "file": "tet.obj", "material": "white", "instances": [
        { "translate": $3 }, { "translate": [-1.5, 0, -1], "rotate": [0, 30, 0] } ] }
  ]
}
JSON
}
scene '{ "keys": [[1, [0, 1.5, 5]], [3, [1, 2, 4]]], "interpolation": "step" }' \
      '{ "keys": [[1, [-1, 0.5, 0]], [3, [1, 0.5, 0]], [5, [1, 1.5, 0]]] }' \
      '{ "keys": [[2, [0.5, 0, 1]], [4, [1.5, 0, 2]]] }' >"$T/anim.json"
scene '[0, 1.5, 5]' '[-1, 0.5, 0]' '[0.5, 0, 1]' >"$T/s1.json"
scene '[0, 1.5, 5]' '[0, 0.5, 0]' '[0.5, 0, 1]' >"$T/s2.json"
scene '[1, 2, 4]' '[1, 0.5, 0]' '[1, 0, 1.5]' >"$T/s3.json"
scene '[1, 2, 4]' '[1, 1.5, 0]' '[1.5, 0, 2]' >"$T/s9.json"
$F render "$T/anim.json" --frames 1-3,9 -o "$T/fr/f.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "frames: $(cat "$T/err")"
for k in 1 2 3 9; do
    $F render "$T/s$k.json" -o "$T/s$k.pfm" -j 2 >/dev/null 2>&1 || bad "render s$k.json"
    cmp -s "$T/fr/f.$k.pfm" "$T/s$k.pfm" && ok || bad "frame $k differs from the still scene at its values"
done
cmp -s "$T/s1.pfm" "$T/s2.pfm" && bad "frames 1 and 2 render the same" || ok

# without --frames: frame 0 (the first keys), said
$F render "$T/anim.json" -o "$T/rest.pfm" -j 2 >/dev/null 2>"$T/err" || bad "render at rest: $(cat "$T/err")"
grep -q "keyed values are posed at frame 0" "$T/err" && ok || bad "no warning at rest: $(cat "$T/err")"
cmp -s "$T/rest.pfm" "$T/s1.pfm" && ok || bad "frame 0 is not the first keys' pose"

# a keyed camera under a shutter: the camera's key, or --shutter
cat >"$T/blur.json" <<'JSON'
{
  "image": { "width": 64, "height": 16, "spp": 64 },
  "camera": { "position": { "keys": [[0, [0, 0, 0]], [24, [96, 0, 0]]] },
              "target": { "keys": [[0, [0, 0, -1]], [24, [96, 0, -1]]] },
              "fov": 53.13010235415598, "shutter": 0.5 },
  "materials": { "glow": { "type": "emitter", "emission": [1, 1, 1] } },
  "shapes": [ { "type": "quad", "vertices": [[46.5, -5, -4], [49.5, -5, -4], [49.5, 5, -4], [46.5, 5, -4]],
                "material": "glow" } ]
}
JSON
sed 's/, "shutter": 0.5//' "$T/blur.json" >"$T/blur2.json"
$F render "$T/blur.json" --frames 12 -o "$T/b.#.pfm" -j 1 >/dev/null 2>"$T/err" || bad "blur: $(cat "$T/err")"
$F render "$T/blur.json" --frames 12 -o "$T/c.#.pfm" -j 2 --slab-rows 5 >/dev/null 2>&1 || bad "blur -j 2"
$F render "$T/blur2.json" --frames 12 --shutter 0.5 -o "$T/d.#.pfm" -j 2 >/dev/null 2>&1 || bad "blur --shutter"
$F render "$T/blur2.json" --frames 12 -o "$T/e.#.pfm" -j 2 >/dev/null 2>&1 || bad "no shutter"
cmp -s "$T/b.12.pfm" "$T/c.12.pfm" && ok || bad "-j 1 and -j 2 --slab-rows 5 differ"
cmp -s "$T/b.12.pfm" "$T/d.12.pfm" && ok || bad "--shutter 0.5 and the camera's shutter 0.5 differ"
cmp -s "$T/b.12.pfm" "$T/e.12.pfm" && bad "the shutter blurs nothing" || ok
# the smear's ends: columns 21 and 42 dark, 22 and 41 lit a little, 30 to 33 fully
python3 - "$T/b.12.pfm" <<'PY' >"$T/check" 2>&1 || bad "profile: $(cat "$T/check")"
import sys
sys.path.insert(0, 'tests/support')
from pfmcols import columns
col = columns(sys.argv[1])
print(col[21] < 0.01 and col[42] < 0.01 and 0.01 < col[22] < 0.15 and 0.01 < col[41] < 0.15 and
      all(c > 0.97 for c in col[30:34]), ' '.join('%.2f' % c for c in col[20:44]))
PY
grep -q "^True" "$T/check" && ok || bad "the JSON camera's smear: $(cat "$T/check")"

# malformed keys: the JSON path named
sed 's/\[3, \[1, 0.5, 0\]\]/[1, [1, 0.5, 0]]/' "$T/anim.json" >"$T/bad1.json"
expect_error "frames not increasing" "shapes[1].center.keys[1]: frame 1 is not after the key before (1)" \
    $F render "$T/bad1.json" --frames 2 -o "$T/x/a.#.pfm"
sed 's/\[3, \[1, 0.5, 0\]\]/[3, 7]/' "$T/anim.json" >"$T/bad2.json"
expect_error "unlike values" "shapes[1].center.keys[1][1]: a value unlike the first key's" \
    $F render "$T/bad2.json" --frames 2 -o "$T/x/b.#.pfm"
sed 's/"interpolation": "step"/"interpolation": "cubic"/' "$T/anim.json" >"$T/bad3.json"
expect_error "interpolation" "camera.position.interpolation: expected \"linear\" or \"step\"" \
    $F render "$T/bad3.json" --frames 2 -o "$T/x/c.#.pfm"
sed 's/\[\[2, \[0.5, 0, 1\]\]/[[2, [0.5, 0, 1], 5]/' "$T/anim.json" >"$T/bad4.json"
expect_error "key shape" "shapes[2].instances[0].translate.keys[0]: expected [frame, value]" \
    $F render "$T/bad4.json" --frames 2 -o "$T/x/d.#.pfm"
summary
