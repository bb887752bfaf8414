#!/bin/sh
# it_full_disk.sh -- tests the final image on a full file system.
#
# The final image on a full file system: for every output format the render
# fails with a message naming the file, the file already there is left as it
# was (no truncated or empty image under the final name), no temporary file
# is left behind, and the job directory keeps the rendered rows so that
# --resume writes the image once there is room.  An output that cannot be
# written at all (a missing or read-only directory, a directory as the
# output) is refused before anything is rendered.  Needs root (it mounts
# small tmpfs file systems); without it the test fails.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need oiiotool
F=$PWD/bin/franja
T=$(mktemp -d)
M=$T/full R=$T/ro
trap 'umount "$M" 2>/dev/null; umount "$R" 2>/dev/null; rm -rf "$T"' EXIT
mkdir "$M" "$R"
if ! mount -t tmpfs -o size=1m tmpfs "$M" 2>"$T/err" || ! mount -t tmpfs -o ro,size=64k tmpfs "$R" 2>>"$T/err"; then
    bad "cannot mount a small tmpfs (this test needs root): $(cat "$T/err")"
    summary
    exit 1
fi
SIZE="--size 128x96 --spp 1 -j 2"
"$F" compile scenes/cornell.json -o "$T/scene.fbin" 2>"$T/err" || bad "compile: $(cat "$T/err")"
EXTS="png bmp tga jpg exr tif hdr pfm"

# Each format, written where there is room, takes more than the 4 KiB the
# full file system will have left.
for ext in $EXTS; do
    "$F" render "$T/scene.fbin" -o "$T/ok.$ext" $SIZE --job "$T/ok-job" 2>"$T/err" ||
        bad "render to .$ext with room: $(cat "$T/err")"
    size=$(stat -c %s "$T/ok.$ext" 2>/dev/null || echo 0)
    [ "$size" -gt 8192 ] && ok || bad ".$ext: $size bytes, too small to overflow the full file system"
done

# An older image under each final name, then the file system filled up to
# 4 KiB of free space.
for ext in $EXTS; do echo "old image" >"$M/out.$ext"; done
dd if=/dev/zero of="$M/slack" bs=4096 count=1 2>/dev/null
dd if=/dev/zero of="$M/pad" bs=4096 2>/dev/null
rm "$M/slack"
for ext in $EXTS; do
    "$F" render "$T/scene.fbin" -o "$M/out.$ext" $SIZE --job "$T/job-$ext" >"$T/out" 2>"$T/err"
    rc=$?
    if [ $rc -eq 0 ]; then
        bad ".$ext on a full disk: exit status 0"
    elif [ $rc -gt 128 ]; then
        bad ".$ext on a full disk: died of signal $((rc - 128))"
    else
        ok
    fi
    grep -qF "franja render: $M/out.$ext: not written" "$T/err" && grep -qF "No space left on device" "$T/err" &&
        ok || bad ".$ext on a full disk: no message naming the file: $(cat "$T/err")"
    grep -qF "rerun with --resume" "$T/err" && ok || bad ".$ext on a full disk: --resume not suggested"
    [ "$(cat "$M/out.$ext")" = "old image" ] && ok || bad ".$ext on a full disk: the old image was replaced"
    left=$(ls -A "$M" | grep -v -e '^pad$' -e '^out\.')
    [ -z "$left" ] && ok || bad ".$ext on a full disk: left behind: $left"
    rows=$(ls "$T/job-$ext" 2>/dev/null | grep -c '^rows-.*\.pf$')
    [ "$rows" -gt 0 ] && ok || bad ".$ext on a full disk: the job directory lost its rows"
done

# Room again: --resume writes each image from the kept rows.
rm "$M/pad"
for ext in $EXTS; do
    rm "$M/out.$ext"
    "$F" render "$T/scene.fbin" -o "$M/out.$ext" $SIZE --job "$T/job-$ext" --resume >"$T/out" 2>"$T/err"
    if [ $? -ne 0 ]; then
        bad ".$ext: --resume after the full disk failed: $(cat "$T/err")"
    else
        grep -q "resuming: 96 of 96 rows already done" "$T/err" && ok || bad ".$ext: --resume rendered again"
        # (EXR and TIFF files hold the time they were written: pixels compared)
        oiiotool "$M/out.$ext" "$T/ok.$ext" --diff --fail 0 2>&1 | grep -q PASS && ok ||
            bad ".$ext: --resume wrote another image than the one with room"
    fi
done

# Outputs that cannot be written are refused before rendering: no job
# directory is made, nothing is rendered.
unwritable() { # unwritable WHAT OUT FRAGMENT
    expect_error "$1" "$3" "$F" render "$T/scene.fbin" -o "$2" $SIZE --job "$T/job-x" &&
        { test ! -e "$T/job-x" && ! grep -q "franja: host" "$T/err" && ok ||
            bad "$1: rendered before refusing: $(cat "$T/err")"; }
}
unwritable "read-only directory" "$R/out.png" "$R/out.png: cannot create a temporary file beside it: Read-only file system"
unwritable "missing directory" "$T/no/out.exr" "$T/no/out.exr: cannot create a temporary file beside it: No such file or directory"
mkdir "$T/dir.png"
unwritable "a directory as output" "$T/dir.png" "$T/dir.png: is a directory"

summary
