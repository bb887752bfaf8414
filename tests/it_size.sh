#!/bin/sh
# it_size.sh -- tests --scale and --size on render's command line.
#
# The image size on render's command line: --scale 50% or
# 0.5 renders at that fraction of the scene's size, each side rounded to
# the nearest pixel (halves up) and at least 1, and gives the same bytes as
# --size with that size; bad scales and --scale with --size are refused
# with what is allowed; a --size of another aspect ratio than the scene's
# is warned about once, naming both ratios, and one of the same ratio is not.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need oiiotool cmp
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
F="$(pwd)/bin/franja"
# A scene of 255x101 pixels: odd sides, so that rounding shows.
sed -e 's/"width": 512/"width": 255/' -e 's/"height": 512/"height": 101/' scenes/cornell.json >"$T/odd.json"
"$F" compile "$T/odd.json" -o "$T/odd.fbin" >/dev/null 2>&1 && ok || bad "compile failed"
R="$F render $T/odd.fbin --spp 1 -j 2"
dims() { oiiotool --info "$1" 2>/dev/null | sed -n 's/.*: *\([0-9]*\) x *\([0-9]*\),.*/\1x\2/p'; }

# scale: expected size (255x101 times it, rounded halves up, at least 1)
for case in "50%:128x51" "0.5:128x51" "10%:26x10" "0.2:51x20" "1%:3x1" "0.001:1x1" "200%:510x202"; do
    s=${case%%:*} want=${case#*:}
    $R --scale "$s" -o "$T/s.ppm" 2>"$T/log" && ok || { bad "--scale $s failed: $(cat "$T/log")"; continue; }
    got=$(dims "$T/s.ppm")
    [ "$got" = "$want" ] && ok || bad "--scale $s: $got, expected $want"
    grep -q "warning" "$T/log" && bad "--scale $s warns: $(cat "$T/log")" || ok
done
# The same image as --size with that size, byte for byte; --scale=50% too.
$R --scale=50% -o "$T/a.pfm" 2>/dev/null && $R --size 128x51 -o "$T/b.pfm" 2>"$T/blog" && ok || bad "renders failed"
cmp -s "$T/a.pfm" "$T/b.pfm" && ok || bad "--scale 50% differs from --size 128x51"

for v in 0 0% -1 500% 4.5 abc 50%% "" 5e; do
    expect_error "--scale '$v'" "is not a scale: a percentage above 0% and at most 400%" $R --scale "$v" -o "$T/x.ppm"
done
expect_error "--scale with --size" "--scale and --size exclude each other" $R --scale 50% --size 8x8 -o "$T/x.ppm"
expect_error "--size with --scale" "--scale and --size exclude each other" $R --size 8x8 --scale 0.5 -o "$T/x.ppm"

# Aspect ratio: 64x32 of a 255x101 scene changes it; the warning names both.
$R --size 64x32 -o "$T/w.ppm" 2>"$T/log" && ok || bad "--size 64x32 failed: $(cat "$T/log")"
n=$(grep -c "warning: --size" "$T/log")
[ "$n" = 1 ] && ok || bad "--size 64x32: $n warnings: $(cat "$T/log")"
grep "warning: --size" "$T/log" | grep -q "64x32 is 2:1 (2.000), the scene's 255x101 is 255:101 (2.525)" && ok ||
    bad "the aspect warning does not name both ratios: $(cat "$T/log")"
# The same ratio (510x202 = 2 x 255x101) says nothing; nor does the scene's size.
$R --size 510x202 -o "$T/w.ppm" 2>"$T/log" && ok || bad "--size 510x202 failed"
grep -q "warning" "$T/log" && bad "--size of the scene's ratio warns: $(cat "$T/log")" || ok
grep -q "warning" "$T/blog" && ok || bad "--size 128x51 (ratio 2.51 of 2.525) does not warn"
summary
