#!/bin/sh
# it_slurm.sh -- tests franja on a real Slurm cluster of three nodes.
#
# franja render --slurm and franja hosts check --slurm on a real Slurm
# cluster of three nodes on this machine (tests/support/slurm_cluster.sh): renders
# inside salloc and sbatch allocations are byte-identical to a one-process
# render whatever the node count, render passes and Metropolis light
# transport included; the scene is
# broadcast once per node, found cached later and sent again when the cached copy is damaged; a
# straggling node's slabs get second copies elsewhere; progress in a batch
# job is a plain line every 10 s;
# a node killed or set down mid-render loses only its slabs, a drained one
# goes on; Ctrl-C and scancel
# mid-render leave no step and no worker running, and so does SIGKILL of
# franja in an allocation that lives on; --resume finishes in a
# second allocation (a batch job from hosts/franja.sbatch);
# a node whose worker is another version is dropped, by name; an
# animation (--frames) runs its frames over one set of nodes and gives
# each frame's own bytes; outside an
# allocation --slurm says what to run instead.
ROOT=$(cd "$(dirname "$0")/.." && pwd)
. "$ROOT/tests/support/slurm_lib.sh"
sl_init 3
cd "$T" || exit 1
SIZE="--size 40x30 --spp 4"
WD="$T/work" # the nodes' scene cache (node-local as far as franja knows)

"$FRANJA" compile "$ROOT/scenes/cornell.json" -o scene.fbin >/dev/null 2>&1
"$WORKER" --scene scene.fbin --rows 0:30 $SIZE -o ref.pfm
check "reference render" test -s ref.pfm

# A worker wrapper: slow (each slab waits first), or another version on one node.
wrapper() {
    cat >"$T/worker-$1" <<SH
#!/bin/sh
case "$1" in
slow) case " \$* " in *" --rows "*) sleep $2 ;; esac ;;
version) if [ "\$SLURMD_NODENAME" = "$2" ] && [ "\$1" = --version ]; then
        echo "franja-worker 0.0.1 scene-format 1"; exit 0; fi ;;
straggler) if [ "\$SLURMD_NODENAME" = "$2" ]; then case " \$* " in *" --rows "*) sleep 60 ;; esac; fi ;;
esac
exec "$WORKER" "\$@"
SH
    chmod +x "$T/worker-$1"
    echo "$T/worker-$1"
}

# render LOG ARGS...: franja render inside an allocation of the test cluster.
render() {
    log=$1
    shift
    sl_alloc 90 "$@" >/dev/null 2>"$log"
}

no_leftovers() {
    test -z "$(sl_steps)" && test -z "$(sl_pids)"
}

# Outside an allocation: a clear refusal with the lines to use.
expect_error "--slurm outside an allocation" "not inside a Slurm allocation" \
    "$FRANJA" render scene.fbin -o x.pfm --slurm
check "it shows the salloc line" grep -q "salloc .*franja render scene.fbin -o x.pfm --slurm" "$T/err"
check "it shows the sbatch line" grep -q "sbatch " "$T/err"
check "and renders nothing" test ! -e x.pfm

# The allocation as the environment describes it, checked before any node
# is asked anything.
fake() { env SLURM_JOB_ID=77 SLURM_JOB_NODELIST='n[1-3]' SLURM_JOB_CPUS_PER_NODE="$1" ${2:+SLURM_STEP_ID=$2} \
    "$FRANJA" hosts list --slurm; }
fake '4,2(x2)' >list.out 2>&1
check "hosts list --slurm reads the CPUs per node ($(cat list.out))" \
    sh -c "grep -Eq '^n1 .* 4 ' list.out && grep -Eq '^n2 .* 2 ' list.out && grep -Eq '^n3 .* 2 ' list.out"
expect_error "too few CPU counts" "describes 2 nodes, SLURM_JOB_NODELIST has 3" fake '2(x2)'
expect_error "too many CPU counts" "more than the 3 nodes" fake '2(x4)'
expect_error "a bad CPU list" "offset 1" fake '2x3'
expect_error "an unclosed repeat" "expected ')'" fake '2(x3'
expect_error "zero CPUs" "not in 1..4096" fake '0,2,2'
expect_error "a huge CPU count" "not in 1..4096" fake '99999999999999999999(x3)'
expect_error "a job step" "inside job step 77.0" fake '2(x3)' 0
expect_error "--slurm with --hosts" "exclude each other" "$FRANJA" render scene.fbin -o x.pfm --slurm --hosts /dev/null
expect_error "--workdir without --slurm" "applies to --slurm only" "$FRANJA" render scene.fbin -o x.pfm --workdir /tmp/x
expect_error "a relative --workdir" "not an absolute path" "$FRANJA" render scene.fbin -o x.pfm --slurm --workdir x

