#!/bin/sh
# it_joblock_nolock.sh -- tests a job directory on a file system without locks.
#
# A job directory on a file system that refuses locks (franja(1), "Job
# directory"): bin/tools/nolockfs mounts a directory through FUSE answering
# every fcntl and flock lock with ENOLCK, as an NFS mount without a lock
# manager does.  There franja render refuses at once (status 2, saying why
# and what to do), writes nothing and leaves no job directory; with
# --no-lock it warns and renders the same image as a lone render; with
# --job on a local file system the output may still live on the mount.
# Needs root and /dev/fuse (it mounts a FUSE file system); without them the
# test fails.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need cmp umount
F=$PWD/bin/franja W=$PWD/bin/franja-worker
T=$(mktemp -d)
M=$T/mnt
trap 'umount "$M" 2>/dev/null; rm -rf "$T"' EXIT
mkdir "$T/back" "$M"
if ! bin/tools/nolockfs "$T/back" "$M" 2>"$T/err"; then
    bad "cannot mount bin/tools/nolockfs (this test needs root and /dev/fuse): $(cat "$T/err")"
    summary
    exit 1
fi
SIZE="--size 32x24 --spp 4"
"$F" compile scenes/cornell.json -o "$T/scene.fbin" >/dev/null 2>"$T/err" || bad "compile: $(cat "$T/err")"
"$W" --scene "$T/scene.fbin" --rows 0:24 $SIZE -o "$T/ref.pfm" || bad "lone render"

# The mount is what it claims: files work, locks do not.
echo text >"$M/probe" && [ "$(cat "$T/back/probe")" = text ] && ok || bad "the mount does not pass files through"
rm -f "$M/probe"

# Refused: status 2, the reason and the two ways out, nothing left behind.
"$F" render "$T/scene.fbin" -o "$M/out.pfm" $SIZE -j 1 2>"$T/log"
rc=$?
check "a job directory without locks is refused with status 2 (got $rc): $(cat "$T/log")" test $rc -eq 2
check "the message says the file system refuses locks" grep -q "the file system refuses locks (No locks available)" "$T/log"
check "and names --job and --no-lock" grep -q -- "--job DIR.*--no-lock" "$T/log"
check "no image is written" test ! -e "$T/back/out.pfm"
check "no job directory is left behind: $(ls -A "$T/back")" test -z "$(ls -A "$T/back")"

# --no-lock: a warning, then the same image as a lone render; the job
# directory goes as usual.
"$F" render "$T/scene.fbin" -o "$M/out.pfm" $SIZE -j 2 --no-lock 2>"$T/log"
rc=$?
check "--no-lock renders (status $rc): $(tail -n 3 "$T/log")" test $rc -eq 0
check "--no-lock warns that nothing keeps another render out" grep -q "is not locked (--no-lock)" "$T/log"
check "--no-lock's image is byte-identical to a lone render" cmp -s "$M/out.pfm" "$T/ref.pfm"
check "--no-lock removes its job directory: $(ls -A "$T/back")" test ! -e "$T/back/out.pfm.franja-job"

# A local job directory for an output on the mount: locked, and rendered.
rm -f "$M/out.pfm"
"$F" render "$T/scene.fbin" -o "$M/out.pfm" $SIZE -j 2 --job "$T/localjob" 2>"$T/log"
rc=$?
check "--job on a local file system renders (status $rc): $(tail -n 3 "$T/log")" test $rc -eq 0
check "with no warning about locks" sh -c "! grep -q 'not locked' '$T/log'"
check "its image is byte-identical to a lone render" cmp -s "$M/out.pfm" "$T/ref.pfm"
summary
