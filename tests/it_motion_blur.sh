#!/bin/sh
# it_motion_blur.sh -- tests motion blur of a moving camera (--shutter).
#
# A camera moving at constant speed past an emissive quad (blur.gltf of
# tests/support/genanim.py: 12 pixels wide, smeared over 8 pixels by a
# shutter of half a frame): without --shutter the quad's edges are sharp;
# with it, each column's mean is the analytic smear, the quad's box
# convolved with the 8-pixel shutter path and averaged over the pixel (a
# trapezoid: ramps 8 pixels long, a plateau of 4), within the noise of
# 64 x 16 samples a column; the total light is the quad's; the frame is
# byte-identical across -j 1, -j 2 --slab-rows 5 and two fake SSH hosts,
# and its pixels the same as a JSON scene's that places the file;
# under the bidirectional integrator a camera sliding past a sunlit quad
# (light-traced paths seen through the camera at each sample's time)
# smears as the analytic one, byte-identical across splits; Metropolis
# light transport refuses motion blur.
. "$(dirname "$0")/support/fakehosts.sh"
need python3 cmp
fh_init
cd "$ROOT" || exit 1
F=bin/franja T=$FH
python3 tests/support/genanim.py "$T" || bad "genanim.py"
R="--size 64x16 --spp 64"
$F render "$T/blur.gltf" --frames 12 -o "$T/sharp.#.pfm" $R -j 2 >/dev/null 2>"$T/err" || bad "sharp: $(cat "$T/err")"
$F render "$T/blur.gltf" --frames 12 --shutter 0.5 -o "$T/a.#.pfm" $R -j 1 >/dev/null 2>"$T/err" ||
    bad "blur: $(cat "$T/err")"

# analytic: the quad covers [26, 38) at the frame's time; across the
# shutter it is shifted by s in [-4, 4] (uniform); pixel x gets the mean
# over s and over [x, x + 1) of the coverage.
python3 - "$T/sharp.12.pfm" "$T/a.12.pfm" <<'PY' >"$T/check" || bad "profile check did not run"
import sys
sys.path.insert(0, 'tests/support')
from pfmcols import columns, smear_report
smear_report(columns(sys.argv[1]), columns(sys.argv[2]), 26, 38, 8, 1e-6)
PY
grep -q "^sharp True" "$T/check" && ok || bad "without a shutter the quad's edges are not sharp: $(cat "$T/check")"
grep -q "^smear True" "$T/check" && ok || bad "the smear is not the analytic one: $(cat "$T/check")"
grep -q "^total True" "$T/check" && ok || bad "the smear does not keep the quad's light: $(cat "$T/check")"
grep -q "^spread 20 12$" "$T/check" && ok || bad "the smear's width: $(cat "$T/check")"

# split invariance
$F render "$T/blur.gltf" --frames 12 --shutter 0.5 -o "$T/b.#.pfm" $R -j 2 --slab-rows 5 >/dev/null 2>&1 ||
    bad "render -j 2 --slab-rows 5"
cmp -s "$T/a.12.pfm" "$T/b.12.pfm" && ok || bad "-j 1 and -j 2 --slab-rows 5 differ"
fh_start a 2 2
fh_start b 3 1
fr render "$T/blur.gltf" --frames 12 --shutter 0.5 -o "$T/c.#.pfm" $R --hosts "$FH/hosts" --slab-rows 3 \
    >/dev/null 2>"$T/err" || bad "fake SSH hosts: $(cat "$T/err")"
cmp -s "$T/a.12.pfm" "$T/c.12.pfm" && ok || bad "fake SSH hosts render a different image"

# the same file as a gltf shape of a JSON scene, its camera taken: the same pixels
printf '{ "image": { "width": 64, "height": 16, "spp": 64 }, "materials": {},\n  "shapes": [ { "type": "gltf", "file": "blur.gltf", "camera": true } ] }\n' >"$T/jblur.json"
$F render "$T/jblur.json" --frames 12 --shutter 0.5 -o "$T/j.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "JSON: $(cat "$T/err")"
tail -c 12288 "$T/a.12.pfm" >"$T/a.px" && tail -c 12288 "$T/j.12.pfm" >"$T/j.px"
cmp -s "$T/a.px" "$T/j.px" && ok || bad "a gltf shape's moving camera is not blurred as the file's own"

# bidirectional: a camera sliding past a sunlit white quad (radiance 1).
# Light-traced paths reach the camera at the sample's time, through the
# camera at that time, so the smear is the analytic one; byte-identical
# across -j 1 and -j 2 --slab-rows 5.
printf 'v -0.6 -2 0\nv 0.6 -2 0\nv 0.6 2 0\nv -0.6 2 0\nf 1 2 3\nf 1 3 4\n' >"$T/quad.obj"
cat >"$T/cam.json" <<'JSON'
{ "image": { "width": 64, "height": 16, "spp": 64, "max_depth": 1 },
  "camera": { "position": { "keys": [[0, [-8, 0, 10]], [10, [8, 0, 10]]] },
              "target": { "keys": [[0, [-8, 0, 0]], [10, [8, 0, 0]]] }, "up": [0, 1, 0], "fov": 9.148694 },
  "lights": [ { "type": "sun", "direction": [0, 0, -1], "irradiance": [3.14159265, 3.14159265, 3.14159265] } ],
  "materials": { "white": { "type": "lambert", "albedo": [1, 1, 1] } },
  "shapes": [ { "type": "mesh", "file": "quad.obj", "material": "white" } ] }
JSON
$F render "$T/cam.json" --frames 5 -o "$T/cs.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "camera sharp: $(cat "$T/err")"
$F render "$T/cam.json" --frames 5 --shutter 0.5 --integrator bdpt -o "$T/cb.#.pfm" -j 1 >/dev/null 2>"$T/err" ||
    bad "bdpt: $(cat "$T/err")"
$F render "$T/cam.json" --frames 5 --shutter 0.5 --integrator bdpt -o "$T/cb2.#.pfm" -j 2 --slab-rows 5 \
    >/dev/null 2>&1 || bad "bdpt -j 2 --slab-rows 5"
cmp -s "$T/cb.5.pfm" "$T/cb2.5.pfm" && ok || bad "bdpt: -j 1 and -j 2 --slab-rows 5 differ"
python3 - "$T/cs.5.pfm" "$T/cb.5.pfm" <<'PY' >"$T/check" || bad "bdpt profile check did not run"
import sys
sys.path.insert(0, 'tests/support')
from pfmcols import columns, smear_report
smear_report(columns(sys.argv[1]), columns(sys.argv[2]), 26, 38, 8)
PY
grep -q "^smear True" "$T/check" && ok || bad "bdpt: the moving camera's smear is not the analytic one: $(cat "$T/check")"
grep -q "^total True" "$T/check" && ok || bad "bdpt: the smear does not keep the quad's light: $(cat "$T/check")"
expect_error "mlt" "motion blur, which Metropolis light transport does not support" \
    $F render "$T/blur.gltf" --frames 12 --shutter 0.5 --integrator mlt -o "$T/m.#.pfm" $R
expect_error "--shutter without --frames" "--shutter is for --frames of one glTF or JSON file" \
    $F render "$T/blur.gltf" --shutter 0.5 -o "$T/e.pfm" $R
summary
