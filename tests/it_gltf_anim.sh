#!/bin/sh
# it_gltf_anim.sh -- tests glTF animations rendered over --frames.
#
# One animated glTF file (tests/support/genanim.py: a box whose node is
# translated, rotated and scaled, a moving point light and a moving camera,
# keys at frames 0..3 of 24 per second) rendered with --frames: each frame
# is byte-identical to a static file with the nodes at that frame's key
# values; --fps 12 puts frame 1 on the key of frame 2; without --frames the
# file renders at rest with a warning; animated morph target weights
# reshape a quad, and a joint moving a skinned strip bends it, as still
# files with the shapes worked out do;
# malformed animation data is refused
# naming the file and the JSON pointer; a gltf shape in a JSON scene is
# posed at the frame too.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need python3 cmp
F=bin/franja
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

python3 tests/support/genanim.py "$T" || bad "genanim.py"
R="--size 48x32 --spp 2 -j 2"
$F render "$T/anim.gltf" --frames 0-3 -o "$T/fr/f.#.pfm" $R >/dev/null 2>"$T/err" || bad "frames: $(cat "$T/err")"
for k in 0 1 2 3; do
    $F render "$T/pose$k.gltf" -o "$T/s$k.pfm" $R >/dev/null 2>&1 || bad "render pose$k.gltf"
    cmp -s "$T/fr/f.$k.pfm" "$T/s$k.pfm" && ok || bad "frame $k differs from the static file at its pose"
done
# the frames differ from each other (the animation moves something)
cmp -s "$T/s0.pfm" "$T/s1.pfm" && bad "frames 0 and 1 render the same" || ok
cmp -s "$T/s1.pfm" "$T/s3.pfm" && bad "frames 1 and 3 render the same" || ok

# --fps: frame 1 at 12 frames per second is time 1/12, frame 2's key at 24
$F render "$T/anim.gltf" --fps 12 --frames 1 -o "$T/fps.#.pfm" $R >/dev/null 2>&1 || bad "--fps 12"
cmp -s "$T/fps.1.pfm" "$T/s2.pfm" && ok || bad "--fps 12 frame 1 is not the pose of frame 2 at 24 fps"
# before the first key and after the last, the ends hold
$F render "$T/anim.gltf" --frames 9 -o "$T/late.#.pfm" $R >/dev/null 2>&1 || bad "frame 9"
cmp -s "$T/late.9.pfm" "$T/s3.pfm" && ok || bad "frame 9 (after the last key) is not the last key's pose"

# morph target weights, animated: each frame is the still quad at its shape
$F render "$T/morph.gltf" --frames 0-2 -o "$T/mo/f.#.pfm" $R >/dev/null 2>"$T/err" || bad "morph: $(cat "$T/err")"
for k in 0 1 2; do
    $F render "$T/morph$k.gltf" -o "$T/m$k.pfm" $R >/dev/null 2>&1 || bad "render morph$k.gltf"
    cmp -s "$T/mo/f.$k.pfm" "$T/m$k.pfm" && ok || bad "morph frame $k differs from the still quad at its shape"
done
cmp -s "$T/m0.pfm" "$T/m2.pfm" && bad "the morph changes nothing" || ok

# a skinned strip whose second joint moves: each frame is the still strip at its pose
$F render "$T/skin.gltf" --frames 0-2 -o "$T/sk/f.#.pfm" $R >/dev/null 2>"$T/err" || bad "skin: $(cat "$T/err")"
for k in 0 1 2; do
    $F render "$T/skin$k.gltf" -o "$T/k$k.pfm" $R >/dev/null 2>&1 || bad "render skin$k.gltf"
    cmp -s "$T/sk/f.$k.pfm" "$T/k$k.pfm" && ok || bad "skin frame $k differs from the still strip at its pose"
done
cmp -s "$T/k0.pfm" "$T/k1.pfm" && bad "the skin changes nothing" || ok

# a gltf shape in a JSON scene is posed at the frame's time too
for f in anim pose1; do
    printf '{ "image": { "width": 48, "height": 32, "spp": 2 }, "materials": {},\n  "shapes": [ { "type": "gltf", "file": "%s.gltf", "camera": true } ] }\n' \
        "$f" >"$T/j$f.json"
done
$F render "$T/janim.json" --frames 1 -o "$T/jf.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "JSON frames: $(cat "$T/err")"
$F render "$T/jpose1.json" -o "$T/jpose1.pfm" -j 2 >/dev/null 2>&1 || bad "JSON still"
cmp -s "$T/jf.1.pfm" "$T/jpose1.pfm" && ok || bad "a gltf shape's frame 1 differs from the still file at that pose"

# without --frames: at rest, said
$F render "$T/anim.gltf" -o "$T/rest.pfm" $R >/dev/null 2>"$T/err" || bad "render at rest"
grep -q "/animations: not played" "$T/err" && ok || bad "no warning that the animations are not played"
expect_error "--fps without --frames" "--fps is for --frames of one glTF or JSON file" $F render "$T/anim.gltf" --fps 30 -o "$T/x.pfm"

# malformed animations: the file and the JSON pointer named
expect_error "sampler index" "bad_sampler.gltf: /animations/0/channels/1: sampler: 7 is not an index" \
    $F render "$T/bad_sampler.gltf" --frames 1 -o "$T/e/a.#.pfm" $R
expect_error "node index" "/animations/1/channels/0/target: node: 99 is not an index into nodes" \
    $F render "$T/bad_node.gltf" --frames 1 -o "$T/e/b.#.pfm" $R
expect_error "output type" "/animations/0/samplers/2/output: accessor 7 has type VEC4, expected 3 components" \
    $F render "$T/bad_type.gltf" --frames 1 -o "$T/e/c.#.pfm" $R
expect_error "cubic count" "/animations/1/samplers/0/output: accessor 9 has 4 elements; 4 key times need 12" \
    $F render "$T/bad_count.gltf" --frames 1 -o "$T/e/d.#.pfm" $R
expect_error "times" "/animations/0/samplers/0/input: accessor 12: time 2 (0.1) is not after time 1 (0.2)" \
    $F render "$T/bad_times.gltf" --frames 1 -o "$T/e/e.#.pfm" $R
expect_error "weights type" "/animations/0/samplers/0/output: accessor 6 has type VEC3, expected 1 components" \
    $F render "$T/bad_weights.gltf" --frames 1 -o "$T/e/f.#.pfm" $R
expect_error "weights count" "/meshes/0/primitives/0/targets: 2 targets, but /animations/0 (a weights channel) gives 3" \
    $F render "$T/bad_morph.gltf" --frames 1 -o "$T/e/g.#.pfm" $R
expect_error "skin joints" "/meshes/0/primitives/0/attributes: JOINTS_0: element 2 names joint 1; /skins/0 has 1" \
    $F render "$T/bad_skin.gltf" --frames 1 -o "$T/e/h.#.pfm" $R
summary
