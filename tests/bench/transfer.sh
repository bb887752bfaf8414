#!/bin/sh
# transfer.sh -- measures zstd's ratio and speed on binary scenes.
#
# Compresses binary scenes at the levels a scene could travel at (1, 3, 9,
# 19) with the zstd command on one thread (the same libzstd franja links)
# and prints, per scene and level, the .fbin size, the compressed size, the
# ratio and the median compress time of three runs, and the decompress
# time at the chosen level.  Scenes: the examples (knot: a 59 k-triangle
# mesh; cornell-textured and bumpy: float textures; courtyard: a glTF
# scene) and a 1 M-triangle knot from bin/gen/genmesh.  Results:
# tests/bench/README.md, "Compressed transfer".
cd "$(dirname "$0")/../.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
make -s bin/franja bin/gen/genmesh >/dev/null || exit 1
for s in knot cornell-textured bumpy; do
    bin/franja compile scenes/$s.json -o "$T/$s.fbin" >/dev/null 2>&1
done
bin/franja compile scenes/courtyard.glb -o "$T/courtyard.fbin" >/dev/null 2>&1
mkdir "$T/big"
bin/gen/genmesh knot --tris 1000000 -o "$T/big/knot.obj" >/dev/null
cat >"$T/big/big.json" <<'JSON'
{ "image": { "width": 64, "height": 64, "spp": 1 },
  "camera": { "position": [0, 1, -3.4], "target": [0, 0.3, 0], "fov": 34 },
  "materials": { "gold": { "type": "phong", "diffuse": [0.4, 0.3, 0.1], "glossy": [0.4, 0.3, 0.1], "exponent": 40 } },
  "lights": [ { "type": "point", "position": [0, 4, -3], "intensity": [20, 20, 20] } ],
  "shapes": [ { "type": "mesh", "file": "knot.obj", "material": "gold" } ] }
JSON
bin/franja compile "$T/big/big.json" -o "$T/knot1m.fbin" >/dev/null 2>&1
# median of three timings (seconds) of a command
median3() {
    for i in 1 2 3; do
        s=$(date +%s.%N)
        "$@" >/dev/null 2>&1
        e=$(date +%s.%N)
        echo "$e - $s" | bc
    done | sort -n | sed -n 2p
}
printf '%-18s %11s %5s %11s %6s %8s %9s\n' scene bytes level packed ratio "pack s" "MB/s"
for f in "$T"/*.fbin; do
    [ -s "$f" ] || continue
    n=$(wc -c <"$f")
    for l in 1 3 9 19; do
        zstd -q -T1 -$l -c "$f" >"$T/z"
        z=$(wc -c <"$T/z")
        t=$(median3 zstd -q -f -T1 -$l "$f" -o "$T/z")
        printf '%-18s %11d %5d %11d %6.2f %8.3f %9.1f\n' "$(basename "$f" .fbin)" "$n" "$l" "$z" \
            "$(echo "$n / $z" | bc -l)" "$t" "$(echo "$n / 1000000 / $t" | bc -l)"
    done
    zstd -q -f -T1 -${LEVEL:-3} "$f" -o "$T/z"
    printf '%-18s unpack at level %s: %.3f s\n' "$(basename "$f" .fbin)" "${LEVEL:-3}" \
        "$(median3 zstd -q -d -f "$T/z" -o "$T/u")"
done
