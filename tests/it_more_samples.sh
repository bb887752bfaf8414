#!/bin/sh
# it_more_samples.sh -- tests --resume --spp adds samples to the exact bytes.
#
# More samples later: a render kept with --keep-job goes on with
# --resume --spp N, rendering only the samples each pixel lacks, to the
# bytes of a render of every sample at once: locally and on fake SSH hosts,
# with another slab split, after an interrupt that left rows of two sample
# counts; what cannot be continued exactly is refused, saying why.
# --time-limit renders passes that double the samples and writes the last
# complete one: the bytes of a render with that many samples.  Nothing here
# depends on how fast the machine is: a pass that must not end is held by a
# worker that never answers.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
T=$FH
SIZE="--size 32x24"
S="$ROOT/scenes/cornell.json"

"$FRANJA" render "$S" -o ref.pfm $SIZE --spp 4 -j 1 --job job0 --keep-job 2>/dev/null
cp job0/scene.fbin scene.fbin
for n in 1 2 4 8 32; do
    "$WORKER" --scene scene.fbin --rows 0:24 $SIZE --spp $n -o ref$n.pfm
done
check "8 and 32 samples differ" sh -c '! cmp -s ref8.pfm ref32.pfm'

# The samples per pixel in a slab file's header.
spp_of() { head -c 300 "$1" | sed -n 's/^# franja .* spp=\([0-9]*\) .*/\1/p'; }
# How many slab files of job directory $1 hold $2 samples per pixel.
slabs_at() {
    k=0
    for f in "$1"/rows-*.pf; do [ -f "$f" ] && [ "$(spp_of "$f")" = "$2" ] && k=$((k + 1)); done
    echo $k
}

# Locally: 8 samples kept, then 32 with another split.
"$FRANJA" render scene.fbin -o l.pfm $SIZE --spp 8 -j 2 --keep-job 2>logl1
check "8 samples with --keep-job" cmp -s l.pfm ref8.pfm
check "the kept slabs carry their sums" sh -c "head -c 300 l.pfm.franja-job/rows-00000-*.pf | grep -aq ' sums=[0-9a-f]\{16\}\$'"
"$FRANJA" render scene.fbin -o l.pfm $SIZE --spp 32 -j 3 --resume --keep-job 2>logl2
check "8 then --resume --spp 32 gives the bytes of 32 at once" cmp -s l.pfm ref32.pfm
check "it says the rows go on from their kept samples" grep -q "adding samples: 24 rows go on from the 8 samples" logl2
check "every slab went on from kept sums" grep -q "; [1-9][0-9]* slabs went on from kept sample sums" logl2
check "the slabs of 8 samples are gone once every row has 32" test "$(slabs_at l.pfm.franja-job 8)" -eq 0
check "the job directory holds 32-sample slabs" test "$(slabs_at l.pfm.franja-job 32)" -gt 0
check "no sums file is left in the job directory" sh -c "! ls -A l.pfm.franja-job | grep -q cont"
# One slab, one process: the same bytes.
"$FRANJA" render scene.fbin -o one.pfm $SIZE --spp 8 -j 1 --slab-rows 24 --keep-job 2>/dev/null
"$FRANJA" render scene.fbin -o one.pfm $SIZE --spp 32 -j 1 --slab-rows 24 --resume 2>/dev/null
check "one slab, 8 then 32 samples: the bytes of 32" cmp -s one.pfm ref32.pfm

# Refusals, each before anything is rendered.
"$FRANJA" render scene.fbin -o l.pfm $SIZE --spp 8 --resume --keep-job 2>logdown
check "fewer samples than kept: status 2" test $? -eq 2
check "fewer samples than kept: says samples cannot be taken away" \
    grep -q "holds rows rendered with 32 samples per pixel, more than the 8 asked for; samples cannot be taken away" logdown
check "the refusal leaves the image alone" cmp -s l.pfm ref32.pfm
"$FRANJA" render scene.fbin -o gone.pfm $SIZE --spp 8 2>/dev/null
expect_error "more samples without a kept job" "nothing to resume: gone.pfm is finished and its job directory" \
    "$FRANJA" render scene.fbin -o gone.pfm $SIZE --spp 32 --resume
