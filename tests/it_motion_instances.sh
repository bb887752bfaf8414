#!/bin/sh
# it_motion_instances.sh -- tests motion blur of moving instances.
#
# A black quad (a mesh, 12 pixels wide) slides past the camera in front of
# a white environment, its `translate` keyed: with --shutter 0.5 it smears
# over 8 pixels, and each column's mean coverage (1 - its mean) is the
# analytic smear, a trapezoid (ramps 8 pixels long, a plateau of 4),
# within the noise of 64 x 16 samples a column; without --shutter its
# edges are sharp; its shadow from a sun smears as the quad does.  A black bar turning 45 degrees across the shutter
# (`rotate` keyed) covers each 6 x 6 block of pixels as the exact bar,
# integrated over the pixels and the turn, does, and not as the bar at
# rest; its total coverage is the bar's area.  A glTF node moved by the
# file's animation smears as the JSON quad does, unwarned; a whole turn
# across the shutter (JSON), and keys inside it that the blend cannot
# follow (glTF), are warned about.  A shape keying both its own
# transform and instances, and a scale through 0, are refused.  The frames are
# byte-identical across -j 1, -j 2 --slab-rows 5 and two fake SSH hosts;
# keys that do not move keep the still scene's bytes; a keyed sphere is
# and a moving emitter are warned about (not blurred: the emitter renders
# as the still one at mid-shutter, byte for byte).  Under the
# bidirectional integrator the quad smears as under the path tracer and
# its shadow as the analytic one, byte-identical across -j 1 and -j 2
# --slab-rows 5; Metropolis light transport refuses motion blur.
. "$(dirname "$0")/support/fakehosts.sh"
need python3 cmp
fh_init
cd "$ROOT" || exit 1
F=bin/franja T=$FH

# 0.1 scene units a pixel at the plane z = 0: tan(fov / 2) = 0.08 (16
# rows) and 0.24 (48 rows) from 10 units away.
printf 'v -0.6 -2 0\nv 0.6 -2 0\nv 0.6 2 0\nv -0.6 2 0\nf 1 2 3\nf 1 3 4\n' >"$T/quad.obj"
printf 'v -2 -0.3 0\nv 2 -0.3 0\nv 2 0.3 0\nv -2 0.3 0\nf 1 2 3\nf 1 3 4\n' >"$T/bar.obj"
scene() { # FILE ROWS FOV MESH TRANSFORM [EXTRA SHAPE]
    printf '{ "image": { "width": %s, "height": %s, "spp": 64, "max_depth": 1 },
  "camera": { "position": [0, 0, 10], "target": [0, 0, 0], "up": [0, 1, 0], "fov": %s },
  "environment": { "color": [1, 1, 1] },
  "materials": { "black": { "type": "lambert", "albedo": [0, 0, 0] },
                 "lamp": { "type": "emitter", "emission": [1, 1, 1] } },
  "shapes": [ { "type": "mesh", "file": "%s", "material": "black", %s } %s ] }\n' \
        "$(( $2 * 4 ))" "$2" "$3" "$4" "$5" "$6" >"$1"
}
scene "$T/slide.json" 16 9.148694 quad.obj '"name": "slider", "translate": { "keys": [[0, [-8, 0, 0]], [10, [8, 0, 0]]] }'
R="--frames 5"
$F render "$T/slide.json" $R -o "$T/sharp.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "sharp: $(cat "$T/err")"
$F render "$T/slide.json" $R --shutter 0.5 -o "$T/a.#.pfm" -j 1 >/dev/null 2>"$T/err" || bad "blur: $(cat "$T/err")"
python3 - "$T/sharp.5.pfm" "$T/a.5.pfm" <<'PY' >"$T/check" || bad "profile check did not run"
import sys
sys.path.insert(0, 'tests/support')
from pfmcols import columns, smear_report
smear_report([1 - v for v in columns(sys.argv[1])], [1 - v for v in columns(sys.argv[2])], 26, 38, 8)
PY
grep -q "^sharp True" "$T/check" && ok || bad "without a shutter the quad's edges are not sharp: $(cat "$T/check")"
grep -q "^smear True" "$T/check" && ok || bad "the smear is not the analytic one: $(cat "$T/check")"
grep -q "^total True" "$T/check" && ok || bad "the smear does not keep the quad's coverage: $(cat "$T/check")"
grep -q "^spread 20 12$" "$T/check" && ok || bad "the smear's width: $(cat "$T/check")"

