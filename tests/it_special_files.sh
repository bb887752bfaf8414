#!/bin/sh
# it_special_files.sh -- tests inputs that are not plain files are refused in time.
#
# Inputs that are not plain files, or that promise more than they hold: a
# FIFO as scene, mesh, MTL, texture or host table; /dev/zero (directly or
# through a symbolic link) as scene or mtllib; a directory; an ASCII PLY
# declaring 10^8 faces; PLY files that make Assimp abort or crash.  Each is
# refused within seconds, with bounded memory, naming the file; nothing
# hangs, nothing dies.  Every command runs under a time limit and an
# address-space limit, so that a failure of this test cannot take the
# machine down with it.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need mkfifo timeout
F=$PWD/bin/franja W=$PWD/bin/franja-worker
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# bounded SECONDS CMD...: CMD under a 3 GiB address-space limit and a time
# limit; its status (124: timed out).
bounded() {
    secs=$1
    shift
    (ulimit -v 3000000; exec timeout -s KILL "$secs" "$@")
}

# refused WHAT FRAGMENT CMD...: CMD fails within 60 s, not by a signal,
# with FRAGMENT on stderr.
refused() {
    what=$1 frag=$2
    shift 2
    bounded 60 "$@" >"$T/out" 2>"$T/err"
    rc=$?
    if [ $rc -eq 0 ]; then
        bad "$what: exit status 0"
    elif [ $rc -eq 124 ] || [ $rc -eq 137 ]; then
        bad "$what: still running after 60 s (killed)"
    elif [ $rc -gt 128 ]; then
        bad "$what: died of signal $((rc - 128)): $(tail -c 300 "$T/err")"
    elif ! grep -qF -- "$frag" "$T/err"; then
        bad "$what: stderr lacks '$frag': $(tail -c 300 "$T/err")"
    else
        ok
    fi
}

mkfifo "$T/fifo.json" "$T/fifo.fbin" "$T/fifo.obj" "$T/fifo.mtl" "$T/fifo.png" "$T/fifo.ply" "$T/fifo.hosts"
ln -s /dev/zero "$T/zero.json"
ln -s /dev/zero "$T/zero.mtl"
ln -s /dev/zero "$T/zero.png"
mkdir "$T/dir.json"

# --- scenes ---
refused "FIFO as scene (worker)" "fifo.json: not a regular file (a FIFO)" $W --scene "$T/fifo.json" --rows 0:1 -o "$T/x"
refused "FIFO as .fbin (worker)" "fifo.fbin: not a regular file (a FIFO)" $W --scene "$T/fifo.fbin" --rows 0:1 -o "$T/x"
refused "FIFO as scene (compile)" "fifo.json: not a regular file (a FIFO)" $F compile "$T/fifo.json" -o "$T/x.fbin"
refused "FIFO as .fbin (render)" "fifo.fbin: not a regular file (a FIFO)" $F render "$T/fifo.fbin" -o "$T/x.png"
refused "/dev/zero as scene (worker)" "/dev/zero: not a regular file (a character device)" $W --scene /dev/zero --rows 0:1 -o "$T/x"
refused "symlink to /dev/zero as scene (worker)" "zero.json: not a regular file (a character device)" $W --scene "$T/zero.json" --rows 0:1 -o "$T/x"
refused "symlink to /dev/zero as scene (compile)" "zero.json: not a regular file (a character device)" $F compile "$T/zero.json" -o "$T/x.fbin"
refused "directory as scene (compile)" "dir.json: not a regular file (a directory)" $F compile "$T/dir.json" -o "$T/x.fbin"
refused "FIFO as host table" "fifo.hosts: cannot open host table: not a regular file (a FIFO)" $F hosts list --hosts "$T/fifo.hosts"

# --- meshes, MTL files and textures, named by a scene ---
scene() { # scene FILE SHAPES
    cat >"$1" <<JSON
{"image": {"width": 8, "height": 8, "spp": 1},
 "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov": 40},
 "materials": {"m": {"type": "lambert", "albedo": [0.5, 0.5, 0.5]}},
 "lights": [{"type": "point", "position": [0, 3, -3], "intensity": [10, 10, 10]}],
 "shapes": [$2]}
JSON
}
mesh() { scene "$T/$1.json" "{\"type\": \"mesh\", \"file\": \"$2\"${3:+, \"material\": \"$3\"}}"; }
mesh fifo-obj fifo.obj m
refused "FIFO as OBJ mesh" "fifo.obj: not a regular file (a FIFO)" $F compile "$T/fifo-obj.json" -o "$T/x.fbin"
mesh fifo-ply fifo.ply m
refused "FIFO as PLY mesh" "fifo.ply: not a regular file (a FIFO)" $F compile "$T/fifo-ply.json" -o "$T/x.fbin"
printf 'mtllib fifo.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$T/a.obj"
printf 'mtllib zero.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$T/b.obj"
mesh mtl-fifo a.obj
refused "FIFO as mtllib" "fifo.mtl: not a regular file (a FIFO)" $F compile "$T/mtl-fifo.json" -o "$T/x.fbin"
mesh mtl-zero b.obj
refused "/dev/zero as mtllib" "zero.mtl: outside the scene's folder" $F compile "$T/mtl-zero.json" -o "$T/x.fbin"
cat >"$T/tex-fifo.json" <<'JSON'
{"image": {"width": 8, "height": 8, "spp": 1},
 "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov": 40},
 "textures": {"i": {"type": "image", "file": "fifo.png"}},
 "materials": {"t": {"type": "lambert", "albedo": "i"}},
 "lights": [{"type": "point", "position": [0, 3, -3], "intensity": [10, 10, 10]}],
 "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "t"}]}
