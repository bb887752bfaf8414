#!/bin/sh
# it_coord_faults.sh -- tests renders survive faults on fake SSH hosts.
#
# Faults on fake SSH hosts, each render still ending byte-identical to the
# one-process render: a worker killed mid-slab, truncated and wrong-size
# partial images, a host unreachable from the start, a whole host killed
# mid-render, a host that goes silent (all its processes stopped), and the
# coordinator killed and resumed.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 32x32 --spp 4"
"$FRANJA" render "$ROOT/scenes/cornell.json" -o local.pfm $SIZE --job job0 --keep-job 2>/dev/null
cp job0/scene.fbin scene.fbin
"$WORKER" --scene scene.fbin --rows 0:32 $SIZE -o ref.pfm

# Hosts whose workers misbehave once, and a healthy one.
fh_start kill 2 2 "$(mkdir -p "$FH/kill" && fh_wrapper kill kill)"
fh_start trunc 3 2 "$(mkdir -p "$FH/trunc" && fh_wrapper trunc truncate)"
fh_start extra 4 2 "$(mkdir -p "$FH/extra" && fh_wrapper extra extra)"
fh_start good 5 2
# A host nobody listens on.
echo "gone 127.0.0.9:$((FH_PORT + 9)) $FH_USER 2 identity=$FH/client_key workdir=$FH/gone" >>hosts
# One-row slabs and more samples, so that every host, whenever it becomes
# ready, still finds slabs to take (and to fail once) on a fast machine.
"$WORKER" --scene scene.fbin --rows 0:32 --size 32x32 --spp 64 -o ref64.pfm
fr render scene.fbin -o bad.pfm --hosts hosts --size 32x32 --spp 64 --slab-rows 1 2>logb
check "render with faulty workers is byte-identical" cmp -s bad.pfm ref64.pfm
check "worker killed mid-slab: retried" grep -q "failed on kill (attempt [1-5] of 5)" logb
check "truncated image: rejected" grep -q "failed on trunc .*bad partial image" logb
check "wrong-size image: rejected" grep -q "failed on extra .*bad partial image.*bytes of pixels" logb
check "unreachable host: reported" grep -q "host gone is not used: .*cannot connect" logb
check "unreachable host: not in the summary" sh -c "! grep -q '^  gone ' logb"

# A host that accepts fewer channels than it claims cores (sshd's
# MaxSessions): it runs what it can take.
: >hosts
FH_SSHD_EXTRA="MaxSessions 2" fh_start narrow 10 4
fr render scene.fbin -o narrow.pfm --hosts hosts $SIZE 2>logn
check "narrow host: render succeeds" cmp -s narrow.pfm ref.pfm
check "narrow host: slots reduced with a message" grep -q "host narrow: cannot start more than 2 workers" logn

# Whole host killed mid-render, and a host that goes silent.  Slow workers
# (0.4 s a slab) leave time to do it while slabs are in flight.
: >hosts
FH_HOSTS_OLD=$FH_HOSTS
for h in s1 s2 s3; do mkdir -p "$FH/$h"; done
fh_start s1 6 2 "$(fh_wrapper s1 slow)"
fh_start s2 7 2 "$(fh_wrapper s2 slow)"
fh_start s3 8 2 "$(fh_wrapper s3 slow)"
# A taller image (96 rows) keeps the render going well past the moment the
# loss is noticed, so second copies of stragglers cannot finish it first.
TALL="--size 32x96 --spp 4"
"$WORKER" --scene scene.fbin --rows 0:96 $TALL -o tall.pfm
fr_bg render scene.fbin -o killed.pfm --hosts hosts $TALL --slab-rows 2 2>logk
fh_until fh_busy s2
fh_kill s2
fr_wait
check "host killed mid-render: render succeeds" test $rc -eq 0
check "host killed mid-render: byte-identical" cmp -s killed.pfm tall.pfm
check "host killed mid-render: dropped with a message" grep -q "dropping host s2: .*connection" logk

# One-row slabs: the render outlasts the time-out, so the host is dropped
# rather than merely overtaken by second copies.
fr_bg render scene.fbin -o silent.pfm --hosts hosts $TALL --slab-rows 1 2>logs
fh_until fh_busy s3
fh_stop s3
t0=$(date +%s)
fr_wait
fh_cont s3
check "silent host: render succeeds" test $rc -eq 0
check "silent host: byte-identical" cmp -s silent.pfm tall.pfm
check "silent host: dropped after the time-out" grep -q "dropping host s3: .*no answer for" logs
check "silent host: noticed within a few time-outs" test $(($(date +%s) - t0)) -lt 40

# The coordinator killed (SIGKILL, no chance to clean up), then --resume.
fr_bg render scene.fbin -o resumed.pfm --hosts hosts $SIZE --slab-rows 2 2>logc1
fh_until fh_has_slabs resumed.pfm.franja-job 3
kill -KILL $FH_BG
wait $FH_BG 2>/dev/null
FH_BG=
kept=$(fh_slabs resumed.pfm.franja-job)
check "killed coordinator leaves no image" test ! -e resumed.pfm
check "killed coordinator leaves its finished slabs" test "$kept" -ge 3
fr render scene.fbin -o resumed.pfm --hosts hosts $SIZE --slab-rows 2 --resume 2>logc2
check "resumed render is byte-identical" cmp -s resumed.pfm ref.pfm
check "resume kept the finished rows" grep -q "resuming: $((kept * 2)) of 32 rows" logc2
check "resume rendered only the rest" grep -q "; $((16 - kept)) slabs" logc2

summary
