#!/bin/sh
# it_conventions.sh -- tests the documented conventions by measuring them.
#
# What the docs say about Franja's conventions, and how
# they map to Cycles, measured.  Each check reads the statement from the docs
# (so a wrong statement fails here) and measures it: against a closed form,
# or against the small Cycles renders in tests/data (made by `make refs`).
#
#   max_depth  scenes/README.md: max_depth 0 renders the emitters alone, 1
#              direct light, ...; Cycles' N max bounces is max_depth N + K.
#              A furnace (the camera inside a closed sphere that emits 1 and
#              reflects 0.5) gives sum(0.5^k, k = 0 .. max_depth), exactly
#              up to max_depth 4 (Russian roulette starts after that),
#              and Cycles' furnace with N bounces (tests/refs/cycles_furnace.py)
#              must equal Franja's with max_depth N + K.
#   fov        scenes/README.md: `fov` is the vertical (or horizontal) field
#              of view: an emitter covering a known part of the view, seen
#              on a 64x32 image, covers the rows (columns) it should.
#   right      scenes/README.md: with +y up and the view along +z, image
#              right is world -x (or +x).
#   roughness  scenes/README.md: alpha = roughness^2 (or roughness^p as the
#              roughness row says).  A conductor plane without Fresnel
#              factor, seen head-on by a camera of 0.5 degrees under a sun
#              straight behind the camera: the radiance is
#              D(n) G(n, n) / 4 = 1 / (4 pi alpha^2) (GGX at its peak, no
#              masking head-on), measured at roughness 0.3 and 0.5.
#
#   sh tests/it_conventions.sh [DOC]    (default scenes/README.md: the
#                                        statements may be read from a copy)
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need awk oiiotool
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
W=bin/franja-worker IS=bin/tools/imgstat
DOC=${1:-scenes/README.md}

# near A B TOL: |A - B| <= TOL.
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; exit !(a != "" && (d < 0 ? -d : d) <= t) }'; }
mean_of() { $IS "$1" | tr ' ' '\n' | sed -n 's/^mean=//p'; }

# --- max_depth and Cycles' bounces -------------------------------------
row=$(grep -n '^| `max_depth` |' $DOC)
if [ -z "$row" ]; then
    bad "$DOC: no max_depth row in the image table (this test reads it)"
else
    line=${row%%:*}
    K=$(printf '%s\n' "$row" | sed -n 's/.*Cycles'"'"' N "max bounces" is `max_depth` N + \([0-9]*\).*/\1/p')
    if [ -z "$K" ]; then
        # A row naming Cycles' max bounces without an offset equates them.
        printf '%s\n' "$row" | grep -q 'Cycles' && K=0
    fi
    if [ -z "$K" ]; then
        bad "$DOC:$line: the max_depth row no longer says how it maps to Cycles' max bounces"
        K=0
    fi
    furnace() {
        printf '{"image": {"width": 8, "height": 8, "spp": 64, "max_depth": %d},
          "camera": {"position": [0, 0, 0], "target": [0, 0, 1], "fov": 60},
          "materials": {"f": {"type": "lambert", "albedo": [0.5, 0.5, 0.5], "emission": [1, 1, 1], "two_sided": true}},
          "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "f"}]}' "$1" >"$T/furnace.json"
        $W --scene "$T/furnace.json" --rows 0:8 -o "$T/furnace.pfm" && mean_of "$T/furnace.pfm"
    }
    # Closed form: each scattering vertex adds one more term of the series
    # (exact up to max_depth 4, before Russian roulette starts).
    for d in 0 1 2 3 4; do
        m=$(furnace $d)
        want=$(awk -v n=$d 'BEGIN { s = 0; for (k = 0; k <= n; k++) s += 0.5 ^ k; print s }')
        near "$m" "$want" 0.001 && ok || bad "furnace with max_depth $d: $m, closed form $want"
    done
    # Cycles: N max bounces equals max_depth N + K.
    for n in 0 1 2 3; do
        ref=tests/data/cycles-furnace-b$n.exr
        c=$(oiiotool --stats "$ref" 2>/dev/null | awk '/Stats Avg:/ { print ($3 + $4 + $5) / 3 }')
        [ -n "$c" ] || { bad "$ref is missing or unreadable (make refs)"; continue; }
        m=$(furnace $((n + K)))
        near "$m" "$c" 0.005 && ok ||
            bad "$DOC:$line says Cycles' $n max bounces is max_depth $((n + K)): Franja's furnace gives $m there, Cycles' $c"
    done
fi

