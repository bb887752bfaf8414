#!/bin/sh
# it_passes.sh -- tests render passes through the coordinator, locally and on fake SSH hosts.
#
# franja render --passes: the multilayer EXR is byte-identical between -j 1,
# -j 2 --slab-rows 5 and fake SSH hosts; oiiotool lists its layers by
# Blender's names and Blender's compositor offers them; the image's bytes
# do not change with passes; PNG and
# PFM outputs get one file per pass; the scene's "passes" key is read;
# --crop, --resume, --time-limit and adaptive sampling work with passes;
# bdpt fills the passes of its camera subpaths, the same bytes on every
# split; its light passes and mlt are refused with a message.
. "$(dirname "$0")/support/fakehosts.sh"
need oiiotool blender
fh_init
cd "$FH" || exit 1
SIZE="--size 40x30 --spp 4"
SCENE="$ROOT/scenes/spheres.json"

"$FRANJA" render "$SCENE" -o j1.exr $SIZE -j 1 --passes all --reproducible 2>log1
check "render with every pass (-j 1)" test $? -eq 0
"$FRANJA" render "$SCENE" -o j2.exr $SIZE -j 2 --slab-rows 5 --passes all --reproducible 2>log2
check "render with every pass (-j 2 --slab-rows 5)" test $? -eq 0
check "-j 2 --slab-rows 5 gives the bytes of -j 1" cmp -s j1.exr j2.exr

fh_start a 2 2
fh_start b 3 3
fr render "$SCENE" -o ssh.exr --hosts hosts $SIZE --passes all --reproducible 2>log3
check "render with every pass on two SSH hosts" test $? -eq 0
check "both hosts rendered slabs" sh -c 'grep -Eq "^  a +[0-9]+ +[1-9]" log3 && grep -Eq "^  b +[0-9]+ +[1-9]" log3'
check "SSH hosts give the bytes of -j 1" cmp -s j1.exr ssh.exr

oiiotool --info -v j1.exr >info 2>&1
for ch in "ViewLayer.Combined.R" "ViewLayer.Combined.A" "ViewLayer.Denoising Albedo.G" \
    "ViewLayer.Denoising Normal.Z" "ViewLayer.Depth.Z" "ViewLayer.Position.X" "ViewLayer.Emit.B" \
    "ViewLayer.DiffDir.R" "ViewLayer.DiffInd.R" "ViewLayer.GlossDir.R" "ViewLayer.GlossInd.R" \
    "ViewLayer.TransDir.R" "ViewLayer.TransInd.R" "ViewLayer.IndexMA.X" "ViewLayer.CryptoMaterial00.R" \
    "ViewLayer.CryptoMaterial02.A" "ViewLayer.Variance.B" "ViewLayer.IndexOB.X" "ViewLayer.CryptoObject00.R" \
    "ViewLayer.CryptoObject02.A" "ViewLayer.Combined_default.B" "ViewLayer.Shadow.G"; do
    check "oiiotool --info -v lists $ch" grep -q "$ch" info
done
check "the EXR has 70 channels" grep -q "70 channel" info
check "the EXR has Cryptomatte's metadata" grep -q 'cryptomatte/[0-9a-f]*/name: "ViewLayer.CryptoMaterial"' info
check "the manifest names the scene's materials" grep -q 'manifest: "{"white":"[0-9a-f]\{8\}","red"' info
check "the material_id name table" grep -q 'franja:materials: "\["white","red","green","light","mirror","glass","phong"\]"' info
check "the EXR names its passes" grep -q 'franja:passes: "albedo,normal,depth' info
check "the EXR has the objects' Cryptomatte metadata" grep -q 'cryptomatte/[0-9a-f]*/name: "ViewLayer.CryptoObject"' info
check "the object manifest names the shapes" grep -q 'manifest: "{"shapes\[0\]":"[0-9a-f]\{8\}","shapes\[1\]"' info
check "the object_id name table" grep -q 'franja:objects: "\["shapes\[0\]","shapes\[1\]",' info

