#!/bin/sh
# it_bdpt.sh -- tests bidirectional renders stitch alike for any split.
#
# Bidirectional renders through the band renderer.  Light tracing adds
# light to rows outside the slab that traced it, yet the stitched image is
# byte-identical for 1, 2, 3 and 7 slabs, any number of worker processes,
# local or over fake SSH hosts, whatever order slabs finish in.  Partial
# images carry their splats (splat=<paths>:<hash>) and are checked; the
# worker and the coordinator refuse what bidirectional tracing cannot do.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
W=24 H=21
SIZE="--size ${W}x$H --spp 4"
B="--integrator bdpt"
"$FRANJA" compile "$ROOT/scenes/spheres.json" -o scene.fbin 2>/dev/null
check "the spheres scene compiles" test -s scene.fbin

"$FRANJA" render scene.fbin -o one.pfm $SIZE $B -j 1 --slab-rows $H 2>log1
check "one slab: a bidirectional render succeeds" test -s one.pfm
check "one slab: 1 slab" grep -q "; 1 slabs" log1
for n in 2 3 7; do
    rows=$(((H + n - 1) / n))
    "$FRANJA" render scene.fbin -o s$n.pfm $SIZE $B -j 3 --slab-rows $rows 2>log$n
    check "$n slabs: $n slabs were rendered" grep -q "; $n slabs" log$n
    check "$n slabs give the bytes of one" cmp -s s$n.pfm one.pfm
done
"$FRANJA" render scene.fbin -o j1.pfm $SIZE $B -j 1 --slab-rows 3 2>/dev/null
check "7 slabs in one process, in order, give the same bytes" cmp -s j1.pfm one.pfm
"$FRANJA" render scene.fbin -o path.pfm $SIZE -j 2 2>/dev/null
check "path tracing gives another image" sh -c "! cmp -s path.pfm one.pfm"

# The scene's own "integrator" (the .fbin setting) is the default.
sed 's/"max_depth": 8,/"max_depth": 8, "integrator": "bdpt",/' "$ROOT/scenes/spheres.json" >sb.json
"$FRANJA" render sb.json -o sb.pfm $SIZE -j 2 2>/dev/null
pixels=$((W * H * 12))
check "image.integrator bdpt renders as --integrator bdpt" \
    sh -c "tail -c $pixels sb.pfm | cmp -s - \$0" "$(tail -c $pixels one.pfm >one.px; echo one.px)"
"$FRANJA" render sb.json -o sp.pfm $SIZE -j 2 --integrator path 2>/dev/null
check "--integrator path overrides the scene's" \
    sh -c "tail -c $pixels sp.pfm | cmp -s - \$0" "$(tail -c $pixels path.pfm >path.px; echo path.px)"

# Over fake SSH hosts, the slabs finishing in whatever order.
fh_start a 2 2
fh_start b 3 3
fh_start c 4 1
for rows in 3 7 11; do
    fr render scene.fbin -o ssh$rows.pfm --hosts hosts $SIZE $B --slab-rows $rows 2>logs$rows
    check "$rows-row slabs over 3 SSH hosts give the same bytes" cmp -s ssh$rows.pfm one.pfm
done

# A worker that cuts its output once: the slab is retried, splats and all.
mkdir -p loc1
printf 'here local - 2 worker=%s\n' "$(fh_wrapper loc1 truncate)" >t_trunc
"$FRANJA" render scene.fbin -o trunc.pfm $SIZE $B --slab-rows 3 --hosts t_trunc 2>logt
check "a truncated bidirectional partial is retried" cmp -s trunc.pfm one.pfm
check "and reported" grep -q "bad partial image" logt

# The partial image: its rows, then the whole image's splats.
"$WORKER" --scene scene.fbin --rows 5:9 $SIZE $B -o part.pf
check "the header counts the light subpaths and hashes the splats" \
    sh -c "head -n 2 part.pf | grep -Eq '^# franja scene=[0-9a-f]{16} rows=5:9 spp=4 size=${W}x$H splat=$((W * 4 * 4)):[0-9a-f]{16}\$'"
header=$(head -n 4 part.pf | wc -c)
check "rows and splats have their sizes" test "$(wc -c <part.pf)" -eq $((header + W * 4 * 12 + W * H * 24))
"$WORKER" --scene scene.fbin --rows 5:9 $SIZE -o ppart.pf
check "a path-traced partial has no splats" sh -c "! grep -q splat= ppart.pf"

