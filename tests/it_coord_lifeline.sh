#!/bin/sh
# it_coord_lifeline.sh -- tests workers end when the coordinator is gone.
#
# Workers end themselves when the coordinator or their channel is gone
# (worker/lifeline.h): a worker whose --lifeline standard input ends, or
# whose standard output's reader goes; a local render's workers and an SSH
# host's workers after the coordinator is killed with SIGKILL (no signal
# reaches them), for a root login (OpenSSH passes no channel signals to
# those) and for an ordinary user's.  Without the lifeline each of them
# would render its slab to the end: slabs here take minutes.
. "$(dirname "$0")/support/fakehosts.sh"
need useradd userdel
fh_init
cd "$FH" || exit 1
"$FRANJA" compile "$ROOT/scenes/cornell.json" -o scene.fbin 2>/dev/null
# A slab of this size takes minutes; the checks wait seconds.
LONG="--size 64x64 --spp 100000"

# Seconds since the epoch, to time the ends.
now() { date +%s; }

# The PIDs of workers rendering this test's scene (from one ps snapshot).
workers() { ps -e -o pid=,args= | awk -v s="$1" 'index($0, "--rows") && index($0, s) && !index($0, "awk") {print $1}'; }

# Waits up to $2 seconds until no worker of scene $1 is left; true if none.
none_left() {
    i=0
    while [ -n "$(workers "$1")" ] && [ $i -lt $(($2 * 10)) ]; do
        sleep 0.1
        i=$((i + 1))
    done
    [ -z "$(workers "$1")" ]
}

# --- the worker alone ---
# Standard input (--lifeline) reaches its end after 1 s.
t0=$(now)
sleep 1 | "$WORKER" --scene scene.fbin --rows 0:8 $LONG -o - --lifeline >/dev/null 2>errin
rc=$?
check "stdin closed: worker ends with status 3 (got $rc)" test $rc -eq 3
check "stdin closed: within 5 s (took $(($(now) - t0)) s)" test $(($(now) - t0)) -le 5
check "stdin closed: says why" grep -q "standard input closed" errin

# Standard output's reader goes after 1 s.
t0=$(now)
( "$WORKER" --scene scene.fbin --rows 0:8 $LONG -o - </dev/null 2>errout; echo $? >rcout ) | sleep 1
fh_until test -s rcout
check "stdout reader gone: worker ends with status 3 (got $(cat rcout))" test "$(cat rcout)" = 3
check "stdout reader gone: within 5 s (took $(($(now) - t0)) s)" test $(($(now) - t0)) -le 5

# Without --lifeline, a standard input at its end (a shell's pipe) does
# not stop a worker run by hand; nor does a regular file as output.
: | "$WORKER" --scene scene.fbin --rows 0:2 --size 16x16 --spp 2 -o - | cat >pipe.pfm
"$WORKER" --scene scene.fbin --rows 0:2 --size 16x16 --spp 2 -o ref.pfm
check "no --lifeline: an ended stdin changes nothing" cmp -s pipe.pfm ref.pfm

# --- a local render, its coordinator killed ---
env -u SSH_AUTH_SOCK "$FRANJA" render "$FH/scene.fbin" -o local.pfm -j 2 $LONG 2>loglocal &
pid=$!
fh_until test -n "$(workers "$FH/scene.fbin")"
check "local: workers started" test -n "$(workers "$FH/scene.fbin")"
kill -KILL $pid
wait $pid 2>/dev/null
check "local: workers end within 5 s of the coordinator's SIGKILL" none_left "$FH/scene.fbin" 5
for p in $(workers "$FH/scene.fbin"); do kill -KILL "$p"; done

# --- SSH hosts, the coordinator killed ---
# $1: label, $2: the host (the only one in ./hosts), $3: the user its
# workers must run as.
ssh_case() {
    label=$1 host=$2 user=$3
    env -u SSH_AUTH_SOCK "$FRANJA" render scene.fbin --known-hosts "$FH/known_hosts" --no-ssh-config \
        --timeout 3 --hosts hosts -o "$label.pfm" --job "job-$label" $LONG 2>"log-$label" &
    pid=$!
    fh_until fh_busy "$host"
    owners=$(for p in $(fh_pids "$host" --rows); do ps -o user= -p "$p"; done | sort -u | tr -d ' \n')
    check "$label: the host runs workers as $user (seen: '$owners')" test "$owners" = "$user"
    kill -KILL $pid
    wait $pid 2>/dev/null
    # Found by their scene in the host's work directory, not under sshd: a
    # worker that outlives its session is no longer sshd's descendant.
    check "$label: workers end within 10 s of the coordinator's SIGKILL" none_left "$FH/$host/work/" 10
    for p in $(workers "$FH/$host/work/"); do kill -KILL "$p" 2>/dev/null; done
}

# The user running the test (root on the test machines: OpenSSH then
# ignores channel signal requests).
: >hosts
fh_start self 2 2
ssh_case "login as $(id -un)" self "$(id -un)"

# As root, also an ordinary user: a throwaway account (no password, not
# locked: sshd without PAM refuses locked accounts) that logs in to a
# fake host.
if [ "$(id -u)" -eq 0 ]; then
    LT=franjalt$$
    trap 'fh_cleanup; [ -n "${LT_MADE:-}" ] && userdel "$LT" 2>/dev/null' EXIT
    if useradd -M -d "$FH/home-$LT" -s /bin/sh -p '*' "$LT" 2>useradd.err; then
        LT_MADE=1
        mkdir -p "$FH/home-$LT"
        : >hosts
        saved=$FH_USER
        FH_USER=$LT
        # A worker the throwaway user can reach: the checkout may sit under
        # a directory only its owner enters (a mktemp -d clone).
        mkdir -p "$FH/bin" && cp "$WORKER" "$FH/bin/" && chmod 755 "$FH/bin" "$FH/bin/franja-worker"
        fh_start plain 3 2 "$FH/bin/franja-worker"
        FH_USER=$saved
        chown -R "$LT" "$FH/home-$LT" "$FH/plain/work"
        ssh_case "ordinary user" plain "$LT"
    else
        bad "cannot create a throwaway user: $(cat useradd.err)"
    fi
fi

summary