# hosts check --slurm: every node, its CPUs, its worker.
sl_alloc 60 -N3 -n6 "$FRANJA" hosts check --slurm >check.out 2>check.err
check "hosts check --slurm succeeds ($(cat check.err))" test $? -eq 0
for n in n1 n2 n3; do
    check "hosts check lists $n with its arch, 2 CPUs and this build's worker version" \
        grep -Eq "^$n +ok +$(uname -m) .* 2 +$("$WORKER" --version) " check.out
done

# Three nodes, then two of unequal size: the same bytes as one process.
render log3 -N3 -n6 "$FRANJA" render scene.fbin -o n3.pfm $SIZE --slurm --workdir "$WD"
check "3-node render is byte-identical to the one-process render ($(tail -n 3 log3))" cmp -s n3.pfm ref.pfm
for n in n1 n2 n3; do
    check "the scene was broadcast to $n once ($(grep -c "^franja: host $n: .*scene uploaded" log3))" \
        test "$(grep -c "^franja: host $n: .*scene uploaded" log3)" -eq 1
done
check "and to no one else" test "$(grep -c 'scene uploaded' log3)" -eq 3
check "it lies in the nodes' cache under its content hash" \
    test "$(ls "$WD/scenes" | grep -Ec '^[0-9a-f]{16}\.fbin$')" -eq 1
check "every node rendered rows" sh -c "for n in n1 n2 n3; do grep -Eq \"^  \$n +2 +[1-9]\" log3 || exit 1; done"
check "no step is left after the render" no_leftovers

# Metropolis light transport: the coordinator's normalisation reaches every
# node's workers through srun (--mlt-norm), the chains the bytes of one process.
"$FRANJA" render scene.fbin -o mref.pfm $SIZE --integrator mlt -j 1 2>/dev/null
render logm -N3 -n6 "$FRANJA" render scene.fbin -o m3.pfm $SIZE --integrator mlt --slurm --workdir "$WD"
check "a 3-node Metropolis render is byte-identical to one process ($(tail -n 2 logm))" cmp -s m3.pfm mref.pfm

# An animation in one allocation: every frame equals its own render.  The
# camera moves (so that frame 2 can travel as a patch of frame 1's scene).
for i in 1 2; do
    sed -e "/\"shapes\": \[/a { \"type\": \"sphere\", \"center\": [250, 100, 300], \"radius\": 80, \"material\": \"white\" }," \
        -e "s/\"position\": \[278, 273, -800\]/\"position\": [$((218 + 60 * i)), 273, -800]/" \
        "$ROOT/scenes/cornell.json" >"f.000$i.json"
    "$FRANJA" render "f.000$i.json" -o "fref$i.pfm" $SIZE -j 1 2>/dev/null
done
render logf -N3 -n6 "$FRANJA" render 'f.####.json' --frames 1-2 -o 'anim/f.####.pfm' $SIZE --slurm --workdir "$T/animwd"
check "frames 1-2 in one allocation: both written ($(tail -n 2 logf))" grep -q "frames: 2 of 2 done (2 rendered" logf
check "frame 1 equals its own render" cmp -s anim/f.0001.pfm fref1.pfm
check "frame 2 equals its own render" cmp -s anim/f.0002.pfm fref2.pfm
check "and the frames differ" sh -c '! cmp -s fref1.pfm fref2.pfm'
check "the frames run over one set of steps: each node probed once" \
    test "$(grep -c ': Linux .* slots, franja-worker' logf)" -eq 3
check "each frame's scene staged on each node" \
    test "$(grep -Ec 'host n[123]: frame [12]: scene (uploaded|already there)' logf)" -eq 6
check "no step is left after the animation" no_leftovers
# On one node, which stages frame 1 before frame 2: frame 2's scene goes
# as a patch of frame 1's (common/fpatch.h), rebuilt by a step there.
render logp -N1 -n2 "$FRANJA" render 'f.####.json' --frames 1-2 -o 'animp/f.####.pfm' $SIZE --slurm \
    --workdir "$T/patchwd"
