#!/bin/sh
# it_coord_local.sh -- tests the coordinator with local workers.
#
# The coordinator on this machine (no SSH): -j 1 and -j N give the same bytes
# as a one-process render; every output format is written; faults of local
# workers (bad output, a stuck process) are survived; Ctrl-C keeps the
# finished slabs and --resume renders only what is missing; the command line
# refuses bad input before rendering.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 32x24 --spp 4"

"$FRANJA" render "$ROOT/scenes/cornell.json" -o j1.pfm $SIZE -j 1 --job job0 --keep-job 2>log1
check "-j 1 render succeeds" test -s j1.pfm
cp job0/scene.fbin scene.fbin
"$WORKER" --scene scene.fbin --rows 0:24 $SIZE -o ref.pfm
check "-j 1 equals the one-process render" cmp -s j1.pfm ref.pfm
"$FRANJA" render scene.fbin -o j3.pfm $SIZE -j 3 2>log3
check "-j 3 equals the one-process render" cmp -s j3.pfm ref.pfm
"$FRANJA" render scene.fbin -o s1.pfm $SIZE -j 2 --slab-rows 1 2>/dev/null
check "one-row slabs give the same bytes" cmp -s s1.pfm ref.pfm
"$FRANJA" render scene.fbin -o s7.pfm $SIZE -j 2 --slab-rows 7 2>/dev/null
check "7-row slabs give the same bytes" cmp -s s7.pfm ref.pfm
"$FRANJA" render scene.fbin -o tab.pfm $SIZE --hosts "$ROOT/hosts/local.hosts" 2>/dev/null
check "hosts/local.hosts gives the same bytes" cmp -s tab.pfm ref.pfm
check "summary names the slots" grep -Eq "^  local +3 " log3
check "summary gives samples/s" grep -q "Msamples/s" log3

for ext in png exr tif jpg hdr bmp ppm; do
    "$FRANJA" render scene.fbin -o "out.$ext" $SIZE 2>/dev/null
    check "writes .$ext" test -s "out.$ext"
    if command -v oiiotool >/dev/null; then
        check ".$ext is a 32x24 image" sh -c "oiiotool --info out.$ext | grep -q '32 x  *24'"
    fi
done
if command -v oiiotool >/dev/null; then
    check "EXR holds the linear radiance of the PFM" sh -c "oiiotool out.exr ref.pfm --diff --fail 0 | grep -q PASS"
fi
# A stream without an extension (a device, a named pipe) gets PFM; /dev/null stays a device.
"$FRANJA" render scene.fbin -o /dev/stdout $SIZE 2>/dev/null >stdout.pfm
check "-o /dev/stdout writes the PFM to standard output" cmp -s stdout.pfm ref.pfm
"$FRANJA" render scene.fbin -o /dev/null $SIZE 2>devnull.log
check "-o /dev/null succeeds" test $? -eq 0
check "/dev/null is still a character device" test -c /dev/null
"$FRANJA" render scene.fbin -o /dev/null $SIZE --keep-job 2>/dev/null
check "-o /dev/null keeps its job directory here, not in /dev" sh -c "test -d null.franja-job && ! test -e /dev/null.franja-job"
rm -rf null.franja-job
mkfifo pipe
timeout 120 cat pipe >fifo.pfm &
"$FRANJA" render scene.fbin -o pipe $SIZE 2>/dev/null
wait
check "-o FIFO writes the PFM into the pipe" cmp -s fifo.pfm ref.pfm
check "the FIFO stays a FIFO" test -p pipe
touch plain
"$FRANJA" render scene.fbin -o plain $SIZE 2>eplain
check "a plain file without an extension is still refused" grep -q "unknown image type ''" eplain
"$FRANJA" render scene.fbin -o bright.png $SIZE --exposure 1 2>/dev/null
check "--exposure changes an LDR output" sh -c "! cmp -s bright.png out.png"
"$FRANJA" render scene.fbin -o bright.pfm $SIZE --exposure 1 2>/dev/null
check "--exposure leaves an HDR output linear" cmp -s bright.pfm ref.pfm