# Blender opens the file as a multilayer EXR: its compositor's Image node
# offers every pass.
cat >open.py <<'PY'
import bpy, sys
img = bpy.data.images.load(sys.argv[sys.argv.index("--") + 1])
bpy.context.scene.use_nodes = True
node = bpy.context.scene.node_tree.nodes.new("CompositorNodeImage")
node.image = img
print("PASSES |" + "|".join(o.name for o in node.outputs) + "|")
PY
blender -b --factory-startup --python open.py -- j1.exr >blender.log 2>&1
for p in Combined "Denoising Albedo" "Denoising Normal" Depth Position Emit DiffDir DiffInd GlossDir GlossInd \
    TransDir TransInd IndexMA CryptoMaterial00 CryptoMaterial02 Variance IndexOB CryptoObject00 CryptoObject02 \
    Combined_default; do
    check "Blender's Image node offers $p" grep -q "^PASSES .*|$p|" blender.log
done

# Light groups: a layer each, summing to the image, the same bytes on
# every split and host.
cat >groups.json <<'EOF'
{
  "image": {"width": 40, "height": 30, "spp": 4, "max_depth": 4},
  "camera": {"position": [0, 1, -6], "target": [0, 1, 0], "fov": 45},
  "materials": {
    "wall": {"type": "lambert", "albedo": [0.7, 0.7, 0.7]},
    "lamp": {"type": "emitter", "emission": [4, 4, 4], "light_group": "panel"}
  },
  "shapes": [
    {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "wall"},
    {"type": "sphere", "name": "ball", "center": [-1, 1, 0], "radius": 1, "material": "wall"},
    {"type": "rect", "origin": [-1, 3, -1], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2], "material": "lamp"}
  ],
  "lights": [
    {"type": "point", "position": [2, 3, -2], "intensity": [5, 5, 5], "light_group": "key"},
    {"type": "point", "position": [-3, 2, -2], "intensity": [2, 2, 2]}
  ],
  "environment": {"color": [0.1, 0.1, 0.15], "light_group": "sky"}
}
EOF
GP="--passes light_groups,object_id,crypto_object --reproducible"
"$FRANJA" render groups.json -o g1.exr -j 1 $GP 2>logg1
check "light groups render (-j 1)" test $? -eq 0
"$FRANJA" render groups.json -o g2.exr -j 2 --slab-rows 5 $GP 2>logg2
check "light groups: -j 2 --slab-rows 5 gives the bytes of -j 1" cmp -s g1.exr g2.exr
fr render groups.json -o gssh.exr --hosts hosts $GP 2>logg3
check "light groups: SSH hosts give the bytes of -j 1" cmp -s g1.exr gssh.exr
oiiotool --info -v g1.exr >ginfo 2>&1
for ch in default key panel sky; do
    check "light group layer ViewLayer.Combined_$ch" grep -q "ViewLayer.Combined_$ch.R" ginfo
    oiiotool g1.exr --ch "ViewLayer.Combined_$ch.R,ViewLayer.Combined_$ch.G,ViewLayer.Combined_$ch.B" -o "l_$ch.exr"
done
check "the object manifest names the ball" grep -q 'manifest: "{.*"ball":"[0-9a-f]\{8\}"' ginfo
oiiotool g1.exr --ch "ViewLayer.Combined.R,ViewLayer.Combined.G,ViewLayer.Combined.B" -o beauty.exr
oiiotool l_default.exr l_key.exr --add l_panel.exr --add l_sky.exr --add -o lsum.exr
check "the light group layers sum to the image" sh -c 'oiiotool --fail 1e-5 --diff lsum.exr beauty.exr | grep -q PASS'
"$FRANJA" render groups.json -o g.png -j 2 --passes light_groups 2>logg4
check "PNG output: a file per light group" sh -c 'test -s g.Combined_key.png && test -s g.Combined_default.png'

# The image is the same bytes with and without passes (PFM: Franja's own
# writer, so the bytes are the pixels and the header).
"$FRANJA" render "$SCENE" -o plain.pfm $SIZE -j 2 2>log4
"$FRANJA" render "$SCENE" -o with.pfm $SIZE -j 2 --passes all 2>log5
check "the image keeps its bytes with passes" cmp -s plain.pfm with.pfm
for p in albedo normal depth position emission diffuse_direct glossy_indirect transmission_indirect material_id \
    object_id; do
    check "PFM output: with.$p.pfm written" test -s "with.$p.pfm"
done

