# fakehosts.sh -- fake SSH hosts (sshd on loopback), sourced by tests.
#
# Sourced by the coordinator's integration tests (it_coord_*.sh).
#
# Fake cluster hosts: real OpenSSH servers on loopback addresses 127.0.0.N,
# each with its own throwaway host key, port and work directory; one
# throwaway client key; a private known_hosts file.  Everything lives under
# $FH (a temporary directory) and every process started here is stopped by
# fh_cleanup, by PID.
#
#   fh_init                   create $FH, the client key, the known_hosts file
#   fh_start NAME N [CORES] [WORKER]
#                             start sshd for host NAME on 127.0.0.N and append
#                             its line to $FH/hosts (WORKER: worker path;
#                             FH_SSHD_EXTRA: lines that override sshd_config;
#                             FH_ADDR: another address; FH_NETNS: run sshd
#                             in that network namespace; FH_SFTP: the SFTP
#                             server program, /bin/false for none)
#   fh_pids NAME [WORD]       PIDs of the host: sshd, its sessions, its workers
#                             (only those whose arguments include WORD)
#   fh_kill NAME / fh_stop NAME / fh_cont NAME
#   fh_wrapper NAME MODE      a worker wrapper that misbehaves once (MODE:
#                             kill, truncate, extra, slow, hang) and prints its path
#   fh_busy NAME              true while host NAME runs a worker on a slab
#   fh_slabs DIR              how many finished slabs job directory DIR holds
#   fh_has_slabs DIR N        true once DIR holds N finished slabs or more
#   fh_until CMD...           runs CMD every 0.1 s until it succeeds (10 s at most)
#   fr CMD ARGS... / fr_bg CMD ARGS... / fr_wait
#                             franja with the fake hosts' SSH settings; in the
#                             background; waiting for that one (status in $rc)
#
# The checks and the closing line are tests/support/lib.sh's (check, summary ...).

ROOT=${ROOT:-$(cd "$(dirname "$0")/.." && pwd)}
. "$ROOT/tests/support/lib.sh"
FRANJA="$ROOT/bin/franja"
WORKER="$ROOT/bin/franja-worker"

fh_init() {
    need /usr/sbin/sshd ssh-keygen ps
    FH=$(mktemp -d /tmp/franja-fh.XXXXXX)
    chmod 755 "$FH"
    mkdir -p -m0755 /run/sshd 2>/dev/null || true
    ssh-keygen -q -t ed25519 -N '' -f "$FH/client_key" -C franja-test
    cp "$FH/client_key.pub" "$FH/authorized_keys"
    : >"$FH/known_hosts"
    : >"$FH/hosts"
    FH_USER=$(id -un)
    # A port range of our own, so parallel runs on one machine do not collide.
    FH_PORT=$((20000 + ($$ % 2000) * 10))
    FH_HOSTS=""
    trap fh_cleanup EXIT
    trap 'exit 130' INT TERM
}

fh_start() {
    name=$1 n=$2 cores=${3:-2} worker=${4:-$WORKER}
    d="$FH/$name"
    mkdir -p "$d/work"
    ssh-keygen -q -t ed25519 -N '' -f "$d/host_key" -C "$name"
    port=$((FH_PORT + n))
    addr=${FH_ADDR:-127.0.0.$n}
    # sshd keeps the first value of a keyword: FH_SSHD_EXTRA overrides.
    cat >"$d/sshd_config" <<CFG
${FH_SSHD_EXTRA:-}
ListenAddress $addr:$port
HostKey $d/host_key
PidFile $d/sshd.pid
AuthorizedKeysFile $FH/authorized_keys
PasswordAuthentication no
KbdInteractiveAuthentication no
UsePAM no
StrictModes no
PermitRootLogin prohibit-password
Subsystem sftp ${FH_SFTP:-/usr/lib/openssh/sftp-server}
MaxStartups 100:30:200
MaxSessions 64
UseDNS no
PrintMotd no
LogLevel ERROR
# bash sources ~/.bashrc for commands run by sshd unless it is a nested
# shell; a heavy .bashrc (version managers, locks) would otherwise cost
# every worker start up to seconds.  SHLVL=1 makes the login shell nested.
SetEnv SHLVL=1
CFG
    rm -f "$d/sshd.pid"
    ${FH_NETNS:+ip netns exec "$FH_NETNS"} /usr/sbin/sshd -f "$d/sshd_config" -E "$d/sshd.log" || {
        echo "FAIL: sshd for $name did not start:"
        cat "$d/sshd.log"
        return 1
    }
    # sshd returns once it has forked, before it listens; it writes its PID
    # file after binding, so a client that starts before the file exists
    # can find the port closed on a busy machine.
    i=0
    while [ ! -s "$d/sshd.pid" ]; do
        [ $i -lt 200 ] || { echo "FAIL: sshd for $name did not listen within 20 s:"; cat "$d/sshd.log"; return 1; }
        sleep 0.1
        i=$((i + 1))
    done
    echo "[$addr]:$port $(cut -d' ' -f1,2 "$d/host_key.pub")" >>"$FH/known_hosts"
    echo "$name $addr:$port $FH_USER $cores identity=$FH/client_key workdir=$d/work worker=$worker" >>"$FH/hosts"
    FH_HOSTS="$FH_HOSTS $name"
}

