#!/bin/sh
# private-dockerd.sh -- starts or stops a private Docker engine.
#
# private-dockerd.sh start STATE_DIR [DATA_DIR] | stop STATE_DIR
#
# Runs a Docker engine of its own, for machines where none is running (the
# tests use it): every path it touches is under STATE_DIR (socket, exec root,
# pid file, log) and DATA_DIR (images and build cache; default
# STATE_DIR/data).  No iptables rules and no bridge are set up, so builds need
# `--network=host` and containers `--network=none`.  The classic builder is
# used (DOCKER_BUILDKIT=0).  Needs root and dockerd (Debian package docker.io).
#
# start prints the DOCKER_HOST value to use; stop kills the engine, waits for
# it, unmounts what it left mounted under STATE_DIR and DATA_DIR (the nsfs of
# its network namespaces, overlays) and removes the exec root.
set -eu
DOCKER=${DOCKER:-docker}

die() { echo "private-dockerd: $*" >&2; exit 1; }

# Unmount everything mounted under $1, deepest first.
umount_under() {
    awk -v d="$1/" 'index($5 "/", d) == 1 { print $5 }' /proc/self/mountinfo |
        sort -r | while read -r m; do umount -l "$m" 2>/dev/null || true; done
}

cmd=${1:-}; state=${2:-}
[ -n "$cmd" ] && [ -n "$state" ] || die "usage: $0 start STATE_DIR [DATA_DIR] | stop STATE_DIR"
case $state in /*) ;; *) state=$(pwd)/$state ;; esac

case $cmd in
start)
    data=${3:-$state/data}
    mkdir -p "$state" "$data"
    echo "$data" >"$state/data-root"
    sock="unix://$state/docker.sock"
    # setsid: the engine must not die with the caller's terminal or job group.
    setsid dockerd --data-root "$data" --exec-root "$state/exec" \
        --pidfile "$state/dockerd.pid" -H "$sock" \
        --iptables=false --ip-masq=false --bridge=none \
        >"$state/dockerd.log" 2>&1 </dev/null &
    i=0
    until $DOCKER -H "$sock" version >/dev/null 2>&1; do
        i=$((i + 1))
        if [ $i -gt 120 ] || ! kill -0 $! 2>/dev/null; then
            tail -n 20 "$state/dockerd.log" >&2
            die "dockerd did not come up (log: $state/dockerd.log)"
        fi
        sleep 0.5
    done
    echo "$sock"
    ;;
stop)
    pidf="$state/dockerd.pid"
    if [ -s "$pidf" ]; then
        pid=$(cat "$pidf")
        kill "$pid" 2>/dev/null || true
        i=0
        while kill -0 "$pid" 2>/dev/null; do
            i=$((i + 1))
            [ $i -gt 60 ] && { kill -9 "$pid" 2>/dev/null || true; }
            [ $i -gt 80 ] && die "dockerd $pid does not stop"
            sleep 0.5
        done
    fi
    umount_under "$state"
    [ -s "$state/data-root" ] && umount_under "$(cat "$state/data-root")"
    rm -rf "$state/exec" "$state/docker.sock" "$pidf"
    ;;
*)
    die "unknown command '$cmd' (start or stop)"
    ;;
esac
