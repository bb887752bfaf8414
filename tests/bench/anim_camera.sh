#!/bin/sh
# anim_camera.sh -- compile time and bytes sent per frame of a camera move.
#
# A camera-only animation of a large scene: a knot of TRIS triangles
# (default 1 M, bin/gen/genmesh) in a JSON scene whose camera position is
# keyed (json_keys.h), FRAMES frames (default 3) rendered with --frames
# over one fake SSH host (tests/support/fakehosts.sh: sshd on loopback),
# 64x64 at 1 spp.  Prints the median of three `franja compile` times of
# the scene (the work each frame's compile repeats), the .fbin's size, and
# per frame what the coordinator says it sent the host.  Results:
# tests/bench/README.md, "A camera move through a large scene".
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
. "$ROOT/tests/support/fakehosts.sh"
fh_init
cd "$ROOT" || exit 1
TRIS=${TRIS:-1000000}
FRAMES=${FRAMES:-3}
. tests/support/bench_common.sh
make -s bin/franja bin/franja-worker bin/gen/genmesh >/dev/null || exit 1
T=$FH
bin/gen/genmesh knot --tris "$TRIS" -o "$T/knot.obj" >/dev/null || exit 1
cat >"$T/move.json" <<'JSON'
{ "image": { "width": 64, "height": 64, "spp": 1 },
  "camera": { "position": { "keys": [[1, [0, 1, -3.4]], [24, [2.4, 1, -2.4]]] }, "target": [0, 0.3, 0], "fov": 34 },
  "materials": { "gold": { "type": "phong", "diffuse": [0.4, 0.3, 0.1], "glossy": [0.4, 0.3, 0.1], "exponent": 40 } },
  "lights": [ { "type": "point", "position": [0, 4, -3], "intensity": [20, 20, 20] } ],
  "shapes": [ { "type": "mesh", "file": "knot.obj", "material": "gold" } ] }
JSON
machine
times=""
for i in 1 2 3; do
    times="$times $(elapsed "bin/franja compile '$T/move.json' -o '$T/move.fbin'")" || exit 1
done
echo "compile of one frame ($TRIS triangles): $times s, median $(median $times) s; .fbin $(stat -c %s "$T/move.fbin") bytes"
fh_start a 2 2
s=$(date +%s.%N)
fr render "$T/move.json" --frames 1-"$FRAMES" -o "$T/out/f.#.pfm" --hosts "$FH/hosts" 2>"$T/log" ||
    { cat "$T/log"; exit 1; }
echo "render of $FRAMES frames over one SSH host: $(calc "$(date +%s.%N) - $s") s"
grep -E "host a: frame [0-9]+: scene" "$T/log"
grep -E "^  a " "$T/log"
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
