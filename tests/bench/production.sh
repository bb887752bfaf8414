#!/bin/sh
# production.sh -- measures a generated production-like scene end to end.
#
# Generates a scene of the size people bring to a farm: TEX_MB MiB of 8-bit
# RGB texels (default 192) as TEX_SIZE x TEX_SIZE images (default 4096),
# PNG and JPEG in turn (bin/gen/gentex's patterns, scaled, tinted and
# given grain by oiiotool); TRIS distinct triangles (default 2 000 000: a
# genmesh terrain, sphere and knot); INSTANCES placements (default 10 000)
# of one MESH_TRIS-triangle knot (default 20 000) as a JSON `mesh` shape
# with `instances`.  Measures, beside the goals of issue 30:
#   - compile wall time and peak RSS (GNU time) and the .fbin's size, for
#     the whole scene, its textures alone and its instances alone;
#   - bytes sent per host (the render summary's `sent`) to HOSTS fake SSH
#     hosts (tests/support/fakehosts.sh; default 2) of WORKERS slots each
#     (default 2), and the render's time, first (scene sent) and second
#     (scene cached); the time to pack the scene and to unpack it, in
#     both forms (bin/bench/packbench);
#   - worker start-up: `franja-worker --check` and a one-row render
#     (medians of REPS, default 3; page cache warm);
#   - memory: the coordinator's peak RSS, and a host's workers sampled from
#     /proc/PID/smaps_rollup during the render (PSS summed over the host's
#     workers at each instant, each worker's private memory), against the
#     formula of tests/bench/README.md, "Memory per host", whose constants
#     this script measures on small scenes first;
#   - the image against the same scene flattened (a `mesh` shape per
#     instance) when INSTANCES x MESH_TRIS <= FLAT_MAX (default 1 000 000),
#     else against a twin of FLAT_MAX / MESH_TRIS instances alone.
# Render: SIZE (default 320x180) at SPP (default 16).  Scratch files go to
# TMPDIR; the default scale needs about 12 GB of disk and 6 GB of memory.
# Results: tests/bench/README.md, "A production-like scene".
cd "$(dirname "$0")/../.." || exit 1
ROOT=$(pwd)
TEX_MB=${TEX_MB:-192}
TEX_SIZE=${TEX_SIZE:-4096}
TRIS=${TRIS:-2000000}
INSTANCES=${INSTANCES:-10000}
MESH_TRIS=${MESH_TRIS:-20000}
HOSTS=${HOSTS:-2}
WORKERS=${WORKERS:-2}
SIZE=${SIZE:-320x180}
SPP=${SPP:-16}
REPS=${REPS:-3}
FLAT_MAX=${FLAT_MAX:-1000000}
[ -x /usr/bin/time ] || { echo "production.sh needs GNU time (/usr/bin/time)"; exit 1; }
command -v oiiotool >/dev/null || { echo "production.sh needs oiiotool"; exit 1; }
make -s bin/franja bin/franja-worker bin/gen/genmesh bin/gen/gentex bin/tools/imgstat bin/tools/imgcmp bin/bench/packbench >/dev/null ||
    exit 1
