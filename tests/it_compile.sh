#!/bin/sh
# it_compile.sh -- tests franja compile end to end.
#
# franja compile end to end: a compiled scene renders the same bytes as the
# JSON it came from, compiling is deterministic, meshes (OBJ/MTL, Assimp
# formats, transforms, levels of detail) arrive, and bad input of every
# kind is refused with a message that says where.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
F=bin/franja W=bin/franja-worker G=bin/gen/genmesh
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# triangles SCENE.json: the triangle count franja compile reports.
triangles() {
    $F compile "$1" -o "$T/count.fbin" | sed -n 's/.*primitives (\([0-9]*\) triangles).*/\1/p'
}

# --- the command line ---
$F compile --help | grep -q 'franja compile SCENE' && ok || bad "compile --help"
expect_error "no scene" "usage: franja compile" $F compile
expect_error "unknown option" "unknown option '--fast'" $F compile --fast scenes/cornell.json
expect_error "two scenes" "one scene at a time" $F compile scenes/cornell.json scenes/spheres.json
cp scenes/cornell.json "$T/box.json"
# Without -o: SCENE.fbin in the current directory, not beside the scene.
mkdir "$T/here"
(R=$(pwd) && cd "$T/here" && "$R/$F" compile "$T/box.json" >/dev/null) && [ -s "$T/here/box.fbin" ] && [ ! -e "$T/box.fbin" ] && ok ||
    bad "default output name (.json -> .fbin in the current directory)"

# A device or a named pipe is written in place, never replaced (as root a
# rename would turn /dev/null into a plain file), the compile runs in the
# current directory instead of beside it, and the summary goes to stderr.
$F compile "$T/box.json" -o "$T/ref.fbin" >/dev/null
mkfifo "$T/pipe"
timeout 30 cat "$T/pipe" >"$T/piped.fbin" &
(R=$(pwd) && cd "$T/here" && "$R/$F" compile "$T/box.json" -o "$T/pipe" >"$T/pipe.out" 2>"$T/pipe.err")
wait
[ -p "$T/pipe" ] && cmp -s "$T/piped.fbin" "$T/ref.fbin" && ok || bad "-o FIFO: the scene written into the pipe, which stays one"
[ ! -s "$T/pipe.out" ] && grep -q "pipe: scene " "$T/pipe.err" && ok || bad "-o FIFO: the summary on stderr, not with the scene"
[ -z "$(ls -A "$T" | grep compile-)" ] && [ -z "$(ls -A "$T/here" | grep compile-)" ] && ok ||
    bad "-o FIFO: the compile's private directory left behind"
$F compile "$T/box.json" -o /dev/stdout 2>/dev/null | cmp -s - "$T/ref.fbin" && ok || bad "-o /dev/stdout: the scene alone"
if $F compile "$T/box.json" -o /dev/null 2>/dev/null && [ -c /dev/null ]; then
    ok
else
    bad "-o /dev/null: /dev/null is still a device"
    [ -c /dev/null ] || { rm -f /dev/null && mknod -m 666 /dev/null c 1 3; } # for the tests after this one
fi

# --- compiled scenes render the bytes their JSON renders ---
for s in scenes/*.json; do
    # (meshes and image textures need the compiler: the worker refuses that JSON)
    grep -q -e '"mesh"' -e '"type": "image"' "$s" && continue
    n=$(basename "$s" .json)
    out=$($F compile "$s" -o "$T/$n.fbin") || { bad "$n: compile failed"; continue; }
    hash=$(echo "$out" | sed -n 's/.*: scene \([0-9a-f]\{16\}\), .*/\1/p')
    [ "$($W --scene "$T/$n.fbin" --check)" = "$hash" ] && ok || bad "$n: worker --check differs from compile's hash"
    [ "$($W --scene "$s" --check)" = "$hash" ] && ok || bad "$n: the JSON's hash differs from the compiled one"
    $W --scene "$T/$n.fbin" --size 48x32 --spp 2 --rows 0:32 -o "$T/$n-bin.pf" &&
        $W --scene "$s" --size 48x32 --spp 2 --rows 0:32 -o "$T/$n-json.pf" &&
        cmp -s "$T/$n-bin.pf" "$T/$n-json.pf" && ok || bad "$n: .fbin and .json render different bytes"
done

# --- the mesh scene: deterministic, renders, refused by the worker as JSON ---
$F compile scenes/knot.json -o "$T/k1.fbin" >/dev/null && $F compile scenes/knot.json -o "$T/k2.fbin" >/dev/null &&
    cmp -s "$T/k1.fbin" "$T/k2.fbin" && ok || bad "knot.json: two compiles differ"
