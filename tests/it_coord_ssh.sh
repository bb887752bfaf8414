#!/bin/sh
# it_coord_ssh.sh -- tests the coordinator over SSH with fake hosts.
#
# The coordinator over SSH with fake hosts (real sshd on loopback): the
# stitched image equals the one-process render byte for byte, the scene
# reaches each host's work directory by SFTP once, a damaged cached copy is
# replaced, and unknown or changed host keys are refused.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 32x32 --spp 4"

# The reference: one worker process renders the whole image from the same
# binary scene the coordinator compiles.
"$FRANJA" render "$ROOT/scenes/cornell.json" -o local.pfm $SIZE -j 1 --job job0 --keep-job 2>log0
check "local render for the reference" test -s job0/scene.fbin
cp job0/scene.fbin scene.fbin
"$WORKER" --scene scene.fbin --rows 0:32 $SIZE -o ref.pfm
HASH=$("$WORKER" --scene scene.fbin --check)
check "local -j 1 equals the one-process render" cmp -s local.pfm ref.pfm

fh_start a 2 2
fh_start b 3 3
fh_start c 4 2

fr render scene.fbin -o out1.pfm --hosts hosts $SIZE 2>log1
check "3-host render succeeds" test $? -eq 0
check "3-host render is byte-identical" cmp -s out1.pfm ref.pfm
for h in a b c; do
    check "scene uploaded to $h" cmp -s "$h/work/scenes/$HASH.fbin" scene.fbin
    check "log says $h got the scene by upload" grep -q "host $h: .*scene uploaded" log1
    check "$h rendered slabs" grep -Eq "^  $h +[0-9]+ +[1-9]" log1
done

# A JSON scene is compiled first, then shipped the same way.
fr render "$ROOT/scenes/cornell.json" -o out2.png --hosts hosts $SIZE 2>log2
check "JSON scene renders to PNG over SSH" test -s out2.png
check "no job directory left behind" test ! -e out2.png.franja-job

# Second render: nothing uploaded again; the cached copy is the same file,
# marked as just used (the cache's least-recently-used order).
touch -d '2000-01-01' a/work/scenes/$HASH.fbin
inode=$(stat -c %i a/work/scenes/$HASH.fbin)
fr render scene.fbin -o out3.pfm --hosts hosts $SIZE 2>log3
check "second render is byte-identical" cmp -s out3.pfm ref.pfm
check "second render uploads nothing" test "$(grep -c 'scene already there' log3)" -eq 3
check "cached copy not replaced" test "$(stat -c %i a/work/scenes/$HASH.fbin)" = "$inode"
check "cached copy marked as used" test "$(stat -c %Y a/work/scenes/$HASH.fbin)" -gt 946684800

# A damaged copy (same size, one byte changed) and a truncated one.
printf 'X' | dd of=b/work/scenes/$HASH.fbin bs=1 seek=200 conv=notrunc 2>/dev/null
head -c 100 scene.fbin >c/work/scenes/$HASH.fbin
fr render scene.fbin -o out4.pfm --hosts hosts $SIZE 2>log4
check "render with damaged caches is byte-identical" cmp -s out4.pfm ref.pfm
check "damaged copy on b detected" grep -q "b .*damaged" log4
check "truncated copy on c detected" grep -q "c .*damaged" log4
check "b's copy replaced" cmp -s b/work/scenes/$HASH.fbin scene.fbin
check "c's copy replaced" cmp -s c/work/scenes/$HASH.fbin scene.fbin

# hosts check reports each host, its worker and its cache.
fr hosts check --hosts hosts >check.out 2>&1
check "hosts check passes" test $? -eq 0
check "hosts check reports the worker version" test "$(grep -c 'franja-worker .* scene-format' check.out)" -eq 3
check "hosts check reports the cache" grep -q "1 scene" check.out
check "hosts check reports the release" grep -q " $(. /etc/os-release; echo "$VERSION_CODENAME") " check.out

