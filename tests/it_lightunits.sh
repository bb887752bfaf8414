#!/bin/sh
# it_lightunits.sh -- tests Blender's light units through glTF against Franja.
#
# Blender's light units, their glTF export and Franja's
# import, measured (scenes/README.md, "Units, glTF and Blender").
#
# tests/refs/cycles_lights.py (make refs) built three Blender scenes -- a
# white diffuse floor (colour 0.8) seen from 3 m above and one light: a
# point of P = 1000 W, a spot of 1000 W with size s = 60 degrees and blend
# b = 0.3, a sun of S = 3 W/m^2 turned 30 degrees -- rendered each with
# Cycles (tests/data/cycles-light-NAME.exr, .pfm) and exported each with
# Blender's glTF exporter (tests/data/blender-light-NAME.gltf).  Here:
#   - the docs still state the mapping this test measures;
#   - the exporter wrote what the docs' table says: candela = P / (4 pi)
#     x 683, lux = S x 683, outerConeAngle = s / 2, innerConeAngle =
#     s/2 - s/2 b;
#   - Franja, given the exported file (its camera, its lights, the floor
#     with a Lambert material of 0.8), renders what Cycles rendered from
#     Blender's watts: so candela / 683 and lux / 683 are Cycles' W/sr and
#     W/m^2.  Point and sun pixel by pixel; the spot on its axis only (the
#     docs say the falloffs differ: Cycles multiplies by the cosine to the
#     axis, so only the central 2x2 pixels, within 6 degrees of it);
#   - closed forms: the sun lights the floor evenly with 0.8 / pi x S
#     cos 30; the point light's brightest pixel is near 0.8 / pi x P /
#     (4 pi) / 1 m^2 (directly below it).
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need awk jq oiiotool
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
D=tests/data IS=bin/tools/imgstat DOC=${1:-scenes/README.md}
PI=3.14159265358979

field() { printf '%s\n' "$2" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
# near A B RELTOL: |A - B| <= RELTOL |B|.
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; m = b < 0 ? -b : b; exit !(a != "" && d <= t * m) }'; }

# --- the docs state the mapping -----------------------------------------
for s in '| point or spot of power P watts | `intensity` = P / (4π) × 683 cd | `intensity` = candela / 683 = P / (4π) |' \
    '| sun of strength S W/m² | `intensity` = S × 683 lux | `irradiance` = lux / 683 = S |' \
    '| spot size s, blend b | `outerConeAngle` = s / 2, `innerConeAngle` = s/2 − s/2 · b | the same angles (in degrees) |' \
    '| `KHR_lights_punctual` lights: `color` times `intensity` / 683 |'; do
    grep -qF -- "$s" "$DOC" && ok || bad "$DOC no longer says '$s' (this test measures it: change both)"
done

# --- what Blender's exporter wrote ----------------------------------------
light() { jq -r ".extensions.KHR_lights_punctual.lights[0].$2" "$D/blender-light-$1.gltf"; }
want=$(awk -v p=$PI 'BEGIN { print 1000 / (4 * p) * 683 }')
for n in point spot; do
    v=$(light $n intensity)
    near "$v" "$want" 1e-6 && ok || bad "blender-light-$n.gltf: intensity $v cd, the docs say P / (4π) × 683 = $want"
done
v=$(light sun intensity)
near "$v" 2049 1e-6 && ok || bad "blender-light-sun.gltf: intensity $v lux, the docs say S × 683 = 2049"
outer=$(light spot spot.outerConeAngle) inner=$(light spot spot.innerConeAngle)
o=$(awk -v p=$PI 'BEGIN { print 30 * p / 180 }') i=$(awk -v p=$PI 'BEGIN { print (30 - 30 * 0.3) * p / 180 }')
near "$outer" "$o" 1e-6 && ok || bad "blender-light-spot.gltf: outerConeAngle $outer, the docs say s / 2 = $o"
near "$inner" "$i" 1e-6 && ok || bad "blender-light-spot.gltf: innerConeAngle $inner, the docs say s/2 − s/2 · b = $i"

# --- Franja renders the exported files as Cycles rendered Blender's -------
for n in point spot sun; do
    oiiotool $D/cycles-light-$n.exr --ch R,G,B $D/cycles-light-$n.pfm --diff >"$T/diff" 2>&1 && ok ||
        bad "$D/cycles-light-$n.pfm differs from the EXR: $(tail -n 3 "$T/diff")"
    cp $D/blender-light-$n.gltf "$T/"
    cat >"$T/$n.json" <<JSON
{"image": {"width": 32, "height": 32, "spp": 64, "max_depth": 1},
 "materials": {"white": {"type": "lambert", "albedo": [0.8, 0.8, 0.8]}},
 "shapes": [{"type": "gltf", "file": "blender-light-$n.gltf", "material": "white", "camera": true}]}
JSON
    if ! bin/franja compile "$T/$n.json" -o "$T/$n.fbin" >"$T/log" 2>&1 ||
        ! bin/franja-worker --scene "$T/$n.fbin" --rows 0:32 -o "$T/$n.pfm" 2>"$T/log"; then
        bad "$n: $(tail -n 3 "$T/log")"
        continue
    fi
    if [ $n = spot ]; then
        r=$($IS "$T/$n.pfm" --rect 15 15 17 17 --ratio $D/cycles-light-$n.pfm)
        m=$(field mean "$r")
        near "$m" 1 0.01 && ok || bad "spot: on its axis Franja / Cycles is $m (want 1 within 1 %)"
        continue
    fi
    r=$($IS "$T/$n.pfm" --ratio $D/cycles-light-$n.pfm)
    m=$(field mean "$r") sd=$(field sd "$r")
    near "$m" 1 0.005 && ok || bad "$n: Franja / Cycles averages $m over the pixels (want 1 within 0.5 %)"
    awk -v s="$sd" 'BEGIN { exit !(s != "" && s <= 0.01) }' && ok || bad "$n: Franja / Cycles varies by $sd (want <= 0.01)"
done

# --- closed forms ---------------------------------------------------------
s=$($IS $D/cycles-light-sun.pfm)
want=$(awk -v p=$PI 'BEGIN { print 0.8 / p * 3 * cos(30 * p / 180) }')
near "$(field min "$s")" "$want" 0.001 && near "$(field max "$s")" "$want" 0.001 && ok ||
    bad "Cycles' sun of 3 W/m² at 30°: the floor is $(field min "$s") to $(field max "$s"), 0.8 / π × 3 cos 30° = $want"
[ -s "$T/sun.pfm" ] && { near "$(field mean "$($IS "$T/sun.pfm")")" "$want" 0.001 && ok ||
    bad "Franja's sun from lux / 683: the floor is $(field mean "$($IS "$T/sun.pfm")"), want $want"; }
# The point light is 1 m above (0.3, 0.2): the pixel under it (0.108 m a
# pixel) is within 3 % of the value straight below.
want=$(awk -v p=$PI 'BEGIN { print 0.8 / p * 1000 / (4 * p) }')
mx=$(field max "$($IS $D/cycles-light-point.pfm)")
near "$mx" "$want" 0.03 && ok || bad "Cycles' point light of 1000 W, 1 m above: brightest pixel $mx, 0.8 / π × P / (4π) = $want"
summary