# --- the field of view -------------------------------------------------
fovline=$(grep -n '`fov` is the [a-z]* field of view' $DOC | head -n 1)
axis=$(printf '%s\n' "$fovline" | sed -n 's/.*`fov` is the \([a-z]*\) field of view.*/\1/p')
case "$axis" in
vertical | horizontal) ;;
*) bad "$DOC: no sentence '\`fov\` is the vertical (or horizontal) field of view' (this test reads it)"; axis=vertical ;;
esac
# An emitter at distance 10 facing the camera, as wide as the image is and
# half as tall (measured on the axis the docs name), its edges 1/4 pixel
# inside the rows or columns they fall on; the image is 64x32.  Covered
# fractions add up: the row (column) means sum to the emitter's extent in
# pixels along that axis.
fov=40
t=$(awk -v f=$fov 'BEGIN { a = f / 2 * 3.14159265358979 / 180; print sin(a) / cos(a) }')
# Half the view's extent at distance 10 on the named axis; the other axis
# is twice (vertical) or half (horizontal) as wide on a 64x32 image.
if [ "$axis" = vertical ]; then half_v=$(awk -v t="$t" 'BEGIN { print 10 * t }'); half_h=$(awk -v t="$t" 'BEGIN { print 20 * t }')
else half_h=$(awk -v t="$t" 'BEGIN { print 10 * t }'); half_v=$(awk -v t="$t" 'BEGIN { print 5 * t }'); fi
# The emitter covers 8.5 of the 32 rows, centred, and every column.
ey=$(awk -v h="$half_v" 'BEGIN { print h * 8.5 / 32 }')
ex=$(awk -v h="$half_h" 'BEGIN { print h * 1.5 }')
cat >"$T/fov.json" <<JSON
{"image": {"width": 64, "height": 32, "spp": 64, "max_depth": 0},
 "camera": {"position": [0, 0, 0], "target": [0, 0, 10], "up": [0, 1, 0], "fov": $fov},
 "materials": {"e": {"type": "emitter", "emission": [1, 1, 1]}},
 "shapes": [{"type": "rect", "origin": [$ex, -$ey, 10], "edge_u": [-$(awk -v e="$ex" 'BEGIN { print 2 * e }'), 0, 0],
             "edge_v": [0, $(awk -v e="$ey" 'BEGIN { print 2 * e }'), 0], "material": "e"}]}
JSON
if $W --scene "$T/fov.json" --rows 0:32 -o "$T/fov.pfm" 2>"$T/err"; then
    rows=$($IS "$T/fov.pfm" --rows | awk '/^row/ { s += $3 } END { print s }')
    cols=$($IS "$T/fov.pfm" --rect 0 0 64 32 --cols | awk '/^col/ { n++; if ($3 > 0.2) c++ } END { print c "/" n }')
    near "$rows" 8.5 0.05 && ok ||
        bad "$DOC:${fovline%%:*}: fov is the $axis field of view: an emitter 8.5 rows tall covers $rows rows"
    [ "$cols" = 64/64 ] && ok || bad "fov: the emitter should span every column ($cols)"
else
    bad "fov render: $(cat "$T/err")"
fi

# --- which way image right is ------------------------------------------
rline=$(grep -n 'image right is world [-+]x' $DOC | head -n 1)
side=$(printf '%s\n' "$rline" | sed -n 's/.*image right is world \([-+]x\).*/\1/p')
if [ -z "$side" ]; then
    bad "$DOC: no sentence 'image right is world -x (or +x)' (this test reads it)"
else
    # An emitter on the world's -x side only.
    cat >"$T/side.json" <<JSON
{"image": {"width": 32, "height": 16, "spp": 4, "max_depth": 0},
 "camera": {"position": [0, 0, 0], "target": [0, 0, 10], "up": [0, 1, 0], "fov": 40},
 "materials": {"e": {"type": "emitter", "emission": [1, 1, 1]}},
 "shapes": [{"type": "rect", "origin": [0, -10, 10], "edge_u": [-20, 0, 0], "edge_v": [0, 20, 0], "material": "e"}]}
JSON
    $W --scene "$T/side.json" --rows 0:16 -o "$T/side.pfm" 2>"$T/err" || bad "side render: $(cat "$T/err")"
    left=$($IS "$T/side.pfm" --rect 0 0 16 16 | tr ' ' '\n' | sed -n 's/^mean=//p')
    right=$($IS "$T/side.pfm" --rect 16 0 32 16 | tr ' ' '\n' | sed -n 's/^mean=//p')
    if [ "$side" = -x ]; then lit=$right dark=$left; else lit=$left dark=$right; fi
    near "$lit" 1 0.001 && near "$dark" 0 0.001 && ok ||
        bad "$DOC:${rline%%:*}: image right is world $side, but an emitter at world -x lights the left half $left, the right half $right"
fi
# --- roughness: alpha = roughness^p -----------------------------------
rrow=$(grep -n '^| `roughness` |' $DOC | head -n 1)
p=""
case "$rrow" in
*'α = roughness²'*) p=2 ;;
*'α = roughness,'* | *'α = roughness '* | *'α = roughness;'*) p=1 ;;
esac
if [ -z "$p" ]; then
    bad "$DOC: the roughness row no longer says 'α = roughness²' (or how α follows roughness; this test reads it)"
else
    for r in 0.3 0.5; do
        cat >"$T/rough.json" <<JSON
{"image": {"width": 8, "height": 8, "spp": 16, "max_depth": 1},
 "camera": {"position": [0, 10, 0], "target": [0, 0, 0], "up": [0, 0, 1], "fov": 0.5},
 "materials": {"m": {"type": "conductor", "roughness": $r, "fresnel": "none", "reflectance": [1, 1, 1]}},
 "lights": [{"type": "sun", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}],
 "shapes": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "m"}]}
JSON
        if $W --scene "$T/rough.json" --rows 0:8 -o "$T/rough.pfm" 2>"$T/err"; then
            m=$(mean_of "$T/rough.pfm")
            want=$(awk -v r=$r -v p=$p 'BEGIN { a = r ^ p; print 1 / (4 * 3.14159265358979 * a * a) }')
            tol=$(awk -v w="$want" 'BEGIN { print w * 0.01 }')
            near "$m" "$want" "$tol" && ok ||
                bad "$DOC:${rrow%%:*}: α = roughness^$p: a conductor of roughness $r seen head-on under a sun behind the camera gives $m, 1 / (4π α²) = $want"
        else
            bad "roughness render: $(cat "$T/err")"
        fi
    done
fi
summary
