#!/bin/sh
# it_gltf.sh -- tests glTF 2.0 scenes end to end.
#
# glTF 2.0 scenes end to end: files written by tests/gen/gengltf compile
# and render; the same triangles as glTF and as JSON give the same binary
# scene and image; node transforms, camera framing (yfov, aspectRatio) and
# UV orientation land on known pixels; the metallicRoughness texture's
# channels reach the right pixels; models of Debian's assimp-testmodels
# compile and render; malformed files are refused with a message naming the
# file and the JSON pointer or byte offset.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need oiiotool cmp
F=bin/franja W=bin/franja-worker G=bin/gen/gengltf P=bin/tools/pfmpix
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# hash FILE.fbin-compile-output: the scene hash franja compile printed.
hash_of() { sed -n 's/.*: scene \([0-9a-f]*\),.*/\1/p' "$1"; }

# near VALUE WANT: |VALUE - WANT| <= 0.02 (pixels of emissive squares).
near() { awk -v a="$1" -v b="$2" 'BEGIN { d = a - b; exit !(d <= 0.02 && d >= -0.02) }'; }

# pixel_is IMAGE X Y R G B: the pixel's colour, within 0.02.
pixel_is() {
    set -- "$@" $($P "$1" "$2" "$3")
    if near "$7" "$4" && near "$8" "$5" && near "$9" "$6"; then ok; else
        bad "$1 pixel ($2, $3) is ($7 $8 $9), expected ($4 $5 $6)"; fi
}

# --- the same scene as glTF (.gltf with a data: URI, .glb) and as JSON ---
$G scene "$T" || bad "gengltf scene"
$F compile "$T/scene.gltf" -o "$T/a.fbin" >"$T/a.out" 2>"$T/a.err" || bad "scene.gltf: $(cat "$T/a.err")"
$F compile "$T/scene.glb" -o "$T/b.fbin" >"$T/b.out" 2>&1 || bad "scene.glb: $(cat "$T/b.out")"
$F compile "$T/scene.json" -o "$T/c.fbin" >"$T/c.out" 2>&1 || bad "scene.json: $(cat "$T/c.out")"
[ -n "$(hash_of "$T/a.out")" ] && ok || bad "no scene hash in: $(cat "$T/a.out")"
[ "$(hash_of "$T/a.out")" = "$(hash_of "$T/b.out")" ] && ok || bad ".gltf and .glb compile to different scenes"
[ "$(hash_of "$T/a.out")" = "$(hash_of "$T/c.out")" ] && ok ||
    bad "the glTF scene and its JSON twin compile to different scenes"
[ ! -s "$T/a.err" ] && ok || bad "warnings for a scene with nothing unsupported: $(cat "$T/a.err")"
for s in a c; do
    $W --scene "$T/$s.fbin" --rows 0:48 --size 64x48 --spp 4 -o "$T/$s.pfm" || bad "render $s"
done
cmp -s "$T/a.pfm" "$T/c.pfm" && ok || bad "glTF and JSON renders differ"
# the lit scene is not black: the floor in front of the prism is lit
v=$($P "$T/a.pfm" 32 44 | awk '{ print ($1 > 0.01) }')
[ "$v" = 1 ] && ok || bad "the glTF scene renders black at the floor"

# franja render takes a .gltf directly (compiled into the job directory)
$F render "$T/scene.gltf" -o "$T/r.pfm" --size 64x48 --spp 4 -j 2 >/dev/null 2>"$T/r.err" || bad "render: $(cat "$T/r.err")"
cmp -s "$T/r.pfm" "$T/a.pfm" && ok || bad "franja render of the .gltf differs from the worker's render"
$F render "$T/scene.glb" -o "$T/r.png" --size 32x24 --spp 1 -j 1 >/dev/null 2>&1 && [ -s "$T/r.png" ] && ok ||
    bad "render .glb to png"