# its shadow from a sun 2 units along +x for each unit up: the shadow ray
# of each sample meets the quad where that sample's camera ray would.  On
# the floor 1 unit behind, the shadow lies 2 units to the left, 11/10 as
# far from the camera: the box [8.36, 19.27) of pixels, smeared 7.27.
sed -e 's/"environment": { "color": \[1, 1, 1\] },/"lights": [ { "type": "sun", "direction": [-2, 0, -1], "irradiance": [3, 3, 3] } ],/' \
    -e 's/"shapes": \[ /"shapes": [ { "type": "plane", "point": [0, 0, -1], "normal": [0, 0, 1], "material": "floor" }, /' \
    -e 's/"materials": { /"materials": { "floor": { "type": "lambert", "albedo": [0.8, 0.8, 0.8] }, /' \
    "$T/slide.json" >"$T/shadow.json"
$F render "$T/shadow.json" $R --shutter 0.5 -o "$T/sh.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "shadow: $(cat "$T/err")"
python3 - "$T/sh.5.pfm" <<'PY' >"$T/check" || bad "shadow check did not run"
import sys
sys.path.insert(0, 'tests/support')
from pfmcols import columns, smear
c = columns(sys.argv[1])
shade = [1 - v / c[0] for v in c]
worst = max(abs(shade[x] - smear(x, 8.3636, 19.2727, 7.2727)) for x in range(21))
print("shadow", worst < 0.06, worst)
PY
grep -q "^shadow True" "$T/check" && ok || bad "the moving quad's shadow is not the analytic smear: $(cat "$T/check")"

# split invariance
$F render "$T/slide.json" $R --shutter 0.5 -o "$T/b.#.pfm" -j 2 --slab-rows 5 >/dev/null 2>&1 ||
    bad "render -j 2 --slab-rows 5"
cmp -s "$T/a.5.pfm" "$T/b.5.pfm" && ok || bad "-j 1 and -j 2 --slab-rows 5 differ"
fh_start a 2 2
fh_start b 3 1
fr render "$T/slide.json" $R --shutter 0.5 -o "$T/c.#.pfm" --hosts "$FH/hosts" --slab-rows 3 \
    >/dev/null 2>"$T/err" || bad "fake SSH hosts: $(cat "$T/err")"
cmp -s "$T/a.5.pfm" "$T/c.5.pfm" && ok || bad "fake SSH hosts render a different image"

# a turning bar: 90 degrees a frame, so 67.5 to 112.5 degrees across the shutter
scene "$T/turn.json" 48 26.991467 bar.obj '"rotate": { "keys": [[0, [0, 0, 0]], [10, [0, 0, 900]]] }'
sed 's/"width": 192/"width": 48/' "$T/turn.json" >"$T/t" && mv "$T/t" "$T/turn.json"
$F render "$T/turn.json" $R --shutter 0.5 -o "$T/turn.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "turn: $(cat "$T/err")"
python3 - "$T/turn.5.pfm" <<'PY' >"$T/check" || bad "turn check did not run"
import math, sys
sys.path.insert(0, 'tests/support')
from pfmcols import rows
got = [[1 - v for v in row] for row in rows(sys.argv[1])]
h, w = len(got), len(got[0])
def cover(px, py, angles):
    n = 0
    for a in angles:
        c, s = math.cos(a), math.sin(a)
        n += abs(px * c + py * s) <= 2.0 and abs(-px * s + py * c) <= 0.3
    return n / len(angles)
