#!/bin/sh
# it_crop.sh -- tests franja render --crop renders only the window.
#
# franja render --crop X0:Y0:X1:Y1: only the window's rows are
# rendered, split like any render; the window's pixels are byte for byte
# those of a full render, the rest black; --crop-output writes the window
# alone; bad windows are refused before rendering.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need oiiotool
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
F="$(pwd)/bin/franja"
IS="$(pwd)/bin/tools/imgstat"
SIZE="--size 40x30 --spp 4"

"$F" compile scenes/cornell.json -o "$T/s.fbin" >/dev/null 2>&1 && ok || bad "compile failed"
"$F" render "$T/s.fbin" -o "$T/ref.pfm" $SIZE -j 2 2>/dev/null && ok || bad "the full render failed"

# The window 5:7:29:23 with several splits: the same bytes each time.
"$F" render "$T/s.fbin" -o "$T/c1.pfm" $SIZE -j 1 --crop 5:7:29:23 --keep-job 2>"$T/log" && ok ||
    bad "crop render failed: $(cat "$T/log")"
"$F" render "$T/s.fbin" -o "$T/c2.pfm" $SIZE -j 3 --slab-rows 1 --crop 5:7:29:23 2>/dev/null &&
    cmp -s "$T/c1.pfm" "$T/c2.pfm" && ok || bad "one-row slabs give another crop"
"$F" render "$T/s.fbin" -o "$T/c3.pfm" $SIZE -j 2 --slab-rows 5 --crop 5:7:29:23 2>/dev/null &&
    cmp -s "$T/c1.pfm" "$T/c3.pfm" && ok || bad "5-row slabs give another crop"
# The window is the full render's, the rest black.
st=$("$IS" "$T/c1.pfm")
case $st in size=40x30*) ok ;; *) bad "the cropped image is not 40x30: $st" ;; esac
d=$("$IS" "$T/c1.pfm" --rect 5 7 29 23 --diff "$T/ref.pfm")
case $d in *" max=0 "*) ok ;; *) bad "the window differs from the full render: $d" ;; esac
w=$("$IS" "$T/c1.pfm" --rect 5 7 29 23)
case $w in *"min=0 max=0 "*) bad "the window is black: $w" ;; *) ok ;; esac
for r in "0 0 40 7" "0 23 40 30" "0 7 5 23" "29 7 40 23"; do
    o=$("$IS" "$T/c1.pfm" --rect $r)
    case $o in *"min=0 max=0 "*) ok ;; *) bad "outside the window ($r) is not black: $o" ;; esac
done
# Only the window's rows were rendered: the slabs kept cover rows 7 to 23.
rows=$(ls "$T/c1.pfm.franja-job" | sed -n 's/^rows-\([0-9]*\)-\([0-9]*\)\.pf$/\1 \2/p' |
    awk '{ a = $1 + 0; b = $2 + 0 } NR == 1 || a < lo { lo = a } NR == 1 || b > hi { hi = b } { n += b - a }
         END { print lo, hi, n }')
[ "$rows" = "7 23 16" ] && ok || bad "the crop's slabs cover rows '$rows', not 7 to 23 once"

# --crop-output: the window alone, as the full render's window.
"$F" render "$T/s.fbin" -o "$T/w.pfm" $SIZE -j 2 --crop 5:7:29:23 --crop-output 2>/dev/null && ok ||
    bad "--crop-output failed"
st=$("$IS" "$T/w.pfm")
case $st in size=24x16*) ok ;; *) bad "--crop-output is not 24x16: $st" ;; esac
oiiotool "$T/ref.pfm" --cut 24x16+5+7 -o "$T/refwin.exr" 2>/dev/null &&
    oiiotool "$T/w.pfm" "$T/refwin.exr" --diff --fail 0 2>&1 | grep -q PASS && ok ||
    bad "--crop-output differs from the full render's window"
# An 8-bit output too: the window's bytes are the full PNG's.
"$F" render "$T/s.fbin" -o "$T/ref.png" $SIZE 2>/dev/null &&
    "$F" render "$T/s.fbin" -o "$T/w.png" $SIZE --crop 5:7:29:23 --crop-output 2>/dev/null &&
    oiiotool "$T/ref.png" --cut 24x16+5+7 -o "$T/refwin.png" 2>/dev/null &&
    oiiotool "$T/w.png" "$T/refwin.png" --diff --fail 0 2>&1 | grep -q PASS && ok ||
    bad "a PNG --crop-output differs from the full PNG's window"

# The whole image as the window is the full render.
"$F" render "$T/s.fbin" -o "$T/all.pfm" $SIZE --crop 0:0:40:30 2>/dev/null && cmp -s "$T/all.pfm" "$T/ref.pfm" && ok ||
    bad "--crop of the whole image differs from the full render"

# Bidirectional: every row is rendered (light from the whole image reaches
# the window), and the window is the full render's.
"$F" render "$T/s.fbin" -o "$T/bref.pfm" --size 24x16 --spp 2 --integrator bdpt 2>/dev/null &&
    "$F" render "$T/s.fbin" -o "$T/b.pfm" --size 24x16 --spp 2 --integrator bdpt --crop 3:4:15:10 2>"$T/blog" && ok ||
    bad "bidirectional crop failed: $(cat "$T/blog")"
grep -q "renders every row" "$T/blog" && ok || bad "the bidirectional crop does not say it renders every row"
d=$("$IS" "$T/b.pfm" --rect 3 4 15 10 --diff "$T/bref.pfm")
case $d in *" max=0 "*) ok ;; *) bad "the bidirectional window differs: $d" ;; esac
o=$("$IS" "$T/b.pfm" --rect 0 10 24 16)
case $o in *"min=0 max=0 "*) ok ;; *) bad "outside the bidirectional window is not black: $o" ;; esac

# --resume of an interrupted full render's job directory with a crop: the
# slabs there are used (same image, full rows).
"$F" render "$T/s.fbin" -o "$T/r.pfm" $SIZE --slab-rows 10 --keep-job 2>/dev/null &&
    rm -f "$T/r.pfm" "$T"/r.pfm.franja-job/rows-*20-*30.pf &&
    "$F" render "$T/s.fbin" -o "$T/r.pfm" $SIZE --crop 5:7:29:23 --resume 2>"$T/rlog" && ok ||
    bad "a crop resuming a full render's job failed: $(cat "$T/rlog")"
grep -q "resuming: 20 of 30 rows" "$T/rlog" && ok || bad "the resumed crop did not find 20 rows: $(cat "$T/rlog")"
cmp -s "$T/r.pfm" "$T/c1.pfm" && ok || bad "the resumed crop differs from the crop"

# Bad windows, before rendering.
expect_error "crop syntax" "'1:2:3' is not X0:Y0:X1:Y1" "$F" render "$T/s.fbin" -o "$T/x.pfm" --crop 1:2:3
expect_error "crop letters" "is not X0:Y0:X1:Y1" "$F" render "$T/s.fbin" -o "$T/x.pfm" --crop 1:2:a:4
expect_error "crop empty" "the window is empty" "$F" render "$T/s.fbin" -o "$T/x.pfm" --crop 5:5:5:9
expect_error "crop too big" "does not fit in the 40x30 image" "$F" render "$T/s.fbin" -o "$T/x.pfm" $SIZE --crop 0:0:41:10
expect_error "crop-output alone" "--crop-output needs --crop" "$F" render "$T/s.fbin" -o "$T/x.pfm" --crop-output
[ -e "$T/x.pfm.franja-job" ] && bad "a refused crop left a job directory" || ok
summary