. tests/support/fakehosts.sh
fh_init
D=$FH/scene
mkdir -p "$D"
W=${SIZE%x*} H=${SIZE#*x}

echo "== production: a generated production-like scene"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p' | head -n 1), load $(cut -d' ' -f1-3 /proc/loadavg), $(free -g | awk '/^Mem:/ { print $2 " GB" }') memory"
echo "reproduce: TEX_MB=$TEX_MB TEX_SIZE=$TEX_SIZE TRIS=$TRIS INSTANCES=$INSTANCES MESH_TRIS=$MESH_TRIS HOSTS=$HOSTS WORKERS=$WORKERS SIZE=$SIZE SPP=$SPP REPS=$REPS FLAT_MAX=$FLAT_MAX sh tests/bench/production.sh"

calc() { awk "BEGIN { printf \"%.${2:-3}f\", $1 }"; }
mib() { calc "$1 / 1048576" 1; }
median() { printf '%s\n' "$@" | sort -n | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }'; }
now() { date +%s.%N; }
since() { calc "$(now) - $1"; }
# verdict OK: "met" or "NOT met"
verdict() { if [ "$1" = 1 ]; then echo met; else echo "NOT met"; fi; }

# ---- the scene's files -------------------------------------------------
t0=$(now)
bin/gen/gentex "$D" >/dev/null || exit 1
NTEX=$(calc "$TEX_MB * 1048576 / ($TEX_SIZE * $TEX_SIZE * 3)" 0)
[ "$TEX_MB" -gt 0 ] && [ "$NTEX" -lt 1 ] && NTEX=1
i=0
while [ "$i" -lt "$NTEX" ]; do
    # Each image its own: a pattern, a tint and grain of its own.
    if [ $((i % 2)) = 0 ]; then src=bricks.ppm ext=png; else src=planet.ppm ext=jpg; fi
    tint=$(awk -v i="$i" 'BEGIN { printf "%.3f,%.3f,%.3f", 0.7 + (i * 37 % 30) / 100, 0.7 + (i * 53 % 30) / 100, 0.7 + (i * 71 % 30) / 100 }')
    oiiotool "$D/$src" --resize "${TEX_SIZE}x$TEX_SIZE" --mulc "$tint" \
        --pattern "noise:type=gaussian:mean=0:stddev=0.04:seed=$i" "${TEX_SIZE}x$TEX_SIZE" 3 --add \
        -d uint8 -o "$D/tex$i.$ext" || exit 1
    i=$((i + 1))
done
T8=$((NTEX * TEX_SIZE * TEX_SIZE * 3))
FILES=$(du -cb "$D"/tex*.* 2>/dev/null | tail -n 1 | cut -f1)
# The distinct triangles: half a terrain, a quarter each a sphere and a knot.
bin/gen/genmesh terrain --tris $((TRIS / 2)) -o "$D/terrain.obj" >/dev/null &&
    bin/gen/genmesh sphere --tris $((TRIS / 4)) -o "$D/sphere.obj" >/dev/null &&
    bin/gen/genmesh knot --p 3 --q 7 --tris $((TRIS / 4)) -o "$D/knot.obj" >/dev/null &&
    bin/gen/genmesh knot --tris "$MESH_TRIS" -o "$D/tree.obj" >/dev/null || exit 1
echo "generated in $(since "$t0") s: $NTEX textures of ${TEX_SIZE}x$TEX_SIZE ($(mib "$T8") MiB of 8-bit texels," \
     "$(mib "${FILES:-0}") MiB of PNG/JPEG), $TRIS distinct triangles, $INSTANCES instances of a $MESH_TRIS-triangle knot"

# scene OUT TEXTURES MESHES INSTANCES FLAT: a JSON scene of the first
# TEXTURES images (each on a quad of a wall behind, and on the ground and
# the distinct meshes), the distinct meshes when MESHES is 1, INSTANCES
# placements of the knot on a grid (one `mesh` shape each when FLAT is 1).
scene() {
    awk -v ntex="$2" -v meshes="$3" -v n="$4" -v flat="$5" -v inst="$INSTANCES" '
    function tex(k) { return ntex ? sprintf("\"t%d\"", k % ntex) : "[0.6, 0.6, 0.55]" }
    BEGIN {
        s = int(sqrt(inst)); if (s * s < inst) s++; if (s < 4) s = 4
        printf "{\"image\": {\"width\": 320, \"height\": 180, \"spp\": 4},\n"
        printf " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, 0, %g], \"fov\": 55},\n",
               s * 0.5, s * 0.45, -s * 0.35, s * 0.5, s * 0.55
        printf " \"textures\": {"
        for (k = 0; k < ntex; k++)
            printf "%s\n  \"t%d\": {\"type\": \"image\", \"file\": \"tex%d.%s\"}", (k ? "," : ""), k, k, (k % 2 ? "jpg" : "png")
        printf "},\n \"materials\": {\"plain\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.7, 0.7]}"
        for (k = 0; k < (ntex ? ntex : 1); k++)
            printf ",\n  \"m%d\": {\"type\": \"lambert\", \"albedo\": %s}", k, tex(k)
        printf "},\n \"lights\": [{\"type\": \"sun\", \"direction\": [-1, -2, 1], \"irradiance\": [3, 3, 3]},\n"
        printf "  {\"type\": \"sun\", \"direction\": [1, -1, 2], \"irradiance\": [0.8, 0.9, 1.1]}],\n"
        printf " \"shapes\": [{\"type\": \"quad\", \"material\": \"m0\", \"vertices\": [[%g, 0, %g], [%g, 0, %g], [%g, 0, %g], [%g, 0, %g]]}",
               -2, -2, -2, s + 2, s + 2, s + 2, s + 2, -2
        # The wall: a quad per image.
        for (k = 0; k < ntex; k++) {
            x0 = -2 + (s + 4) * k / ntex; x1 = -2 + (s + 4) * (k + 1) / ntex
            printf ",\n  {\"type\": \"quad\", \"material\": \"m%d\", \"vertices\": [[%g, 0, %g], [%g, %g, %g], [%g, %g, %g], [%g, 0, %g]]}",
                   k, x1, s + 2, x1, s * 0.4, s + 2, x0, s * 0.4, s + 2, x0, s + 2
        }
        if (meshes) {
            printf ",\n  {\"type\": \"mesh\", \"file\": \"terrain.obj\", \"material\": \"m%d\", \"scale\": [%g, %g, %g], \"translate\": [%g, 0, %g]}",
                   1 % (ntex ? ntex : 1), s * 0.5, s * 0.15, s * 0.2, s * 0.5, s + 0.5
            printf ",\n  {\"type\": \"mesh\", \"file\": \"sphere.obj\", \"material\": \"m%d\", \"scale\": %g, \"translate\": [%g, %g, %g]}",
                   2 % (ntex ? ntex : 1), s * 0.06, s * 0.25, s * 0.07, s * 0.1
            printf ",\n  {\"type\": \"mesh\", \"file\": \"knot.obj\", \"material\": \"m%d\", \"scale\": %g, \"translate\": [%g, %g, %g]}",
                   3 % (ntex ? ntex : 1), s * 0.06, s * 0.75, s * 0.07, s * 0.1
        }
        if (n > 0 && !flat) printf ",\n  {\"type\": \"mesh\", \"file\": \"tree.obj\", \"material\": \"plain\", \"instances\": ["
        for (i = 0; i < n; i++) {
            t = sprintf("\"translate\": [%d.5, 0.35, %d.5], \"rotate\": [0, %d, 0], \"scale\": %g",
                        i % s, int(i / s), (i * 37) % 360, 0.3 + (i % 5) * 0.03)
            if (flat) printf ",\n  {\"type\": \"mesh\", \"file\": \"tree.obj\", \"material\": \"plain\", %s}", t
            else printf "%s\n    {%s}", (i ? "," : ""), t
        }
        if (n > 0 && !flat) printf "]}"
        printf "]}\n"
    }' >"$D/$1"
}

# compile NAME JSON: sets SZ (bytes), CT (s), CR (peak RSS, bytes), CSUM
# (the compile's summary line).
compile() {
    /usr/bin/time -f "%e %M" -o "$FH/time" bin/franja compile "$D/$2" -o "$D/$1.fbin" >"$FH/clog" 2>&1 ||
        { cat "$FH/clog"; exit 1; }
    CT=$(cut -d' ' -f1 "$FH/time") CR=$(($(cut -d' ' -f2 "$FH/time") * 1024))
    SZ=$(stat -c %s "$D/$1.fbin")
    CSUM=$(grep 'primitives' "$FH/clog" | sed 's/^[^:]*: scene [0-9a-f]*, //')
}
# nodes/blocks of the last compile's scene tree
tree_bytes() {
    echo "$CSUM" | awk '{ for (i = 1; i < NF; i++) { if ($(i + 1) == "BVH") nd = $i; if ($(i + 1) == "leaf") bl = $i }
                          b = int((nd * 256 + 63) / 64) * 64 + bl * 160
                          if (b < 4194304) b = 0; else b = int((b + 2097151) / 2097152) * 2097152
                          print b }'
}

