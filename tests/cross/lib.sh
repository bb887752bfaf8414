# lib.sh -- sourced by the cross-build tests (tests/cross/it_*.sh).
#
#   check DESC CMD...    counts a passed or failed check (prints failures)
#   need TOOL...         fails the whole test at once if a tool is missing
#   cross_summary        prints "N passed, N failed"; returns non-zero on failure
#   cross_refs DIR       compiles the test scene into DIR/scene.fbin and renders
#                        the reference slabs DIR/ref-json.pf and DIR/ref-fbin.pf
#                        with this machine's bin/franja-worker
#
# Variables: ROOT (the repository), SLAB (worker arguments of the test slab),
# CROSS (state shared by the tests in one run: the Docker builds' dist/),
# FRANJA_CACHE (debootstrap roots and Docker images kept between runs),
# QEMU (qemu-aarch64-static).

ROOT=$(cd "$(dirname "$0")/../.." && pwd)
# A small slab keeps qemu quick: 20 rows of a 64x64 image at 4 samples.
SLAB="--rows 10:30 --spp 4 --size 64x64"
CROSS=${FRANJA_CROSS_DIR:-$ROOT/build/cross}
FRANJA_CACHE=${FRANJA_CACHE:-/var/cache/franja}
export FRANJA_CACHE
QEMU=${QEMU:-qemu-aarch64-static}
PASSED=0
FAILED=0

check() {
    desc=$1
    shift
    if "$@"; then
        PASSED=$((PASSED + 1))
    else
        FAILED=$((FAILED + 1))
        echo "FAIL: $desc"
    fi
}

need() {
    for tool in "$@"; do
        if ! command -v "$tool" >/dev/null 2>&1; then
            echo "FAIL: $tool is missing (run tests/install-deps.sh)"
            echo "$PASSED passed, $((FAILED + 1)) failed"
            exit 1
        fi
    done
}

cross_summary() {
    echo "$PASSED passed, $FAILED failed"
    [ "$FAILED" -eq 0 ]
}

cross_refs() {
    d=$1
    check "franja compiles the test scene" \
        "$ROOT/bin/franja" compile "$ROOT/scenes/cornell.json" -o "$d/scene.fbin"
    check "reference slab from JSON" \
        "$ROOT/bin/franja-worker" --scene "$ROOT/scenes/cornell.json" $SLAB -o "$d/ref-json.pf"
    check "reference slab from the binary scene" \
        "$ROOT/bin/franja-worker" --scene "$d/scene.fbin" $SLAB -o "$d/ref-fbin.pf"
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