# --- camera framing: tan(yfov/2) = 0.5, aspectRatio 2 -> 640x320; an
# emissive square 1 wide at distance 2 covers the middle half of the rows
# and the middle quarter of the columns ---
$G frame "$T" && $F compile "$T/frame.gltf" -o "$T/frame.fbin" >/dev/null || bad "frame.gltf"
$W --scene "$T/frame.fbin" --rows 0:1 --spp 1 -o "$T/one.pfm" &&
    grep -a -q 'size=640x320' "$T/one.pfm" && ok || bad "aspectRatio 2 does not give 640x320"
$W --scene "$T/frame.fbin" --rows 0:32 --size 64x32 --spp 4 -o "$T/frame.pfm" || bad "render frame"
for xy in "25 16" "38 16" "32 9" "32 22"; do pixel_is "$T/frame.pfm" $xy 1 1 1; done
for xy in "22 16" "41 16" "32 6" "32 25"; do pixel_is "$T/frame.pfm" $xy 0 0 0; done

# --- node transforms: TRS parent (rotation 90 degrees about y, scale 2),
# matrix child; a mirrored node still faces the camera ---
$G nodes "$T" && $F compile "$T/nodes.gltf" -o "$T/nodes.fbin" >/dev/null || bad "nodes.gltf"
$W --scene "$T/nodes.fbin" --rows 0:64 --size 64x64 --spp 4 -o "$T/nodes.pfm" || bad "render nodes"
for xy in "34 32" "58 32" "46 20" "46 44" "10 32" "14 32"; do pixel_is "$T/nodes.pfm" $xy 1 1 1; done
for xy in "29 32" "62 32" "46 15" "46 49" "2 32" "19 32"; do pixel_is "$T/nodes.pfm" $xy 0 0 0; done

# --- UV orientation: a texture whose corners differ, seen as glTF means it
# (UV origin at the image's top-left), embedded as a data: URI and in a .glb
# bufferView; KHR_texture_transform picks the top-right texel ---
printf 'P6\n2 2\n255\n\377\0\0\0\377\0\0\0\377\377\377\377' >"$T/corners.ppm"
oiiotool "$T/corners.ppm" -o "$T/corners.png" || bad "oiiotool"
$G uv "$T" "$T/corners.png" || bad "gengltf uv"
for s in uv.gltf uv.glb; do
    $F compile "$T/$s" -o "$T/$s.fbin" >/dev/null && $W --scene "$T/$s.fbin" --rows 0:32 --size 32x32 --spp 1 \
        -o "$T/$s.pfm" || { bad "$s"; continue; }
    pixel_is "$T/$s.pfm" 8 8 1 0 0
    pixel_is "$T/$s.pfm" 24 8 0 1 0
    pixel_is "$T/$s.pfm" 8 24 0 0 1
    pixel_is "$T/$s.pfm" 24 24 1 1 1
done
$F compile "$T/uvxf.gltf" -o "$T/uvxf.fbin" >/dev/null &&
    $W --scene "$T/uvxf.fbin" --rows 0:32 --size 32x32 --spp 1 -o "$T/uvxf.pfm" || bad "uvxf.gltf"
for xy in "8 8" "24 8" "8 24" "24 24"; do pixel_is "$T/uvxf.pfm" $xy 0 1 0; done
# The same image as a metallicRoughnessTexture (G roughness, B metallic) of a
# white material under a point light: the smooth dielectric (red texel) and
# the rough one (green) show their diffuse base, the smooth metal (blue)
# reflects the light away from the camera (black), the rough metal (white)
# glints.  Metallic read from another channel, or the texture ignored,
# turns a quadrant the other way.
# value IMAGE X Y: the pixel's mean channel.
value() { $P "$1" "$2" "$3" | awk '{ print ($1 + $2 + $3) / 3 }'; }
above() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a > b) }'; }
$F compile "$T/mr.gltf" -o "$T/mr.fbin" >/dev/null 2>"$T/mr.err" &&
    $W --scene "$T/mr.fbin" --rows 0:32 --size 32x32 --spp 16 -o "$T/mr.pfm" || bad "mr.gltf: $(cat "$T/mr.err")"