# A scene that asks for passes; PNG files beside the image.
sed 's/"image": {/"image": { "passes": "albedo,normal",/' "$ROOT/scenes/cornell.json" >asks.json
"$FRANJA" render asks.json -o asks.png $SIZE -j 2 2>log6
check "the scene's passes: albedo and normal PNGs" sh -c 'test -s asks.albedo.png && test -s asks.normal.png'
check "the scene's passes: no other pass" test ! -e asks.depth.png
"$FRANJA" render asks.json -o none.png $SIZE -j 2 --passes none 2>log7
check "--passes none overrides the scene's" sh -c 'test -s none.png && test ! -e none.albedo.png'

# --crop with passes: the window's rows only.
"$FRANJA" render "$SCENE" -o crop.exr $SIZE -j 2 --passes denoise --crop 5:7:29:23 --crop-output 2>log8
check "--crop --crop-output with passes" test $? -eq 0
check "the cropped EXR is the window, with its passes" \
    sh -c 'oiiotool --info -v crop.exr | grep -q "24 x   16, 10 channel"'
"$FRANJA" render "$SCENE" -o full.exr $SIZE -j 2 --passes denoise 2>log8b
oiiotool full.exr --cut 24x16+5+7 -o cut.exr
oiiotool full.exr --cut 24x16+6+7 -o off.exr
check "the window's image and passes are the full render's" sh -c 'oiiotool --diff cut.exr crop.exr | grep -q PASS'
check "(a window one pixel off is not)" sh -c '! oiiotool --diff off.exr crop.exr | grep -q PASS'

# --resume: the kept slabs, with their passes, give the same file.
"$FRANJA" render "$SCENE" -o kept.exr $SIZE -j 2 --passes all --reproducible --keep-job 2>log9
"$FRANJA" render "$SCENE" -o kept.exr $SIZE -j 2 --passes all --reproducible --resume --keep-job 2>log10
check "--resume with passes writes the same bytes" cmp -s kept.exr j1.exr
check "--resume with passes rendered nothing again" grep -q "already done" log10
"$FRANJA" render "$SCENE" -o kept.exr $SIZE -j 2 --passes albedo --resume 2>log11
check "--resume with other passes is refused" test $? -eq 2
check "--resume with other passes: said" grep -q "another render (.*render passes)" log11
"$FRANJA" render "$SCENE" -o kept.exr --size 40x30 --spp 8 -j 2 --passes all --resume 2>log16
check "--resume with more samples and passes is refused" test $? -eq 2
check "--resume with more samples and passes: said" grep -q "a render with passes cannot be continued" log16

# An animation: every frame gets its passes.
cp "$ROOT/scenes/cornell.json" f.0001.json
cp "$ROOT/scenes/cornell.json" f.0002.json
"$FRANJA" render 'f.####.json' --frames 1-2 -o 'anim/f.####.exr' $SIZE -j 2 --passes denoise 2>log17
check "--frames with passes" test $? -eq 0
for f in 0001 0002; do
    check "frame $f has its albedo pass" sh -c "oiiotool --info -v anim/f.$f.exr | grep -q 'Denoising Albedo.R'"
done

# --time-limit with passes: each pass renders from the first sample; the
# last complete pass is written with its passes, the bytes of a render
# with that many samples, whatever the split.
"$FRANJA" render "$SCENE" -o tl.exr $SIZE -j 2 --slab-rows 5 --passes all --reproducible --time-limit 1h 2>log14
check "--time-limit with passes, every pass within it" test $? -eq 0
check "--time-limit with passes: the 4 samples' bytes" cmp -s tl.exr j1.exr
check "--time-limit with passes: passes of 1, 2, 4 samples" grep -q "pass 3 done: 4 samples" log14
"$FRANJA" render "$SCENE" -o ts.exr --size 40x30 --spp 1000000 -j 2 --slab-rows 5 --passes denoise,object_id \
    --reproducible --time-limit 1s 2>log18
check "--time-limit with passes, stopped" grep -q "time limit of 1 s reached" log18
N=$(sed -n 's/.*time limit of 1 s reached: \([0-9]*\) samples.*/\1/p' log18)
"$FRANJA" render "$SCENE" -o tn.exr --size 40x30 --spp "${N:-0}" -j 1 --passes denoise,object_id --reproducible \
    2>log19