check "and says how to keep a job for later" grep -q "with --keep-job to add samples to it later" "$T/err"
"$FRANJA" render scene.fbin -o ad.pfm $SIZE --spp 8 --noise-threshold 0.2 --keep-job 2>/dev/null
expect_error "an adaptive job with more samples" "an adaptive render cannot be continued to 32 exactly" \
    "$FRANJA" render scene.fbin -o ad.pfm $SIZE --spp 32 --noise-threshold 0.2 --resume
expect_error "--time-limit with adaptive sampling" "--time-limit: its passes add samples" \
    "$FRANJA" render scene.fbin -o x.pfm $SIZE --noise-threshold 0.2 --time-limit 1h
expect_error "--time-limit bidirectional" "is bidirectional" \
    "$FRANJA" render scene.fbin -o x.pfm $SIZE --integrator bdpt --time-limit 1h
for v in 0 10x -1m 1e3 m '' 200h; do
    expect_error "--time-limit '$v'" "is not a duration: a number above 0 followed by s" \
        "$FRANJA" render scene.fbin -o x.pfm $SIZE --time-limit "$v"
done
check "no refused render wrote an image" test ! -e x.pfm

# Fake SSH hosts: the sums travel to the hosts, which keep nothing of them.
fh_start a 2 2
fh_start b 3 1
fh_start c 4 2
fr render scene.fbin -o s.pfm --hosts hosts $SIZE --spp 8 --slab-rows 3 --keep-job 2>logs1
check "8 samples on three SSH hosts" cmp -s s.pfm ref8.pfm
fr render scene.fbin -o s.pfm --hosts hosts $SIZE --spp 32 --slab-rows 5 --resume 2>logs2
check "then --resume --spp 32 with 5-row slabs: the bytes of 32 at once" cmp -s s.pfm ref32.pfm
check "the SSH slabs went on from kept sums" grep -q "; [1-9][0-9]* slabs went on from kept sample sums" logs2
check "every attempt got its sums" sh -c "! grep -q 'rendered every sample' logs2"
for h in a b c; do
    check "host $h keeps no sums file" sh -c "! find $h/work -name 'cont-*' | grep -q ."
done
check "more than one host went on from sums" test "$(grep -Ec '^  [abc] +[0-9]+ +[1-9]' logs2)" -ge 2

# A host that takes fewer channels than it claims cores (sshd's
# MaxSessions 3, 4 cores): the sums of the start that finds no channel left
# were uploaded already, and are removed again.
: >hosts
FH_SSHD_EXTRA="MaxSessions 3" fh_start narrow 5 4
fr render scene.fbin -o n.pfm --hosts hosts $SIZE --spp 8 --slab-rows 2 --keep-job 2>logn1
fr render scene.fbin -o n.pfm --hosts hosts $SIZE --spp 32 --slab-rows 3 --resume 2>logn2
check "a narrow host goes on to 32 samples: the bytes of 32 at once" cmp -s n.pfm ref32.pfm
check "its slots were lowered ($(grep -c 'cannot start more' logn2) times)" grep -q "host narrow: cannot start more than" logn2
check "and it keeps no sums file" sh -c "! find narrow/work -name 'cont-*' | grep -q ."

# Interrupted while adding samples: rows of two sample counts, and rows
# never rendered, then resumed elsewhere with another split.  A worker that
# never answers for rows at or below the row in the file "gate" holds the
# render where the test wants it.
cat >gate.sh <<SH
#!/bin/sh
prev=
for a in "\$@"; do
    if [ "\$prev" = --rows ] && [ "\${a%%:*}" -ge "\$(cat "$FH/gate")" ]; then exec sleep 8$$; fi
    prev=\$a