tl=$(value "$T/mr.pfm" 8 8) tr=$(value "$T/mr.pfm" 24 8) bl=$(value "$T/mr.pfm" 8 24) br=$(value "$T/mr.pfm" 24 24)
check "smooth dielectric texel lit ($tl)" above "$tl" 0.1
check "rough dielectric texel lit ($tr)" above "$tr" 0.1
check "smooth metal texel black ($bl)" above 0.005 "$bl"
check "rough metal texel glints ($br), less than the diffuse ($tr)" above "$br" 0.01
check "rough metal texel ($br) below the rough dielectric ($tr)" above "$tr" "$br"

# --- a glTF file as a shape of a JSON scene ---
cat >"$T/inc.json" <<EOF
{"image": {"width": 640, "height": 480, "spp": 64, "max_depth": 8},
 "camera": {"position": [0, 1, 4], "target": [0, 1, 3], "up": [0, 1, 0], "fov": 40},
 "materials": {}, "shapes": [{"type": "gltf", "file": "scene.gltf"}]}
EOF
$F compile "$T/inc.json" -o "$T/inc.fbin" >"$T/inc.out" 2>&1 || bad "inc.json: $(cat "$T/inc.out")"
[ "$(hash_of "$T/inc.out")" = "$(hash_of "$T/a.out")" ] && ok ||
    bad "a JSON scene holding scene.gltf with the same camera differs from scene.gltf"
# the file's camera through the JSON scene
cat >"$T/incam.json" <<EOF
{"image": {"width": 64, "height": 32}, "materials": {},
 "shapes": [{"type": "gltf", "file": "frame.gltf", "camera": true}]}
EOF
$F compile "$T/incam.json" -o "$T/incam.fbin" >/dev/null 2>"$T/err" || bad "incam.json: $(cat "$T/err")"
$W --scene "$T/incam.fbin" --rows 0:32 --size 64x32 --spp 4 -o "$T/incam.pfm" &&
    [ "$(tail -c 24576 "$T/incam.pfm" | cksum)" = "$(tail -c 24576 "$T/frame.pfm" | cksum)" ] && ok || bad "the glTF camera taken through JSON frames differently"
# the shape's transform places the file
cat >"$T/move.json" <<EOF
{"image": {"width": 64, "height": 32}, "materials": {},
 "camera": {"position": [0, 0, 0], "target": [0, 0, -1], "fov": 53.1301024},
 "shapes": [{"type": "gltf", "file": "frame.gltf", "translate": [0.5, 0, 0], "rotate": [0, 0, 90]}]}
EOF
$F compile "$T/move.json" -o "$T/move.fbin" >/dev/null 2>"$T/err" || bad "move.json: $(cat "$T/err")"
$W --scene "$T/move.fbin" --rows 0:32 --size 64x32 --spp 4 -o "$T/move.pfm" || bad "render move.json"
# the square, turned a quarter about z (no change) and moved 0.5 right: columns 32 to 48
for xy in "34 16" "46 16"; do pixel_is "$T/move.pfm" $xy 1 1 1; done
for xy in "28 16" "50 16"; do pixel_is "$T/move.pfm" $xy 0 0 0; done
sed 's/"camera": true/"camera": true, "translate": [0, 0, -2]/; s/"height": 32}/"height": 32}, "camera": {"position": [0, 0, 0], "target": [0, 0, -1], "fov": 50}/' \
    "$T/incam.json" >"$T/twocams.json"
expect_error "two cameras" "shapes[0].camera: the scene has a camera of its own" $F compile "$T/twocams.json" -o "$T/x.fbin"
expect_error "worker and a gltf shape" "shapes[0]: glTF files need the scene compiler" \
    $W --scene "$T/incam.json" --rows 0:1 -o "$T/x.pfm"