JSON
sed 's/fifo.png/zero.png/' "$T/tex-fifo.json" >"$T/tex-zero.json"
refused "FIFO as texture" "textures.i.file: cannot read $T/fifo.png: not a regular file (a FIFO)" $F compile "$T/tex-fifo.json" -o "$T/x.fbin"
refused "symlink to /dev/zero as texture" "zero.png: outside the scene's folder" $F compile "$T/tex-zero.json" -o "$T/x.fbin"

# --- Assimp: a header that promises 10^8 faces, files that abort or crash it ---
H='ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n'
printf "${H}element face 100000000\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n" >"$T/huge.ply"
printf "${H}element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0\n" >"$T/abort.ply"
# (a face of 255 indices where the file ends: as many bytes as the header
# asks for at least, so it reaches Assimp, which reads past the end)
printf "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n%036d\377" 0 >"$T/crash.ply"
printf "${H}element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n" >"$T/good.ply"
mesh huge huge.ply m
start=$(date +%s)
refused "PLY declaring 10^8 faces" "huge.ply: the PLY header declares 100000000 'face' elements, which take at least 200000000 bytes" $F compile "$T/huge.json" -o "$T/x.fbin"
[ $(($(date +%s) - start)) -lt 5 ] && ok || bad "PLY declaring 10^8 faces: refused after $(($(date +%s) - start)) s"
# The same in binary, and a count past 2^64 bytes; one element more than
# the file holds.
printf "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 100000000\nproperty list uchar int vertex_indices\nend_header\n" >"$T/huge-bin.ply"
mesh huge-bin huge-bin.ply m
refused "binary PLY declaring 10^8 faces" "huge-bin.ply: the PLY header declares 100000000 'face' elements" $F compile "$T/huge-bin.json" -o "$T/x.fbin"
printf "${H}element face 18446744073709551615\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n" >"$T/wrap.ply"
mesh wrap wrap.ply m
refused "PLY declaring 2^64-1 faces" "wrap.ply: the PLY header declares 18446744073709551615 'face' elements" $F compile "$T/wrap.json" -o "$T/x.fbin"
printf "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n%036d" 0 >"$T/short.ply"
mesh short short.ply m
refused "binary PLY one vertex short" "short.ply: the PLY header declares elements of at least 48 bytes, more than the 36 bytes after the header" $F compile "$T/short.json" -o "$T/x.fbin"
mesh abort abort.ply m
refused "PLY that makes Assimp abort" "abort.ply: the mesh importer (Assimp) crashed (signal 6" $F compile "$T/abort.json" -o "$T/x.fbin"
mesh crash crash.ply m
refused "truncated binary PLY that crashes Assimp" "crash.ply: the mesh importer (Assimp) crashed (signal 11" $F compile "$T/crash.json" -o "$T/x.fbin"
# ... while a good one still arrives (also in binary, exactly the size its
# header declares).
mesh good good.ply m
bounded 60 $F compile "$T/good.json" -o "$T/good.fbin" >"$T/out" 2>&1 && grep -q '1 primitives (1 triangles)' "$T/out" &&
    ok || bad "a good PLY: $(cat "$T/out")"
printf "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" >"$T/goodbin.ply"
printf '\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200\077\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200\077\000\000\000\000\003\000\000\000\000\001\000\000\000\002\000\000\000' >>"$T/goodbin.ply"
mesh goodbin goodbin.ply m
bounded 60 $F compile "$T/goodbin.json" -o "$T/good.fbin" >"$T/out" 2>&1 && grep -q '1 primitives (1 triangles)' "$T/out" &&
    ok || bad "a good binary PLY: $(cat "$T/out")"

# --- size caps: files larger than a reader takes (sparse, so they cost
# nothing) are refused by their size before anything is read ---
truncate -s 1073741825 "$T/big.json" "$T/big.obj" "$T/big.mtl" "$T/big.ply"
truncate -s 4294967297 "$T/big.png"
refused "a scene over 1 GiB" "big.json: 1073741825 bytes, more than the 1073741824 this reader takes" $F compile "$T/big.json" -o "$T/x.fbin"
mesh big-obj big.obj m
refused "an OBJ mesh over 1 GiB" "big.obj: 1073741825 bytes, more than the 1073741824 this reader takes" $F compile "$T/big-obj.json" -o "$T/x.fbin"
mesh big-ply big.ply m
refused "a PLY mesh over 1 GiB" "big.ply: 1073741825 bytes, more than the 1073741824 this reader takes" $F compile "$T/big-ply.json" -o "$T/x.fbin"
printf 'mtllib big.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$T/c.obj"
mesh mtl-big c.obj
refused "an MTL file over 1 GiB" "big.mtl: 1073741825 bytes, more than the 1073741824 this reader takes" $F compile "$T/mtl-big.json" -o "$T/x.fbin"
sed 's/fifo.png/big.png/' "$T/tex-fifo.json" >"$T/tex-big.json"
refused "a texture over 4 GiB" "big.png: 4294967297 bytes, more than the 4294967296 this reader takes" $F compile "$T/tex-big.json" -o "$T/x.fbin"

summary
