#!/bin/sh
# it_joblock.sh -- tests one render per output through the job lock.
#
# One render per output: the job directory's lock keeps a second franja out
# (status 2, naming the first), a killed render's lock is taken over at once
# by --resume, --fresh is refused while another render holds the lock,
# finished slabs are never discarded without --fresh, the messages about
# what was kept stay true when the directory is removed under a render, and
# a job directory someone else could write into, or a planted link, is
# refused.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 32x24 --spp 4"

"$FRANJA" render "$ROOT/scenes/cornell.json" -o ref0.pfm $SIZE -j 1 --job job0 --keep-job 2>/dev/null
cp job0/scene.fbin scene.fbin
"$WORKER" --scene scene.fbin --rows 0:24 $SIZE -o ref.pfm
mkdir -p slow
printf 'here local - 1 worker=%s\n' "$(fh_wrapper slow slow)" >t_slow
SLOW="--hosts t_slow --slab-rows 4"

# Two renders of one output: the second refuses at once, the first finishes.
# The first one's workers wait for the file "go", so it holds its lock for
# as long as the checks take, however slow the machine.
cat >held.sh <<SH
#!/bin/sh
case " \$* " in *" --rows "*) ;; *) exec "$WORKER" "\$@" ;; esac
while [ ! -e "$FH/go" ]; do sleep 0.1; done
exec "$WORKER" "\$@"
SH
chmod +x held.sh
printf 'here local - 2 worker=%s\n' "$FH/held.sh" >t_held
"$FRANJA" render scene.fbin -o same.pfm $SIZE --hosts t_held --slab-rows 4 2>logA &
A=$!
fh_until test -s same.pfm.franja-job/lock
"$FRANJA" render scene.fbin -o same.pfm $SIZE 2>logB
rc=$?
check "a second render of the same output exits 2 (got $rc)" test $rc -eq 2
check "it names the first render's pid" grep -q "same.pfm is being rendered by another franja (pid $A on host " logB
"$FRANJA" render scene.fbin -o same.pfm $SIZE --resume 2>logB2
check "--resume is refused too (status 2)" test $? -eq 2
"$FRANJA" render scene.fbin -o same.pfm $SIZE --fresh 2>logB3
check "--fresh is refused while the lock is held (status 2)" test $? -eq 2
check "--fresh names the holder" grep -q "being rendered by another franja (pid $A" logB3
touch go
wait $A
rc=$?
check "the first render finishes (status $rc)" test $rc -eq 0
check "the first render is byte-identical to a lone render" cmp -s same.pfm ref.pfm
check "its job directory is gone" test ! -e same.pfm.franja-job

# A render killed with SIGKILL: its lock dies with it; --resume takes over.
"$FRANJA" render scene.fbin -o killed.pfm $SIZE $SLOW 2>/dev/null &
K=$!
fh_until fh_has_slabs killed.pfm.franja-job 2
kill -KILL $K
wait $K 2>/dev/null
check "the killed render left its lock file" test -e killed.pfm.franja-job/lock
t0=$(date +%s)
"$FRANJA" render scene.fbin -o killed.pfm $SIZE --resume 2>logK
rc=$?
check "--resume after SIGKILL succeeds at once (status $rc)" test $rc -eq 0 -a $(($(date +%s) - t0)) -lt 30
check "--resume after SIGKILL is byte-identical" cmp -s killed.pfm ref.pfm

# Finished slabs are not discarded silently: refused, then --fresh.
"$FRANJA" render scene.fbin -o again.pfm $SIZE $SLOW 2>/dev/null &
G=$!
fh_until fh_has_slabs again.pfm.franja-job 2
kill -INT $G
wait $G 2>/dev/null
kept=$(ls again.pfm.franja-job | grep -c '^rows-.*\.pf$')
"$FRANJA" render scene.fbin -o again.pfm $SIZE 2>logR
rc=$?
check "a rerun over finished slabs without --resume exits 2 (got $rc)" test $rc -eq 2
check "it says how many rows are done and both choices" \
    grep -q "holds $((kept * 4)) finished rows .*--resume .*--fresh" logR
check "the slabs are still there" test "$(ls again.pfm.franja-job | grep -c '^rows-.*\.pf$')" -eq "$kept"
"$FRANJA" render scene.fbin -o again.pfm $SIZE --fresh 2>/dev/null
check "--fresh renders from scratch, byte-identical" cmp -s again.pfm ref.pfm

# The job directory removed under a running render: the message says so.
"$FRANJA" render scene.fbin -o gone.pfm $SIZE $SLOW 2>logD &
D=$!
fh_until fh_has_slabs gone.pfm.franja-job 1
rm -rf gone.pfm.franja-job
kill -INT $D
wait $D 2>/dev/null
check "the message says the job directory was removed" grep -q "was removed by another process; nothing was kept" logD
check "and promises no resume" sh -c '! grep -q "rerun with --resume" logD'

# Job directories others could write into, and planted links.
mkdir -m 0777 open.pfm.franja-job
chmod 0777 open.pfm.franja-job
expect_error "a world-writable job directory" "writable by others" "$FRANJA" render scene.fbin -o open.pfm $SIZE
mkdir -m 0700 theirs.pfm.franja-job
chown 65534 theirs.pfm.franja-job 2>/dev/null &&
    expect_error "a job directory of another user" "belongs to uid 65534" \
        "$FRANJA" render scene.fbin -o theirs.pfm $SIZE
mkdir -m 0700 elsewhere
ln -s elsewhere link.pfm.franja-job
expect_error "a job directory that is a symbolic link" "symbolic link" "$FRANJA" render scene.fbin -o link.pfm $SIZE
echo precious >victim
mkdir -m 0700 planted.pfm.franja-job
ln -s "$FH/victim" planted.pfm.franja-job/lock
expect_error "a planted lock link" "symbolic link" "$FRANJA" render scene.fbin -o planted.pfm $SIZE
check "the link's target is untouched" test "$(cat victim)" = precious
check "nothing was written through the planted link" test ! -e planted.pfm

# A scene that does not parse leaves no job directory behind.
echo '{ "image": ' >broken.json
"$FRANJA" render broken.json -o broken.png $SIZE 2>/dev/null
check "a failed parse exits 1" test $? -eq 1
check "a failed parse leaves no job directory" test ! -e broken.png.franja-job

summary