# ---- constants of the memory formula, on small scenes ------------------
echo "-- constants (small scenes)"

bin/gen/genmesh terrain --tris 100000 -o "$D/cal.obj" >/dev/null || exit 1
printf '{"image": {"width": 64, "height": 64, "spp": 1}, "camera": {"position": [0, 1, -3], "target": [0, 0, 0], "fov": 40},
 "materials": {"m": {"type": "lambert", "albedo": [0.5, 0.5, 0.5]}}, "lights": [{"type": "sun", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}],
 "shapes": [{"type": "quad", "material": "m", "vertices": [[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1]]}%s]}\n' "" >"$D/cal0.json"
sed 's/\]}$/, {"type": "mesh", "file": "cal.obj", "material": "m"}]}/' "$D/cal0.json" >"$D/calt.json"
awk 'BEGIN { printf "{\"type\": \"mesh\", \"file\": \"tree.obj\", \"material\": \"m\", \"instances\": ["
             for (i = 0; i < 2000; i++) printf "%s{\"translate\": [%d, 0, %d]}", (i ? ", " : ""), i % 50, int(i / 50)
             printf "]}" }' >"$D/inst.part"
awk -v p="$(cat "$D/inst.part")" '{ sub(/\]}$/, ", " p "]}"); print }' "$D/cal0.json" >"$D/cali.json"
awk -v p="$(cat "$D/inst.part")" '{ sub(/\]}$/, ", {\"type\": \"mesh\", \"file\": \"tree.obj\", \"material\": \"m\"}]}"); print }' "$D/cal0.json" >"$D/calm.json"
oiiotool "$D/bricks.ppm" --resize 1024x1024 -d uint8 -o "$D/cal.png" || exit 1
sed 's/"materials": {"m": {"type": "lambert", "albedo": \[0.5, 0.5, 0.5\]}}/"textures": {"c": {"type": "image", "file": "cal.png"}}, "materials": {"m": {"type": "lambert", "albedo": "c"}}/' \
    "$D/cal0.json" >"$D/calx.json"
