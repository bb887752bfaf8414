#!/bin/sh
# it_20_docker.sh -- tests each Dockerfile builds and its binaries render alike.
#
# Every docker/Dockerfile.* is built by a real Docker engine (a private
# dockerd started here and stopped after; base images made by debootstrap when
# the engine lacks them), and what each build produces renders the test slab
# byte-identical to this machine's worker: the amd64 worker natively and the
# arm64 worker under qemu, each inside its own OS's image; the coordinator
# built there compiles the scene to the same binary scene.  The static workers
# run in the bare base images of the oldest and newest OS.  The builds are
# left in $CROSS/dist for the cluster test.
. "$(dirname "$0")/lib.sh"
need dockerd debootstrap flock readelf cmp "$QEMU"
if [ "$(id -u)" != 0 ]; then
    echo "FAIL: the Docker test needs root (dockerd, debootstrap)"
    echo "0 passed, 1 failed"
    exit 1
fi
# The client that comes with dockerd, whatever else is on PATH.
if [ -x /usr/bin/docker ]; then DOCKER=/usr/bin/docker; else DOCKER=docker; fi
export DOCKER DOCKER_BUILDKIT=0

# One run at a time per cache: the engine's data root lives there.
mkdir -p "$FRANJA_CACHE"
exec 9>"$FRANJA_CACHE/lock"
flock 9

T=$(mktemp -d /tmp/franja-docker.XXXXXX)
chmod 755 "$T"
ENGINE="$T/engine"
stop_engine() { sh "$ROOT/docker/private-dockerd.sh" stop "$ENGINE"; }
trap 'stop_engine; rm -rf "$T"' EXIT
DOCKER_HOST=$(sh "$ROOT/docker/private-dockerd.sh" start "$ENGINE" "$FRANJA_CACHE/engine-data")
check "private dockerd starts" test $? -eq 0
export DOCKER_HOST

cross_refs "$T"
# The first line of --version is what hosts must agree on (the second
# names the BVH walk, which differs between processors).
VERSION=$("$ROOT/bin/franja-worker" --version | head -n 1)

TARGETS=""
for f in "$ROOT"/docker/Dockerfile.*; do TARGETS="$TARGETS ${f##*/Dockerfile.}"; done
DIST="$CROSS/dist"
rm -rf "$DIST"
mkdir -p "$DIST"
start=$(date +%s)
sh "$ROOT/docker/build.sh" --bootstrap -j 3 -o "$DIST" $TARGETS
check "docker/build.sh builds every Dockerfile:$TARGETS" test $? -eq 0
echo "docker builds: $(($(date +%s) - start)) s"

# Run inside the image of each OS: its workers, the arm64 one through qemu
# (the image has the arm64 libc and libcjson as a foreign architecture), and
# its coordinator.
cat >"$T/in-image.sh" <<SH
cd /t
d=/dist/\$1
\$d-amd64/franja-worker --version >\$1-amd64.version
\$d-amd64/franja-worker --scene /scenes/cornell.json $SLAB -o \$1-amd64-json.pf
\$d-amd64/franja-worker --scene /t/scene.fbin $SLAB -o \$1-amd64-fbin.pf
qemu-aarch64-static \$d-arm64/franja-worker --version >\$1-arm64.version
qemu-aarch64-static \$d-arm64/franja-worker --scene /scenes/cornell.json $SLAB -o \$1-arm64-json.pf
qemu-aarch64-static \$d-arm64/franja-worker --scene /t/scene.fbin $SLAB -o \$1-arm64-fbin.pf
\$d-amd64/franja compile /scenes/cornell.json -o \$1.fbin
# The arm64 run-time libraries of this release, for qemu -L in the cluster test.
mkdir -p sysroot-\$1/lib/aarch64-linux-gnu
cp -L /lib/ld-linux-aarch64.so.1 sysroot-\$1/lib/
for f in /lib/aarch64-linux-gnu/*.so* /usr/lib/aarch64-linux-gnu/*.so*; do
    cp -L "\$f" sysroot-\$1/lib/aarch64-linux-gnu/
done
SH
run_in() {
    image=$1
    shift
    $DOCKER run --rm --network=none -v "$T:/t" -v "$DIST:/dist:ro" \
        -v "$ROOT/scenes:/scenes:ro" -v "$ROOT/bin/static:/static:ro" \
        -v "$(command -v "$QEMU"):/usr/local/bin/qemu-aarch64-static:ro" \
        "$image" "$@"
}
for t in $TARGETS; do
    check "$t: amd64 worker is x86-64" is_machine "$DIST/$t-amd64/franja-worker" "Advanced Micro Devices X86-64"
    check "$t: arm64 worker is AArch64" is_machine "$DIST/$t-arm64/franja-worker" AArch64
    check "$t: amd64 coordinator built" test -x "$DIST/$t-amd64/franja"
    run_in "franja-build:$t" sh -e /t/in-image.sh "$t" 2>"$T/$t.err"
    check "$t: workers and coordinator run in their image" test $? -eq 0
    sed "s/^/  $t: /" "$T/$t.err"
    for a in amd64 arm64; do
        check "$t-$a: version" test "$(head -n 1 "$T/$t-$a.version")" = "$VERSION"
        check "$t-$a: JSON slab is byte-identical" cmp "$T/$t-$a-json.pf" "$T/ref-json.pf"
        check "$t-$a: binary-scene slab is byte-identical" cmp "$T/$t-$a-fbin.pf" "$T/ref-fbin.pf"
    done
    check "$t: coordinator compiles the same binary scene" cmp "$T/$t.fbin" "$T/scene.fbin"
    rm -rf "$CROSS/sysroot-$t-arm64"
    mv "$T/sysroot-$t" "$CROSS/sysroot-$t-arm64"
done

# The static workers in the bare base images: nothing there but the OS.
for t in $TARGETS; do
    run_in "debian:$t" /static/amd64/franja-worker --scene /t/scene.fbin $SLAB -o /t/bare-$t-amd64.pf
    check "amd64 static worker in bare debian:$t is byte-identical" \
        cmp "$T/bare-$t-amd64.pf" "$T/ref-fbin.pf"
    run_in "debian:$t" qemu-aarch64-static /static/arm64/franja-worker \
        --scene /t/scene.fbin $SLAB -o /t/bare-$t-arm64.pf
    check "arm64 static worker in bare debian:$t is byte-identical" \
        cmp "$T/bare-$t-arm64.pf" "$T/ref-fbin.pf"
done

# Old layers of earlier runs would pile up in the cached data root.
$DOCKER container prune -f >/dev/null 2>&1
$DOCKER image prune -f >/dev/null 2>&1
DPID=$(cat "$ENGINE/dockerd.pid")
stop_engine
check "dockerd stopped" sh -c "! kill -0 $DPID 2>/dev/null"
unmounted() { ! awk '{print $5}' /proc/self/mountinfo | grep -q -e "^$1/"; }
check "nothing left mounted under the engine's state" unmounted "$ENGINE"
check "nothing left mounted under its data root" unmounted "$FRANJA_CACHE/engine-data"
summary