check "--time-limit with passes, stopped: the bytes of a render with its ${N:-0} samples" cmp -s ts.exr tn.exr
check "--time-limit with passes: no slab discarded" sh -c '! grep -q discarded log14 log18'

# BDPT: the passes of its camera subpaths, the same bytes on every split
# and host; its image keeps its bytes; on the Cornell box's Lambertian
# walls its first-hit passes are the path tracer's.
BP="--integrator bdpt --passes denoise,depth,position,material_id,object_id,crypto_material,crypto_object --reproducible"
CORNELL="$ROOT/scenes/cornell.json"
"$FRANJA" render "$CORNELL" -o bd1.exr $SIZE -j 1 $BP 2>log21
check "bdpt with its passes (-j 1)" test $? -eq 0
"$FRANJA" render "$CORNELL" -o bd2.exr $SIZE -j 2 --slab-rows 5 $BP 2>log22
check "bdpt with passes: -j 2 --slab-rows 5 gives the bytes of -j 1" cmp -s bd1.exr bd2.exr
fr render "$CORNELL" -o bdssh.exr --hosts hosts $BP $SIZE 2>log23
check "bdpt with passes: SSH hosts give the bytes of -j 1" cmp -s bd1.exr bdssh.exr
oiiotool --info -v bd1.exr >bdinfo 2>&1
check "bdpt's EXR has 4 + 36 channels" grep -q "40 channel" bdinfo
"$FRANJA" render "$CORNELL" -o bdplain.pfm $SIZE -j 2 --integrator bdpt 2>log24
"$FRANJA" render "$CORNELL" -o bdwith.pfm $SIZE -j 2 --integrator bdpt --passes denoise,depth 2>log25
check "bdpt's image keeps its bytes with passes" cmp -s bdplain.pfm bdwith.pfm
check "bdpt: PFM files of its passes" sh -c 'test -s bdwith.albedo.pfm && test -s bdwith.depth.pfm'
"$FRANJA" render "$CORNELL" -o bdk.exr $SIZE -j 2 $BP --keep-job 2>log27
"$FRANJA" render "$CORNELL" -o bdk.exr $SIZE -j 2 $BP --resume 2>log28
check "bdpt with passes: --resume writes the same bytes" cmp -s bdk.exr bd1.exr
check "bdpt with passes: --resume rendered nothing again" grep -q "30 of 30 rows already done" log28
"$FRANJA" render "$CORNELL" -o bdc.exr $SIZE -j 2 $BP --crop 5:7:29:23 2>log29
check "bdpt with passes and --crop" test $? -eq 0
"$FRANJA" render "$CORNELL" -o pt1.exr $SIZE -j 2 --passes denoise,depth,material_id --reproducible 2>log26
for ch in "ViewLayer.Depth.Z" "ViewLayer.IndexMA.X" \
    "ViewLayer.Denoising Albedo.R,ViewLayer.Denoising Albedo.G,ViewLayer.Denoising Albedo.B"; do
    oiiotool bd1.exr --ch "$ch" -o bdch.exr
    oiiotool pt1.exr --ch "$ch" -o ptch.exr
    check "bdpt's $ch is the path tracer's on the Cornell box" sh -c 'oiiotool --fail 0 --diff bdch.exr ptch.exr | grep -q PASS'
done

# Adaptive sampling with passes.
"$FRANJA" render "$SCENE" -o adapt.exr --size 40x30 --spp 64 --noise-threshold 0.5 -j 2 --passes light 2>log12
check "adaptive sampling with passes" test $? -eq 0

# Refusals, with a message.
"$FRANJA" render "$SCENE" -o b.png $SIZE --passes albedo,emission --integrator bdpt 2>log13
check "bdpt with light passes: status 2" test $? -eq 2
check "bdpt with light passes: said, naming them" grep -q "camera subpaths .*, not emission: light tracing" log13
"$FRANJA" render "$SCENE" -o m.png $SIZE --passes albedo --integrator mlt 2>log20
check "mlt with passes: status 2" test $? -eq 2
check "mlt with passes: said" grep -q "path integrator and bdpt, not mlt" log20
"$FRANJA" render "$SCENE" -o t.png $SIZE --passes albedo,nrm 2>log15
check "an unknown pass: status 2" test $? -eq 2
check "an unknown pass is named" grep -q "unknown pass 'nrm'" log15

fh_cleanup
summary
