#!/bin/sh
# it_mlt.sh -- tests Metropolis renders are the same bytes for any split.
#
# Metropolis light transport through the band renderer: row y of the image
# stands for chain y, so a slab is a range of chains whose splats cover the
# whole image.  The stitched image is byte-identical for any slab height,
# any number of worker processes, local or over fake SSH hosts; the
# normalisation is computed once, by the coordinator, and handed to every
# worker (one left to compute it gets the same bits), which covers only
# the paths of more than one bounce (the shorter ones are bidirectional
# samples of each slab's rows); a resumed
# job renders only the lost chains, to the same bytes; --time-limit writes
# its last complete pass, the bytes of a render asked for its mutations,
# as bright as the whole render; franja stitch adds a kept job's splats;
# what MLT cannot do is refused with the reason.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
W=24 H=21
SIZE="--size ${W}x$H --spp 8"
M="--integrator mlt"
"$FRANJA" compile "$ROOT/scenes/spheres.json" -o scene.fbin 2>/dev/null
check "the spheres scene compiles" test -s scene.fbin

"$FRANJA" render scene.fbin -o one.pfm $SIZE $M -j 1 --slab-rows $H 2>log1
check "one slab: a Metropolis render succeeds" test -s one.pfm
check "one slab: 1 slab" grep -q "; 1 slabs" log1
for n in 2 7; do
    rows=$(((H + n - 1) / n))
    "$FRANJA" render scene.fbin -o s$n.pfm $SIZE $M -j 2 --slab-rows $rows 2>log$n
    check "$n slabs: $n slabs were rendered" grep -q "; $n slabs" log$n
    check "$n slabs give the bytes of one" cmp -s s$n.pfm one.pfm
done
"$FRANJA" render scene.fbin -o bd.pfm $SIZE --integrator bdpt -j 2 2>/dev/null
check "bdpt gives another image" sh -c "! cmp -s bd.pfm one.pfm"

# Over fake SSH hosts, the slabs finishing in whatever order.
fh_start a 2 2
fh_start b 3 3
for rows in 3 8; do
    fr render scene.fbin -o ssh$rows.pfm --hosts hosts $SIZE $M --slab-rows $rows 2>logs$rows
    check "$rows-row slabs over 2 SSH hosts give the same bytes" cmp -s ssh$rows.pfm one.pfm
done

# --time-limit: passes of 1, 2, 4, 8 mutations per pixel, each the render
# of its mutations with their own normalisation; the last complete pass is
# written.  A pass that must not end is held by a worker that never
# answers its last chains, so nothing depends on how fast the machine is.
"$FRANJA" render scene.fbin -o t8.pfm $SIZE $M -j 2 --time-limit 1h 2>logt8
check "--time-limit with room for every pass: passes of 1, 2, 4 and 8 mutations" \
    sh -c "sed -n 's/.*pass [0-9]* done: \([0-9]*\) samples.*/\1/p' logt8 | tr '\n' ' ' | grep -qx '1 2 4 8 '"
check "and the bytes of 8 at once" cmp -s t8.pfm one.pfm
fr render scene.fbin -o t8s.pfm --hosts hosts $SIZE $M --slab-rows 4 --time-limit 1h 2>/dev/null
check "the same bytes over 2 SSH hosts" cmp -s t8s.pfm one.pfm
cat >stuck.sh <<SH
#!/bin/sh
prev= spp=0 rows=
for a in "\$@"; do
    [ "\$prev" = --spp ] && spp=\$a
    [ "\$prev" = --rows ] && rows=\$a
    prev=\$a
done
if [ "\$spp" -ge 4 ] && [ "\$rows" = 14:21 ]; then exec sleep 7$$; fi
exec "$WORKER" "\$@"
SH
chmod +x stuck.sh
printf 'here local - 2 worker=%s/stuck.sh\n' "$FH" >t_stuck
"$FRANJA" render scene.fbin -o ts.pfm $SIZE $M --hosts t_stuck --slab-rows 7 --time-limit 3s --job tj --keep-job \
    2>logts