$W --scene "$T/k1.fbin" --size 40x25 --spp 1 --rows 10:14 -o "$T/k.pf" && ok || bad "knot.fbin does not render"
expect_error "JSON mesh scene in the worker" "franja compile" $W --scene scenes/knot.json --rows 0:1 -o "$T/x"

# --- meshes: OBJ + MTL, placement, formats ---
mkdir -p "$T/m"
cat >"$T/m/quad.obj" <<'EOF'
mtllib quad.mtl
v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
vn 0 1 0
usemtl lamp
f 1//1 2//1 3//1 4//1
EOF
cat >"$T/m/quad.mtl" <<'EOF'
newmtl lamp
Ke 5 5 5
EOF
scene() { # scene FILE SHAPE-JSON [PIXELS]: a square image, a camera, a grey material and SHAPE
    cat >"$1" <<EOF
{"image": {"width": ${3:-32}, "height": ${3:-32}, "spp": 1},
 "camera": {"position": [0, 3, -6], "target": [0, 0, 0], "fov": 40},
 "materials": {"grey": {"type": "lambert", "albedo": [0.5, 0.5, 0.5]}},
 "lights": [{"type": "point", "position": [0, 5, 0], "intensity": [10, 10, 10]}],
 "shapes": [$2]}
EOF
}
scene "$T/m/a.json" '{"type": "mesh", "file": "quad.obj"}'
out=$($F compile "$T/m/a.json" -o "$T/a.fbin") && echo "$out" | grep -q '2 primitives (2 triangles), 2 materials, 3 lights' &&
    ok || bad "OBJ quad with an emissive MTL material: $out"
scene "$T/m/b.json" '{"type": "mesh", "file": "quad.obj", "material": "grey", "scale": [2, 1, -1], "rotate": [0, 45, 0], "translate": [0, 1, 0]}'
out=$($F compile "$T/m/b.json" -o "$T/b.fbin") && echo "$out" | grep -q '2 triangles), 1 materials, 1 lights' &&
    ok || bad "material override with a mirroring transform: $out"
# a mesh placed three times: the summary counts the placements
scene "$T/m/i.json" '{"type": "mesh", "file": "quad.obj", "material": "grey", "instances": [{"translate": [0, 1, 0]}, {"translate": [2, 1, 0]}, {"translate": [4, 1, 0]}]}'
out=$($F compile "$T/m/i.json" -o "$T/i.fbin") && echo "$out" | grep -q '(2 triangles), 3 instances of 1 meshes, 1 materials' &&
    ok || bad "instances in the summary: $out"
scene "$T/m/c.json" '{"type": "mesh", "file": "quad.obj", "matrix": [0,0,1,2, 0,1,0,0, -1,0,0,0, 0,0,0,1]}'
$F compile "$T/m/c.json" -o "$T/c.fbin" >/dev/null && ok || bad "matrix transform"
printf 'solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n' >"$T/m/t.stl"
scene "$T/m/d.json" '{"type": "mesh", "file": "t.stl", "material": "grey"}'
[ "$(triangles "$T/m/d.json")" = 1 ] && ok || bad "STL through Assimp"
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n' >"$T/m/q.ply"
scene "$T/m/e.json" '{"type": "mesh", "file": "q.ply", "material": "grey"}'
[ "$(triangles "$T/m/e.json")" = 2 ] && ok || bad "PLY quad through Assimp"

# --- level of detail: near picks the finest level, far the coarsest ---
# In a 1024-pixel image the sphere (bounding radius 1.8) covers about
# pi (2532 / distance)^2 pixels; a quarter triangle per pixel is wanted.
$G sphere --tris 8000 --no-uv -o "$T/m/s0.obj" && $G sphere --tris 2000 --no-uv -o "$T/m/s1.obj" &&
    $G sphere --tris 200 --no-uv -o "$T/m/s2.obj" || bad "genmesh"
for k in 0 1 2; do
    scene "$T/m/l.json" "{\"type\": \"mesh\", \"file\": \"s$k.obj\", \"material\": \"grey\"}"
    eval "n$k=$(triangles "$T/m/l.json")"