# A damaged splat block in a kept slab is found on --resume and redone.
"$FRANJA" render scene.fbin -o keep.pfm $SIZE $B -j 2 --slab-rows 7 --job kj --keep-job 2>/dev/null
slab=$(ls kj/rows-*.pf | head -n 1)
size=$(wc -c <"$slab")
printf 'X' | dd of="$slab" bs=1 seek=$((size - 5)) conv=notrunc 2>/dev/null
"$FRANJA" render scene.fbin -o keep.pfm $SIZE $B -j 2 --slab-rows 7 --job kj --resume --keep-job 2>logk
check "a damaged splat block is discarded" grep -q "discarded.*splat block does not match" logk
check "and the slab rendered again, to the same bytes" cmp -s keep.pfm one.pfm
"$FRANJA" render scene.fbin -o other.pfm $SIZE -j 2 --job kj --resume 2>logo
check "a bidirectional job directory is not resumed by a path-traced render" grep -q "belongs to another render" logo

# A slab lost from a kept job, resumed with another slab height: the new
# slabs fill the gap, and the stitch sums each light subpath once.
"$FRANJA" render scene.fbin -o keep2.pfm $SIZE $B -j 2 --slab-rows 7 --job kj2 --keep-job 2>/dev/null
rm -f kj2/rows-00007-00014.pf
"$FRANJA" render scene.fbin -o keep2.pfm $SIZE $B -j 2 --slab-rows 2 --job kj2 --resume --keep-job 2>logk2
check "a resume with 2-row slabs renders only the lost rows" grep -q "; 4 slabs" logk2
check "and gives the same bytes" cmp -s keep2.pfm one.pfm
check "the kept slabs split the image once" test "$(ls kj2/rows-*.pf | wc -l)" -eq 6
"$FRANJA" stitch kj2 -o st.pfm >/dev/null 2>logst
check "franja stitch of a complete bidirectional job adds the splats: the bytes of one slab" cmp -s st.pfm one.pfm
rm -f kj2/rows-00007-00009.pf
"$FRANJA" stitch kj2 -o st2.pfm >/dev/null 2>logst2
check "franja stitch of an incomplete bidirectional job makes no image" test ! -e st2.pfm
check "and names the missing rows" grep -q "rows 7:9 are missing" logst2
check "and leaves the other slabs alone" test "$(ls kj2/rows-*.pf | wc -l)" -eq 5

# A stuck worker: its slab is started a second time elsewhere and the
# first valid copy wins, its splats counted once.
mkdir -p loc2
printf 'here local - 2 worker=%s\n' "$(fh_wrapper loc2 hang)" >t_hang
timeout 60 "$FRANJA" render scene.fbin -o hang.pfm $SIZE $B --slab-rows 3 --hosts t_hang 2>logh
check "a stuck bidirectional slab is overtaken by a second copy" grep -q "starting a second copy" logh
check "and the image has the bytes of one slab" cmp -s hang.pfm one.pfm

# What bidirectional tracing cannot do is refused, with the reason.
"$WORKER" --scene scene.fbin --rows 0:5 $SIZE $B --format ppm8 -o x.ppm 2>e1
check "an sRGB slab of a bidirectional render is refused (status 2)" test $? -eq 2
check "because light tracing adds light to every row" grep -q "needs the whole image" e1
"$WORKER" --scene scene.fbin --rows 0:$H $SIZE $B --format ppm16 -o whole.ppm 2>/dev/null
check "the whole image in sRGB is fine" test -s whole.ppm
"$WORKER" --scene scene.fbin --rows 0:5 $SIZE --integrator bogus -o x.pf 2>e2
check "an unknown integrator is refused (status 2)" test $? -eq 2
check "and named" grep -q "expected path, bdpt or mlt, got 'bogus'" e2
"$FRANJA" compile "$ROOT/scenes/fog-room.json" -o fog.fbin 2>/dev/null
"$WORKER" --scene fog.fbin --rows 0:4 --size 8x8 --spp 1 $B -o f.pf 2>e3
check "a scene with media is refused by the worker (status 2)" test $? -eq 2
check "with the reason" grep -q "participating media" e3
"$FRANJA" render fog.fbin -o f.png --size 8x8 --spp 1 $B 2>e4
check "and by franja render (status 2)" test $? -eq 2
check "before rendering anything" sh -c "grep -q 'participating media' e4 && ! grep -q Msamples e4"
sed 's/"max_depth": 8,/"max_depth": 8, "integrator": "bidir",/' "$ROOT/scenes/spheres.json" >bad.json
"$FRANJA" compile bad.json -o bad.fbin 2>e5
check "a bad image.integrator is refused at compile time" test $? -ne 0
check "with its JSON path" grep -q "image.integrator" e5

summary