s1=$(sed -n "s/^franja: host n[123]: frame 1: scene .*, \([0-9]*\) bytes sent).*/\1/p" logp)
s2=$(sed -n "s/^franja: host n[123]: frame 2: scene .*, \([0-9]*\) bytes sent).*/\1/p" logp)
check "one node: frame 2 sent as a patch ($s2 bytes) of frame 1's scene ($s1 bytes)" \
    test -n "$s1" -a -n "$s2" -a "${s2:-0}" -gt 0 -a "$((${s2:-0} * 4))" -lt "${s1:-0}"
check "one node: no patch failed" sh -c "! grep -q 'did not unpack' logp"
check "one node: frame 2 equals its own render" cmp -s animp/f.0002.pfm fref2.pfm

# Bidirectional: every step's partial carries its splats over the whole
# image, and the sum over nodes has the bytes of a one-process render.
"$FRANJA" render scene.fbin -o bref.pfm $SIZE --integrator bdpt -j 1 --slab-rows 30 2>/dev/null
render logb -N3 -n6 "$FRANJA" render scene.fbin -o b3.pfm $SIZE --integrator bdpt --slurm --workdir "$WD" --slab-rows 4
check "a bidirectional 3-node render is byte-identical to one process ($(tail -n 3 logb))" cmp -s b3.pfm bref.pfm
check "and differs from path tracing" sh -c "! cmp -s b3.pfm ref.pfm"

# Render passes travel in the partials: the image and each pass file have
# the bytes of a one-process render's.
"$FRANJA" render scene.fbin -o pref.pfm $SIZE --passes albedo,normal,depth,material_id -j 1 2>/dev/null
render logp -N3 -n6 "$FRANJA" render scene.fbin -o p3.pfm $SIZE --passes albedo,normal,depth,material_id --slurm \
    --workdir "$WD" --slab-rows 4
for s in "" .albedo .normal .depth .material_id; do
    check "with --passes over 3 nodes, p3$s.pfm is byte-identical to one process ($(tail -n 2 logp))" \
        cmp -s "p3$s.pfm" "pref$s.pfm"
done
render log2 -N2 -n3 "$FRANJA" render scene.fbin -o n2.pfm $SIZE --slurm --workdir "$WD" --slab-rows 3
check "2 nodes (2 + 1 CPUs) give the same bytes" cmp -s n2.pfm ref.pfm
check "the second render finds the scene cached on both nodes" test "$(grep -c "scene already there" log2)" -eq 2
check "and sends nothing" test "$(grep -c "scene uploaded" log2)" -eq 0
check "a 1-CPU node runs one worker" grep -Eq "^  n2 +1 " log2

# A shared work directory: the scene is copied there, once, no sbcast.
render logs -N3 -n6 "$FRANJA" render scene.fbin -o sh.pfm $SIZE --slurm --shared-workdir "$T/shared"
check "a shared work directory gives the same bytes" cmp -s sh.pfm ref.pfm
check "the scene is in the shared directory" test "$(ls "$T/shared/scenes" | grep -c '\.fbin$')" -eq 1

# More samples later: a job kept at 2 samples goes on to 4.  Into a shared
# work directory the sums are sent (and gone once the workers opened
# them); to the nodes' own disks they are not (sbcast would wait for a
# CPU that every worker holds), so those slabs render every sample again.
render logk1 -N3 -n6 "$FRANJA" render scene.fbin -o more.pfm --size 40x30 --spp 2 --slurm --shared-workdir "$T/shared" \
    --keep-job
render logk2 -N3 -n6 "$FRANJA" render scene.fbin -o more.pfm $SIZE --slurm --shared-workdir "$T/shared" --resume \
    --slab-rows 7
