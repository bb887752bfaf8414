#!/bin/sh
# bdpt.sh -- measures bidirectional against path tracing at equal CPU time.
#
# Bidirectional against unidirectional path tracing at equal CPU time on
# the spheres scene (a mirror ball, a glass ball and a Phong ball in the
# Cornell box) under a small lamp: tests/bench/scenes/spheres-lamp.json,
# scenes/spheres.json with a lamp of half the Cornell light's side and the
# same power (SCENE= another scene, e.g. scenes/spheres.json itself), at
# SIZE x SIZE pixels (128).  Path tracing renders at PT_SPP samples per
# pixel; bidirectional path tracing gets the samples per pixel that take
# the same CPU time, from the cost per sample of a calibration run.  Both
# are compared with a converged reference (BDPT at REF_SPP, which
# tests/test_bdpt.c shows agrees with path tracing), by RMSE over the
# pixels off the light: overall, in the caustic that the glass ball
# focuses onto the floor, and everywhere else.  The caustic region is a
# rectangle around the spot without the pixels that see the glass ball
# (found by rendering the scene with the ball as the only thing that
# shines): through the ball the floor's caustic is reached only by camera
# paths that hit the lamp, for both integrators alike.  Goals: at least 5x
# lower RMSE in the caustic, at most 1.5x path tracing's RMSE elsewhere.
#
# The reference is made once and kept in build/bench/ (its name holds a
# checksum of the scene and of the worker's version line; delete it after a
# change to light transport): about 10 CPU-minutes at 128x128.  The two
# equal-time images are kept there too (PNG), for scenes/README.md.
cd "$(dirname "$0")/../.." || exit 1
N=$(nproc)
W=${SIZE:-128} H=${SIZE:-128} PT_SPP=${PT_SPP:-256} REF_SPP=${REF_SPP:-4096} RUNS=${RUNS:-3}
BIN=${BIN:-bin}
SCENE=${SCENE:-tests/bench/scenes/spheres-lamp.json}
# The caustic under the glass ball: x, y fractions of the image (top row 0).
REGION=0.58,0.84,0.84,0.95
OUT=build/bench
mkdir -p "$OUT"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
echo "== bdpt: $SCENE ${W}x${H}, path tracing at $PT_SPP spp against BDPT at equal CPU time, $N worker processes"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "reproduce: SCENE=$SCENE SIZE=$W PT_SPP=$PT_SPP REF_SPP=$REF_SPP RUNS=$RUNS sh tests/bench/bdpt.sh"
"$BIN/franja" compile "$SCENE" -o "$T/spheres.fbin" >/dev/null 2>&1 || { echo "compile failed"; exit 1; }
# The mask: the glass ball as a blue lamp, nothing else lit, only what the
# camera sees directly (max_depth 0), at enough samples per pixel that a
# pixel the ball covers a sliver of is in it.
sed -e 's/"type": "glass"/"type": "emitter"/' -e 's/"ior": 1.5/"emission": [0, 0, 1000]/' \
    -e 's/"max_depth": [0-9]*/"max_depth": 0/' "$SCENE" >"$T/mask.json"
grep -q '"emission": \[0, 0, 1000\]' "$T/mask.json" || { echo "no glass ball (\"type\": \"glass\", \"ior\": 1.5) in $SCENE"; exit 1; }
"$BIN/franja" render "$T/mask.json" -o "$T/mask.pfm" --size ${W}x$H --spp 256 -j "$N" >/dev/null 2>&1 ||
    { echo "mask render failed"; exit 1; }

# render INTEGRATOR SPP OUT [FBIN]: prints the CPU seconds (user + system)
# of the render and its workers.  CPU time rather than wall time, so that
# other load on a shared machine does not tilt the comparison; on an idle
# machine with N workers busy the two are proportional.
render() {
    /usr/bin/time -f '%U %S' -o "$T/time" "$BIN/franja" render "${4:-$T/spheres.fbin}" -o "$3" --size ${W}x$H \
        --spp "$2" --integrator "$1" -j "$N" 2>"$T/log" || { tail -n 5 "$T/log" >&2; exit 1; }
    awk '{ printf "%.3f", $1 + $2 }' "$T/time"
}

key=$( ("$BIN/franja-worker" --version; cat "$SCENE") | sha256sum | cut -c1-12)
REF="$OUT/spheres-ref-${W}-${REF_SPP}-$key.pfm"
if [ ! -s "$REF" ]; then
    echo "making the reference (BDPT, $REF_SPP spp) into $REF ..."
    t=$(render bdpt "$REF_SPP" "$T/ref.pfm") && mv "$T/ref.pfm" "$REF" || exit 1
    echo "reference: $t CPU s"
fi

