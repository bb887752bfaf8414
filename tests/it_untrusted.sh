#!/bin/sh
# it_untrusted.sh -- tests that scene files read only their own folder.
#
# Untrusted scene files: every file a glTF, OBJ or JSON scene names must lie
# in the scene's own folder (or one --allow-path gives), FIFOs and devices
# are refused at once, and no message, output or .fbin repeats a byte of a
# file outside the folder or of a referenced file that fails to parse.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need mkfifo timeout grep base64
F=$PWD/bin/franja
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
S=$T/scene O=$T/outside
mkdir -p "$S/sub" "$O"
MARK=FRANJA-SECRET-7f3a9c
# The outside files: text and binary that hold the marker, and a real image.
for i in 1 2 3 4; do printf '%s %s\n' "$MARK" "$MARK"; done >"$O/secret.bin"
printf '%s\nnewmtl x\nKd 1 0 0\n' "$MARK" >"$O/secret.mtl"
printf '%s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' "$MARK" >"$O/secret.obj"
cp scenes/textures/bricks.png "$O/secret.png"
cp scenes/textures/bricks.png "$O/wood.png"

# A glTF triangle whose buffer is BUF and whose material's base colour
# image is IMG (positions from a data: URI when BUF is "").
TRI=AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA
gltf() {
    buf=${1:-data:application/octet-stream;base64,$TRI} img=$2
    images="" mat=""
    if [ -n "$img" ]; then
        images=', "images": [{"uri": "'"$img"'"}], "textures": [{"source": 0}]'
        mat=', "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]'
    fi
    printf '%s\n' '{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}'"${img:+, \"material\": 0}"'}]}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0, 0, 0], "max": [1, 1, 0]}],
 "bufferViews": [{"buffer": 0, "byteLength": 36}],
 "buffers": [{"byteLength": 36, "uri": "'"$buf"'"}]'"$images$mat"'}'
}

# A JSON scene with a textured sphere (texture file TEX, "" for none) and
# the shape SHAPE (a JSON object, or "").
json() {
    tex=$1 shape=$2 env=""
    [ -n "$3" ] && env='"environment": {"color": "t"},'
    textures="" albedo="[0.5, 0.5, 0.5]"
    if [ -n "$tex" ]; then
        textures='"textures": {"t": {"type": "image", "file": "'"$tex"'"}},'
        albedo='"t"'
    fi
    printf '%s\n' '{"image": {"width": 8, "height": 8, "spp": 1},
 "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov": 40}, '"$textures"'
 "materials": {"m": {"type": "lambert", "albedo": '"$albedo"'}},
 '"$env"'
 "lights": [{"type": "point", "position": [0, 3, -3], "intensity": [10, 10, 10]}],
 "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}'"${shape:+, $shape}"']}'
}