sed 's/frame.gltf/nothere.gltf/' "$T/incam.json" >"$T/nofile.json"
expect_error "missing glTF file" "shapes[0].camera: $T/nothere.gltf: No such file" $F compile "$T/nofile.json" -o "$T/x.fbin"
sed 's/"camera": true/"camera": true, "scale": 0/' "$T/incam.json" >"$T/zero.json"
expect_error "singular placement" "shapes[0]: the transform is singular" $F compile "$T/zero.json" -o "$T/x.fbin"
sed 's/"camera": true/"camera": true, "lod": 2/' "$T/incam.json" >"$T/field.json"
expect_error "unknown field" "shapes[0].lod: unknown field" $F compile "$T/field.json" -o "$T/x.fbin"

# --- --camera NAME ---
M=/usr/share/assimp/models/glTF2
if [ -d $M ]; then
    $F compile $M/cameras/Cameras.gltf -o "$T/cam.fbin" >/dev/null 2>&1 && ok || bad "Cameras.gltf"
    expect_error "unknown camera" "no perspective camera named 'nope'" $F compile --camera nope \
        $M/cameras/Cameras.gltf -o "$T/cam.fbin"
else
    bad "assimp-testmodels is not installed (tests/install-deps.sh)"
fi
expect_error "camera for JSON" "--camera names a camera of a glTF scene" $F compile --camera x "$T/scene.json"
$F compile --camera lens0 "$T/scene.gltf" -o "$T/cam2.fbin" >"$T/cam2.out" &&
    [ "$(hash_of "$T/cam2.out")" = "$(hash_of "$T/a.out")" ] && ok || bad "--camera lens0 (a camera's name)"
$F compile --camera cam "$T/scene.gltf" -o "$T/cam3.fbin" >/dev/null && ok || bad "--camera cam (a node's name)"

# --- models from Debian's assimp-testmodels compile and render ---
for m in BoxTextured-glTF-Binary/BoxTextured.glb BoxTextured-glTF-Embedded/BoxTextured.gltf \
    BoxTextured-glTF/BoxTextured.gltf 2CylinderEngine-glTF-Binary/2CylinderEngine.glb \
    textureTransform/TextureTransformTest.gltf glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_05.gltf \
    glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_06.gltf simple_skin/simple_skin.gltf \
    glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf; do
    [ -f "$M/$m" ] || { bad "$m is missing"; continue; }
    if $F render "$M/$m" -o "$T/m.pfm" --size 48x36 --spp 1 -j 1 >/dev/null 2>"$T/m.err"; then
        # something was drawn: some pixel is not black
        $P "$T/m.pfm" 24 18 12 9 36 9 12 27 36 27 24 9 24 27 | awk '$1 + $2 + $3 > 0 { f = 1 } END { exit !f }' &&
            ok || bad "$m renders black"
    else
        bad "$m: $(cat "$T/m.err")"
    fi
done
# unsupported features are named, once each
$F compile $M/simple_skin/simple_skin.gltf -o "$T/s.fbin" >/dev/null 2>"$T/s.err" && ok || bad "simple_skin.gltf"
grep -q 'skinning' "$T/s.err" && bad "skin warning: $(cat "$T/s.err")" || ok
$F compile $M/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf -o "$T/s.fbin" >/dev/null 2>"$T/s.err"
grep -q '/animations: not played' "$T/s.err" && ok || bad "animation warning: $(cat "$T/s.err")"
[ "$(grep -c 'animations' "$T/s.err")" = 1 ] && ok || bad "the animation warning is repeated"
$F compile $M/textureTransform/TextureTransformTest.gltf -o "$T/s.fbin" >/dev/null 2>"$T/s.err"
! grep -q 'rotation' "$T/s.err" && ok || bad "TextureTransformTest: its rotations are not all applied: $(cat "$T/s.err")"

# malformed models of that package: refused with where
expect_error "index out of range" "/meshes/0/primitives/0: indices: accessor 0 element 0 is 255, not below the vertex count 24" \
    $F compile $M/IndexOutOfRange/IndexOutOfRange.gltf -o "$T/x.fbin"
