#!/bin/sh
# it_limits.sh -- tests unusable numbers and empty scene files are refused.
#
# Numbers a single-precision renderer cannot use, and empty scene files:
# refused with the JSON path (or the file) and what was expected, never an
# internal message, a vanished shape or a file misread as another kind.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
F=bin/franja W=bin/franja-worker
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# scene FILE MATERIAL-JSON SHAPE-JSON [LIGHTS-JSON]: a 4x4 image, a camera and MATERIAL "m".
point='{"type": "point", "position": [0, 3, -3], "intensity": [10, 10, 10]}'
scene() {
    lights=${4:-$point}
    cat >"$1" <<JSON
{"image": {"width": 4, "height": 4, "spp": 1},
 "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov": 40},
 "materials": {"m": $2},
 "lights": [$lights],
 "shapes": [$3]}
JSON
}
lambert='{"type": "lambert", "albedo": [0.5, 0.5, 0.5]}'
ball='{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}'

# refused WHAT FRAGMENT: both the compiler and the worker (which reads JSON
# itself) refuse $T/s.json with FRAGMENT, and never with an internal message.
refused() {
    for cmd in "$F compile $T/s.json -o $T/s.fbin" "$W --scene $T/s.json --rows 0:1 -o $T/x"; do
        expect_error "$1 (${cmd%% *})" "$2" $cmd || continue
        ! grep -q -e 'pick probability' -e 'section ' "$T/err" && ok || bad "$1: internal message: $(cat "$T/err")"
    done
}

scene "$T/s.json" '{"type": "emitter", "emission": [3e38, 3e38, 3e38]}' "$ball"
refused "emission of 3e38" "materials.m.emission[0]: expected a finite number (of magnitude at most 1e+18)"
scene "$T/s.json" "$lambert" '{"type": "sphere", "center": [0, 0, 0], "radius": 3e38, "material": "m"}'
refused "sphere of radius 3e38" "shapes[0].radius: expected a finite number"
scene "$T/s.json" "$lambert" '{"type": "sphere", "center": [0, 2e19, 0], "radius": 1, "material": "m"}'
refused "centre at 2e19" "shapes[0].center[1]: expected a finite number"
scene "$T/s.json" "$lambert" "$ball" '{"type": "point", "position": [0, 3, -3], "intensity": [1e30, 1, 1]}'
refused "point light of 1e30" "lights[0].intensity[0]: expected a finite number"
scene "$T/s.json" "$lambert" '{"type": "triangle", "vertices": [[0, 0, 0], [1e20, 0, 0], [0, 1, 0]], "material": "m"}'
refused "triangle corner at 1e20" "shapes[0].vertices"

# At the limit: compiled and rendered (the light's power and pick
# probability stay finite), every pixel a finite number.
scene "$T/s.json" '{"type": "emitter", "emission": [1e18, 1e18, 1e18]}' \
    '{"type": "sphere", "center": [0, 0, 0], "radius": 1e9, "material": "m"}, {"type": "rect", "origin": [-1e9, -1e9, 1e18], "edge_u": [1e18, 0, 0], "edge_v": [0, 1e18, 0], "material": "m"}'
if $F compile "$T/s.json" -o "$T/s.fbin" >"$T/out" 2>"$T/err"; then
    ok
    $W --scene "$T/s.fbin" --rows 0:4 -o "$T/s.pfm" && ok || bad "the scene at the limit does not render"
else
    bad "emission 1e18, radius 1e9, a 1e18 rectangle refused: $(cat "$T/err")"
fi

# Empty files: said so, not "invalid JSON" nor a damaged binary scene.
: >"$T/empty.fbin"
: >"$T/empty.json"
expect_error "empty .fbin (worker)" "empty.fbin: empty file" $W --scene "$T/empty.fbin" --rows 0:1 -o "$T/x"
expect_error "empty .json (worker)" "empty.json: empty file" $W --scene "$T/empty.json" --rows 0:1 -o "$T/x"
expect_error "empty .json (compile)" "empty.json: empty file" $F compile "$T/empty.json" -o "$T/x.fbin"
expect_error "empty .fbin (render)" "empty.fbin: empty file" $F render "$T/empty.fbin" -o "$T/x.png"
printf '{}' >"$T/json.fbin"
expect_error "JSON named .fbin (worker)" "json.fbin: header: file is 2 bytes" $W --scene "$T/json.fbin" --rows 0:1 -o "$T/x"
grep -q "invalid JSON" "$T/err" && bad "json.fbin read as JSON" || ok

summary