compile cal0 cal0.json; F0=$SZ
compile calt calt.json; CTRI=$(calc "($SZ - $F0) / $(echo "$CSUM" | sed -n 's/.*(\([0-9]*\) triangles).*/\1/p')" 1)
compile calm calm.json; FM=$SZ
compile cali cali.json; CINST=$(calc "($SZ - $FM) / 2000" 1)
compile calx calx.json; CTEX=$(calc "($SZ - $F0) / (1024 * 1024)" 2)
# A worker's own memory: its RSS on the smallest scene less the scene.
/usr/bin/time -f "%M" -o "$FH/time" bin/franja-worker --scene "$D/cal0.fbin" --rows 0:1 --size "${W}x1" --spp 1 -o "$FH/w.pfm" ||
    exit 1
W0=$(($(cat "$FH/time") * 1024 - F0))
echo "fbin bytes = $F0 + $CTRI x triangles + $CINST x instances + $CTEX x texels;" \
     "worker private = $W0 + tree copy + 12 x width x slab rows (bytes)"

# ---- compiles ----------------------------------------------------------
echo "-- compile (wall s, peak RSS, .fbin)"
scene prod.json "$NTEX" 1 "$INSTANCES" 0
scene tex.json "$NTEX" 0 0 0
scene inst.json 0 0 "$INSTANCES" 0
compile tex tex.json
FT=$SZ
TEXGOAL=$(calc "$T8 * 4 / 3 * 1.4" 0)
echo "textures alone: $CT s, $(mib "$CR") MiB, .fbin $(mib "$FT") MiB = $(calc "$FT / ($T8 + 1)" 2) x the 8-bit texels" \
     "| goal: .fbin <= 1.4 x 8-bit texels with mip-maps = $(mib "$TEXGOAL") MiB: $(verdict "$(calc "$FT <= $TEXGOAL" 0)")"
compile inst inst.json
echo "instances alone: $INSTANCES x $MESH_TRIS triangles: $CT s, $(mib "$CR") MiB, .fbin $(mib "$SZ") MiB" \
     "| goal: 10^4 instances < 10 s and < 1 GB: $(verdict "$(calc "$CT < 10 && $CR < 1e9" 0)")"
compile prod prod.json
F=$SZ
TREE=$(tree_bytes)
PRED=$(calc "$F0 + $CTRI * ($TRIS + $MESH_TRIS) + $CINST * $INSTANCES + $CTEX * $NTEX * $TEX_SIZE * $TEX_SIZE" 0)
echo "whole scene: $CT s, $(mib "$CR") MiB, .fbin $(mib "$F") MiB ($CSUM)" \
     "| goal: compile peak RSS <= 2 x .fbin: $(calc "$CR / $F" 2) x, $(verdict "$(calc "$CR <= 2 * $F" 0)")"
