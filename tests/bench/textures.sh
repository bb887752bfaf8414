#!/bin/sh
# textures.sh -- measures texture storage and mip-mapped lookups.
#
# Textures at their own precision, with mip-maps: what a large 8-bit image
# costs when compiled, and what the lookups cost when rendering.
#
#   1. A 4096x4096 8-bit RGB PNG (scenes/textures/bricks.png enlarged by
#      oiiotool) on a rectangle: `franja compile` wall and CPU seconds
#      (user + system) and peak RSS (/usr/bin/time), and the .fbin's size;
#      medians of RUNS (3).  Wall time on a shared VM is mostly waiting
#      (the .fbin written back, other work): CPU seconds compare better.
#   2. scenes/cornell-textured.json at 512x512, 64 spp, one worker process
#      over all rows: wall and CPU seconds, medians of RUNS_RENDER (5).
#
# BASE=path/to/bin (a directory with the franja and franja-worker of an
# older build) measures that build in the same run, alternating with this
# one, so both see the same load.
cd "$(dirname "$0")/../.." || exit 1
. tests/support/lib.sh
need oiiotool /usr/bin/time
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
RUNS=${RUNS:-3} RUNS_RENDER=${RUNS_RENDER:-5}
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
oiiotool scenes/textures/bricks.png --resize 4096x4096 -d uint8 -o "$T/big.png" || exit 1
cat >"$T/big.json" <<'JSON'
{
  "image": {"width": 64, "height": 64, "spp": 4},
  "camera": {"position": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40},
  "textures": {"big": {"type": "image", "file": "big.png"}},
  "materials": {"m": {"type": "lambert", "albedo": "big"}},
  "shapes": [{"type": "rect", "origin": [-1, -1, 0], "edge_u": [2, 0, 0], "edge_v": [0, 2, 0], "material": "m"}],
  "lights": [{"type": "point", "position": [0, 0, 3], "intensity": [10, 10, 10]}]
}
JSON
median() { sort -n | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
builds="this:bin"
[ -n "$BASE" ] && builds="$builds base:$BASE"
i=0
while [ $i -lt "$RUNS" ]; do
    for b in $builds; do
        name=${b%%:*} dir=${b#*:}
        /usr/bin/time -f '%e %M %U %S' -o "$T/t" "$dir/franja" compile "$T/big.json" -o "$T/$name.fbin" >/dev/null 2>&1
        cat "$T/t" >>"$T/compile-$name"
        wc -c <"$T/$name.fbin" >"$T/size-$name"
    done
    i=$((i + 1))
done
for b in $builds; do
    name=${b%%:*}
    echo "4096x4096 8-bit PNG, $name: .fbin $(cat "$T/size-$name") bytes, compile $(cut -d' ' -f1 "$T/compile-$name" | median) s wall," \
         "$(awk '{ print $3 + $4 }' "$T/compile-$name" | median) CPU-s, peak RSS $(cut -d' ' -f2 "$T/compile-$name" | median) KB (medians of $RUNS)"
done
i=0
while [ $i -lt "$RUNS_RENDER" ]; do
    for b in $builds; do
        name=${b%%:*} dir=${b#*:}
        [ -f "$T/ct-$name.fbin" ] || "$dir/franja" compile scenes/cornell-textured.json -o "$T/ct-$name.fbin" >/dev/null 2>&1
        /usr/bin/time -f '%e %U' -o "$T/t" "$dir/franja-worker" --scene "$T/ct-$name.fbin" --rows 0:512 -o "$T/ct-$name.pfm"
        cat "$T/t" >>"$T/render-$name"
    done
    i=$((i + 1))
done
[ "$RUNS_RENDER" -gt 0 ] && for b in $builds; do
    name=${b%%:*}
    echo "cornell-textured 512x512 64 spp, one process, $name: $(cut -d' ' -f1 "$T/render-$name" | median) s wall," \
         "$(cut -d' ' -f2 "$T/render-$name" | median) CPU-s (medians of $RUNS_RENDER)"
done
[ "$RUNS_RENDER" -gt 0 ] && [ -n "$BASE" ] && [ -x bin/tools/imgcmp ] && bin/tools/imgcmp "$T/ct-this.pfm" "$T/ct-base.pfm"
exit 0
