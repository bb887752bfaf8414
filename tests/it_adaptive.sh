#!/bin/sh
# it_adaptive.sh -- tests adaptive sampling through the band renderer.
#
# Adaptive sampling through the band renderer: `franja render
# --noise-threshold E` stitches the same bytes from 1, 2, 3 and 7 slabs and
# any number of workers (each pixel's decision reads only its own samples),
# differs from the full-sample image, keeps its threshold in the job
# directory (a resume with another threshold is refused), and refuses
# thresholds outside (0, 1] and adaptive bidirectional renders.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
F=bin/franja
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
W=24 H=21
SIZE="--size ${W}x$H --spp 64"
A="--noise-threshold 0.05"
"$F" compile scenes/spheres.json -o "$T/s.fbin" >/dev/null 2>&1
check "the spheres scene compiles" test -s "$T/s.fbin"

"$F" render "$T/s.fbin" -o "$T/one.pfm" $SIZE $A -j 1 --slab-rows $H 2>"$T/log1"
check "one slab: an adaptive render succeeds" test -s "$T/one.pfm"
for n in 2 3 7; do
    rows=$(((H + n - 1) / n))
    "$F" render "$T/s.fbin" -o "$T/s$n.pfm" $SIZE $A -j 2 --slab-rows $rows 2>"$T/log$n"
    check "$n slabs were rendered" grep -q "; $n slabs" "$T/log$n"
    check "$n slabs give the bytes of one" cmp -s "$T/s$n.pfm" "$T/one.pfm"
done
"$F" render "$T/s.fbin" -o "$T/full.pfm" $SIZE -j 2 2>/dev/null
check "without a threshold the image differs" sh -c "! cmp -s '$T/full.pfm' '$T/one.pfm'"
# The worker alone, the threshold from the command line: the same pixels.
bin/franja-worker --scene "$T/s.fbin" $SIZE $A --rows 0:$H -o "$T/w.pfm"
bin/tools/imgcmp "$T/w.pfm" "$T/one.pfm" >"$T/cmp" 2>&1
check "a worker with --noise-threshold renders the coordinator's pixels" grep -q "^rmse 0\(\.0*\)\? " "$T/cmp"

# The job directory records the threshold; resuming with another is refused.
"$F" render "$T/s.fbin" -o "$T/k.pfm" $SIZE $A -j 1 --job "$T/kj" --keep-job 2>/dev/null
check "the job file names the threshold" grep -qx "noise_threshold=0.0500000007" "$T/kj/job"
expect_error "a resume with another threshold" "noise threshold" \
    "$F" render "$T/s.fbin" -o "$T/k.pfm" $SIZE --noise-threshold 0.1 -j 1 --job "$T/kj" --resume
"$F" render "$T/s.fbin" -o "$T/k.pfm" $SIZE $A -j 1 --job "$T/kj" --resume 2>/dev/null
check "a resume with the same threshold gives the same bytes" cmp -s "$T/k.pfm" "$T/one.pfm"

for bad in 0 -0.1 1.5 nan x; do
    expect_error "--noise-threshold $bad" "--noise-threshold" "$F" render "$T/s.fbin" -o "$T/b.pfm" $SIZE \
        --noise-threshold "$bad"
done
expect_error "an adaptive bidirectional render" "not bdpt" \
    "$F" render "$T/s.fbin" -o "$T/b.pfm" $SIZE $A --integrator bdpt
summary
