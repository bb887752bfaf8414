#!/bin/sh
# it_continue.sh -- tests franja-worker --sums and --continue give exact bytes.
#
# franja-worker --sums and --continue FILE: a slab
# rendered with fewer samples and continued gives the bytes of a render of
# every sample at once; what cannot be continued exactly is refused.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
W="$(pwd)/bin/franja-worker"
"$(pwd)/bin/franja" compile scenes/cornell.json -o "$T/c.fbin" >/dev/null 2>&1 && ok || bad "compile failed"
"$(pwd)/bin/franja" compile scenes/spheres.json -o "$T/s.fbin" >/dev/null 2>&1 && ok || bad "compile failed"
S="--scene $T/c.fbin --rows 3:9 --size 32x24"

"$W" $S --spp 20 -o "$T/full.pf" && "$W" $S --spp 20 --sums -o "$T/fulls.pf" && ok || bad "plain renders failed"
"$W" $S --spp 7 --sums -o "$T/a7.pf" && "$W" $S --spp 20 --continue "$T/a7.pf" -o "$T/b.pf" && ok ||
    bad "7 then 20 samples failed"
cmp -s "$T/full.pf" "$T/b.pf" && ok || bad "7 samples continued to 20 differ from 20 at once"
# In steps, through standard output, keeping the sums: the same bytes.
"$W" $S --spp 13 --sums --continue "$T/a7.pf" >"$T/a13.pf" &&
    "$W" $S --spp 20 --sums --continue "$T/a13.pf" -o "$T/a20.pf" && cmp -s "$T/a20.pf" "$T/fulls.pf" && ok ||
    bad "7, 13, 20 samples with sums differ from 20 at once"
head -c 200 "$T/a20.pf" | grep -aq ' sums=[0-9a-f]\{16\}$' && ok || bad "no sums= in the header"
cmp -s "$T/a7.pf" "$T/a13.pf" && bad "13 samples gave the bytes of 7" || ok
# As many samples as the file has: the same image.
"$W" $S --spp 20 --continue "$T/fulls.pf" -o "$T/same.pf" && cmp -s "$T/same.pf" "$T/full.pf" && ok ||
    bad "continuing 20 samples to 20 changed the image"

# Refused, before rendering.
expect_error "other rows" "rows 3:9 of a 32x24 image, not rows 4:9" "$W" --scene "$T/c.fbin" --rows 4:9 --size 32x24 \
    --spp 20 --continue "$T/a7.pf" -o "$T/x.pf"
expect_error "other size" "not rows 3:9 of 32x25" "$W" --scene "$T/c.fbin" --rows 3:9 --size 32x25 --spp 20 \
    --continue "$T/a7.pf" -o "$T/x.pf"
expect_error "fewer samples" "has 13 samples per pixel, more than the 7 asked for" "$W" $S --spp 7 \
    --continue "$T/a13.pf" -o "$T/x.pf"
expect_error "no sums" "has no sample sums" "$W" $S --spp 30 --continue "$T/full.pf" -o "$T/x.pf"
expect_error "another scene" "another scene" "$W" --scene "$T/s.fbin" --rows 3:9 --size 32x24 --spp 30 \
    --continue "$T/a7.pf" -o "$T/x.pf"
printf 'P6\n1 1\n255\nabc' >"$T/junk.pf"
expect_error "not a partial" "--continue $T/junk.pf: byte 0: not a PF" "$W" $S --spp 30 --continue "$T/junk.pf" -o "$T/x.pf"
expect_error "missing file" "$T/none.pf" "$W" $S --spp 30 --continue "$T/none.pf" -o "$T/x.pf"
expect_error "bdpt" "need the path integrator" "$W" $S --spp 8 --integrator bdpt --sums -o "$T/x.pf"
expect_error "adaptive" "without adaptive sampling" "$W" $S --spp 8 --noise-threshold 0.1 --sums -o "$T/x.pf"
expect_error "8-bit" "--format pf" "$W" $S --spp 8 --format ppm8 --continue "$T/a7.pf" -o "$T/x.pf"
expect_error "no value" "--continue needs a value" "$W" $S --continue
[ -e "$T/x.pf" ] && bad "a refused render left its output" || ok
summary
