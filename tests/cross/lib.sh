# lib.sh -- helpers sourced by the cross-build tests.
#
# Sourced by the cross-build tests (tests/cross/it_*.sh).
#
#   cross_refs DIR       compiles the test scene into DIR/scene.fbin and renders
#                        the reference slabs DIR/ref-json.pf and DIR/ref-fbin.pf
#                        with this machine's bin/franja-worker
#   cross_fakehosts      starts the coordinator tests' fake-host harness
#                        (tests/support/fakehosts.sh: fh_start, fr ...) in $FH
#                        and makes it the current directory
#
# The checks and the closing line are tests/support/lib.sh's (check, need, summary).
#
# Variables: ROOT (the repository), SLAB (worker arguments of the test slab),
# CROSS (state shared by the tests in one run: the Docker builds' dist/),
# FRANJA_CACHE (debootstrap roots and Docker images kept between runs),
# QEMU (qemu-aarch64-static).

ROOT=$(cd "$(dirname "$0")/../.." && pwd)
. "$ROOT/tests/support/lib.sh"
# A small slab keeps qemu quick: 20 rows of a 64x64 image at 4 samples.
SLAB="--rows 10:30 --spp 4 --size 64x64"
CROSS=${FRANJA_CROSS_DIR:-$ROOT/build/cross}
FRANJA_CACHE=${FRANJA_CACHE:-/var/cache/franja}
export FRANJA_CACHE
QEMU=${QEMU:-qemu-aarch64-static}

cross_refs() {
    d=$1
    check "franja compiles the test scene" \
        "$ROOT/bin/franja" compile "$ROOT/scenes/cornell.json" -o "$d/scene.fbin"
    check "reference slab from JSON" \
        "$ROOT/bin/franja-worker" --scene "$ROOT/scenes/cornell.json" $SLAB -o "$d/ref-json.pf"
    check "reference slab from the binary scene" \
        "$ROOT/bin/franja-worker" --scene "$d/scene.fbin" $SLAB -o "$d/ref-fbin.pf"
}

cross_fakehosts() {
    . "$ROOT/tests/support/fakehosts.sh"
    need "$QEMU" cmp
    fh_init
    cd "$FH" || exit 1
}

# True if the ELF file $1 has no program interpreter and no shared libraries.
is_static() {
    ! readelf -lW "$1" 2>/dev/null | grep -q 'INTERP' &&
        ! readelf -dW "$1" 2>/dev/null | grep -q '(NEEDED)' &&
        readelf -hW "$1" >/dev/null 2>&1
}

# True if the ELF file $1 is for machine $2 (as readelf -h names it).
is_machine() {
    readelf -hW "$1" 2>/dev/null | grep -q "Machine: *$2\$"
}
