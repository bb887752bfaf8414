#!/bin/sh
# it_envlight.sh -- tests the environment map against Cycles.
#
# The environment map against Cycles: scenes/textures/sky.hdr read through
# the scene compiler (OpenImageIO) and rendered by Franja, view by view,
# against Cycles' renders of the same views with the map as Blender's
# Environment Texture (tests/data/cycles-env-*.pfm, made by `make refs`:
# tests/refs/cycles_env.py, Blender 3.4.1).  The views look at the map's
# sun (without and with a rotation of 90 degrees), along the horizon, and
# down at a diffuse sphere on a diffuse plane lit by the map alone; pixel by
# pixel the ratio Franja / Cycles must average 1 and barely vary, so the sky
# must be where Cycles has it, the right way round, as bright.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need awk
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
IS=bin/tools/imgstat
SKY=$(pwd)/scenes/textures/sky.hdr
SUN="[0.409576, 0.573576, 0.709406]"  # elevation 35, azimuth 60 (gensky's defaults)
FAR='{"type": "sphere", "center": [0, -1000, 0], "radius": 1, "material": "d"}'

# scene NAME W H FOV POSITION TARGET ROTATION MAX_DEPTH SPP SHAPES
scene() {
    cat >"$T/$1.json" <<J
{"image": {"width": $2, "height": $3, "spp": $9, "max_depth": $8},
 "camera": {"position": $5, "target": $6, "fov": $4},
 "textures": {"sky": {"type": "image", "file": "$SKY"}},
 "environment": {"color": "sky", "rotation": $7},
 "materials": {"d": {"type": "lambert", "albedo": [0.5, 0.5, 0.5]}},
 "shapes": [${10}]}
J
    bin/franja render "$T/$1.json" --allow-path scenes/textures -o "$T/$1.pfm" >"$T/log" 2>&1 || bad "$1: render: $(tail -3 "$T/log")"
}

# field NAME LINE: the value of NAME= in an imgstat line.
field() { printf '%s\n' "$2" | tr ' ' '\n' | sed -n "s/^$1=//p"; }

# within X LO HI: LO <= X <= HI.
within() { awk -v x="$1" -v lo="$2" -v hi="$3" 'BEGIN { exit !(x >= lo && x <= hi) }'; }

# compare NAME RATIO_TOL SD_MAX MEAN_TOL: the ratio Franja / Cycles over the
# pixels has mean 1 +- RATIO_TOL and standard deviation <= SD_MAX; the
# images' means agree within MEAN_TOL.
compare() {
    ref=tests/data/cycles-env-$1.pfm
    r=$($IS "$T/$1.pfm" --ratio "$ref") || { bad "$1: imgstat"; return; }
    m=$(field mean "$r") sd=$(field sd "$r")
    a=$(field mean "$($IS "$T/$1.pfm")") b=$(field mean "$($IS "$ref")")
    check "$1: Franja / Cycles averages $m (want 1 +- $2)" within "$m" "$(awk -v t="$2" 'BEGIN { print 1 - t }')" \
        "$(awk -v t="$2" 'BEGIN { print 1 + t }')"
    check "$1: Franja / Cycles varies by $sd (want <= $3)" within "$sd" 0 "$3"
    check "$1: mean $a, Cycles $b" within "$(awk -v a="$a" -v b="$b" 'BEGIN { print a / b }')" \
        "$(awk -v t="$4" 'BEGIN { print 1 - t }')" "$(awk -v t="$4" 'BEGIN { print 1 + t }')"
}

scene sun 48 32 20 "[0, 0, 0]" "$SUN" 0 0 64 "$FAR"
compare sun 0.01 0.05 0.02
scene rot 48 32 20 "[0, 0, 0]" "[-0.709406, 0.573576, 0.409576]" 90 0 64 "$FAR"
compare rot 0.01 0.05 0.02
scene wide 64 32 90 "[0, 0, 0]" "[1, 0.15, 0]" 0 0 64 "$FAR"
# (The sun is cut by the frame's top edge here: one pixel holds a part of
# it that differs with antialiasing, so the means differ by 7 %.)
compare wide 0.005 0.03 0.1
scene ground 64 64 40 "[3, 5, -3]" "[0, 0.3, 0]" 0 1 256 \
    '{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "d"},
     {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "d"}'
compare ground 0.01 0.05 0.01
# The sun's shadow: the darkest 8x8 block is the same in both.
darkest() {
    best="" bv=1e30
    for y in 0 8 16 24 32 40 48 56; do
        for x in 0 8 16 24 32 40 48 56; do
            v=$(field mean "$($IS "$1" --rect $x $y $((x + 8)) $((y + 8)))")
            if awk -v v="$v" -v b="$bv" 'BEGIN { exit !(v < b) }'; then bv=$v best="$x,$y"; fi
        done
    done
    echo "$best"
}
f=$(darkest "$T/ground.pfm") c=$(darkest tests/data/cycles-env-ground.pfm)
check "ground: the darkest block (the shadow) at $f, Cycles at $c" test "$f" = "$c"
# The comparison can fail: the map turned the other way does not match.
scene sun 48 32 20 "[0, 0, 0]" "$SUN" 180 0 16 "$FAR"
r=$($IS "$T/sun.pfm" --ratio tests/data/cycles-env-sun.pfm)
if within "$(field mean "$r")" 0.9 1.1; then bad "a map turned by 180 degrees matches too"; else ok; fi
summary