# Unknown host: refused with a fix-it message, accepted with --accept-new-hosts.
cp known_hosts known_full
grep -v "127.0.0.3" known_full >known_hosts
fr render scene.fbin -o out5.pfm --hosts hosts $SIZE 2>log5
check "render without b still succeeds" cmp -s out5.pfm ref.pfm
check "unknown host refused" grep -q "b (.*REFUSED: unknown host" log5
check "refusal says how to fix it" grep -q "ssh-keyscan -p" log5
fr hosts check --hosts hosts >check2.out 2>&1
check "hosts check fails on the unknown host" test $? -eq 1
fr render scene.fbin -o out6.pfm --hosts hosts $SIZE --accept-new-hosts 2>log6
check "--accept-new-hosts renders" cmp -s out6.pfm ref.pfm
check "--accept-new-hosts adds the key" grep -q "127.0.0.3" known_hosts
check "added key is b's" grep -q "$(cut -d' ' -f2 b/host_key.pub)" known_hosts

# Changed key: refused, even with --accept-new-hosts.
ssh-keygen -q -t ed25519 -N '' -f other_key
grep -v "127.0.0.2" known_full >known_hosts
echo "[127.0.0.2]:$((FH_PORT + 2)) $(cut -d' ' -f1,2 other_key.pub)" >>known_hosts
fr render scene.fbin -o out7.pfm --hosts hosts $SIZE --accept-new-hosts 2>log7
check "render without a still succeeds" cmp -s out7.pfm ref.pfm
check "changed key refused" grep -q "a (.*REFUSED: the host key changed" log7
check "changed key message says ssh-keygen -R" grep -q "ssh-keygen -R" log7
check "changed key not replaced" grep -q "$(cut -d' ' -f2 other_key.pub)" known_hosts
printf 'a 127.0.0.2:%s %s 2 identity=%s/client_key workdir=%s/a/work worker=%s\n' \
    $((FH_PORT + 2)) "$FH_USER" "$FH" "$FH" "$WORKER" >only_a
fr render scene.fbin -o out8.pfm --hosts only_a $SIZE 2>log8
check "render with no usable host fails" test $? -ne 0
check "and writes no image" test ! -e out8.pfm
check "and says why" grep -q "no host could be used" log8

# ~/.ssh/config is honoured (here a file given with --ssh-config): the table
# names an alias, the configuration gives address, port, user, key and
# known_hosts file.
cat >ssh_config <<CFG
Host viacfg
    HostName 127.0.0.3
    Port $((FH_PORT + 3))
    User $FH_USER
    IdentityFile $FH/client_key
    UserKnownHostsFile $FH/known_full
CFG
echo "viacfg viacfg - 2 workdir=$FH/b/work worker=$WORKER" >t_cfg
env -u SSH_AUTH_SOCK "$FRANJA" render scene.fbin -o cfg.pfm --hosts t_cfg --ssh-config ssh_config --timeout 3 $SIZE 2>logcfg
check "SSH client configuration honoured" cmp -s cfg.pfm ref.pfm
check "configuration's HostName and Port used" grep -q "viacfg: .*scene already there" logcfg

# Remote arguments are quoted: a work directory full of shell syntax is
# created and used literally.
QDIR="$FH/q/it's\$HOME;*\`true\`"
echo "q 127.0.0.4:$((FH_PORT + 4)) $FH_USER 2 identity=$FH/client_key workdir=$QDIR worker=$WORKER" >t_q
cp known_full known_hosts
fr render scene.fbin -o q.pfm --hosts t_q $SIZE 2>logq
check "shell syntax in paths reaches the worker unharmed" cmp -s q.pfm ref.pfm
check "scene stored under the literal path" cmp -s "$QDIR/scenes/$HASH.fbin" scene.fbin
# ... and hosts check's trial upload goes there too, and leaves nothing.
fr hosts check --hosts t_q >checkq.out 2>&1
check "hosts check passes with shell syntax in the work directory" test $? -eq 0
check "hosts check leaves no trial file" test -z "$(ls -A "$QDIR/scenes" | grep -v "^$HASH.fbin\$")"

# A host whose SSH server has no SFTP: render cannot ship it the scene, and
# hosts check says so instead of passing it.
FH_SFTP=/bin/false fh_start nosftp 5 2
tail -n 1 hosts >t_nosftp
fr hosts check --hosts t_nosftp >checkn.out 2>&1
check "hosts check fails a host without SFTP" test $? -eq 1
check "hosts check says why" grep -qi "^nosftp .*PROBLEM: .*sftp" checkn.out
fr render scene.fbin -o n.pfm --hosts t_nosftp $SIZE 2>logn
check "render cannot use a host without SFTP either" test $? -ne 0

summary
