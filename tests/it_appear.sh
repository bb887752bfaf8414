#!/bin/sh
# it_appear.sh -- tests the appearance scenes compile and render end to end.
#
# The appearance scenes end to end: each compiles (image textures through
# OpenImageIO) and renders a slab; the worker alone refuses a JSON scene with
# image textures and says to compile it; textures really reach the binary
# scene (a flat-coloured texture renders like the plain colour); tone
# mapping options reach the output; bad textures are refused with the path.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
F=bin/franja W=bin/franja-worker
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

for s in cornell-textured dof-spheres fog-room bumpy; do
    if $F compile scenes/$s.json -o "$T/$s.fbin" >"$T/log" 2>&1; then ok; else bad "$s does not compile: $(cat "$T/log")"; continue; fi
    if $W --scene "$T/$s.fbin" --rows 3:5 --size 8x8 --spp 2 -o "$T/$s.pf" 2>"$T/log"; then ok; else bad "$s: worker: $(cat "$T/log")"; fi
done
expect_error "worker and image textures" "franja compile" $W --scene scenes/cornell-textured.json --rows 0:1 -o "$T/x.pf"

# A 4x4 PNG of one colour, as a texture, against the same colour given as
# numbers (after sRGB decoding: 8-bit 188 is linear 0.5029).
oiiotool --pattern constant:color=0.7373,0.7373,0.7373 4x4 3 -d uint8 -o "$T/grey.png" 2>"$T/log" || bad "oiiotool: $(cat "$T/log")"
scene() {
    cat >"$T/$1.json" <<JSON
{"image": {"width": 8, "height": 8, "spp": 4},
 "camera": {"position": [0, 0, 3], "target": [0, 0, 0], "fov": 40},
 "textures": {"grey": {"type": "image", "file": "grey.png"}},
 "materials": {"m": {"type": "lambert", "albedo": $2}, "lamp": {"type": "emitter", "emission": [3, 3, 3]}},
 "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"},
            {"type": "sphere", "center": [1, 2, 2], "radius": 0.5, "material": "lamp"}]}
JSON
}
scene tex '"grey"'
scene plain '[0.50289, 0.50289, 0.50289]'
$F compile "$T/tex.json" -o "$T/tex.fbin" >/dev/null && $F compile "$T/plain.json" -o "$T/plain.fbin" >/dev/null || bad "compile the grey scenes"
$W --scene "$T/tex.fbin" --rows 0:8 --format ppm16 -o "$T/tex.ppm" && $W --scene "$T/plain.fbin" --rows 0:8 --format ppm16 -o "$T/plain.ppm" || bad "render the grey scenes"
# The same pixels up to the rounding of the colour written as numbers.
if oiiotool "$T/tex.ppm" "$T/plain.ppm" --fail 0.0001 --warn 0.0001 --diff >"$T/log" 2>&1; then ok; else
    bad "a one-colour PNG texture renders differently from its colour: $(head -5 "$T/log")"
fi
# And a different colour does differ (the comparison can fail).
scene other '[0.45, 0.45, 0.45]'
$F compile "$T/other.json" -o "$T/other.fbin" >/dev/null && $W --scene "$T/other.fbin" --rows 0:8 --format ppm16 -o "$T/other.ppm" || bad "render the other grey"
if oiiotool "$T/tex.ppm" "$T/other.ppm" --fail 0.0001 --warn 0.0001 --diff >/dev/null 2>&1; then bad "the texture comparison cannot fail"; else ok; fi

# A float image (EXR) holds linear values: no sRGB decoding by default.
oiiotool --pattern constant:color=0.5,0.5,0.5 4x4 3 -d half -o "$T/grey.exr" 2>"$T/log" || bad "oiiotool exr: $(cat "$T/log")"
sed 's/grey.png/grey.exr/' "$T/tex.json" >"$T/exr.json"
scene half '[0.5, 0.5, 0.5]'
$F compile "$T/exr.json" -o "$T/exr.fbin" >/dev/null && $W --scene "$T/exr.fbin" --rows 0:8 --format ppm16 -o "$T/exr.ppm" &&
    $F compile "$T/half.json" -o "$T/half.fbin" >/dev/null && $W --scene "$T/half.fbin" --rows 0:8 --format ppm16 -o "$T/half.ppm" || bad "render the EXR scenes"
if oiiotool "$T/exr.ppm" "$T/half.ppm" --fail 0.0001 --warn 0.0001 --diff >"$T/log" 2>&1; then ok; else
    bad "an EXR texture of 0.5 renders differently from albedo 0.5: $(head -5 "$T/log")"
fi

# Tone mapping from the scene and the command line.
$F render scenes/dof-spheres.json -o "$T/a.png" --size 32x16 --spp 2 -j 2 >/dev/null 2>&1 &&
    $F render scenes/dof-spheres.json -o "$T/b.png" --size 32x16 --spp 2 -j 2 --tonemap filmic --exposure 1 >/dev/null 2>&1 || bad "render with --tonemap"
if cmp -s "$T/a.png" "$T/b.png"; then bad "--tonemap filmic --exposure 1 changed nothing"; else ok; fi
expect_error "bad --tonemap" "--tonemap" $F render scenes/dof-spheres.json -o "$T/c.png" --tonemap aces

# Bad textures are refused with the JSON path.
cp "$T/grey.png" "$T/grey.gif"
sed 's/grey.png/missing.png/' "$T/tex.json" >"$T/missing.json"
sed 's/grey.png/grey.gif/' "$T/tex.json" >"$T/gif.json"
printf 'not a png' >"$T/junk.png"
sed 's/grey.png/junk.png/' "$T/tex.json" >"$T/junk.json"
expect_error "missing texture file" "textures.grey.file" $F compile "$T/missing.json" -o "$T/x.fbin"
expect_error "unsupported format" "unsupported image format" $F compile "$T/gif.json" -o "$T/x.fbin"
expect_error "corrupt image" "textures.grey.file" $F compile "$T/junk.json" -o "$T/x.fbin"

summary
