#!/bin/sh
# coord_ssh.sh -- measures the cost of fake SSH hosts against local workers.
#
# The cost of distribution: the same render on fake SSH hosts (sshd on
# loopback, one worker slot each) against local worker processes with the
# same total number of slots.  ratio = T(ssh) / T(local); the goal is a
# ratio <= 1.03 for a render of about a minute.  Also checks that the scene
# is uploaded once per host (the second run finds it cached).
cd "$(dirname "$0")/../.." || exit 1
ROOT=$(pwd)
. tests/support/bench_common.sh
. tests/support/fakehosts.sh
N=$(nproc)
ARGS="--size ${SIZE:-256x256} --spp ${SPP:-128}"
fh_init
machine
bin/franja render scenes/cornell.json -o "$FH/warm.pfm" --size 16x16 --spp 1 --job "$FH/job" --keep-job >/dev/null 2>&1
SCENE="$FH/job/scene.fbin"
i=1
while [ $i -le "$N" ]; do
    fh_start "h$i" $((i + 1)) 1 >/dev/null
    i=$((i + 1))
done
fr render "$SCENE" -o "$FH/first.pfm" --size 16x16 --spp 1 --hosts "$FH/hosts" 2>"$FH/first.log"
fr render "$SCENE" -o "$FH/second.pfm" --size 16x16 --spp 1 --hosts "$FH/hosts" 2>"$FH/second.log"
echo "scene uploads: first run $(grep -c 'scene uploaded' "$FH/first.log") of $N hosts, second run $(grep -c 'scene uploaded' "$FH/second.log")"
SSH="env -u SSH_AUTH_SOCK bin/franja render $SCENE -o $FH/s.pfm $ARGS --hosts $FH/hosts --known-hosts $FH/known_hosts --no-ssh-config"
compare "bin/franja render $SCENE -o $FH/l.pfm $ARGS -j $N" "$SSH" || exit 1
cmp -s "$FH/l.pfm" "$FH/s.pfm" || { echo "SSH and local images differ"; exit 1; }
echo "local $N slots: $TA s, $N fake SSH hosts x 1 slot: $TB s; ratio $(calc "$TB / $TA") (overhead $(calc "($TB - $TA) * 100 / $TA") %, $(calc "$TB - $TA") s)"
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
