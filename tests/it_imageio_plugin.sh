#!/bin/sh
# it_imageio_plugin.sh -- tests OpenImageIO is loaded through its plug-in only.
#
# franja loads OpenImageIO through its plug-in
# franja-imageio.so only when it reads or writes an image other than PFM:
# franja itself needs none of OpenImageIO's libraries; with the plug-in
# beside it (or in ../lib/franja) a PNG is written; without it a PFM
# render still works and a PNG render, or a scene with an image texture,
# fails with status 2 naming the missing plug-in and where it was looked
# for; a file of that name that is no plug-in is refused with the loader's
# message.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need oiiotool ldd
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# The program alone links no image library.
if ldd bin/franja | grep -qi "OpenImageIO"; then bad "bin/franja links OpenImageIO: $(ldd bin/franja | grep -i openimageio)"; else ok; fi
ldd bin/franja-imageio.so | grep -qi "OpenImageIO" && ok || bad "the plug-in does not link OpenImageIO"

# A copy of the programs without the plug-in.
mkdir -p "$T/bare" "$T/tree/bin" "$T/tree/lib/franja"
cp bin/franja bin/franja-worker "$T/bare/"
R="render scenes/cornell.json --size 16x16 --spp 1 -j 1"
"$T/bare/franja" $R -o "$T/a.pfm" 2>"$T/log" && ok || bad "PFM without the plug-in: $(cat "$T/log")"
[ -s "$T/a.pfm" ] && ok || bad "PFM without the plug-in: no image"
"$T/bare/franja" $R -o "$T/a.png" >"$T/out" 2>"$T/err"
rc=$?
[ $rc -eq 2 ] && ok || bad "PNG without the plug-in: status $rc, expected 2"
grep -q "franja-imageio.so is not installed (looked in $T/bare" "$T/err" && ok ||
    bad "PNG without the plug-in: $(cat "$T/err")"
[ ! -e "$T/a.png" ] && ok || bad "PNG without the plug-in: a file was written"
expect_error "texture without the plug-in" "franja-imageio.so is not installed" \
    "$T/bare/franja" compile scenes/cornell-textured.json -o "$T/t.fbin"

# Beside the program, and in ../lib/franja as make install puts it.
cp bin/franja-imageio.so "$T/bare/"
"$T/bare/franja" $R -o "$T/b.png" 2>"$T/log" && [ -s "$T/b.png" ] && ok || bad "PNG, plug-in beside: $(cat "$T/log")"
cp bin/franja bin/franja-worker "$T/tree/bin/"
cp bin/franja-imageio.so "$T/tree/lib/franja/"
"$T/tree/bin/franja" $R -o "$T/c.png" 2>"$T/log" && [ -s "$T/c.png" ] && ok ||
    bad "PNG, plug-in in ../lib/franja: $(cat "$T/log")"
same_pixels "$T/b.png" "$T/c.png" && ok || bad "the two PNGs differ"

# Not a plug-in: the loader's message.
printf 'not a shared object\n' >"$T/bare/franja-imageio.so"
expect_error "a broken plug-in" "cannot load" "$T/bare/franja" $R -o "$T/d.png"
summary