done
[ "$n2" -lt "$n1" ] && [ "$n1" -lt "$n0" ] && ok || bad "levels of decreasing detail: $n0 $n1 $n2"
for case in "0 0 0:s0" "0 0 100:s1" "0 0 400:s2"; do
    at=${case%%:*} want=${case##*:}
    scene "$T/m/l.json" "{\"type\": \"mesh\", \"lod\": [\"s0.obj\", \"s1.obj\", \"s2.obj\"], \"material\": \"grey\", \"translate\": [$(echo "$at" | tr ' ' ',')]}" 1024
    got=$(triangles "$T/m/l.json")
    case $want in s0) exp=$n0 ;; s1) exp=$n1 ;; *) exp=$n2 ;; esac
    [ "$got" = "$exp" ] && ok || bad "lod at $at: $got triangles, expected $exp ($want)"
done
scene "$T/m/l.json" '{"type": "mesh", "lod": ["s0.obj", "s1.obj", "s2.obj"], "material": "grey", "translate": [0, 0, 100], "lod_density": 8}' 1024
got=$(triangles "$T/m/l.json")
[ "$got" = "$n0" ] && ok || bad "a higher lod_density picks a finer level: $got, expected $n0"

# --- errors name the place ---
scene "$T/m/f.json" '{"type": "mesh", "file": "nothing.obj", "material": "grey"}'
expect_error "missing mesh file" "nothing.obj: No such file" $F compile "$T/m/f.json" -o "$T/x.fbin"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n' >"$T/m/bad.obj"
scene "$T/m/g.json" '{"type": "mesh", "file": "bad.obj", "material": "grey"}'
expect_error "bad OBJ index" "bad.obj:4: vertex index 7 out of range" $F compile "$T/m/g.json" -o "$T/x.fbin"
scene "$T/m/h.json" '{"type": "mesh", "file": "quad.obj", "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "scale": 2}'
expect_error "matrix and scale" "shapes[0].matrix: give either matrix or scale/rotate/translate" $F compile "$T/m/h.json" -o "$T/x.fbin"
scene "$T/m/i.json" '{"type": "mesh", "file": "quad.obj", "sclae": 2}'
expect_error "unknown field" "shapes[0].sclae: unknown field" $F compile "$T/m/i.json" -o "$T/x.fbin"
scene "$T/m/j.json" '{"type": "mesh", "file": "quad.obj", "scale": [1, 0, 1]}'
expect_error "singular transform" "shapes[0]: the transform is singular" $F compile "$T/m/j.json" -o "$T/x.fbin"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl ghost\nf 1 2 3\n' >"$T/m/ghost.obj"
scene "$T/m/k.json" '{"type": "mesh", "file": "ghost.obj"}'
# A name no MTL file defines: the default material, with a warning (as in Blender).
$F compile "$T/m/k.json" -o "$T/x.fbin" >/dev/null 2>"$T/err" &&
    grep -q "warning: .*ghost.obj:4: usemtl: 1 material name defined in no mtllib file" "$T/err" && ok ||
    bad "undefined usemtl: $(cat "$T/err")"
scene "$T/m/n.json" '{"type": "mesh", "file": "quad.obj", "lod": ["quad.obj"]}'
expect_error "file and lod" "give exactly one of file" $F compile "$T/m/n.json" -o "$T/x.fbin"
printf 'not a mesh\n' >"$T/m/junk.ply"
scene "$T/m/o.json" '{"type": "mesh", "file": "junk.ply", "material": "grey"}'
expect_error "Assimp error" "junk.ply" $F compile "$T/m/o.json" -o "$T/x.fbin"
expect_error "output in a missing directory" "$T/no/dir/x.fbin" $F compile scenes/cornell.json -o "$T/no/dir/x.fbin"

# --- damaged binary scenes: the worker says what is wrong, and where ---
size=$(wc -c <"$T/cornell.fbin")
head -c $((size - 64)) "$T/cornell.fbin" >"$T/cut.fbin"
expect_error "truncated file" "truncated" $W --scene "$T/cut.fbin" --rows 0:1 -o "$T/x"
cp "$T/cornell.fbin" "$T/flip.fbin"
printf 'X' | dd of="$T/flip.fbin" bs=1 seek=$((size - 100)) conv=notrunc 2>/dev/null
expect_error "corrupt file" "byte 32: content hash mismatch" $W --scene "$T/flip.fbin" --rows 0:1 -o "$T/x"
# A version no build has had (126), not the next one: the test outlives version bumps.
cp "$T/cornell.fbin" "$T/ver.fbin"
printf '\176' | dd of="$T/ver.fbin" bs=1 seek=8 conv=notrunc 2>/dev/null
expect_error "other format version" "byte 8: scene format version 126" $W --scene "$T/ver.fbin" --rows 0:1 -o "$T/x"

summary
