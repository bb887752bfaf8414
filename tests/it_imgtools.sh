#!/bin/sh
# it_imgtools.sh -- tests the image tools the other tests measure with.
#
# The image tools the other tests measure with, on PFM
# files whose values are known: pfmpix's orientation (y = 0 is the top row,
# which a PFM stores last), imgstat's means, and imgcmp's RMSE with and
# without --clamp-pct (a percentile of the reference's channels off the
# light, pixels of the reference at 10 or more being the light); broken
# files and bad values are refused with status 2 (imgcmp, imgstat) or 1.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
B=bin/tools

# Little-endian IEEE 754 single floats, as printf octal escapes.
f() {
    case $1 in
    0) printf '\000\000\000\000' ;; 0.25) printf '\000\000\200\076' ;; 0.5) printf '\000\000\000\077' ;;
    0.75) printf '\000\000\100\077' ;; 1) printf '\000\000\200\077' ;; 20) printf '\000\000\240\101' ;;
    esac
}
# pfm FILE W H V...: a grey image (each V repeated over R, G, B), the
# values given top row first; the file holds the bottom row first.
pfm() {
    out=$1 w=$2 h=$3
    shift 3
    printf 'PF\n%s %s\n-1.0\n' "$w" "$h" >"$out"
    y=$h
    while [ "$y" -gt 0 ]; do
        y=$((y - 1))
        i=0
        for v in "$@"; do
            if [ $((i / w)) -eq "$y" ]; then f "$v" >>"$out"; f "$v" >>"$out"; f "$v" >>"$out"; fi
            i=$((i + 1))
        done
    done
}

# A reference of 5 x 2 pixels: the lamp (20) in the top row, the rest 0.25
# to 1; the image differs at one pixel of the bottom row (1 -> 0.75) and
# under the lamp (20 -> 0), which does not count.
pfm "$T/ref.pfm" 5 2 20 0.25 0.5 0.5 1   0.25 0.5 0.5 1 0.5
pfm "$T/img.pfm" 5 2 0  0.25 0.5 0.5 1   0.25 0.5 0.5 0.75 0.5

check "pfmpix: the size" sh -c "[ \"\$($B/pfmpix $T/ref.pfm size)\" = '5 2' ]"
check "pfmpix: (0, 0) is the top left pixel (the lamp)" sh -c "[ \"\$($B/pfmpix $T/ref.pfm 0 0)\" = '20 20 20' ]"
check "pfmpix: (3, 1) is in the bottom row" sh -c "[ \"\$($B/pfmpix $T/img.pfm 3 1)\" = '0.75 0.75 0.75' ]"
expect_error "pfmpix outside the image" "(5, 0) is outside 5x2" $B/pfmpix "$T/ref.pfm" 5 0

$B/imgstat "$T/img.pfm" --rect 1 0 5 2 >"$T/stat"
check "imgstat: the mean over a rectangle ($(cat "$T/stat"))" grep -q 'size=5x2 mean=0.5625 .*min=0.25 max=1 ' "$T/stat"

# RMSE off the light: one pixel of nine off by 0.25 in each channel.
$B/imgcmp "$T/img.pfm" "$T/ref.pfm" --clamp-pct 99 >"$T/c99"
check "imgcmp: rmse 0.25/3 over 9 pixels off the light ($(grep '^rmse' "$T/c99"))" \
    grep -q '^rmse 0.08333 over 9 pixels off the light' "$T/c99"
# The 99th percentile of the 27 channel values off the light is 1: the
# difference survives the clamp.
check "imgcmp: clamped at the 99th percentile ($(grep clamped "$T/c99"))" \
    grep -q '^clamped rmse 0.08333 (both clamped at 1.00000' "$T/c99"
# The 50th percentile is 0.5: both 1 and 0.75 clamp to it.
$B/imgcmp "$T/img.pfm" "$T/ref.pfm" --clamp-pct 50 >"$T/c50"
check "imgcmp: clamped at the median ($(grep clamped "$T/c50"))" \
    grep -q '^clamped rmse 0.00000 (both clamped at 0.50000' "$T/c50"
$B/imgcmp "$T/img.pfm" "$T/ref.pfm" --max-rmse 0.08 >"$T/lim"
check "imgcmp: a limit below the rmse fails with status 1" test $? -eq 1
check "imgcmp: it says which" grep -q 'FAIL: rmse 0.08333 above 0.08000' "$T/lim"
$B/imgcmp "$T/img.pfm" "$T/ref.pfm" --max-rmse 0.09 >"$T/lim2"
check "imgcmp: a limit above it passes (status $?)" grep -q '^1 passed, 0 failed' "$T/lim2"

expect_error "imgcmp --clamp-pct 0" "expected a percentile between 0 and 100" \
    $B/imgcmp "$T/img.pfm" "$T/ref.pfm" --clamp-pct 0
printf 'PF\n5 2\n-1.0\n' >"$T/short.pfm"
expect_error "imgcmp on a file cut short" "short.pfm: not a little-endian RGB PFM" \
    $B/imgcmp "$T/short.pfm" "$T/ref.pfm"
expect_error "imgstat on a file cut short" "imgstat: $T/short.pfm: not a little-endian RGB PFM" \
    $B/imgstat "$T/short.pfm"
expect_error "pfmpix on a file cut short" "pfmpix: $T/short.pfm: not a little-endian RGB PFM" \
    $B/pfmpix "$T/short.pfm" size
summary