# The PID and every descendant of a process, from one snapshot of the
# process table (a walk with one ps per process takes long enough on a busy
# machine for short-lived workers to come and go unseen); with a second
# argument, only those whose command line contains that word.
fh_tree() {
    ps -e -o pid=,ppid=,args= | awk -v root="$1" -v word="${2:-}" '
        { kids[$2] = kids[$2] " " $1; args[$1] = " " $0 " " }
        END {
            n = 1; q[1] = root
            for (i = 1; i <= n; i++) {
                if (word == "" || index(args[q[i]], " " word " ")) print q[i]
                m = split(kids[q[i]], k, " ")
                for (j = 1; j <= m; j++) q[++n] = k[j]
            }
        }'
}

fh_pids() {
    pidfile="$FH/$1/sshd.pid"
    [ -s "$pidfile" ] && fh_tree "$(cat "$pidfile")" "${2:-}"
}

fh_busy() { [ -n "$(fh_pids "$1" --rows)" ]; }

fh_slabs() { ls "$1" 2>/dev/null | grep -c '^rows-.*\.pf$'; }

fh_has_slabs() { [ "$(fh_slabs "$1")" -ge "$2" ]; }

fh_until() {
    i=0
    while ! "$@" && [ $i -lt 100 ]; do
        sleep 0.1
        i=$((i + 1))
    done
}

fh_kill() { for p in $(fh_pids "$1"); do kill -KILL "$p" 2>/dev/null; done; }
fh_stop() { for p in $(fh_pids "$1"); do kill -STOP "$p" 2>/dev/null; done; }
fh_cont() { for p in $(fh_pids "$1"); do kill -CONT "$p" 2>/dev/null; done; }

fh_cleanup() {
    for h in $FH_HOSTS; do
        pids=$(fh_pids "$h")
        for p in $pids; do kill -CONT "$p" 2>/dev/null; done
        for p in $pids; do kill -TERM "$p" 2>/dev/null; done
    done
    [ -n "${FH_BG:-}" ] && kill -KILL "$FH_BG" 2>/dev/null
    [ -n "$FH" ] && [ -d "$FH" ] && [ -z "${KEEP:-}" ] && rm -rf "$FH"
}

# A wrapper around the worker for host NAME that misbehaves on the first
# slab it is asked for (later calls, --version and --check behave):
#   kill      dies by SIGKILL after writing part of the image
#   truncate  writes only part of the image and exits 0
#   extra     writes the image plus stray bytes (wrong size) and exits 0
#   slow      every slab waits 0.4 s first (for faults injected from outside)
#   hang      never finishes (a stuck process)
fh_wrapper() {
    name=$1 mode=$2 w="$FH/$1/worker-$2.sh"
    cat >"$w" <<SH
#!/bin/sh
case " \$* " in *" --rows "*) ;; *) exec "$WORKER" "\$@" ;; esac
if [ "$mode" = slow ]; then sleep 0.4; exec "$WORKER" "\$@"; fi
if mkdir "$FH/$name/faulted" 2>/dev/null; then
    case "$mode" in
    kill) "$WORKER" "\$@" | head -c 100; kill -KILL \$\$ ;;
    truncate) "$WORKER" "\$@" | head -c 200; exit 0 ;;
    extra) "$WORKER" "\$@"; printf 'stray'; exit 0 ;;
    hang) exec sleep 600 ;;
    esac
fi
exec "$WORKER" "\$@"
SH
    chmod +x "$w"
    echo "$w"
}

# franja with the test's SSH settings: private known_hosts, no ~/.ssh/config,
# no agent, a short time-out (options given later win).  fr_bg runs it in
# the background with FH_BG set to the coordinator's own PID; fr_wait waits
# for it (or for any command whose PID is in FH_BG) and puts its exit status
# in $rc.
fr() {
    cmd=$1
    shift
    env -u SSH_AUTH_SOCK "$FRANJA" "$cmd" --known-hosts "$FH/known_hosts" --no-ssh-config --timeout 3 "$@"
}

fr_bg() {
    cmd=$1
    shift
    env -u SSH_AUTH_SOCK "$FRANJA" "$cmd" --known-hosts "$FH/known_hosts" --no-ssh-config --timeout 3 "$@" &
    FH_BG=$!
}

fr_wait() {
    wait "$FH_BG"
    rc=$?
    FH_BG=
}