done
exec "$WORKER" "\$@"
SH
chmod +x gate.sh
printf 'here local - 2 worker=%s/gate.sh\n' "$FH" >t_gate
echo 12 >gate
"$FRANJA" render scene.fbin -o m.pfm $SIZE --spp 8 --hosts t_gate --slab-rows 4 2>logm1 &
pid=$!
fh_until fh_has_slabs m.pfm.franja-job 3
kill -INT $pid
wait $pid
check "the first render is interrupted (status 130)" test $? -eq 130
check "it kept rows 0:12 with 8 samples" test "$(slabs_at m.pfm.franja-job 8)" -eq 3
echo 6 >gate
has32() { [ "$(slabs_at m.pfm.franja-job 32)" -ge 2 ]; }
"$FRANJA" render scene.fbin -o m.pfm $SIZE --spp 32 --hosts t_gate --slab-rows 3 --resume 2>logm2 &
pid=$!
fh_until has32
kill -INT $pid
wait $pid
check "the continuation is interrupted (status 130)" test $? -eq 130
check "the job holds rows 0:6 with 32 samples" test "$(slabs_at m.pfm.franja-job 32)" -eq 2
check "and rows 0:12 with 8" test "$(slabs_at m.pfm.franja-job 8)" -eq 3
fr render scene.fbin -o m.pfm --hosts hosts $SIZE --spp 32 --slab-rows 5 --resume 2>logm3
check "resumed on SSH hosts with 5-row slabs: the bytes of 32 at once" cmp -s m.pfm ref32.pfm
check "the rows with 8 samples went on from their sums" grep -q "adding samples: 6 rows go on from the 8 samples" logm3
check "and the slabs say so" grep -q "; [1-9][0-9]* slabs\{0,1\} went on from kept sample sums" logm3
check "no gated worker is left" sh -c "! pgrep -x -f 'sleep 8$$' >/dev/null"

# --time-limit: passes of 1, 2, 4, 8 samples, capped by --spp.
"$FRANJA" render scene.fbin -o t8.pfm $SIZE --spp 8 -j 2 --time-limit 1h --progress json >t8.json 2>logt8
check "--time-limit with room for every pass: the bytes of 8 samples" cmp -s t8.pfm ref8.pfm
check "four passes" test "$(grep -c '"event":"pass"' t8.json)" -eq 4
check "passes of 1, 2, 4 and 8 samples" sh -c "grep -o '\"event\":\"pass\",\"pass\":[0-9]*,\"spp\":[0-9]*' t8.json |
    sed 's/.*://' | tr '\n' ' ' | grep -qx '1 2 4 8 '"
check "the JSON done event says 8 samples" grep -q '"event":"done","status":"ok","spp":8,' t8.json
check "the summary says every pass ended" grep -q "every 8 samples per pixel within the time limit" logt8

# A pass that never ends: a worker that answers no slab of 8 samples or
# more.  The limit stops it and the last complete pass is written.
cat >stuck.sh <<SH
#!/bin/sh
prev=
for a in "\$@"; do
    if [ "\$prev" = --spp ] && [ "\$a" -ge 8 ]; then exec sleep 7$$; fi
    prev=\$a
done
exec "$WORKER" "\$@"
SH
chmod +x stuck.sh
printf 'here local - 2 worker=%s/stuck.sh\n' "$FH" >t_stuck
t0=$(date +%s)
"$FRANJA" render scene.fbin -o tl.pfm $SIZE --spp 64 --hosts t_stuck --time-limit 4s --progress json >tl.json 2>logtl
rc=$?
t1=$(date +%s)
check "a render stopped by its time limit succeeds (status $rc)" test $rc -eq 0
reached=$(sed -n 's/.*"event":"done","status":"ok","spp":\([0-9]*\),.*/\1/p' tl.json)
check "the JSON done event says how many samples ($reached)" test -n "$reached"
case $reached in 1 | 2 | 4) ok ;; *) bad "reached $reached samples, where the pass to 8 cannot end" ;; esac
[ -n "$reached" ] && check "the image is the bytes of $reached samples at once" cmp -s tl.pfm "ref$reached.pfm"
check "the summary says the limit stopped a pass" grep -q "time limit of 4 s reached: $reached samples per pixel (the pass to" logtl
check "the written image says $reached spp" grep -q "wrote tl.pfm (32x24, $reached spp)" logtl
check "it ends soon after the limit ($((t1 - t0)) s)" test $((t1 - t0)) -lt 30
check "no stuck worker is left" sh -c "! pgrep -x -f 'sleep 7$$' >/dev/null"
summary