rc=$?
check "a Metropolis render stopped by its time limit succeeds (status $rc)" test $rc -eq 0
check "no stuck worker is left" sh -c "! pgrep -x -f 'sleep 7$$' >/dev/null"
N=$(sed -n 's/.*time limit of 3 s reached: \([0-9]*\) samples per pixel (the pass to 4 was stopped).*/\1/p' logts)
case $N in 1 | 2) ok ;; *) bad "stopped at '$N' mutations per pixel, where the pass to 4 cannot end" ;; esac
"$FRANJA" render scene.fbin -o tn.pfm --size ${W}x$H --spp "${N:-0}" $M -j 1 2>/dev/null
check "its image is the bytes of a render asked for its ${N:-0} mutations per pixel" cmp -s ts.pfm tn.pfm
# The chains of an MLT image add exactly the b of the longer paths,
# whatever their mutations; the short paths are N bidirectional samples a
# pixel, whose mean over this small image moves by up to a fifth at N = 1
# or 2 (BDPT at 1 spp: 0.106 against 0.127).  So the stopped render is as
# bright as path tracing within that noise (its bytes are a plain render's
# of its N, checked above).
lum() { "$ROOT/bin/tools/imgstat" "$1" | tr ' ' '\n' | awk -F= '$1 == "r" { r = $2 } $1 == "g" { g = $2 }
    $1 == "b" { b = $2 } END { printf "%.6f", 0.2126 * r + 0.7152 * g + 0.0722 * b }'; }
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { exit !(a > 0 && b > 0 && a / b > 1 - t && a / b < 1 + t) }'; }
"$FRANJA" render scene.fbin -o pt.pfm --size ${W}x$H --spp 64 -j 2 2>/dev/null
check "the stopped render's mean luminance $(lum ts.pfm) is path tracing's $(lum pt.pfm) within 35 %" \
    near "$(lum ts.pfm)" "$(lum pt.pfm)" 0.35
check "and the whole render's $(lum one.pfm) is path tracing's within 5 %" near "$(lum one.pfm)" "$(lum pt.pfm)" 0.05
# A complete pass makes the slabs of fewer mutations useless, and the
# chains of the stopped pass that ended stay: resumed, the first pass
# renders only the chains it lacks (with other slabs: the job then holds
# passes of two sample counts side by side, and each pass's image is
# stitched from its own slabs only).
check "the stopped job keeps no slab of fewer than ${N:-0} mutations" \
    sh -c "for f in tj/rows-*.pf; do head -n 2 \$f | grep -Eq ' spp=(${N:-0}|$((2 * ${N:-0}))) ' || exit 1; done"
R=0 # chains kept of the stopped pass
for f in tj/rows-*.pf; do
    rows=$(head -n 2 "$f" | sed -n "s/.* rows=\([0-9]*\):\([0-9]*\) spp=$((2 * ${N:-0})) .*/\2 - \1/p")
    R=$((R + ${rows:-0}))
done
"$FRANJA" render scene.fbin -o tr.pfm $SIZE $M -j 2 --slab-rows 3 --time-limit 1h --job tj --resume 2>logtr
check "the first renders the $((H - R)) chains the stopped pass left" \
    grep -q "pass 1: $((2 * ${N:-0})) samples per pixel, $((H - R)) rows to render" logtr
check "to 8, the passes of 1 not rendered again" sh -c "grep -q 'pass [0-9]* done: 8 samples' logtr &&
    ! grep -q 'pass [0-9]*: 1 samples' logtr"
check "the bytes of 8 at once" cmp -s tr.pfm one.pfm
check "no slab discarded" sh -c "! grep -q discarded logtr"

# The partial image: its rows (the short paths' own radiance), then the
# splats of its short paths and chains over the whole image.
"$WORKER" --scene scene.fbin --rows 5:9 $SIZE $M -o part.pf
check "the header counts the slab's mutations and hashes the splats" \
    sh -c "head -n 2 part.pf | grep -Eq '^# franja scene=[0-9a-f]{16} rows=5:9 spp=8 size=${W}x$H splat=$((W * 4 * 8)):[0-9a-f]{16}\$'"

# A job interrupted (slabs lost), resumed with another slab height: only
# the lost chains are rendered, to the bytes of the uninterrupted render.
"$FRANJA" render scene.fbin -o keep.pfm $SIZE $M -j 2 --slab-rows 7 --job kj --keep-job 2>/dev/null
check "a kept job gives the same bytes" cmp -s keep.pfm one.pfm
check "its job file names the integrator" grep -q "integrator=mlt" kj/job
rm -f kj/rows-00007-00014.pf
"$FRANJA" render scene.fbin -o keep2.pfm $SIZE $M -j 2 --slab-rows 2 --job kj --resume --keep-job 2>logk
check "a resume with 2-row slabs renders only the lost chains" grep -q "; 4 slabs" logk
check "and gives the bytes of the uninterrupted render" cmp -s keep2.pfm one.pfm
check "the normalisation is computed once per render, not per slab" \
    test "$(grep -c 'Metropolis normalisation: b = ' logk)" -eq 1

# The coordinator hands its normalisation to every worker (--mlt-norm); a
# worker without it computes the same bits itself, and one given other
# numbers renders another image.
"$WORKER" --scene scene.fbin --rows 0:7 $SIZE $M -o own.pf
check "a worker's own normalisation gives the job's slab, byte for byte" cmp -s own.pf kj/rows-00000-00007.pf
ones=3f800000,3f800000,3f800000,3f800000,3f800000,3f800000,3f800000,3f800000,3f800000
"$WORKER" --scene scene.fbin --rows 0:7 $SIZE $M --mlt-norm $ones -o ones.pf
check "a worker uses the normalisation it is given" sh -c "test -s ones.pf && ! cmp -s ones.pf own.pf"
# Veach's split: depths 0 and 1 are bidirectional samples of the slab's
# rows, the chains cover only the longer paths, so b_0 and b_1 change
# nothing, b_2 does.
z=00000000
"$WORKER" --scene scene.fbin --rows 0:7 $SIZE $M --mlt-norm $z,$z,$z,$z,$z,$z,$z,$z,$z -o z.pf
"$WORKER" --scene scene.fbin --rows 0:7 $SIZE $M --mlt-norm 3f800000,3f800000,$z,$z,$z,$z,$z,$z,$z -o z01.pf
"$WORKER" --scene scene.fbin --rows 0:7 $SIZE $M --mlt-norm $z,$z,3f800000,$z,$z,$z,$z,$z,$z -o z2.pf
check "the chains leave depths 0 and 1 to bidirectional samples" cmp -s z.pf z01.pf
check "and render depth 2" sh -c "test -s z2.pf && ! cmp -s z.pf z2.pf"
"$WORKER" --scene scene.fbin --rows 7:14 $SIZE $M --mlt-norm 3f800000 -o x.pf 2>e0
check "a normalisation of the wrong number of depths is refused (status 2)" test $? -eq 2
check "saying how many it expects" grep -q "1 values for mlt, expected 9" e0
"$FRANJA" stitch kj -o st.pfm >/dev/null 2>logst
check "franja stitch of a complete Metropolis job: the same bytes" cmp -s st.pfm one.pfm
"$FRANJA" render scene.fbin -o other.pfm $SIZE --integrator bdpt -j 2 --job kj --resume 2>logo
check "a Metropolis job directory is not resumed by a bidirectional render" grep -q "belongs to another render" logo

# What MLT cannot do is refused, with the reason.
"$WORKER" --scene scene.fbin --rows 0:5 $SIZE $M --format ppm8 -o x.ppm 2>e1
check "an sRGB slab of a Metropolis render is refused (status 2)" test $? -eq 2
check "because every chain adds light to every row" grep -q "every Metropolis chain" e1
"$FRANJA" compile "$ROOT/scenes/fog-room.json" -o fog.fbin 2>/dev/null
"$WORKER" --scene fog.fbin --rows 0:4 --size 8x8 --spp 1 $M -o f.pf 2>e3
check "a scene with media is refused by the worker (status 2)" test $? -eq 2
check "with the reason" grep -q "Metropolis light transport.*participating media" e3
"$FRANJA" render fog.fbin -o f.png --size 8x8 --spp 1 $M 2>e4
check "and by franja render (status 2)" test $? -eq 2
check "before rendering anything" sh -c "grep -q 'participating media' e4 && ! grep -q Msamples e4"
"$FRANJA" render scene.fbin -o t.pfm $SIZE $M --noise-threshold 0.1 2>e6
check "--noise-threshold is refused (status 2)" test $? -eq 2
check "as adaptive sampling is for path tracing" grep -q "not mlt" e6
sed 's/"max_depth": 8,/"max_depth": 8, "integrator": "mlt",/' "$ROOT/scenes/spheres.json" >sm.json
"$FRANJA" render sm.json -o sm.pfm $SIZE -j 2 2>/dev/null
pixels=$((W * H * 12))
check "image.integrator mlt renders as --integrator mlt" \
    sh -c "tail -c $pixels sm.pfm | cmp -s - \$0" "$(tail -c $pixels one.pfm >one.px; echo one.px)"

summary