# refused WHAT FRAGMENT COMMAND...: exits non-zero within 2 s, says
# FRAGMENT, and neither its output nor any .fbin holds the marker.
refused() {
    what=$1 frag=$2
    shift 2
    rm -f "$T"/*.fbin
    t0=$(date +%s%N)
    timeout -s KILL 20 "$@" >"$T/out" 2>"$T/err"
    rc=$? t1=$(date +%s%N)
    ms=$(((t1 - t0) / 1000000))
    if [ $rc -eq 0 ]; then
        bad "$what: exit status 0"
    elif [ $rc -ge 124 ]; then
        bad "$what: still running after 20 s (killed)"
    elif [ $ms -gt 2000 ]; then
        bad "$what: refused after $ms ms (more than 2 s)"
    elif ! grep -qF -- "$frag" "$T/err"; then
        bad "$what: stderr lacks '$frag': $(cat "$T/err")"
    else
        ok
    fi
    clean "$what"
}

# clean WHAT: nothing of the outside files in the last output or any .fbin,
# and no raw control byte (ESC) in the messages.
clean() {
    if cat "$T/out" "$T/err" "$T"/*.fbin 2>/dev/null | grep -aqF "$MARK"; then
        bad "$1: the outside file's content leaked"
    else
        ok
    fi
    if grep -q "$(printf '\033')" "$T/out" "$T/err"; then
        bad "$1: a raw ESC byte reached the output"
    else
        ok
    fi
}

RULE="outside the scene's folder"

# --- glTF buffers and images ---
gltf ../outside/secret.bin >"$S/buf-up.gltf"
refused "glTF buffer ../" "/buffers/0: $S/../outside/secret.bin: $RULE" $F compile "$S/buf-up.gltf" -o "$T/x.fbin"
gltf sub/../../outside/secret.bin >"$S/buf-deep.gltf"
refused "glTF buffer sub/../../" "$RULE" $F compile "$S/buf-deep.gltf" -o "$T/x.fbin"
gltf "$(echo "$O/secret.bin" | sed 's|^/||; s|[^/]*|..|g')$O/secret.bin" >"$S/buf-many.gltf"
refused "glTF buffer ../../.. to the root" "$RULE" $F compile "$S/buf-many.gltf" -o "$T/x.fbin"
gltf "%2E%2E/outside/secret.bin" >"$S/buf-pct.gltf"
refused "glTF buffer %2E%2E/" "$RULE" $F compile "$S/buf-pct.gltf" -o "$T/x.fbin"
ln -s ../outside/secret.bin "$S/link.bin"
gltf link.bin >"$S/buf-link.gltf"
refused "glTF buffer through a symlink out" "link.bin: $RULE" $F compile "$S/buf-link.gltf" -o "$T/x.fbin"
ln -s ../outside "$S/outdir"
gltf outdir/secret.bin >"$S/buf-dirlink.gltf"
refused "glTF buffer through a folder symlink out" "$RULE" $F compile "$S/buf-dirlink.gltf" -o "$T/x.fbin"
gltf "" ../outside/secret.png >"$S/img-up.gltf"
refused "glTF image ../" "/images/0: uri: $S/../outside/secret.png: $RULE" $F compile "$S/img-up.gltf" -o "$T/x.fbin"
ln -s ../outside/secret.png "$S/link.png"
gltf "" link.png >"$S/img-link.gltf"
refused "glTF image through a symlink out" "link.png: $RULE" $F compile "$S/img-link.gltf" -o "$T/x.fbin"
refused "glTF image ../ in render" "$RULE" $F render "$S/img-up.gltf" -o "$T/x.pfm" --spp 1 --size 8x8 -j 1

# --- FIFOs and devices: refused at once ---
mkfifo "$S/fifo.bin" "$S/fifo.png"
gltf fifo.bin >"$S/buf-fifo.gltf"
refused "glTF buffer a FIFO" "fifo.bin: not a regular file (a FIFO)" $F compile "$S/buf-fifo.gltf" -o "$T/x.fbin"
gltf "" fifo.png >"$S/img-fifo.gltf"
refused "glTF image a FIFO" "fifo.png: not a regular file (a FIFO)" $F compile "$S/img-fifo.gltf" -o "$T/x.fbin"
ln -s /dev/zero "$S/z.png"
ln -s /dev/zero "$S/z.bin"
gltf z.bin >"$S/buf-zero.gltf"
refused "glTF buffer a symlink to /dev/zero" "z.bin: $RULE" $F compile "$S/buf-zero.gltf" -o "$T/x.fbin"
gltf "" z.png >"$S/img-zero.gltf"
refused "glTF image a symlink to /dev/zero" "z.png: $RULE" $F compile "$S/img-zero.gltf" -o "$T/x.fbin"
gltf "" ../../../../../../../../dev/zero >"$S/img-devzero.gltf"
refused "glTF image ../../dev/zero" "$RULE" $F compile "$S/img-devzero.gltf" -o "$T/x.fbin"

# --- OBJ: mtllib out of the folder, and files that are not what they should be ---
printf 'mtllib ../outside/secret.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$S/mtl-up.obj"
json "" '{"type": "mesh", "file": "mtl-up.obj"}' >"$S/mtl-up.json"
refused "mtllib ../" "mtllib: $S/../outside/secret.mtl: $RULE" $F compile "$S/mtl-up.json" -o "$T/x.fbin"
printf 'mtllib %s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' "$O/secret.mtl" >"$S/mtl-abs.obj"
json "" '{"type": "mesh", "file": "mtl-abs.obj"}' >"$S/mtl-abs.json"
refused "mtllib an absolute path" "$RULE" $F compile "$S/mtl-abs.json" -o "$T/x.fbin"
printf 'mtllib /etc/passwd\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$S/mtl-passwd.obj"
json "" '{"type": "mesh", "file": "mtl-passwd.obj"}' >"$S/mtl-passwd.json"
refused "mtllib /etc/passwd" "/etc/passwd: $RULE" $F compile "$S/mtl-passwd.json" -o "$T/x.fbin"
grep -q 'root' "$T/err" && bad "mtllib /etc/passwd: a word of the file is in the message" || ok
# an MTL in the folder that is no MTL: its words are not repeated
printf '%s here\n' "$MARK" >"$S/junk.mtl"
printf 'mtllib junk.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$S/mtl-junk.obj"
json "" '{"type": "mesh", "file": "mtl-junk.obj"}' >"$S/mtl-junk.json"
refused "an MTL that is not one" "junk.mtl:1:" $F compile "$S/mtl-junk.json" -o "$T/x.fbin"
printf 'v 0 0 0\n%s 1 2\n' "$MARK" >"$S/junk.obj"
json "" '{"type": "mesh", "file": "junk.obj"}' >"$S/obj-junk.json"
refused "an OBJ that is not one" "junk.obj:2: unknown OBJ statement" $F compile "$S/obj-junk.json" -o "$T/x.fbin"
printf 'v 0 0 0\n\033[31mred\033[0m 1 2\n' >"$S/esc.obj"
json "" '{"type": "mesh", "file": "esc.obj"}' >"$S/obj-esc.json"
refused "an OBJ keyword with ESC bytes" "esc.obj:2:" $F compile "$S/obj-esc.json" -o "$T/x.fbin"
# map_Kd out of the folder: never read (the OBJ reader ignores maps)
printf 'newmtl x\nKd 1 0 0\nmap_Kd ../outside/secret.bin\n' >"$S/map.mtl"
printf 'mtllib map.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n' >"$S/map.obj"
json "" '{"type": "mesh", "file": "map.obj"}' >"$S/map.json"
$F compile "$S/map.json" -o "$T/map.fbin" >"$T/out" 2>"$T/err" && ok || bad "map_Kd: $(cat "$T/err")"
clean "map_Kd ../"

# --- JSON scenes: meshes, textures, environment maps, gltf shapes ---
json "" '{"type": "mesh", "file": "../outside/secret.obj"}' >"$S/mesh-up.json"
refused "JSON mesh ../" "$S/../outside/secret.obj: $RULE" $F compile "$S/mesh-up.json" -o "$T/x.fbin"
json "" '{"type": "mesh", "lod": ["'"$O"'/secret.obj"]}' >"$S/mesh-abs.json"
refused "JSON mesh lod an absolute path" "$RULE" $F compile "$S/mesh-abs.json" -o "$T/x.fbin"
ln -s ../outside/secret.obj "$S/link.obj"
json "" '{"type": "mesh", "file": "link.obj"}' >"$S/mesh-link.json"
refused "JSON mesh through a symlink out" "link.obj: $RULE" $F compile "$S/mesh-link.json" -o "$T/x.fbin"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n' >"$O/secret.ply"
printf 'element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >>"$O/secret.ply"
json "" '{"type": "mesh", "file": "../outside/secret.ply"}' >"$S/ply-up.json"
refused "JSON mesh (Assimp) ../" "$RULE" $F compile "$S/ply-up.json" -o "$T/x.fbin"
json ../outside/secret.png >"$S/tex-up.json"
refused "JSON texture ../" "textures.t.file: cannot read $S/../outside/secret.png: $RULE" \
    $F compile "$S/tex-up.json" -o "$T/x.fbin"
json "$O/secret.png" >"$S/tex-abs.json"
refused "JSON texture an absolute path" "$RULE" $F compile "$S/tex-abs.json" -o "$T/x.fbin"
json link.png >"$S/tex-link.json"
refused "JSON texture through a symlink out" "link.png: $RULE" $F compile "$S/tex-link.json" -o "$T/x.fbin"
json ../outside/secret.png "" env | sed 's/"albedo": "t"/"albedo": [0.5, 0.5, 0.5]/' >"$S/env-up.json"
refused "JSON environment map ../" "$RULE" $F compile "$S/env-up.json" -o "$T/x.fbin"
gltf >"$O/tri.gltf"
json "" '{"type": "gltf", "file": "../outside/tri.gltf"}' >"$S/gltf-up.json"
refused "JSON gltf shape ../" "$RULE" $F compile "$S/gltf-up.json" -o "$T/x.fbin"
gltf ../../outside/secret.bin >"$S/sub/inner.gltf"
json "" '{"type": "gltf", "file": "sub/inner.gltf"}' >"$S/gltf-inner.json"
refused "JSON gltf shape whose buffer leaves the folder" "$RULE" $F compile "$S/gltf-inner.json" -o "$T/x.fbin"

# --- control bytes from a file never reach the terminal raw ---
gltf | sed 's/"asset"/"extensionsUsed": ["EVIL\\u001b[2J\\u001b]0;x\\u0007"], "asset"/' >"$S/esc.gltf"
$F compile "$S/esc.gltf" -o "$T/esc.fbin" >"$T/out" 2>"$T/err" && ok || bad "extensionsUsed with ESC: $(cat "$T/err")"
grep -q 'EVIL\\x1b\[2J' "$T/err" && ok || bad "extensionsUsed with ESC: not named escaped: $(cat "$T/err")"
clean "extensionsUsed with ESC"
printf '{"image": {"width": 8, "height": 8}, "\033]0;t\007": 1}\n' >"$S/esc.json"
refused "JSON member name with ESC" "esc.json" $F compile "$S/esc.json" -o "$T/x.fbin"

# --- inside the folder and with --allow-path, the same files are read ---
cp "$O/wood.png" "$S/sub/wood.png"
json sub/wood.png >"$S/tex-in.json"
$F compile "$S/tex-in.json" -o "$T/in.fbin" >"$T/out" 2>"$T/err" && ok || bad "a texture in a subfolder: $(cat "$T/err")"
json ../outside/wood.png >"$S/tex-allowed.json"
refused "an outside texture without --allow-path" "$RULE" $F compile "$S/tex-allowed.json" -o "$T/x.fbin"
$F compile "$S/tex-allowed.json" --allow-path "$O" -o "$T/allowed.fbin" >"$T/out" 2>"$T/err" && ok ||
    bad "--allow-path: $(cat "$T/err")"
[ -s "$T/allowed.fbin" ] && ok || bad "--allow-path: no .fbin"
$F render "$S/tex-allowed.json" --allow-path "$O" -o "$T/allowed.pfm" --spp 1 -j 1 >"$T/out" 2>"$T/err" && ok ||
    bad "render --allow-path: $(cat "$T/err")"
expect_error "--allow-path a missing folder" "--allow-path" $F compile "$S/tex-allowed.json" --allow-path "$T/nope" -o "$T/x.fbin"
echo "$TRI" | base64 -d >"$O/tri.bin"
gltf ../outside/tri.bin >"$S/buf-allowed.gltf"
$F compile "$S/buf-allowed.gltf" --allow-path "$O" -o "$T/buf.fbin" >"$T/out" 2>"$T/err" && ok ||
    bad "--allow-path for a glTF buffer: $(cat "$T/err")"

summary
