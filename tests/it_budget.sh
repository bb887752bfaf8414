#!/bin/sh
# it_budget.sh -- tests the compile budget against crafted scenes.
#
# The compile budget: crafted glTF and JSON scenes that declare huge
# accessors, name one file many times, hold a buffer past the per-file
# limit, drive lookups quadratic or keep vertices no triangle uses are
# refused with the limit and its option named (or compiled, when they are
# legitimate) within 2 s and 200 MB, and --limit raises or lowers a limit.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need python3
F=bin/franja
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
SECS=2 RSS_KB=204800

# bounded WHAT CMD...: CMD (any exit status) ends within SECS seconds
# (killed after 10) and peaks under RSS_KB of resident memory (with
# /usr/bin/time, which counts the compiling child too); its output is in
# $T/out and $T/err, its exit status in $rc.
bounded() {
    what=$1
    shift
    start=$(date +%s.%N)
    if [ -x /usr/bin/time ]; then
        timeout 10 /usr/bin/time -f %M -o "$T/rss" "$@" >"$T/out" 2>"$T/err"
    else
        timeout 10 "$@" >"$T/out" 2>"$T/err"
    fi
    rc=$?
    secs=$(echo "$(date +%s.%N) - $start" | bc 2>/dev/null || echo 0)
    awk -v s="$secs" -v m="$SECS" 'BEGIN { exit !(s + 0 <= m + 0) }' && ok ||
        bad "$what: took $secs s (at most $SECS)"
    if [ -s "$T/rss" ]; then
        kb=$(tail -n 1 "$T/rss")
        [ "$kb" -le "$RSS_KB" ] 2>/dev/null && ok || bad "$what: peak RSS $kb KiB (at most $RSS_KB)"
    fi
}

# refused WHAT FRAGMENT CMD...: bounded, non-zero, FRAGMENT on stderr.
refused() {
    what=$1 frag=$2
    shift 2
    bounded "$what" "$@"
    [ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] && grep -qF -- "$frag" "$T/err" && ok ||
        bad "$what: exit $rc, stderr lacks '$frag': $(head -c 400 "$T/err")"
}

# compiled WHAT CMD...: bounded and successful.
compiled() {
    what=$1
    shift
    bounded "$what" "$@"
    [ "$rc" -eq 0 ] && ok || bad "$what: exit $rc: $(head -c 400 "$T/err")"
}

# gen.py KIND DIR: writes DIR/s.gltf (and its files) for case KIND.
cat >"$T/gen.py" <<'PY'
import base64, json, struct, sys
kind, d = sys.argv[1], sys.argv[2]
tri = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
data = "data:application/octet-stream;base64," + base64.b64encode(tri).decode()
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
     "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
     "buffers": [{"byteLength": 36, "uri": data}],
     "bufferViews": [{"buffer": 0, "byteLength": 36}],
     "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                    "min": [0, 0, 0], "max": [1, 1, 0]}]}
if kind == "huge-positions":      # 3 * 2^26 vertices without a bufferView
    g["accessors"] = [{"componentType": 5126, "count": 3 << 26, "type": "VEC3"}]
    del g["buffers"], g["bufferViews"]
elif kind == "huge-indices":      # one triangle's vertices, 3 * 2^26 indices of zeros
    g["accessors"].append({"componentType": 5125, "count": 3 << 26, "type": "SCALAR"})
    g["meshes"][0]["primitives"][0]["indices"] = 1
elif kind in ("repeated", "repeated-used"):   # 20 entries naming one 100 MB file
    with open(d + "/big.bin", "wb") as f:
        f.truncate(100 << 20)
    for i in range(20):
        g["buffers"].append({"byteLength": 100 << 20, "uri": "big.bin"})
        if kind == "repeated-used":
            g["bufferViews"].append({"buffer": i + 1, "byteLength": 36})
            g["accessors"].append({"bufferView": i + 1, "componentType": 5126, "count": 3, "type": "VEC3"})
            g["meshes"][0]["primitives"].append({"attributes": {"POSITION": i + 1}})
elif kind == "oversized":         # a 1.5 GiB buffer file, used
    with open(d + "/big.bin", "wb") as f:
        f.truncate(3 << 29)
    g["buffers"] = [{"byteLength": 3 << 29, "uri": "big.bin"}]
elif kind == "roots":             # 200 000 root nodes
    n = 200000
    g["nodes"] += [{} for _ in range(n)]
    g["scenes"][0]["nodes"] = list(range(n + 1))
elif kind == "unused":            # 2^21 vertices, one triangle uses 3 of them
    n = 1 << 21
    with open(d + "/v.bin", "wb") as f:
        f.write(tri)
        f.truncate(n * 12)
        f.seek(n * 12)
        f.write(struct.pack("<3I", 0, 1, 2))
    g["buffers"] = [{"byteLength": n * 12 + 12, "uri": "v.bin"}]
    g["bufferViews"] = [{"buffer": 0, "byteLength": n * 12}, {"buffer": 0, "byteOffset": n * 12, "byteLength": 12}]
    g["accessors"] = [{"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3"},
                      {"bufferView": 1, "componentType": 5125, "count": 3, "type": "SCALAR"}]
    g["meshes"][0]["primitives"][0]["indices"] = 1