echo "  .fbin from the formula: $(mib "$PRED") MiB ($(calc "$PRED / $F" 3) x the measured)"

# ---- worker start-up ---------------------------------------------------
cs="" rs=""
i=0
while [ $i -lt "$REPS" ]; do
    s=$(now); bin/franja-worker --scene "$D/prod.fbin" --check >/dev/null || exit 1; cs="$cs $(since "$s")"
    s=$(now); bin/franja-worker --scene "$D/prod.fbin" --rows 0:1 --size "$SIZE" --spp 1 -o "$FH/row.pfm" || exit 1
    rs="$rs $(since "$s")"
    i=$((i + 1))
done
echo "-- worker start-up (page cache warm): --check $(median $cs) s (runs:$cs), first row at 1 spp $(median $rs) s (runs:$rs)"

# ---- render over fake SSH hosts ----------------------------------------
# (fh_start uses i, n, d of its own: this loop counts in k.)
k=1
while [ $k -le "$HOSTS" ]; do
    fh_start "h$k" $((k + 1)) "$WORKERS" || exit 1
    k=$((k + 1))
done
# sample HOST OUT: every 0.1 s, the host's workers' memory from smaps_rollup:
# "workers sumPss sumRss maxAnonymous maxRss host" in kB, one line per
# instant.  A worker's private memory is its anonymous pages (the .fbin's
# pages count as private too while one worker alone maps them); the host's
# is the most file pages one worker maps (the one copy in the page cache)
# plus every worker's anonymous pages.  The PSS sum is a cross-check: the
# workers are read one after another, so one that ends between two reads
# can leave the scene counted up to twice.
sample() {
    while [ ! -e "$FH/stop" ]; do
        for p in $(fh_pids "$1" --rows); do
            [ "$(cat "/proc/$p/comm" 2>/dev/null)" = franja-worker ] && cat "/proc/$p/smaps_rollup" 2>/dev/null && echo "--"
        done | awk '/^Rss:/ { r = $2 } /^Pss:/ { ps += $2 } /^Anonymous:/ { pr += $2 }
                    /^--/ { n++; sr += r; sa += pr; if (pr > mp) mp = pr; if (r > mr) mr = r
                            if (r - pr > mf) mf = r - pr; pr = 0 }
                    END { if (n) print n, ps, sr, mp, mr, mf + sa }'
        sleep 0.1
    done >"$2"
}
rm -f "$FH/stop"
sample h1 "$FH/mem1" &
SAMPLER=$!
s=$(now)
/usr/bin/time -f "%e %M" -o "$FH/ctime" env -u SSH_AUTH_SOCK bin/franja render "$D/prod.fbin" -o "$FH/prod.pfm" \
    --size "$SIZE" --spp "$SPP" --hosts "$FH/hosts" --known-hosts "$FH/known_hosts" --no-ssh-config --timeout 30 2>"$FH/r1" ||
    { cat "$FH/r1"; exit 1; }
T1=$(since "$s")
: >"$FH/stop"
wait "$SAMPLER"
CRSS=$(($(cut -d' ' -f2 "$FH/ctime") * 1024))
s=$(now)
fr render "$D/prod.fbin" -o "$FH/prod2.pfm" --size "$SIZE" --spp "$SPP" --hosts "$FH/hosts" --timeout 30 2>"$FH/r2" ||
    { cat "$FH/r2"; exit 1; }
T2=$(since "$s")
# bytes TEXT: "123 B", "4.5 KiB", "1.2 MiB" as a number of bytes
bytes() { echo "$1" | awk '{ m = $2 == "KiB" ? 1024 : $2 == "MiB" ? 1048576 : $2 == "GiB" ? 1073741824 : 1; printf "%d\n", $1 * m }'; }
echo "-- render $SIZE at $SPP spp on $HOSTS fake SSH hosts x $WORKERS slots"
echo "first (scene sent): $(calc "$T1" 2) s wall ($(sed -n 's/^franja: \([0-9x]* at [0-9]* spp in [0-9.]* s\).*/\1/p' "$FH/r1") of rendering);" \
     "second (scene cached): $(calc "$T2" 2) s wall"