# Faulty local workers.
mkdir -p loc1
printf 'here local - 2 worker=%s\n' "$(fh_wrapper loc1 truncate)" >t_trunc
"$FRANJA" render scene.fbin -o trunc.pfm $SIZE --hosts t_trunc 2>logt
check "truncated partial is retried" cmp -s trunc.pfm ref.pfm
check "truncated partial is reported" grep -q "bad partial image" logt
mkdir -p loc2
printf 'here local - 2 worker=%s\n' "$(fh_wrapper loc2 hang)" >t_hang
timeout 60 "$FRANJA" render scene.fbin -o hang.pfm $SIZE --hosts t_hang 2>logh
check "a stuck worker is overtaken by a second copy" cmp -s hang.pfm ref.pfm
check "the second copy is logged" grep -q "starting a second copy" logh

# Ctrl-C, then --resume.
mkdir -p loc3
printf 'here local - 1 worker=%s\n' "$(fh_wrapper loc3 slow)" >t_slow
"$FRANJA" render scene.fbin -o int.pfm $SIZE --hosts t_slow --slab-rows 4 2>logi &
FH_BG=$!
fh_until fh_has_slabs int.pfm.franja-job 2
kill -INT $FH_BG
fr_wait
check "interrupted render exits 130" test $rc -eq 130
check "interrupted render writes no image" test ! -e int.pfm
check "interrupted render says how to resume" grep -q "rerun with --resume" logi
kept=$(ls int.pfm.franja-job | grep -c '^rows-.*\.pf$')
check "finished slabs are kept" test "$kept" -ge 2
# The summary says first that the render was interrupted, and counts the
# rows it rendered, not the rows it was asked for.
sline=$(grep '^franja: .* s: ' logi | tail -n 1)
case $sline in "franja: interrupted after "*" s: $((kept * 4)) of 24 rows rendered"*) ok ;;
*) bad "the summary of an interrupted render: '$sline' (expected 'interrupted after ...: $((kept * 4)) of 24 rows rendered')" ;; esac
"$FRANJA" render scene.fbin -o int.pfm $SIZE --hosts t_slow --slab-rows 4 --resume 2>logr
check "resumed render is byte-identical" cmp -s int.pfm ref.pfm
check "resume reports what was kept" grep -q "resuming: $((kept * 4)) of 24 rows" logr
check "resume renders only the missing slabs" grep -q "; $((6 - kept)) slabs" logr
"$FRANJA" render scene.fbin -o int2.pfm --size 16x16 --resume --job job0 2>logm
check "resume refuses another render's job directory" grep -q "belongs to another render" logm

# Bad command lines are refused before anything runs.
"$FRANJA" render scene.fbin -o x.xyz 2>e1
check "unknown output type refused (status 2)" test $? -eq 2
check "unknown output type named" grep -q "unknown image type 'xyz'" e1
"$FRANJA" render -o x.png 2>e2
check "missing scene refused" test $? -eq 2
"$FRANJA" render scene.fbin -o x.png --size 0x4 2>e3
check "bad --size refused" grep -q "size: '0x4' is not WxH" e3
"$FRANJA" render scene.fbin -o x.png --bogus 2>e4
check "unknown option refused" grep -q "unknown option '--bogus'" e4
"$FRANJA" render missing.fbin -o x.png 2>e5
check "missing scene refused" test $? -eq 1
check "no image for a failed render" test ! -e x.png
"$FRANJA" --version >v
check "--version" grep -Eq "^franja [0-9]+\.[0-9]+\.[0-9]+ scene-format [0-9]+$" v
for c in render hosts; do
    "$FRANJA" $c --help >h
    check "$c --help" grep -q "usage: franja $c" h
done
"$FRANJA" --help >h
check "--help" grep -q "franja render SCENE" h
"$FRANJA" frobnicate 2>/dev/null
check "unknown command refused" test $? -eq 2

summary
