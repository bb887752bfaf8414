#!/bin/sh
# it_gltf_blender.sh -- tests that frame f of a Blender animation is frame f here.
#
# Blender (tests/support/blender_anim.py) keys a cube's location, rotation
# and scale at frames 1, 4 and 10 of a 24-frames-a-second scene and exports
# it, with its camera and light, as a glTF binary file; franja renders it
# over --frames 1-10.  Each frame is compared with still copies of the file
# (tests/support/glbpose.py) that hold the cube where Blender itself puts it
# at a frame: frame 1 (the cube at rest) is the still of frame 1 byte for
# byte; frames 4 and 7 (a key, and a frame between keys on the curve the
# exporter bakes) are within rounding of the still of their own frame --
# the exporter rounds its rotation and scale through a matrix, a few units
# in the seventh digit -- and at least ten times as close to it as to the
# stills of the frames before and after (a numbering one frame off would
# match one of those instead).
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need blender python3 cmp
F=bin/franja
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

blender -b --factory-startup --python tests/support/blender_anim.py -- "$T" 1 3 4 5 6 7 8 >"$T/blender.log" 2>&1 &&
    [ -s "$T/anim.glb" ] || { bad "Blender's export: $(tail -n 5 "$T/blender.log")"; summary; exit 1; }
R="--size 64x48 --spp 2 -j 2"
$F render "$T/anim.glb" --frames 1-10 -o "$T/fr/f.#.pfm" $R >/dev/null 2>"$T/err" || bad "frames 1-10: $(cat "$T/err")"
for k in 1 3 4 5 6 7 8; do
    python3 tests/support/glbpose.py "$T/anim.glb" Cube "$T/pose-$k.json" "$T/still-$k.glb" || bad "glbpose.py $k"
    $F render "$T/still-$k.glb" -o "$T/s$k.pfm" $R >/dev/null 2>"$T/err" || bad "still $k: $(cat "$T/err")"
done
cmp -s "$T/fr/f.1.pfm" "$T/s1.pfm" && ok || bad "frame 1 differs from the cube at Blender's pose of frame 1"
rmse() { bin/tools/imgcmp "$1" "$2" | sed -n 's/^rmse \([0-9.e+-]*\).*/\1/p'; }
for k in 4 7; do
    own=$(rmse "$T/fr/f.$k.pfm" "$T/s$k.pfm")
    before=$(rmse "$T/fr/f.$k.pfm" "$T/s$((k - 1)).pfm")
    after=$(rmse "$T/fr/f.$k.pfm" "$T/s$((k + 1)).pfm")
    awk -v o="$own" -v b="$before" -v a="$after" 'BEGIN { exit !(o != "" && o < 1e-3 && 10 * o < b && 10 * o < a) }' && ok ||
        bad "frame $k: RMSE $own to Blender's frame $k, $before to frame $((k - 1)), $after to frame $((k + 1))"
done
summary