turn = [math.radians(67.5 + 45 * (k + 0.5) / 24) for k in range(24)]
rest = [math.radians(90.0)]
def expect(angles):
    e = [[0.0] * w for _ in range(h)]
    for y in range(h):
        for x in range(w):
            e[y][x] = sum(cover((x + (i + 0.5) / 3 - 24) * 0.1, (24 - y - (j + 0.5) / 3) * 0.1, angles)
                          for i in range(3) for j in range(3)) / 9
    return e
blur, sharp = expect(turn), expect(rest)
def blocks(a):
    return [sum(a[y][x] for y in range(by, by + 6) for x in range(bx, bx + 6)) / 36
            for by in range(0, h, 6) for bx in range(0, w, 6)]
g, b, s = blocks(got), blocks(blur), blocks(sharp)
worst = max(abs(p - q) for p, q in zip(g, b))
apart = max(abs(p - q) for p, q in zip(b, s))
print("blocks", worst < 0.025, worst)
print("apart", apart > 0.05, apart)
print("area", abs(sum(map(sum, got)) - 240) < 5, sum(map(sum, got)))
PY
grep -q "^blocks True" "$T/check" && ok || bad "the turning bar's blur is not the exact one: $(cat "$T/check")"
grep -q "^apart True" "$T/check" && ok || bad "the turn does not blur enough to test: $(cat "$T/check")"
grep -q "^area True" "$T/check" && ok || bad "the turning bar does not keep its area: $(cat "$T/check")"

# keys that do not move: the still scene's bytes
scene "$T/still.json" 16 9.148694 quad.obj '"translate": [1, 0, 0]'
scene "$T/keyed.json" 16 9.148694 quad.obj '"translate": { "keys": [[0, [1, 0, 0]], [10, [1, 0, 0]]] }'
$F render "$T/still.json" -o "$T/still.pfm" -j 2 >/dev/null 2>&1 || bad "still"
$F render "$T/keyed.json" $R --shutter 0.5 -o "$T/keyed.#.pfm" -j 2 >/dev/null 2>&1 || bad "keyed still"
tail -c 12288 "$T/still.pfm" >"$T/s.px" && tail -c 12288 "$T/keyed.5.pfm" >"$T/k.px"
cmp -s "$T/s.px" "$T/k.px" && ok || bad "keys that do not move change the still scene's pixels"

# a keyed sphere is posed sharp, with a warning; a moving emitter, bdpt: refused
scene "$T/sphere.json" 16 9.148694 quad.obj '"translate": [1, 0, 0]' \
    ', { "type": "sphere", "radius": 0.5, "material": "black", "center": { "keys": [[0, [-8, 0, -1]], [10, [8, 0, -1]]] } }'
$F render "$T/sphere.json" $R --shutter 0.5 -o "$T/sph.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "sphere: $(cat "$T/err")"
grep -q "shapes\[1\]: moves across the shutter, but only mesh shapes" "$T/err" && ok ||
    bad "no warning for a keyed sphere: $(cat "$T/err")"
sed 's/"material": "black", "name"/"material": "lamp", "name"/' "$T/slide.json" >"$T/lamp.json"
$F render "$T/lamp.json" $R --shutter 0.5 -o "$T/l.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "lamp: $(cat "$T/err")"
grep -q "moving lights are not motion blurred" "$T/err" && ok || bad "no warning for a moving emitter: $(cat "$T/err")"
sed 's/"translate": { "keys": \[\[0, \[-8, 0, 0\]\], \[10, \[8, 0, 0\]\]\] }/"translate": [0, 0, 0]/' "$T/lamp.json" \
    >"$T/lamp0.json"
