#!/bin/sh
# instances.sh -- measures compiling and rendering a mesh placed many times.
#
# A 20 000-triangle torus knot (bin/gen/genmesh) placed by N instances
# (default 10 000, a 100 x 100 grid, each turned and scaled) of a JSON
# mesh shape: the compile's wall time and peak RSS (GNU time), the .fbin's
# size, and a worker's render of 256x256 at 1 spp (one process); then the
# same for a scene of 100 instances and its flattened twin (100 mesh
# shapes, 2 M triangles), whose images are compared.  Medians of REPS runs
# (default 3).  Goal: 10^4 instances compiled in under 10 s and 1 GB.
cd "$(dirname "$0")/../.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
REPS=${REPS:-3}
N=${N:-10000}
[ -x /usr/bin/time ] || { echo "instances.sh needs GNU time (/usr/bin/time)"; exit 1; }
echo "== instances: one mesh placed many times"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p' | head -n 1), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: REPS=$REPS N=$N sh tests/bench/instances.sh"
bin/gen/genmesh knot --tris 20000 -o "$T/knot.obj" >/dev/null || exit 1

# scene FILE N FLAT: N placements of the knot on a grid, as instances of
# one shape or (FLAT=1) as one shape each.
scene() {
    side=$(awk -v n="$2" 'BEGIN { s = int(sqrt(n)); if (s * s < n) s++; print s }')
    awk -v n="$2" -v flat="$3" -v side="$side" 'BEGIN {
        printf "{\"image\": {\"width\": 256, \"height\": 256, \"spp\": 1},\n"
        printf " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, 0, %g], \"fov\": 50},\n",
               side * 0.5, side * 0.8, -side * 0.3, side * 0.5, side * 0.5
        printf " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.7, 0.7]}},\n"
        printf " \"lights\": [{\"type\": \"sun\", \"direction\": [-1, -2, 1], \"irradiance\": [3, 3, 3]}],\n"
        printf " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"m\"}"
        if (!flat) printf ",\n  {\"type\": \"mesh\", \"file\": \"knot.obj\", \"material\": \"m\", \"instances\": ["
        for (i = 0; i < n; i++) {
            t = sprintf("\"translate\": [%d, 0.4, %d], \"rotate\": [0, %d, 0], \"scale\": %g",
                        i % side, int(i / side), (i * 37) % 360, 0.3 + (i % 5) * 0.03)
            if (flat) printf ",\n  {\"type\": \"mesh\", \"file\": \"knot.obj\", \"material\": \"m\", %s}", t
            else printf "%s\n    {%s}", (i ? "," : ""), t
        }
        if (!flat) printf "]}"
        printf "]}\n"
    }' >"$1"
}

median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

# measure NAME JSON: compile REPS times (wall s, peak RSS MB), size, render.
measure() {
    ts="" rs="" rt=""
    i=0
    while [ $i -lt "$REPS" ]; do
        /usr/bin/time -f "%e %M" -o "$T/time" bin/franja compile "$2" -o "$T/$1.fbin" >"$T/log" 2>&1 ||
            { cat "$T/log"; exit 1; }
        set -- "$1" "$2" $(cat "$T/time")
        ts="$ts $3" rs="$rs $(awk -v k="$4" 'BEGIN { printf "%.0f", k / 1024 }')"
        s=$(date +%s.%N)
        bin/franja-worker --scene "$T/$1.fbin" --rows 0:256 -o "$T/$1.pfm" || exit 1
        rt="$rt $(awk -v a="$s" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')"
        i=$((i + 1))
    done
    echo "$1: compile $(median $ts) s (runs:$ts), peak RSS $(median $rs) MB, .fbin $(stat -c %s "$T/$1.fbin") bytes," \
         "render 256x256 1 spp $(median $rt) s (runs:$rt)"
    sed -n 's/^[^:]*: scene [0-9a-f]*, //p' "$T/log"
}

echo "\$ bin/franja compile inst$N.json -o inst.fbin  (N=$N instances of a 20000-triangle knot)"
scene "$T/inst$N.json" "$N" 0
measure "inst$N" "$T/inst$N.json"
echo "\$ 100 instances against 100 mesh shapes (2 M triangles)"
scene "$T/inst100.json" 100 0
scene "$T/flat100.json" 100 1
measure inst100 "$T/inst100.json"
measure flat100 "$T/flat100.json"
if [ -x bin/tools/imgstat ]; then
    echo "image difference, instanced against flattened: $(bin/tools/imgstat "$T/inst100.pfm" --diff "$T/flat100.pfm")"
fi
