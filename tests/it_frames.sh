#!/bin/sh
# it_frames.sh -- tests franja render --frames gives each frame's bytes.
#
# franja render PATTERN --frames LIST: a three-frame
# animation (a sphere moving) gives, frame for frame, the bytes of three
# single renders; outputs that exist are skipped unless --overwrite; an
# interrupt keeps the frame's finished slabs and --resume goes on from
# there; frames run together over one set of hosts (a slab of frame 2
# starts while frame 1's last slab runs; an interrupt with two frames in
# flight keeps both frames' slabs for --resume; a host that fails in the
# middle of the range is dropped and the others finish); over SSH each
# frame's scene is uploaded once per host; bad patterns and lists are
# refused before anything renders.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 24x16 --spp 2"

for i in 1 2 3; do
    sed "/\"shapes\": \[/a { \"type\": \"sphere\", \"center\": [$((100 * i + 150)), 100, 300], \"radius\": 80, \"material\": \"white\" }," \
        "$ROOT/scenes/cornell.json" >"f.000$i.json"
    "$FRANJA" render "f.000$i.json" -o "ref$i.pfm" $SIZE -j 1 2>/dev/null || bad "single render of frame $i failed"
done
check "the sphere moves: frames 1 and 2 differ" sh -c '! cmp -s ref1.pfm ref2.pfm'
check "the sphere moves: frames 2 and 3 differ" sh -c '! cmp -s ref2.pfm ref3.pfm'

mkdir out
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'out/f.####.pfm' $SIZE -j 2 2>log1
check "the animation renders (status 0)" test $? -eq 0
for i in 1 2 3; do
    check "frame $i equals its single render" cmp -s "out/f.000$i.pfm" "ref$i.pfm"
done
check "the summary counts the frames" grep -q "frames: 3 of 3 done (3 rendered, 0 skipped" log1
check "each frame is announced with its files" grep -q "frame 2 (2 of 3): f.0002.json -> out/f.0002.pfm" log1

# Outputs that exist are skipped; --overwrite renders them again.
printf 'not an image' >out/f.0002.pfm
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'out/f.####.pfm' $SIZE -j 2 2>log2
check "an existing output is kept" grep -q "not an image" out/f.0002.pfm
check "the skips are counted" grep -q "frames: 3 of 3 done (0 rendered, 3 skipped" log2
"$FRANJA" render 'f.####.json' --frames 2 -o 'out/f.####.pfm' $SIZE -j 2 --overwrite 2>log3
check "--overwrite renders it again" cmp -s out/f.0002.pfm ref2.pfm
check "--overwrite counts it rendered" grep -q "frames: 1 of 1 done (1 rendered, 0 skipped" log3
# A step list: frames 1 and 3 only.
# The output's directories (here one a frame) are made.
"$FRANJA" render 'f.####.json' --frames 1-3:2 -o 'step/s.##/s.##.pfm' $SIZE 2>/dev/null
check "1-3:2 makes each frame's directory" test -d step/s.01 -a -d step/s.03
mv step/s.01/s.01.pfm step/s.03/s.03.pfm step/
check "1-3:2 renders frame 1" cmp -s step/s.01.pfm ref1.pfm
check "1-3:2 renders frame 3" cmp -s step/s.03.pfm ref3.pfm
check "1-3:2 skips frame 2" test ! -e step/s.02.pfm -a ! -e step/s.02

# Ctrl-C during frame 2, then --resume.
mkdir -p loc slow
printf 'here local - 1 worker=%s\n' "$(fh_wrapper loc slow)" >t_slow
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'slow/f.####.pfm' $SIZE --hosts t_slow --slab-rows 4 2>logi &
FH_BG=$!
fh_until fh_has_slabs slow/f.0002.pfm.franja-job 1
kill -INT $FH_BG
fr_wait
check "the interrupted animation exits 130" test $rc -eq 130
check "frame 1 was written before the interrupt" cmp -s slow/f.0001.pfm ref1.pfm
check "frame 2 was not written" test ! -e slow/f.0002.pfm
check "frame 3 was not started" test ! -e slow/f.0003.pfm.franja-job
check "the interrupt names the frame" grep -q "interrupted at frame 2 (slow/f.0002.pfm)" logi
kept=$(fh_slabs slow/f.0002.pfm.franja-job)
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'slow/f.####.pfm' $SIZE --hosts t_slow --slab-rows 4 --resume 2>logr
check "the resumed animation succeeds" test $? -eq 0
for i in 1 2 3; do
    check "resumed frame $i equals its single render" cmp -s "slow/f.000$i.pfm" "ref$i.pfm"
