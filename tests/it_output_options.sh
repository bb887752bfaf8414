#!/bin/sh
# it_output_options.sh -- tests the JPEG and OpenEXR output options.
#
# How the output is stored: --jpeg-quality for
# .jpg (default 98, as the help says), --exr-half and --exr-compression for
# .exr (default 32-bit floats, zip), each visible in the file; bad values
# are refused with what is allowed.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need oiiotool
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
F="$(pwd)/bin/franja"
"$F" compile scenes/cornell.json -o "$T/c.fbin" >/dev/null 2>&1 && ok || bad "compile failed"
R="$F render $T/c.fbin --size 48x48 --spp 4 -j 2"
size() { wc -c <"$1" | tr -d ' '; }

$R -o "$T/def.jpg" 2>/dev/null && $R -o "$T/q98.jpg" --jpeg-quality 98 2>/dev/null &&
    $R -o "$T/q20.jpg" --jpeg-quality 20 2>/dev/null && $R -o "$T/q90.jpg" --jpeg-quality=90 2>/dev/null && ok ||
    bad "JPEG renders failed"
same_pixels "$T/def.jpg" "$T/q98.jpg" && ok || bad "the default JPEG quality is not 98"
[ "$(size "$T/q20.jpg")" -lt "$(size "$T/q90.jpg")" ] && [ "$(size "$T/q90.jpg")" -lt "$(size "$T/def.jpg")" ] && ok ||
    bad "JPEG sizes do not grow with the quality: $(size "$T/q20.jpg") $(size "$T/q90.jpg") $(size "$T/def.jpg")"

$R -o "$T/f.exr" 2>/dev/null && $R -o "$T/h.exr" --exr-half --exr-compression piz 2>/dev/null &&
    $R -o "$T/n.exr" --exr-compression none 2>/dev/null && ok || bad "EXR renders failed"
oiiotool --info -v "$T/f.exr" >"$T/fi" 2>&1
oiiotool --info -v "$T/h.exr" >"$T/hi" 2>&1
oiiotool --info -v "$T/n.exr" >"$T/ni" 2>&1
grep -q ' float openexr' "$T/fi" && grep -q 'compression: "zip"' "$T/fi" && ok ||
    bad "the default EXR is not float with zip: $(cat "$T/fi")"
grep -q ' half openexr' "$T/hi" && grep -q 'compression: "piz"' "$T/hi" && ok ||
    bad "--exr-half --exr-compression piz: $(cat "$T/hi")"
grep -q 'compression: "none"' "$T/ni" && [ "$(size "$T/n.exr")" -gt "$(size "$T/f.exr")" ] && ok ||
    bad "--exr-compression none: $(cat "$T/ni")"
# Half floats hold the same image to their precision; uncompressed, the same floats.
oiiotool --fail 0.02 --warn 0.02 "$T/h.exr" "$T/f.exr" --diff 2>&1 | grep -q PASS && ok || bad "the half EXR is not the image"
oiiotool "$T/n.exr" "$T/f.exr" --diff --fail 0 2>&1 | grep -q PASS && ok || bad "the uncompressed EXR is not the image"

expect_error "quality 0" "--jpeg-quality: '0' is not an integer in 1..100" $R -o "$T/x.jpg" --jpeg-quality 0
expect_error "compression" "--exr-compression" $R -o "$T/x.exr" --exr-compression lzma
grep -q "piz" "$T/err" && ok || bad "a bad compression does not list the choices: $(cat "$T/err")"
summary