check "2 then 4 samples in a shared work directory: the bytes of 4 at once ($(tail -n 3 logk2))" cmp -s more.pfm ref.pfm
check "the slabs went on from the kept sums" grep -q "slabs\{0,1\} went on from kept sample sums" logk2
check "no sums are left in the shared directory" sh -c "! ls '$T/shared/scenes' | grep -q cont-"
render logk3 -N3 -n6 "$FRANJA" render scene.fbin -o more2.pfm --size 40x30 --spp 2 --slurm --workdir "$WD" --keep-job
render logk4 -N3 -n6 "$FRANJA" render scene.fbin -o more2.pfm $SIZE --slurm --workdir "$WD" --resume --slab-rows 7
check "2 then 4 samples on the nodes' own disks: the bytes of 4 at once ($(tail -n 3 logk4))" cmp -s more2.pfm ref.pfm
check "those slabs rendered every sample, and the summary says so" grep -q "rendered every sample: the sums could not be sent" logk4

# A node whose worker is another version is dropped, by name.
render logv -N3 -n6 "$FRANJA" render scene.fbin -o v.pfm $SIZE --slurm --workdir "$WD" --worker "$(wrapper version n2)"
check "a wrong worker version on n2 does not stop the render" cmp -s v.pfm ref.pfm
check "the message names n2 and its version" grep -q "n2.*0.0.1" logv
check "n2 rendered nothing" sh -c "! grep -Eq '^  n2 +[0-9]+ +[1-9]' logv"

sl_alloc 60 -N3 -n6 "$FRANJA" hosts check --slurm --worker "$T/worker-version" >checkv.out 2>&1
check "hosts check --slurm fails for a node with another worker version" test $? -eq 1
check "and names it ($(cat checkv.out))" grep -Eq "^n2 +FAIL .*0\.0\.1" checkv.out