done
check "frame 2 kept its finished slabs" grep -q "resuming: $((kept * 4)) of 16 rows" logr
check "frame 1 is skipped on resume" grep -q "frame 1 (1 of 3): slow/f.0001.pfm exists, skipped" logr

# Frames overlap: frame 1's last slab (rows 12:16) is held until a slab
# of frame 2 has started, so the animation ends (within the gate's 30 s)
# only if the slot that finished frame 1's other slabs went on to frame 2
# while frame 1's tail still ran.
cat >gate.sh <<SH
#!/bin/sh
case " \$* " in *" --rows "*) ;; *) exec "$WORKER" "\$@" ;; esac
case " \$* " in
*f.0001*" --rows 12:16 "*)
    n=0
    while [ ! -e "$FH/f2started" ] && [ \$n -lt 300 ]; do sleep 0.1; n=\$((n + 1)); done
    [ -e "$FH/f2started" ] && echo overlapped >>"$FH/gatelog" || echo "no frame 2 slab in 30 s" >>"$FH/gatelog" ;;
*f.0002*) touch "$FH/f2started" ;;
esac
exec "$WORKER" "\$@"
SH
chmod +x gate.sh
printf 'here local - 2 worker=%s/gate.sh\n' "$FH" >t_gate
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'ov/f.####.pfm' $SIZE --hosts t_gate --slab-rows 4 2>logo
check "the gated animation renders" test $? -eq 0
check "frame 2 started while frame 1's last slab ran" grep -q overlapped gatelog
check "frame 1's last slab waited for nothing else" sh -c "! grep -q 'no frame 2' gatelog"
for i in 1 2 3; do
    check "overlapped frame $i equals its single render" cmp -s "ov/f.000$i.pfm" "ref$i.pfm"
done

# Ctrl-C while two frames are in flight (the last slab of frames 1 and 2
# held, one on each slot), then --resume: each frame keeps its own
# finished slabs and ends in its bytes.
cat >hold.sh <<SH
#!/bin/sh
case " \$* " in *f.000[12]*" --rows 12:16 "*) [ -e "$FH/hold" ] && exec sleep 600 ;; esac
exec "$WORKER" "\$@"
SH
chmod +x hold.sh
printf 'here local - 2 worker=%s/hold.sh\n' "$FH" >t_hold
touch hold
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'held/f.####.pfm' $SIZE --hosts t_hold --slab-rows 4 2>logh &
FH_BG=$!
fh_until fh_has_slabs held/f.0002.pfm.franja-job 3
kill -INT $FH_BG
fr_wait
check "the animation interrupted with two frames in flight exits 130" test $rc -eq 130
check "the interrupt names the first unfinished frame" grep -q "interrupted at frame 1 (held/f.0001.pfm)" logh
check "frame 1 kept its 3 finished slabs" test "$(fh_slabs held/f.0001.pfm.franja-job)" -eq 3
check "frame 2 kept its 3 finished slabs" test "$(fh_slabs held/f.0002.pfm.franja-job)" -eq 3
check "frame 3 was not started" test ! -e held/f.0003.pfm.franja-job
check "neither frame was written" test ! -e held/f.0001.pfm -a ! -e held/f.0002.pfm
rm hold
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'held/f.####.pfm' $SIZE --hosts t_hold --slab-rows 4 --resume 2>logh2
check "the resumed animation renders" test $? -eq 0
check "frame 1 resumes from 12 rows" grep -q "resuming: 12 of 16 rows already done in held/f.0001.pfm.franja-job" logh2
check "frame 2 resumes from 12 rows" grep -q "resuming: 12 of 16 rows already done in held/f.0002.pfm.franja-job" logh2
for i in 1 2 3; do
    check "held and resumed frame $i equals its single render" cmp -s "held/f.000$i.pfm" "ref$i.pfm"
done

# A host that fails from its sixth slab on, in the middle of the range: it
# is dropped, the other host renders the rest, every frame in its bytes.
# The good host starts its first slab once the bad host has started one
# (at most 10 s later) and takes 0.15 s a slab, so that slabs are left for
# the bad host's three failures in a row (each fails at once): had the good
# host taken them all first (the bad one joining late on a loaded machine),
# or won the last ones as second copies (a failed copy of a finished slab
# does not count), the bad host would not be dropped.
cat >failing.sh <<SH
#!/bin/sh
case " \$* " in *" --rows "*) ;; *) exec "$WORKER" "\$@" ;; esac
echo x >>"$FH/failcount"
[ "\$(wc -l <"$FH/failcount")" -gt 5 ] && exit 1
exec "$WORKER" "\$@"
SH
cat >slow.sh <<SH
#!/bin/sh
case " \$* " in
*" --rows "*)
    n=0
    while [ ! -e "$FH/failcount" ] && [ \$n -lt 200 ]; do sleep 0.05; n=\$((n + 1)); done
    sleep 0.15 ;;