# RUNS renders of each integrator with the scene's seed set to 1, 2, ...
# (the reference has the scene's own): a few pixels of the caustic carry
# most of its error, so one run's RMSE is itself noisy; the medians count.
for r in $(seq 1 "$RUNS"); do
    sed "s/\"seed\": [0-9]*/\"seed\": $r/" "$SCENE" >"$T/seed$r.json"
    "$BIN/franja" compile "$T/seed$r.json" -o "$T/seed$r.fbin" >/dev/null 2>&1 || { echo "compile failed"; exit 1; }
done
# Calibrate: BDPT at a quarter of path tracing's samples, then the samples
# that match path tracing's time.
t_pt=$(render path "$PT_SPP" "$T/pt.pfm" "$T/seed1.fbin") || exit 1
cal=$((PT_SPP / 4))
t_cal=$(render bdpt "$cal" "$T/cal.pfm" "$T/seed1.fbin") || exit 1
spp_bd=$(awk "BEGIN { s = int($cal * $t_pt / $t_cal + 0.5); print s < 1 ? 1 : s }")
echo "BDPT at $spp_bd spp (calibration: path $PT_SPP spp in $t_pt CPU s, BDPT $cal spp in $t_cal CPU s)"

us() { awk "BEGIN { printf \"%.2f\", $1 / ($W * $H * $2) * 1e6 }"; }
field() { sed -n "s/^rmse in region \([0-9.]*\) over [0-9]* pixels, outside \([0-9.]*\) over.*/\\$2/p" "$1"; }
all() { sed -n 's/^rmse \([0-9.]*\) over.*/\1/p' "$1"; }
: >"$T/runs"
for r in $(seq 1 "$RUNS"); do
    t_pt=$(render path "$PT_SPP" "$T/pt$r.pfm" "$T/seed$r.fbin") || exit 1
    t_bd=$(render bdpt "$spp_bd" "$T/bd$r.pfm" "$T/seed$r.fbin") || exit 1
    for name in pt bd; do
        "$BIN/tools/imgcmp" "$T/$name$r.pfm" "$REF" --region "$REGION" --mask "$T/mask.pfm" >"$T/$name.cmp" || exit 1
    done
    # us_pt us_bd all_pt all_bd caustic_pt caustic_bd else_pt else_bd
    echo "$(us "$t_pt" "$PT_SPP") $(us "$t_bd" "$spp_bd") $(all "$T/pt.cmp") $(all "$T/bd.cmp")" \
        "$(field "$T/pt.cmp" 1) $(field "$T/bd.cmp" 1) $(field "$T/pt.cmp" 2) $(field "$T/bd.cmp" 2)" >>"$T/runs"
    echo "run $r (seed $r): $(tail -n 1 "$T/runs" | awk '{ printf "path %s us/sample, BDPT %s; caustic RMSE path %s, BDPT %s; elsewhere path %s, BDPT %s", $1, $2, $5, $6, $7, $8 }')"
done
# med COLUMN: the median of that column of the runs.
med() { cut -d' ' -f"$1" "$T/runs" | sort -g | awk '{ v[NR] = $1 } END { print NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
u_pt=$(med 1) u_bd=$(med 2) c_pt=$(med 5) c_bd=$(med 6) e_pt=$(med 7) e_bd=$(med 8)
npx=$(sed -n 's/^rmse in region [0-9.]* over \([0-9]*\) pixels.*/\1/p' "$T/pt.cmp")
echo "medians of $RUNS runs:"
echo "cost per sample: path $u_pt us, BDPT $u_bd us: BDPT/path $(awk "BEGIN { printf \"%.2f\", $u_bd / $u_pt }")"
echo "RMSE against the reference (off the light):"
echo "  overall:    path $(med 3), BDPT $(med 4)"
echo "  caustic ($npx pixels): path $c_pt, BDPT $c_bd: BDPT $(awk "BEGIN { printf \"%.1f\", $c_pt / $c_bd }")x lower (goal >= 5x)"
echo "  elsewhere:  path $e_pt, BDPT $e_bd: BDPT/path $(awk "BEGIN { printf \"%.2f\", $e_bd / $e_pt }") (goal <= 1.5)"
"$BIN/franja" render "$T/spheres.fbin" -o "$OUT/spheres-path-equal-time.png" --size ${W}x$H --spp "$PT_SPP" -j "$N" 2>/dev/null
"$BIN/franja" render "$T/spheres.fbin" -o "$OUT/spheres-bdpt-equal-time.png" --size ${W}x$H --spp "$spp_bd" \
    --integrator bdpt -j "$N" 2>/dev/null
echo "images (the scene's seed): $OUT/spheres-path-equal-time.png $OUT/spheres-bdpt-equal-time.png"
