#!/bin/sh
# it_reference.sh -- tests the Cornell box against the Cycles reference.
#
# Against a peer: scenes/cornell.json at 256x256 and 64 spp, rendered as two
# worker slabs, against the Cycles reference (4096 spp) in tests/data:
# each channel's mean within 1.5 %, RMSE off the light <= 0.010.
cd "$(dirname "$0")/.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
if ! cp tests/data/cornell-ref-256.pfm "$T/ref.pfm"; then
    echo "FAIL: reference missing"
    echo "0 passed, 1 failed"; exit 1
fi
# The PFM copy of the reference holds the EXR's pixels.
if command -v oiiotool >/dev/null && ! oiiotool tests/data/cornell-ref-256.exr tests/data/cornell-ref-256.pfm --diff >"$T/diff" 2>&1; then
    echo "FAIL: tests/data/cornell-ref-256.pfm differs from the EXR: $(tail -n 3 "$T/diff")"
    echo "0 passed, 1 failed"; exit 1
fi
R="--scene scenes/cornell.json --size 256x256 --spp 64"
bin/franja-worker $R --rows 0:128 -o "$T/a.pfm" &
bin/franja-worker $R --rows 128:256 -o "$T/b.pfm" || { echo "FAIL: render"; echo "0 passed, 1 failed"; exit 1; }
wait $! || { echo "FAIL: render"; echo "0 passed, 1 failed"; exit 1; }
# Stitch the two PF slabs (bottom row first: the lower slab's pixels come
# first) into one PFM.
{ printf 'PF\n256 256\n-1.0\n'; tail -c $((128 * 256 * 12)) "$T/b.pfm"; tail -c $((128 * 256 * 12)) "$T/a.pfm"; } >"$T/full.pfm"
bin/tools/imgcmp "$T/full.pfm" "$T/ref.pfm" --max-rmse 0.010 --max-mean-rel 0.015
