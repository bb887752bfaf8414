#!/bin/sh
# it_10_static.sh -- tests the static amd64 and arm64 workers render alike.
#
# The fully static workers (make static): they need no shared library, the
# arm64 one runs under qemu-aarch64-static, and both render the test slab
# byte-identical to this machine's bin/franja-worker, and a bidirectional
# slab too (its rows and its light-tracing splats over the whole image),
# and a slab of instanced meshes (the fuzz seed tests/fuzz/corpus/fbin/
# instances.json: a rotation, a mirror, a non-uniform scale), and one of
# the same instances moving across a shutter, path traced and
# bidirectionally.
. "$(dirname "$0")/lib.sh"
need readelf cmp "$QEMU"
T=$(mktemp -d /tmp/franja-static.XXXXXX)
trap 'rm -rf "$T"' EXIT
S64="$ROOT/bin/static/amd64/franja-worker"
SA64="$ROOT/bin/static/arm64/franja-worker"
# The first line of --version is what hosts must agree on; the second
# names the BVH walk the processor runs, which differs between them.
VERSION=$("$ROOT/bin/franja-worker" --version | head -n 1)

# alike TAG SCENE WHAT OPTS...: the static amd64 worker, and the arm64 one
# under qemu, render SCENE with OPTS byte-identical to $T/TAG-ref.pf.
alike() {
    tag=$1 sc=$2 what=$3
    shift 3
    "$S64" --scene "$sc" "$@" -o "$T/$tag-s64.pf"
    check "amd64 static $what is byte-identical" cmp "$T/$tag-s64.pf" "$T/$tag-ref.pf"
    "$QEMU" "$SA64" --scene "$sc" "$@" -o "$T/$tag-sa64.pf"
    check "arm64 static $what under qemu is byte-identical" cmp "$T/$tag-sa64.pf" "$T/$tag-ref.pf"
}

cross_refs "$T"

check "amd64 static worker built" test -x "$S64"
check "amd64 static worker is x86-64" is_machine "$S64" "Advanced Micro Devices X86-64"
check "amd64 static worker is static" is_static "$S64"
check "amd64 static worker reports the same version" \
    test "$("$S64" --version | head -n 1)" = "$VERSION"
"$S64" --scene "$T/scene.fbin" $SLAB -o "$T/s64.pf"
check "amd64 static slab is byte-identical" cmp "$T/s64.pf" "$T/ref-fbin.pf"
"$S64" --scene "$T/scene.fbin" $SLAB -o - >"$T/s64-stdout.pf"
check "amd64 static slab on stdout is byte-identical" cmp "$T/s64-stdout.pf" "$T/ref-fbin.pf"

check "arm64 static worker built" test -x "$SA64"
check "arm64 static worker is AArch64" is_machine "$SA64" AArch64
check "arm64 static worker is static" is_static "$SA64"
# No -L: a static binary needs no arm64 libraries on this machine.
check "arm64 static worker reports the same version under qemu" \
    test "$("$QEMU" "$SA64" --version | head -n 1)" = "$VERSION"
"$QEMU" "$SA64" --scene "$T/scene.fbin" $SLAB -o "$T/sa64.pf"
check "arm64 static slab under qemu is byte-identical" cmp "$T/sa64.pf" "$T/ref-fbin.pf"
check "arm64 static worker validates the scene to the same hash" \
    test "$("$QEMU" "$SA64" --scene "$T/scene.fbin" --check)" = \
         "$("$ROOT/bin/franja-worker" --scene "$T/scene.fbin" --check)"

# Bidirectional: mirror, glass and Phong balls, rows and splats.
"$ROOT/bin/franja" compile "$ROOT/scenes/spheres.json" -o "$T/spheres.fbin" >/dev/null 2>&1
BD="--rows 10:14 --spp 2 --size 32x32 --integrator bdpt"
"$ROOT/bin/franja-worker" --scene "$T/spheres.fbin" $BD -o "$T/bd-ref.pf"
check "reference bidirectional slab carries splats" grep -q "splat=" "$T/bd-ref.pf"
alike bd "$T/spheres.fbin" "bidirectional slab" $BD

# Instances: the mesh walked in object space, normals back by the inverse.
"$ROOT/bin/franja" compile "$ROOT/tests/fuzz/corpus/fbin/instances.json" -o "$T/inst.fbin" >/dev/null 2>&1
IN="--rows 0:12 --spp 8 --size 32x24"
"$ROOT/bin/franja-worker" --scene "$T/inst.fbin" $IN -o "$T/in-ref.pf"
check "instanced scene renders" test -s "$T/in-ref.pf"
alike in "$T/inst.fbin" "instanced slab" $IN
# Moving instances (motion blur): the fuzz seed moving.json, two of the
# placements above sliding, turning and growing across the shutter.
MJ="$ROOT/tests/fuzz/corpus/fbin/moving.json"
"$ROOT/bin/franja" render "$MJ" --frames 1 --shutter 1 -o "$T/mv.#.pfm" --keep-job -j 1 >/dev/null 2>&1
MV="--rows 0:12 --spp 8 --size 32x24"
"$ROOT/bin/franja-worker" --scene "$T/mv.1.pfm.franja-job/scene.fbin" $MV -o "$T/mv-ref.pf"
"$ROOT/bin/franja" render "$MJ" --frames 1 -o "$T/st.#.pfm" --keep-job -j 1 >/dev/null 2>&1
"$ROOT/bin/franja-worker" --scene "$T/st.1.pfm.franja-job/scene.fbin" $MV -o "$T/st-ref.pf"
check "moving instances render, blurred" test -s "$T/mv-ref.pf" -a -s "$T/st-ref.pf"
check "the blurred slab is not the still one" sh -c "! cmp -s '$T/mv-ref.pf' '$T/st-ref.pf'"
alike mv "$T/mv.1.pfm.franja-job/scene.fbin" "slab of moving instances" $MV
# and bidirectionally (light subpaths and connections at each sample's time)
MB="$MV --integrator bdpt"
"$ROOT/bin/franja-worker" --scene "$T/mv.1.pfm.franja-job/scene.fbin" $MB -o "$T/mb-ref.pf"
alike mb "$T/mv.1.pfm.franja-job/scene.fbin" "bidirectional slab of moving instances" $MB
# Textures at their own precision and mip levels: 8-bit sRGB images read
# through the table and filtered across mip levels (the brick wall spans
# several texels a pixel at 64x64), and an HDR sky stored as halves.
for sc in cornell-textured sky-spheres; do
    "$ROOT/bin/franja" compile "$ROOT/scenes/$sc.json" -o "$T/$sc.fbin" >/dev/null 2>&1
    for integ in path bdpt; do
        TX="--rows 20:44 --spp 2 --size 64x64 --integrator $integ"
        "$ROOT/bin/franja-worker" --scene "$T/$sc.fbin" $TX -o "$T/$sc-$integ-ref.pf"
        "$QEMU" "$SA64" --scene "$T/$sc.fbin" $TX -o "$T/$sc-$integ-sa64.pf"
        check "arm64 static $sc slab ($integ) under qemu is byte-identical" \
            cmp "$T/$sc-$integ-sa64.pf" "$T/$sc-$integ-ref.pf"
    done
done

# Built without cJSON, the static worker refuses a JSON scene with a message
# instead of misreading it.
"$S64" --scene "$ROOT/scenes/cornell.json" $SLAB -o "$T/json.pf" 2>"$T/json.err"
check "static worker refuses a JSON scene" test $? -ne 0
check "and says so on stderr" test -s "$T/json.err"
check "and writes no image" test ! -s "$T/json.pf"

summary