esac
exec "$WORKER" "\$@"
SH
chmod +x failing.sh slow.sh
printf 'good local - 1 worker=%s/slow.sh\nbad local - 1 worker=%s/failing.sh\n' "$FH" "$FH" >t_fail
"$FRANJA" render 'f.####.json' --frames 1-3 -o 'fail/f.####.pfm' $SIZE --hosts t_fail --slab-rows 2 2>logf
check "the animation with a failing host renders" test $? -eq 0
check "the failing host is dropped" grep -q "dropping host bad: 3 failures in a row" logf
check "the failing host rendered 5 slabs, then failed 3 times" test "$(wc -l <failcount)" -eq 8
for i in 1 2 3; do
    check "frame $i with a failing host equals its single render" cmp -s "fail/f.000$i.pfm" "ref$i.pfm"
done
check "every frame is written" grep -q "frames: 3 of 3 done (3 rendered" logf

# A frame whose scene is missing in the middle of the range: the frames
# before it are finished and written, the animation stops there (status 1).
cp f.0001.json g.0001.json
cp f.0003.json g.0003.json
"$FRANJA" render 'g.####.json' --frames 1-3 -o 'gap/g.####.pfm' $SIZE -j 2 2>logg
check "a missing frame fails the animation (status 1)" test $? -eq 1
check "the frame before it is written" cmp -s gap/g.0001.pfm ref1.pfm
check "the missing frame is named" grep -q "frame 2 (g.0002.json -> gap/g.0002.pfm) failed; 1 of 3 frames done" logg
check "the frame after it is not started" test ! -e gap/g.0003.pfm -a ! -e gap/g.0003.pfm.franja-job

# Two SSH hosts: each frame's scene goes to each host once.
fh_start a 2 1
fh_start b 3 1
mkdir ssh
fr render 'f.####.json' --frames 1-3 -o 'ssh/f.####.pfm' $SIZE --hosts hosts 2>logs
check "the SSH animation renders" test $? -eq 0
for i in 1 2 3; do
    check "SSH frame $i equals its single render" cmp -s "ssh/f.000$i.pfm" "ref$i.pfm"
done
for h in a b; do
    n=$(grep -c "host $h: .*scene uploaded" logs)
    check "host $h got 3 uploads, not $n" test "$n" -eq 3
    n=$(ls $h/work/scenes | grep -c '\.fbin$')
    check "host $h caches 3 scenes, not $n" test "$n" -eq 3
done
fr render 'f.####.json' --frames 1-3 -o 'ssh/f.####.pfm' $SIZE --hosts hosts --overwrite 2>logs2
check "a second pass uploads nothing" sh -c "! grep -q 'scene uploaded' logs2"
check "a second pass finds every scene cached" test "$(grep -c 'scene already there' logs2)" -eq 6

# Bad command lines.
expect_error "--frames without # in the scene" "the scene 'f.0001.json' has no #" \
    "$FRANJA" render f.0001.json --frames 1-3 -o 'x.####.png'
expect_error "--frames with one output" "the output (-o, else named after the scene) 'x.png' has no #" \
    "$FRANJA" render 'f.####.json' --frames 1-3 -o x.png
expect_error "--frames with one job directory" "--job 'j' has no #" \
    "$FRANJA" render 'f.####.json' --frames 1-3 -o 'x.####.png' --job j
expect_error "a pattern without --frames" "give --frames LIST" "$FRANJA" render 'f.####.json' -o x.png
expect_error "a backward range" "the range 3-1 runs backwards" "$FRANJA" render 'f.####.json' --frames 3-1
expect_error "a zero step" "at byte 2: expected N, A-B or A-B:S" "$FRANJA" render 'f.####.json' --frames 1,2-4:0
expect_error "--overwrite alone" "--overwrite is for --frames" "$FRANJA" render f.0001.json --overwrite
touch nodir
expect_error "a directory that cannot be made is named" "frame 1: cannot make the directory of nodir/x/f.0001.pfm" \
    "$FRANJA" render 'f.####.json' --frames 1 -o 'nodir/x/f.####.pfm'
expect_error "a frame that fails is named" "frame 7 (f.0007.json -> x.0007.pfm) failed" \
    "$FRANJA" render 'f.####.json' --frames 7 -o 'x.####.pfm'
summary
