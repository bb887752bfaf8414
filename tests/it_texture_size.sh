#!/bin/sh
# it_texture_size.sh -- an 8-bit image stays 8-bit in the binary scene.
#
# scenes/textures/bricks.png (256x256, 8-bit RGB) on a rectangle, against
# the same scene with a checker: the .fbin grows by the image's texels, 3
# bytes each, and its mip levels (a third more), so at most 1.4 x 196608
# bytes; stored as 32-bit floats it grew by 786432.  A 16-bit and a half-
# float copy of it (made with oiiotool when it is installed) grow by at
# most 1.4 x twice that, and render within 8-bit rounding of the 8-bit one.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need od
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# scene TEXTURE-DEFINITION: a 32x32 scene of a textured rectangle.
scene() {
    cat <<JSON
{
  "image": {"width": 32, "height": 32, "spp": 4, "max_depth": 1},
  "camera": {"position": [0, 0, 3], "target": [0, 0, 0], "fov": 40},
  "textures": {"t": $1},
  "materials": {"m": {"type": "lambert", "albedo": "t"}},
  "lights": [{"type": "point", "position": [0, 0, 3], "intensity": [9, 9, 9]}],
  "shapes": [{"type": "rect", "origin": [-1, -1, 0], "edge_u": [2, 0, 0], "edge_v": [0, 2, 0], "material": "m"}]
}
JSON
}
cp scenes/textures/bricks.png "$T/bricks.png"
scene '{"type": "image", "file": "bricks.png"}' >"$T/png.json"
scene '{"type": "checker", "colors": [[1, 1, 1], [0, 0, 0]]}' >"$T/checker.json"
size() { wc -c <"$1" | tr -d ' '; }
for s in png checker; do
    bin/franja compile "$T/$s.json" -o "$T/$s.fbin" >/dev/null 2>"$T/err" || bad "compile $s: $(cat "$T/err")"
done
grow=$(($(size "$T/png.fbin") - $(size "$T/checker.fbin")))
texels=$((256 * 256 * 3))
[ "$grow" -gt "$texels" ] && [ $((grow * 10)) -le $((texels * 14)) ] && ok ||
    bad "a 256x256 8-bit RGB image grows the .fbin by $grow bytes (expected $texels to $((texels * 14 / 10)))"

if command -v oiiotool >/dev/null 2>&1; then
    bin/franja-worker --scene "$T/png.fbin" --rows 0:32 -o "$T/png.pfm" || bad "render the 8-bit scene"
    for ty in uint16:tif half:exr; do
        d=${ty%%:*} ext=${ty##*:}
        # The 16-bit copy holds sRGB-encoded values (decoded as the PNG's
        # are), the half one linear values.
        if [ "$d" = half ]; then
            oiiotool "$T/bricks.png" --colorconvert sRGB linear -d half -o "$T/bricks-$d.$ext" 2>"$T/err"
        else
            oiiotool "$T/bricks.png" -d "$d" -o "$T/bricks-$d.$ext" 2>"$T/err"
        fi || { bad "oiiotool $d: $(cat "$T/err")"; continue; }
        scene "{\"type\": \"image\", \"file\": \"bricks-$d.$ext\"}" >"$T/$d.json"
        bin/franja compile "$T/$d.json" -o "$T/$d.fbin" >/dev/null 2>"$T/err" || { bad "compile $d: $(cat "$T/err")"; continue; }
        g=$(($(size "$T/$d.fbin") - $(size "$T/checker.fbin")))
        lim=$((texels * 2 * 14 / 10))
        [ "$g" -le "$lim" ] && ok || bad "$d copy: the .fbin grows by $g bytes (at most $lim)"
        bin/franja-worker --scene "$T/$d.fbin" --rows 0:32 -o "$T/$d.pfm" || bad "render the $d scene"
        bin/tools/imgcmp "$T/$d.pfm" "$T/png.pfm" --max-rmse 0.002 >"$T/cmp" 2>&1 && ok ||
            bad "the $d copy renders away from the 8-bit one: $(cat "$T/cmp")"
    done
fi
summary
