#!/bin/sh
# it_worker.sh -- tests franja-worker end to end.
#
# franja-worker end to end: its command line, its errors on bad input,
# split invariance through real processes, and the formats it writes.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
W=bin/franja-worker
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# worker_error "what it tests" "fragment of stderr" command...: expect_error
# (tests/support/lib.sh), and the failing worker wrote nothing on stdout.
worker_error() {
    expect_error "$@" || return
    [ ! -s "$T/out" ] && ok || bad "$1: wrote to stdout"
}

$W --help | grep -q -- '--rows Y0:Y1' && ok || bad "--help"
$W --version | grep -Eq '^franja-worker [0-9]+\.[0-9]+\.[0-9]+ scene-format [0-9]+$' && ok || bad "--version"
# Its second line names the BVH walk in use and those the processor runs.
$W --version | sed -n 2p | grep -Eq '^walk (portable|avx2|avx512) \(this processor runs: portable( avx2)?( avx512)?\)$' &&
    ok || bad "--version's walk line: $($W --version | sed -n 2p)"
FRANJA_WALK=portable $W --version | grep -q '^walk portable ' && ok || bad "FRANJA_WALK=portable not taken"
worker_error "FRANJA_WALK unknown" "FRANJA_WALK=fast: expected portable, avx2 or avx512" env FRANJA_WALK=fast $W --version
[ "$(env FRANJA_WALK=fast $W --version 2>/dev/null; echo $?)" = 2 ] && ok || bad "FRANJA_WALK unknown: not exit status 2"

# Every walk the processor runs renders the same bytes: a mesh (BVH of
# triangles), spheres and rectangles in mixed leaves, a textured box, a
# glTF courtyard.
walks=$($W --version | sed -n 's/.*this processor runs: \(.*\))$/\1/p')
for s in knot spheres cornell-textured courtyard; do
    f=scenes/$s.json
    [ -e "$f" ] || f=scenes/$s.glb
    bin/franja compile "$f" -o "$T/walk.fbin" >/dev/null || bad "$s: franja compile failed"
    for w in $walks; do
        FRANJA_WALK=$w $W --scene "$T/walk.fbin" --size 48x36 --spp 2 --rows 0:36 -o "$T/walk-$w.pfm" ||
            bad "$s: the $w walk failed"
    done
    for w in $walks; do
        cmp -s "$T/walk-portable.pfm" "$T/walk-$w.pfm" && ok || bad "$s: the $w walk's image differs from the portable walk's"
    done
done

S=scenes/cornell.json
worker_error "rows past the end" "need 0 <= Y0 < Y1 <= 32" $W --scene $S --size 32x32 --rows 10:33 -o "$T/x"
worker_error "empty rows" "need 0 <= Y0 < Y1" $W --scene $S --rows 5:5 -o "$T/x"
worker_error "malformed rows" "--rows: expected Y0:Y1" $W --scene $S --rows 5-9 -o "$T/x"
worker_error "negative spp" "--spp: expected an integer" $W --scene $S --rows 0:1 --spp -3
worker_error "bad size" "--size: expected WxH" $W --scene $S --rows 0:1 --size 0x10
worker_error "bad format" "--format: expected pf, ppm16 or ppm8" $W --scene $S --rows 0:1 --format png
worker_error "missing scene" "No such file" $W --scene "$T/none.json" --rows 0:1 -o "$T/x"
worker_error "unknown flag" "unknown argument" $W --scene $S --rows 0:1 --bogus
[ ! -e "$T/x" ] && ok || bad "a failed run left an output file"