# A damaged copy in the nodes' cache (same name, other bytes) is found
# by the workers' hash check and sent again.
f=$(ls "$WD"/scenes/*.fbin)
printf 'XXXXXXXX' | dd of="$f" bs=1 seek=200 conv=notrunc 2>/dev/null
render logr -N3 -n6 "$FRANJA" render scene.fbin -o r.pfm $SIZE --slurm --workdir "$WD"
check "a damaged cached scene is noticed and sent again ($(grep -c damaged logr))" \
    grep -q "cached scene .* is damaged; uploading it again" logr
check "and the image is the same" cmp -s r.pfm ref.pfm
check "the cache holds the right scene again" cmp -s "$f" scene.fbin

# A straggler: n3's workers take a minute per slab.  Once nothing is
# queued, the other nodes run second copies of its slabs, the first copy
# to finish wins, and n3's losing steps are cancelled.
t0=$(date +%s)
render logs3 -N3 -n6 "$FRANJA" render scene.fbin -o st.pfm $SIZE --slurm --workdir "$WD" \
    --worker "$(wrapper straggler n3)" --slab-rows 2
took=$(($(date +%s) - t0))
check "a render with a straggling node succeeds ($(tail -n 3 logs3))" cmp -s st.pfm ref.pfm
check "without waiting for the straggler (${took} s)" test $took -lt 50
check "n3's slabs got second copies on n1 or n2" grep -q "still running; starting a second copy on n[12]" logs3
check "n3 finished no slab" grep -Eq "^  n3 +2 +0 " logs3
# The losing steps are cancelled as the render ends; slurmd ends them a
# moment later.
sl_until 10 no_leftovers
check "its steps are cancelled at the end, gone within 10 s ($(sl_steps) $(sl_pids))" no_leftovers

# An administrator sets n2 down and drains n1 mid-render: n2's steps fail
# and it is dropped at once, its slabs going elsewhere; a drained node
# keeps the steps of running jobs, so n1 goes on rendering.
sl_alloc_bg 90 -N3 -n6 --no-kill "$FRANJA" render scene.fbin -o d.pfm $SIZE --slurm --workdir "$WD" \
    --worker "$(wrapper slow 0.6)" --slab-rows 1 --job djob --timeout 3 >/dev/null 2>logd
sl_until 40 sh -c "ls djob/rows-* 2>/dev/null | wc -l | grep -qv '^[0-2]$'"
sl_q scontrol update nodename=n2 state=down reason=franja-test
sl_q scontrol update nodename=n1 state=drain reason=franja-test
wait "$SL_BG"
rc=$?
SL_BG=
check "a render that lost n2 and had n1 drained succeeds (status $rc: $(tail -n 3 logd))" test $rc -eq 0
check "and is byte-identical" cmp -s d.pfm ref.pfm
check "n2 is dropped as lost to the job" grep -q "dropping host n2: .*lost to the job" logd
check "the drained n1 is not dropped and renders" grep -Eq "^  n1 +2 +[0-9]+ +[0-9]+ .* ok$" logd
sl_q scontrol update nodename=n1 state=resume
sl_q scontrol update nodename=n2 state=resume 2>/dev/null # (already back by itself: ReturnToService=2)
check "n1 and n2 are back" sl_until 20 sh -c \
    "test \"\$(timeout 5 sinfo -h -N -t idle -o %N </dev/null | sort -u | tr '\n' ' ')\" = 'n1 n2 n3 '"

# A node killed mid-render (slurmd, its slurmstepd and its workers): its
# slabs go to the others and the image is the same.
sl_alloc_bg 90 -N3 -n6 --no-kill "$FRANJA" render scene.fbin -o k.pfm $SIZE --slurm --workdir "$WD" \
    --worker "$(wrapper slow 0.6)" --slab-rows 1 --job kjob >/dev/null 2>logk
sl_until 40 sh -c "ls kjob/rows-* 2>/dev/null | wc -l | grep -qv '^[0-2]$'"
sh "$CLUSTER" kill-node "$T/cl" n3
wait "$SL_BG"
rc=$?
SL_BG=
check "a render that lost a node succeeds (status $rc: $(tail -n 3 logk))" test $rc -eq 0
check "and is byte-identical" cmp -s k.pfm ref.pfm
check "n3's unfinished slabs were run again elsewhere" grep -q "starting a second copy on n[12]" logk
# The controller still lists the dead node's steps until it notices the
# node is gone; the other nodes must have nothing left.
check "no process of the render is left" test -z "$(sl_pids)"
check "no step is left on the live nodes ($(sl_steps))" test -z "$(sl_steps | grep -v ' n3$')"
sh "$CLUSTER" start-node "$T/cl" n3
sl_until 30 sh -c "timeout 5 sinfo -h -N -n n3 -t idle -o %N </dev/null | grep -q n3"
check "once n3 is back, the controller lists no step either" sl_until 10 sh -c "test -z \"\$(timeout 5 squeue -h -s </dev/null)\""

# Ctrl-C (SIGINT to franja): it stops its steps, keeps its slabs, exits 130.
sl_alloc_bg 90 -N3 -n6 "$FRANJA" render scene.fbin -o i.pfm $SIZE --slurm --workdir "$WD" \
    --worker "$(wrapper slow 0.6)" --slab-rows 1 >/dev/null 2>logi
sl_until 40 sh -c "ls i.pfm.franja-job/rows-* 2>/dev/null | wc -l | grep -qv '^[0-2]$'"
pid=$(pgrep -f "render scene.fbin -o i.pfm" | while read -r p; do
    [ "$(cat /proc/"$p"/comm 2>/dev/null)" = franja ] && echo "$p"; done | head -n 1)
kill -INT "$pid"
sl_until 30 sh -c "! kill -0 $pid 2>/dev/null"
check "franja stops on SIGINT" sh -c "! kill -0 $pid 2>/dev/null"
wait "$SL_BG"
rc=$?
SL_BG=
check "and exits 130 ($rc)" test $rc -eq 130
check "Ctrl-C leaves no step and no worker running ($(sl_steps) $(sl_pids))" no_leftovers
check "the slabs done so far are kept" test -n "$(ls i.pfm.franja-job/rows-* 2>/dev/null)"

# SIGKILL of franja in an allocation that outlives it (an interactive
# salloc shell): franja can do nothing, yet its sruns are told by the
# kernel (parent-death signal) and cancel their steps.  The slabs take
# 60 s, so a step that was not cancelled would still be there.
sl_alloc_bg 120 -N3 -n6 sh -c 'echo $$ >alloc.pid; "$@" & wait; exec sleep 100' sh "$FRANJA" render scene.fbin -o kill.pfm $SIZE --slurm \
    --workdir "$WD" --worker "$(wrapper slow 60)" --slab-rows 1 >/dev/null 2>logkill
sl_until 40 sh -c "test \"\$(timeout 5 squeue -h -s </dev/null | grep -vc '\.extern')\" -ge 6"
check "six steps of the render are running ($(sl_steps | tr '\n' ' '))" test "$(sl_steps | grep -vc '\.extern')" -ge 6
pid=$(pgrep -f "render scene.fbin -o kill.pfm" | while read -r p; do
    [ "$(cat /proc/"$p"/comm 2>/dev/null)" = franja ] && echo "$p"; done | head -n 1)
kill -KILL "$pid"
sl_until 10 no_leftovers
check "SIGKILL of franja leaves no step and no worker running within 10 s ($(sl_steps) $(sl_pids))" no_leftovers
check "while the allocation lives on" test -n "$(sl_jobs)"
kill "$(cat alloc.pid)" # the allocation's shell ends, and so does the allocation
wait "$SL_BG"
SL_BG=
sl_until 10 sh -c "test -z \"\$(timeout 5 squeue -h </dev/null)\""

# scancel mid-render: every step goes, franja stops and keeps its slabs;
# --resume in a second allocation (a batch job) finishes the same image.
sl_alloc_bg 90 -N3 -n6 "$FRANJA" render scene.fbin -o c.pfm $SIZE --slurm --workdir "$WD" \
    --worker "$(wrapper slow 0.6)" --slab-rows 1 >/dev/null 2>logc
sl_until 40 sh -c "ls c.pfm.franja-job/rows-* 2>/dev/null | wc -l | grep -qv '^[0-2]$'"
job=$(sl_q squeue -h -o %i | head -n 1)
sl_q scancel "$job"
sl_until 30 sh -c "! kill -0 $SL_BG 2>/dev/null"
check "franja ends after scancel" sh -c "! kill -0 $SL_BG 2>/dev/null"
sl_bg_stop
check "scancel leaves no step and no worker running ($(sl_steps) $(sl_pids))" no_leftovers
check "the finished slabs are kept" test -n "$(ls c.pfm.franja-job/rows-* 2>/dev/null)"
check "no image was written" test ! -e c.pfm
check "franja says the job has ended ($(tail -n 2 logc))" grep -q "Slurm job has ended" logc
FRANJA="$FRANJA" sl_q sbatch -N2 -n4 -o "$T/resume.log" "$ROOT/hosts/franja.sbatch" \
    scene.fbin -o c.pfm $SIZE --workdir "$WD" --resume >/dev/null
sl_until 60 sh -c "test -z \"\$(timeout 5 squeue -h </dev/null)\""
check "--resume in a batch job finishes the image ($(tail -n 3 resume.log))" cmp -s c.pfm ref.pfm
check "it renders only the missing rows" grep -q "resuming: [1-9][0-9]* of 30 rows already done" resume.log
check "progress in a batch job is plain lines" sh -c "! grep -q \"$(printf '\r')\" resume.log"
check "nothing left running after the batch job" no_leftovers

# Progress in a batch job (no terminal): a plain line every 10 s and one
# at the end.  Each slab waits 2 s, so this render lasts about 16 s.
FRANJA="$FRANJA" sl_q sbatch -N2 -n4 -o "$T/prog.log" "$ROOT/hosts/franja.sbatch" \
    scene.fbin -o p.pfm $SIZE --workdir "$WD" --slab-rows 1 --worker "$(wrapper slow 2)" >/dev/null
sl_until 120 sh -c "test -z \"\$(timeout 5 squeue -h </dev/null)\""
check "the batch render is the same image ($(tail -n 2 prog.log))" cmp -s p.pfm ref.pfm
sed -n 's/^franja: \[ *\([0-9.]*\)s\] rows \([0-9]*\)\/30 .*/\1 \2/p' prog.log >prog.lines
check "its log has progress lines, the last at 30/30 ($(tr '\n' ' ' <prog.lines))" \
    sh -c "test \"\$(tail -n 1 prog.lines | cut -d' ' -f2)\" = 30"
check "including one before the end" sh -c "awk '\$2 < 30' prog.lines | grep -q ."
check "10 s apart (but the last)" awk 'NR > 1 && prev_t != "" && $2 < 30 && $1 - prev_t < 9.9 { bad = 1 }
    { prev_t = $1 } END { exit bad }' prog.lines
check "no terminal control characters" sh -c "! grep -q \"\$(printf '\033')\" prog.log"

sl_stop
check "the cluster stops, leaving no daemon, step or task ($(sh "$CLUSTER" pids "$T/cl"))" \
    test -z "$(sh "$CLUSTER" pids "$T/cl")"
check "nothing started in an allocation is left running ($(sl_strays | tr '\n' ' '))" test -z "$(sl_strays)"

summary