k=1
while [ $k -le "$HOSTS" ]; do
    t=$(awk -v h="h$k" '$1 == h && $NF == "ok" { print $(NF - 2), $(NF - 1) }' "$FH/r1")
    b=$(bytes "$t")
    echo "h$k: sent $t ($(calc "$b / $F" 3) x the .fbin)" \
         "| goal: <= half the .fbin for a textured scene: $(verdict "$(calc "$b <= $F / 2" 0)")"
    k=$((k + 1))
done

# Packing alone (what the first host waits for) and unpacking on a host.
echo "-- packing at PACK_LEVEL (bin/bench/packbench, medians of $REPS; unpacked scene checked byte for byte)"
bin/bench/packbench "$D/prod.fbin" "$REPS" || exit 1

# ---- memory ------------------------------------------------------------
ROWS=$(sed -n 's/.*[^0-9]\([0-9][0-9]*\) slabs.*/\1/p' "$FH/r1" | head -n 1)
SLAB=$(calc "($H + ${ROWS:-1} - 1) / ${ROWS:-1}" 0)
[ "$SLAB" -lt 1 ] && SLAB=1
if [ -s "$FH/mem1" ]; then
    set -- $(awk '{ if ($6 > hm) { hm = $6; n = $1 } if ($2 > ps) ps = $2; if ($4 > mp) mp = $4; if ($5 > mr) mr = $5
                    if ($1 > nw) nw = $1 }
                  END { print n + 0, hm * 1024, mp * 1024, mr * 1024, nw + 0, NR, ps * 1024 }' "$FH/mem1")
    WPRED=$(calc "$W0 + $TREE + 12 * $W * $SLAB" 0)
    HPRED=$(calc "$F + $WORKERS * $WPRED" 0)
    echo "-- memory ($6 samples of h1; slabs of about $SLAB rows)"
    echo "host h1: peak of its workers $(mib "$2") MiB (file pages + anonymous; $1 running then, up to $5;" \
         "largest PSS sum $(mib "$7") MiB); formula .fbin + $WORKERS x private = $(mib "$F") + $WORKERS x $(mib "$WPRED")" \
         "= $(mib "$HPRED") MiB ($(calc "$2 / $HPRED" 3) x)"
    echo "a worker: peak RSS $(mib "$4") MiB, peak anonymous (private) $(mib "$3") MiB; formula private" \
         "$(mib "$W0") + tree copy $(mib "$TREE") + slab $(mib "$(calc "12 * $W * $SLAB" 0)") = $(mib "$WPRED") MiB"
else
    echo "-- memory: no worker was sampled on h1 (the render was too short)"
fi
CPRED=$(calc "$F + 12 * $W * $H" 0)
echo "coordinator: peak RSS $(mib "$CRSS") MiB; .fbin (mapped) + 12 x width x height = $(mib "$CPRED") MiB" \
     "(the rest, $(mib "$((CRSS - CPRED))") MiB, the process's own)"

# ---- the image against the flattened scene -----------------------------
echo "-- instanced against flattened"
if [ $((INSTANCES * MESH_TRIS)) -le "$FLAT_MAX" ]; then
    scene flat.json "$NTEX" 1 "$INSTANCES" 1
    A=prod what="the whole scene"
else
    n=$((FLAT_MAX / MESH_TRIS))
    scene inst2.json 0 0 "$n" 0
    scene flat.json 0 0 "$n" 1
    compile inst2 inst2.json
    A=inst2 what="$n instances alone (the whole scene's $((INSTANCES * MESH_TRIS)) triangles flattened exceed FLAT_MAX)"
fi
compile flat flat.json
echo "flattened: compile $CT s, $(mib "$CR") MiB, .fbin $(mib "$SZ") MiB"
bin/franja-worker --scene "$D/$A.fbin" --rows "0:$H" --size "$SIZE" --spp "$SPP" -o "$FH/a.pfm" &&
    bin/franja-worker --scene "$D/flat.fbin" --rows "0:$H" --size "$SIZE" --spp "$SPP" -o "$FH/b.pfm" || exit 1
echo "$what: $(bin/tools/imgstat "$FH/a.pfm" --diff "$FH/b.pfm")"
echo "  imgcmp: $(bin/tools/imgcmp "$FH/a.pfm" "$FH/b.pfm" 2>&1 | tail -n 1)"
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