# Bad scenes: each names the JSON path and what was expected.
scene_error() {
    printf '%s' "$2" >"$T/bad.json"
    worker_error "scene: $1" "$1" $W --scene "$T/bad.json" --rows 0:1 -o "$T/x"
}
base='"image": {"width": 4, "height": 4}, "camera": {"position": [0,0,-5], "target": [0,0,0], "fov": 40}'
mats='"materials": {"m": {"type": "lambert", "albedo": [0.5,0.5,0.5], "emission": [1,1,1]}}'
scene_error "shapes[0].radius: expected a positive number" "{$base, $mats, \"shapes\": [{\"type\": \"sphere\", \"center\": [0,0,0], \"radius\": -1, \"material\": \"m\"}]}"
scene_error "shapes[1].material: no material named 'x'" "{$base, $mats, \"shapes\": [{\"type\": \"sphere\", \"center\": [0,0,0], \"radius\": 1, \"material\": \"m\"}, {\"type\": \"sphere\", \"center\": [0,0,0], \"radius\": 1, \"material\": \"x\"}]}"
scene_error "shapes[0]: zero-area rectangle" "{$base, $mats, \"shapes\": [{\"type\": \"rect\", \"origin\": [0,0,0], \"edge_u\": [1,0,0], \"edge_v\": [2,0,0], \"material\": \"m\"}]}"
scene_error "shapes[0].center: expected an array of 3 numbers" "{$base, $mats, \"shapes\": [{\"type\": \"sphere\", \"center\": \"here\", \"radius\": 1, \"material\": \"m\"}]}"
scene_error "camera: target equals position" "{\"image\": {\"width\": 4, \"height\": 4}, \"camera\": {\"position\": [1,1,1], \"target\": [1,1,1], \"fov\": 40}, $mats, \"shapes\": []}"
scene_error "image.width: missing" "{\"image\": {\"height\": 4}, \"camera\": {}, $mats, \"shapes\": []}"
scene_error "materials.m: lobe albedos sum to" "{$base, \"materials\": {\"m\": {\"type\": \"mix\", \"diffuse\": [0.7,0.7,0.7], \"specular\": [0.5,0.5,0.5]}}, \"shapes\": []}"
scene_error "shapes[0].center[1]: expected a finite number" "{$base, $mats, \"shapes\": [{\"type\": \"sphere\", \"center\": [0,1e999,0], \"radius\": 1, \"material\": \"m\"}]}"
scene_error "shapes[0].radiu: unknown field" "{$base, $mats, \"shapes\": [{\"type\": \"sphere\", \"center\": [0,0,0], \"radiu\": 1, \"material\": \"m\"}]}"
scene_error "bad.json:3:12: expected a value" "{$base,
$mats,
\"shapes\": [}"

# Split invariance through the worker process: three uneven slabs of an
# 8-bit image, pixel bytes concatenated, equal the full render's.
R="--scene scenes/spheres.json --size 40x30 --spp 4 --format ppm8"
$W $R --rows 0:30 -o "$T/full.ppm" && ok || bad "full render"
$W $R --rows 0:7 -o "$T/a.ppm" && $W $R --rows 7:8 -o "$T/b.ppm" && $W $R --rows 8:30 -o - >"$T/c.ppm" && ok || bad "slab renders"
# A P6 header is 4 lines (magic, comment, size, maxval).
for f in full a b c; do tail -n +5 "$T/$f.ppm" >"$T/$f.pix"; done
cat "$T/a.pix" "$T/b.pix" "$T/c.pix" | cmp -s - "$T/full.pix" && ok || bad "slabs differ from the full image"
head -n 2 "$T/b.ppm" | grep -Eq '^# franja scene=[0-9a-f]{16} rows=7:8 spp=4 size=40x30$' && ok || bad "header comment: $(head -n 2 "$T/b.ppm")"

# PF is a standard PFM that other tools read, and the pixels decode.
$W --scene scenes/cornell.json --size 16x8 --spp 2 --rows 2:6 -o "$T/p.pfm" && ok || bad "pf render"
size=$(wc -c <"$T/p.pfm")
hdr=$(head -n 4 "$T/p.pfm" | wc -c)
[ $((size - hdr)) -eq $((16 * 4 * 12)) ] && ok || bad "PF payload size $((size - hdr))"
if command -v oiiotool >/dev/null; then
    oiiotool --info "$T/p.pfm" 2>&1 | grep -q '16 x    4, 3 channel, float' && ok || bad "oiiotool cannot read the PF: $(oiiotool --info "$T/p.pfm" 2>&1)"
fi

# The render path calls no transcendental function from libm.
if nm -u $W | grep -Eq ' (sin|cos|tan|exp|exp2|log|log2|pow|atan|atan2|acos|asin|sincos)f?(@|$)'; then
    bad "worker imports libm transcendentals: $(nm -u $W | grep -E ' (sin|cos|tan|exp|log|pow|atan|acos|asin)')"
else
    ok
fi

summary
