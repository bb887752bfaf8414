#!/bin/sh
# build.sh -- builds the Dockerfile.* images and copies out their binaries.
#
# build.sh [-o DIST] [-j N] [--bootstrap] [--own-engine] [TARGET...]
#
# Builds the docker/Dockerfile.TARGET images (TARGET: bullseye, bookworm,
# trixie; all of them by default) and copies their binaries to
# DIST/TARGET-amd64/ and DIST/TARGET-arm64/ (DIST defaults to dist).
#   -j N          build N images at once (default 1)
#   --bootstrap   make a missing base image debian:TARGET with debootstrap
#                 (docker/base-image.sh) instead of pulling it
#   --own-engine  run a private Docker engine for this build (as root, with
#                 dockerd installed but not running); implies --bootstrap.
#                 Its images stay under $FRANJA_CACHE/engine-data.
# Environment: DOCKER (client, default docker), FRANJA_CACHE.
# The build context sent to the engine holds only the sources it needs.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
DOCKER=${DOCKER:-docker}
DOCKER_BUILDKIT=${DOCKER_BUILDKIT:-0}
export DOCKER DOCKER_BUILDKIT
cache=${FRANJA_CACHE:-/var/cache/franja}

dist=dist jobs=1 bootstrap=0 own=0
while [ $# -gt 0 ]; do
    case $1 in
    -o) dist=$2; shift 2 ;;
    -j) jobs=$2; shift 2 ;;
    --bootstrap) bootstrap=1; shift ;;
    --own-engine) own=1; bootstrap=1; shift ;;
    -h|--help) sed -n '4,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "build.sh: unknown option '$1'" >&2; exit 2 ;;
    *) break ;;
    esac
done
if [ $# -eq 0 ]; then
    set --
    for f in "$here"/Dockerfile.*; do set -- "$@" "${f##*/Dockerfile.}"; done
fi
for t in "$@"; do
    [ -f "$here/Dockerfile.$t" ] || { echo "build.sh: no docker/Dockerfile.$t" >&2; exit 2; }
done
case $dist in /*) ;; *) dist=$(pwd)/$dist ;; esac

if [ $own = 1 ]; then
    # One engine at a time on the cached data root (the tests take this lock too).
    mkdir -p "$cache"
    exec 9>"$cache/lock"
    flock 9
    state=$(mktemp -d /tmp/franja-engine.XXXXXX)
    trap 'sh "$here/private-dockerd.sh" stop "$state"; rm -rf "$state"' EXIT
    DOCKER_HOST=$(sh "$here/private-dockerd.sh" start "$state" "$cache/engine-data")
    export DOCKER_HOST
fi

# build_one TARGET: image franja-build:TARGET, binaries into $dist; the log
# goes to $dist/TARGET.log.
build_one() {
    t=$1
    log="$dist/$t.log"
    if [ $bootstrap = 1 ]; then
        sh "$here/base-image.sh" "$t" >"$log" 2>&1 || { cat "$log" >&2; return 1; }
    fi
    if ! tar -C "$root" -cf - Makefile common worker coordinator docker |
            $DOCKER build --force-rm --network=host -f "docker/Dockerfile.$t" \
                -t "franja-build:$t" - >>"$log" 2>&1; then
        tail -n 30 "$log" >&2
        echo "build.sh: docker build of $t failed (log: $log)" >&2
        return 1
    fi
    tmp=$(mktemp -d "$dist/.$t.XXXXXX")
    id=$($DOCKER create "franja-build:$t")
    $DOCKER cp "$id:/out/." "$tmp/" && ok=1 || ok=0
    $DOCKER rm "$id" >/dev/null
    [ $ok = 1 ] || { rm -rf "$tmp"; return 1; }
    for arch in "$tmp"/*; do
        a=${arch##*/}
        rm -rf "$dist/$t-$a"
        mv "$arch" "$dist/$t-$a"
    done
    rm -rf "$tmp"
    echo "build.sh: $t -> $(cd "$dist" && ls -d "$t"-* | tr '\n' ' ')" >&2
}

mkdir -p "$dist"
fail=0 running=0 pids=""
for t in "$@"; do
    build_one "$t" &
    pids="$pids $!"
    running=$((running + 1))
    if [ $running -ge "$jobs" ]; then
        for p in $pids; do wait "$p" || fail=1; done
        pids="" running=0
    fi
done
for p in $pids; do wait "$p" || fail=1; done
exit $fail