$F render "$T/lamp0.json" -o "$T/l0.pfm" -j 2 >/dev/null 2>&1 || bad "still lamp"
tail -c 12288 "$T/l.5.pfm" >"$T/l.px" && tail -c 12288 "$T/l0.pfm" >"$T/l0.px"
cmp -s "$T/l.px" "$T/l0.px" && ok || bad "a moving emitter is not the still one at mid-shutter"

# a glTF node moved by the file's animation: the same smear as the JSON quad's
python3 - "$T/slide.gltf" <<'PY' || bad "writing slide.gltf"
import base64, json, struct, sys
f = lambda x: struct.unpack('<f', struct.pack('<f', x))[0]
pos = [-0.6, -2, 0, 0.6, -2, 0, 0.6, 2, 0, -0.6, -2, 0, 0.6, 2, 0, -0.6, 2, 0]
raw = struct.pack('<18f', *pos) + struct.pack('<2f', 0.0, f(10 / 24)) + struct.pack('<6f', -8, 0, 0, 8, 0, 0)
acc = lambda off, n, t: {"bufferView": 0, "byteOffset": off, "componentType": 5126, "count": n, "type": t}
doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
       "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
       "buffers": [{"byteLength": len(raw),
                    "uri": "data:application/octet-stream;base64," + base64.b64encode(raw).decode()}],
       "bufferViews": [{"buffer": 0, "byteLength": len(raw)}],
       "accessors": [dict(acc(0, 6, "VEC3"), min=[-0.6, -2, 0], max=[0.6, 2, 0]),
                     dict(acc(72, 2, "SCALAR"), min=[0.0], max=[f(10 / 24)]), acc(80, 2, "VEC3")],
       "animations": [{"samplers": [{"input": 1, "output": 2, "interpolation": "LINEAR"}],
                       "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}]}
json.dump(doc, open(sys.argv[1], 'w'))
# and a node turning 270 degrees across the shutter of frame 5 (keys at
# 4.75, 5 and 5.25: 0, 135 and 270 degrees about z), which the blend of
# its two ends cannot follow
import math
q = lambda deg: [0, 0, math.sin(math.radians(deg) / 2), math.cos(math.radians(deg) / 2)]
raw = struct.pack('<18f', *pos) + struct.pack('<3f', *(f(k / 24) for k in (4.75, 5, 5.25)))
raw += struct.pack('<12f', *(q(0) + q(135) + q(270)))
doc["buffers"][0] = {"byteLength": len(raw),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(raw).decode()}
doc["bufferViews"][0]["byteLength"] = len(raw)
doc["accessors"][1:] = [dict(acc(72, 3, "SCALAR"), min=[f(4.75 / 24)], max=[f(5.25 / 24)]), acc(84, 3, "VEC4")]
doc["animations"][0]["channels"][0]["target"]["path"] = "rotation"
json.dump(doc, open(sys.argv[1].replace('slide', 'spin'), 'w'))
PY
scene "$T/gspin.json" 16 9.148694 quad.obj '"translate": [100, 0, 0]' \
    ', { "type": "gltf", "file": "spin.gltf", "material": "black" }'
$F render "$T/gspin.json" $R --shutter 0.5 -o "$T/gs.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "gltf spin: $(cat "$T/err")"
grep -q "nodes/0: at the frame's time the node is not where the blend" "$T/err" && ok ||
    bad "no warning for a glTF node the blend cannot follow: $(cat "$T/err")"
scene "$T/gslide.json" 16 9.148694 quad.obj '"translate": [100, 0, 0]' \
    ', { "type": "gltf", "file": "slide.gltf", "material": "black" }'
$F render "$T/gslide.json" $R --shutter 0.5 -o "$T/g.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "gltf: $(cat "$T/err")"
python3 - "$T/g.5.pfm" <<'PY' >"$T/check" || bad "gltf profile check did not run"
import sys
sys.path.insert(0, 'tests/support')
from pfmcols import columns, smear
blur = [1 - v for v in columns(sys.argv[1])]
worst = max(abs(blur[x] - smear(x, 26, 38, 8)) for x in range(64))
print("smear", worst < 0.06, worst)
PY
grep -q "^smear True" "$T/check" && ok || bad "a glTF node's smear is not the analytic one: $(cat "$T/check")"
grep -q "blend" "$T/err" && bad "a glTF node moving at constant speed is warned about: $(cat "$T/err")" || ok

# a spin of more than half a turn across the shutter is warned about
scene "$T/spin.json" 16 9.148694 quad.obj '"rotate": { "keys": [[0, [0, 0, 0]], [10, [0, 0, 7200]]] }'
$F render "$T/spin.json" $R --shutter 0.5 -o "$T/spin.#.pfm" -j 2 >/dev/null 2>"$T/err" || bad "spin: $(cat "$T/err")"
grep -q "turns 360 degrees across the shutter; the blur takes the shorter way" "$T/err" && ok ||
    bad "no warning for a spin of a whole turn: $(cat "$T/err")"
scene "$T/both.json" 16 9.148694 quad.obj '"translate": { "keys": [[0, [-8, 0, 0]], [10, [8, 0, 0]]] }, "instances": [ {} ]'
expect_error "a keyed shape with instances" "shapes[0].translate: a mesh shape with instances moves by its instances'" \
    $F render "$T/both.json" $R --shutter 0.5 -o "$T/both.#.pfm"
scene "$T/flat.json" 16 9.148694 quad.obj '"scale": { "keys": [[0, [1, 1, 1]], [10, [1, -9, 1]]] }'
expect_error "a flat blend" "passes through a flat transform" $F render "$T/flat.json" --frames 1 --shutter 0.5 -o "$T/f.#.pfm"

# bidirectional: a sample's light subpath and connections see the scene at
# the sample's time, so the quad smears as under the path tracer and its
# shadow (sun: next-event and light-traced paths) as the analytic one;
# byte-identical across splits.  Metropolis refuses motion.
$F render "$T/slide.json" $R --shutter 0.5 --integrator bdpt -o "$T/d.#.pfm" -j 1 >/dev/null 2>"$T/err" ||
    bad "bdpt: $(cat "$T/err")"
$F render "$T/shadow.json" $R --shutter 0.5 --integrator bdpt -o "$T/ds.#.pfm" -j 1 >/dev/null 2>"$T/err" ||
    bad "bdpt shadow: $(cat "$T/err")"
$F render "$T/shadow.json" $R --shutter 0.5 --integrator bdpt -o "$T/ds2.#.pfm" -j 2 --slab-rows 5 >/dev/null 2>&1 ||
    bad "bdpt shadow -j 2 --slab-rows 5"
cmp -s "$T/ds.5.pfm" "$T/ds2.5.pfm" && ok || bad "bdpt: -j 1 and -j 2 --slab-rows 5 differ"
python3 - "$T/a.5.pfm" "$T/d.5.pfm" "$T/ds.5.pfm" <<'PY' >"$T/check" || bad "bdpt check did not run"
import sys
sys.path.insert(0, 'tests/support')
from pfmcols import columns, smear, smear_report
smear_report([1 - v for v in columns(sys.argv[1])], [1 - v for v in columns(sys.argv[2])], 26, 38, 8)
c = columns(sys.argv[3])
shade = [1 - v / c[0] for v in c]
worst = max(abs(shade[x] - smear(x, 8.3636, 19.2727, 7.2727)) for x in range(21))
print("shadow", worst < 0.06, worst)
PY
grep -q "^smear True" "$T/check" && ok || bad "bdpt: the smear is not the path tracer's: $(cat "$T/check")"
grep -q "^shadow True" "$T/check" && ok || bad "bdpt: the shadow is not the analytic smear: $(cat "$T/check")"
expect_error "mlt" "motion blur, which Metropolis light transport does not support" \
    $F render "$T/slide.json" $R --shutter 0.5 --integrator mlt -o "$T/m.#.pfm"
summary