expect_error "recursive nodes" "/scenes/0/nodes: node 0 is the child of node 1" \
    $F compile $M/RecursiveNodes/RecursiveNodes.gltf -o "$T/x.fbin"
expect_error "missing .bin" "/buffers/0: /usr/share/assimp/models/glTF2/MissingBin/BoxTextured0.bin: No such file" $F compile $M/MissingBin/BoxTextured.gltf -o "$T/x.fbin"
expect_error "bad index type" "/materials/0/pbrMetallicRoughness/baseColorTexture: index: -1 is not an index into textures (the file has 1)" \
    $F compile $M/wrongTypes/badUint.gltf -o "$T/x.fbin"
expect_error "required extension" "requires extension KHR_draco_mesh_compression" \
    $F compile $M/draco/2CylinderEngine.gltf -o "$T/x.fbin"
expect_error "infinite positions" "POSITION: accessor 2 element 0 is not finite" \
    $F compile $M/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb -o "$T/x.fbin"

# --- malformed files of our own ---
size=$(wc -c <"$T/scene.glb")
head -c $((size / 2)) "$T/scene.glb" >"$T/trunc.glb"
expect_error "truncated .glb" "trunc.glb: truncated .glb: the header says $size bytes, the file has $((size / 2))" \
    $F compile "$T/trunc.glb" -o "$T/x.fbin"
head -c 10 "$T/scene.glb" >"$T/tiny.glb"
expect_error "a .glb of 10 bytes" "truncated .glb: 10 bytes" $F compile "$T/tiny.glb" -o "$T/x.fbin"
sed 's/"POSITION":0/"POSITION":99/' "$T/scene.gltf" >"$T/badacc.gltf"
expect_error "bad accessor index" \
    "badacc.gltf: /meshes/0/primitives/0/attributes: POSITION: 99 is not an index into accessors (the file has 3)" \
    $F compile "$T/badacc.gltf" -o "$T/x.fbin"
sed 's/"byteOffset":0,"byteLength":72}/"byteOffset":0,"byteLength":7200}/' "$T/scene.gltf" >"$T/badview.gltf"
expect_error "bufferView out of range" "badview.gltf: /bufferViews/0: bytes 0 to 7200 lie outside buffer 0" \
    $F compile "$T/badview.gltf" -o "$T/x.fbin"
sed 's/"componentType":5126,"count":6/"componentType":5126,"count":600/' "$T/scene.gltf" >"$T/badcount.gltf"
expect_error "accessor past its view" "/accessors/0: 600 elements from byte 0 need 7200 bytes; bufferView 0 has 72" \
    $F compile "$T/badcount.gltf" -o "$T/x.fbin"
sed 's/"version":"2.0"/"version":"1.0"/' "$T/scene.gltf" >"$T/v1.gltf"
expect_error "glTF 1" "/asset/version: '1.0': only glTF 2.x is supported" $F compile "$T/v1.gltf" -o "$T/x.fbin"
printf '{"asset":{"version":"2.0"},\n"nodes":[{]}' >"$T/syntax.gltf"
expect_error "invalid JSON" "syntax.gltf: line 2: invalid JSON" $F compile "$T/syntax.gltf" -o "$T/x.fbin"
sed 's/"children"/"kids"/; s/"nodes":\[0,1,2,3,4\]/"nodes":[0,1,2,3,4,4]/' "$T/scene.gltf" >"$T/twice.gltf"
expect_error "root listed twice" "/scenes/0/nodes: node 4 is listed twice" $F compile "$T/twice.gltf" -o "$T/x.fbin"
sed 's/base64,/base64,@@/' "$T/scene.gltf" >"$T/b64.gltf"
expect_error "bad base64" "/buffers/0: uri: data: URI: byte 0 of the payload is not base64" \
    $F compile "$T/b64.gltf" -o "$T/x.fbin"
summary
