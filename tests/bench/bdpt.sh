#!/bin/sh
# Bidirectional against unidirectional path tracing at equal CPU time:
# scenes/spheres.json (a mirror ball, a glass ball and a Phong ball under
# the Cornell box's small ceiling light) at SIZE x SIZE pixels (128).  Path tracing renders
# at PT_SPP samples per pixel; bidirectional path tracing gets the samples
# per pixel that take the same CPU time, from the cost per sample of a
# calibration run.  Both are compared with a converged reference (BDPT at
# REF_SPP, which tests/test_bdpt.c shows agrees with path tracing), by RMSE
# over the pixels off the light: overall, in the caustic that the glass
# ball focuses onto the floor, and everywhere else.  Goals: at least 5x
# lower RMSE in the caustic, at most 1.5x path tracing's RMSE elsewhere.
#
# The reference is made once and kept in build/bench/ (its name holds a
# checksum of the scene and of the worker's version line; delete it after a
# change to light transport): about 10 CPU-minutes.  The two equal-time images are kept
# there too (PNG), for scenes/README.md.
cd "$(dirname "$0")/../.." || exit 1
N=$(nproc)
W=${SIZE:-128} H=${SIZE:-128} PT_SPP=${PT_SPP:-256} REF_SPP=${REF_SPP:-4096}
BIN=${BIN:-bin}
# The caustic under the glass ball: x, y fractions of the image (top row 0).
REGION=0.58,0.84,0.84,0.95
OUT=build/bench
mkdir -p "$OUT"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
echo "== bdpt: scenes/spheres.json ${W}x${H}, path tracing at $PT_SPP spp against BDPT at equal CPU time, $N worker processes"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "reproduce: SIZE=$W PT_SPP=$PT_SPP REF_SPP=$REF_SPP sh tests/bench/bdpt.sh"
"$BIN/franja" compile scenes/spheres.json -o "$T/spheres.fbin" >/dev/null 2>&1 || { echo "compile failed"; exit 1; }

# render INTEGRATOR SPP OUT: prints the CPU seconds (user + system) of
# the render and its workers.  CPU time rather than wall time, so that
# other load on a shared machine does not tilt the comparison; on an idle
# machine with N workers busy the two are proportional.
render() {
    /usr/bin/time -f '%U %S' -o "$T/time" "$BIN/franja" render "$T/spheres.fbin" -o "$3" --size ${W}x$H \
        --spp "$2" --integrator "$1" -j "$N" 2>"$T/log" || { tail -n 5 "$T/log" >&2; exit 1; }
    awk '{ printf "%.3f", $1 + $2 }' "$T/time"
}

key=$( ("$BIN/franja-worker" --version; cat scenes/spheres.json) | sha256sum | cut -c1-12)
REF="$OUT/spheres-ref-${W}-${REF_SPP}-$key.pfm"
if [ ! -s "$REF" ]; then
    echo "making the reference (BDPT, $REF_SPP spp) into $REF ..."
    t=$(render bdpt "$REF_SPP" "$T/ref.pfm") && mv "$T/ref.pfm" "$REF" || exit 1
    echo "reference: $t CPU s"
fi

t_pt=$(render path "$PT_SPP" "$T/pt.pfm") || exit 1
# Calibrate: BDPT at a quarter of path tracing's samples, then the samples
# that match path tracing's time.
cal=$((PT_SPP / 4))
t_cal=$(render bdpt "$cal" "$T/cal.pfm") || exit 1
spp_bd=$(awk "BEGIN { s = int($cal * $t_pt / $t_cal + 0.5); print s < 1 ? 1 : s }")
t_bd=$(render bdpt "$spp_bd" "$T/bd.pfm") || exit 1

us() { awk "BEGIN { printf \"%.2f\", $1 / ($W * $H * $2) * 1e6 }"; }
echo "path tracing: $PT_SPP spp in $t_pt CPU s, $(us "$t_pt" "$PT_SPP") us per sample"
echo "BDPT:         $spp_bd spp in $t_bd CPU s, $(us "$t_bd" "$spp_bd") us per sample; calibration $cal spp in $t_cal CPU s"
echo "cost per sample BDPT/path: $(awk "BEGIN { printf \"%.2f\", ($t_bd / $spp_bd) / ($t_pt / $PT_SPP) }")"
for name in pt bd; do
    "$BIN/tools/imgcmp" "$T/$name.pfm" "$REF" --region "$REGION" >"$T/$name.cmp" || exit 1
done
field() { sed -n "s/^rmse in region \([0-9.]*\) over [0-9]* pixels, outside \([0-9.]*\) over.*/\\$2/p" "$T/$1.cmp"; }
all() { sed -n 's/^rmse \([0-9.]*\) over.*/\1/p' "$T/$1.cmp"; }
c_pt=$(field pt 1) c_bd=$(field bd 1) e_pt=$(field pt 2) e_bd=$(field bd 2)
echo "RMSE against the reference (off the light):"
echo "  overall:    path $(all pt), BDPT $(all bd)"
echo "  caustic:    path $c_pt, BDPT $c_bd: BDPT $(awk "BEGIN { printf \"%.1f\", $c_pt / $c_bd }")x lower (goal >= 5x)"
echo "  elsewhere:  path $e_pt, BDPT $e_bd: BDPT/path $(awk "BEGIN { printf \"%.2f\", $e_bd / $e_pt }") (goal <= 1.5)"
"$BIN/franja" render "$T/spheres.fbin" -o "$OUT/spheres-path-equal-time.png" --size ${W}x$H --spp "$PT_SPP" -j "$N" 2>/dev/null
"$BIN/franja" render "$T/spheres.fbin" -o "$OUT/spheres-bdpt-equal-time.png" --size ${W}x$H --spp "$spp_bd" \
    --integrator bdpt -j "$N" 2>/dev/null
echo "images: $OUT/spheres-path-equal-time.png $OUT/spheres-bdpt-equal-time.png"