elif kind == "materials":         # a JSON scene: 20 000 materials, 20 000 shapes using the last
    n = 20000
    s = {"image": {"width": 8, "height": 8, "spp": 1},
         "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov": 40},
         "materials": {"m%d" % i: {"type": "lambert", "albedo": [0.5, 0.5, 0.5]} for i in range(n)},
         "lights": [{"type": "point", "position": [0, 3, -3], "intensity": [10, 10, 10]}],
         "shapes": [{"type": "sphere", "center": [i % 100, i // 100, 0], "radius": 0.4,
                     "material": "m%d" % (n - 1)} for i in range(n)]}
    json.dump(s, open(d + "/s.json", "w"))
    sys.exit(0)
json.dump(g, open(d + "/s.gltf", "w"))
PY

gen() {
    rm -rf "$T/$1"
    mkdir "$T/$1"
    python3 "$T/gen.py" "$1" "$T/$1" || bad "gen.py $1 failed"
}

# Accessors counted before anything is read or allocated.
gen huge-positions
[ "$(wc -c <"$T/huge-positions/s.gltf")" -lt 1024 ] && ok || bad "huge-positions: the file is not small"
refused "3*2^26 vertices without a bufferView" "would pass the compile's limit of 134217728 vertices (--limit vertices=N raises it)" \
    $F compile "$T/huge-positions/s.gltf" -o "$T/x.fbin"
grep -qF "/meshes/0/primitives/0" "$T/err" && ok || bad "huge-positions: no JSON pointer: $(cat "$T/err")"
refused "the same with --limit vertices=1G: zeros only" "no triangles" \
    $F compile "$T/huge-positions/s.gltf" -o "$T/x.fbin" --limit vertices=1G
gen huge-indices
refused "3*2^26 indices of zeros" "no triangles" $F compile "$T/huge-indices/s.gltf" -o "$T/x.fbin"
refused "3*2^26 indices, --limit triangles=1M" "(--limit triangles=N raises it)" \
    $F compile "$T/huge-indices/s.gltf" -o "$T/x.fbin" --limit triangles=1M

# A buffer file is read when an accessor needs it, and each read counts.
gen repeated
compiled "20 unused buffers naming one 100 MB file" $F compile "$T/repeated/s.gltf" -o "$T/x.fbin"
gen repeated-used
refused "20 used buffers naming one 100 MB file, --limit read=150M" "(--limit read=BYTES raises it)" \
    $F compile "$T/repeated-used/s.gltf" -o "$T/x.fbin" --limit read=150M
grep -qF "/buffers/" "$T/err" && ok || bad "repeated-used: no buffer named: $(cat "$T/err")"
refused "a used 100 MB buffer, --limit memory=64M" "(the compile may map 64 MiB: --limit memory=BYTES raises it)" \
    $F compile "$T/repeated-used/s.gltf" -o "$T/x.fbin" --limit memory=64M
gen oversized
refused "a 1.5 GiB buffer" "more than the 1073741824 bytes a buffer file may have" \
    $F compile "$T/oversized/s.gltf" -o "$T/x.fbin"

# An OBJ naming one 1 MB MTL file 200 times: every read counts.
mkdir "$T/obj"
awk 'BEGIN { for (i = 0; i < 16384; i++) printf "# %062d\n", i }' >"$T/obj/big.mtl"
{ i=0; while [ $i -lt 200 ]; do echo "mtllib big.mtl"; i=$((i + 1)); done
  printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n'; } >"$T/obj/m.obj"
cat >"$T/obj/s.json" <<'JSON'
{"image": {"width": 4, "height": 4, "spp": 1},
 "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov": 40},
 "materials": {"m": {"type": "lambert", "albedo": [0.5, 0.5, 0.5]}},
 "lights": [{"type": "point", "position": [0, 3, -3], "intensity": [10, 10, 10]}],
 "shapes": [{"type": "mesh", "file": "m.obj", "material": "m"}]}
JSON
refused "one MTL file named 200 times, --limit read=20M" "m.obj:20: mtllib: " \
    $F compile "$T/obj/s.json" -o "$T/x.fbin" --limit read=20M
grep -qF "(--limit read=BYTES raises it)" "$T/err" && ok || bad "mtllib: no option named: $(cat "$T/err")"

# Linear lookups.
gen roots
compiled "200 000 glTF root nodes" $F compile "$T/roots/s.gltf" -o "$T/x.fbin"
gen materials
compiled "20 000 JSON materials, every shape using the last" $F compile "$T/materials/s.json" -o "$T/x.fbin"

# Vertices no triangle uses are not kept.
gen unused
compiled "one triangle of 2^21 vertices" $F compile "$T/unused/s.gltf" -o "$T/x.fbin"
size=$(wc -c <"$T/x.fbin")
[ "$size" -lt 65536 ] && ok || bad "one triangle of 2^21 vertices: a .fbin of $size bytes"

# The .fbin limit, and --limit's own errors.
gen unused
refused "--limit fbin=1K" "the binary scene: " $F compile "$T/unused/s.gltf" -o "$T/x.fbin" --limit fbin=1K
grep -qF "(--limit fbin=BYTES raises it)" "$T/err" && ok || bad "fbin limit: no option named: $(cat "$T/err")"
expect_error "--limit size=1" "expected NAME=VALUE with NAME one of read, vertices" \
    $F compile "$T/unused/s.gltf" -o "$T/x.fbin" --limit size=1
expect_error "--limit read=0" "read: '0' is not a whole number at least 1" \
    $F compile "$T/unused/s.gltf" -o "$T/x.fbin" --limit read=0
expect_error "render --limit cpu=1x" "cpu: '1x' is not a whole number" \
    $F render "$T/unused/s.gltf" -o "$T/x.png" --limit cpu=1x

summary
