#!/bin/sh
# it_anim_reuse.sh -- tests that animation frames reuse the frame before's geometry.
#
# A JSON scene of a mesh with a keyed camera, three frames over fake SSH
# hosts (coordinator/reuse.h, common/fpatch.h): frames 2 and 3 are made
# of the frame before's sections (no full compile), their scenes are byte
# for byte what a full compile of the frame gives, and their images are
# those of rendering each frame alone; the host gets a patch of kilobytes
# for frames 2 and 3 instead of the whole scene, and its cached scenes are
# the .fbin files.  A patch damaged on the way, or naming a base the host
# no longer holds, is refused by the worker and the whole scene is sent;
# a worker without the patch-1 feature gets whole scenes.  Compiled .fbin
# frames travel as patches too.  A camera that
# moves into a mesh holding a medium (which medium the camera sits in
# depends on both) compiles each frame whole, to the bytes of the frame
# alone.  glTF animations (tests/support/genanim.py): a camera move is made
# of the frame before's sections, a moving box compiles whole; with a
# shutter too, every frame is the bytes of the frame alone.  JSON frames
# placing two glTF files of the same nodes but other vertices compile
# whole.  A mesh that moves within half a frame of frame 2 (the most a
# shutter is open), not at frame 2 itself, compiles frame 2 whole, so that
# what a blur of it needs is never taken from frame 1.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
"$ROOT/bin/gen/genmesh" knot --tris 20000 -o knot.obj >/dev/null || bad "genmesh"
cat >move.json <<'JSON'
{ "image": { "width": 24, "height": 16, "spp": 2 },
  "camera": { "position": { "keys": [[1, [0, 1, -3.4]], [4, [2.4, 1, -2.4]]] }, "target": [0, 0.3, 0], "fov": 34 },
  "materials": { "gold": { "type": "phong", "diffuse": [0.4, 0.3, 0.1], "glossy": [0.4, 0.3, 0.1], "exponent": 40 } },
  "lights": [ { "type": "point", "position": [0, 4, -3], "intensity": [20, 20, 20] } ],
  "shapes": [ { "type": "mesh", "file": "knot.obj", "material": "gold" },
              { "type": "plane", "point": [0, -1, 0], "normal": [0, 1, 0], "material": "gold" } ] }
JSON

# sent LOG HOST FRAME: the bytes the log says went to HOST for FRAME.
sent() { sed -n "s/^franja: host $2: frame $3: scene .*, \([0-9]*\) bytes sent).*/\1/p" "$1" | head -n 1; }

# A worker that, on --unpack of a patch (its magic \x89FRJPAT), damages it:
# `data` a byte of its section, `base` the base hash it names.
patch_damaging() {
    w="$FH/worker-$1.sh"
    at=$([ "$1" = data ] && echo 90 || echo 16)
    cat >"$w" <<SH
#!/bin/sh
if [ "\$1" = --unpack ] && head -c 8 "\$2" | od -An -tx1 | grep -q '89 46 52 4a 50 41 54 0a'; then
    printf 'XXXX' | dd of="\$2" bs=1 seek=$at conv=notrunc 2>/dev/null
fi
exec "$WORKER" "\$@"
SH
    chmod +x "$w"
    echo "$w"
}
cat >"$FH/old-worker.sh" <<SH
#!/bin/sh
[ "\$1" = --features ] && { echo unpack-zstd unpack-fpak1; exit 0; }
exec "$WORKER" "\$@"
SH
chmod +x "$FH/old-worker.sh"

fh_start a 1 2
fh_start b 2 2 "$(patch_damaging data)"
fh_start c 3 2 "$(patch_damaging base)"
fh_start d 4 2 "$FH/old-worker.sh"

# Each frame alone: its first (full) compile, and its image.
for f in 1 2 3; do
    "$FRANJA" render move.json --frames $f -o "still/f.#.pfm" --keep-job 2>/dev/null || bad "still frame $f"
done

for h in a b c d; do
    grep "^$h " hosts >"hosts.$h"
    fr render move.json --frames 1-3 -o "$h/f.#.pfm" --hosts "hosts.$h" --keep-job 2>"log-$h" ||
        bad "render on $h: $(cat "log-$h")"
    for f in 1 2 3; do
        check "$h: frame $f equals the frame rendered alone" cmp -s "$h/f.$f.pfm" "still/f.$f.pfm"
        check "$h: frame $f's scene is the full compile's" \
            cmp -s "$h/f.$f.pfm.franja-job/scene.fbin" "still/f.$f.pfm.franja-job/scene.fbin"
    done
done
for f in 2 3; do
    check "frame $f made of the frame before's sections" grep -q "frame $f: scene made of the frame before's" log-a
done
s1=$(sent log-a a 1) s2=$(sent log-a a 2) s3=$(sent log-a a 3)
check "a: frame 1 sends the scene ($s1 bytes)" test "${s1:-0}" -gt 100000
check "a: frames 2 and 3 send a patch ($s2, $s3 bytes)" test -n "$s2" -a "${s2:-99999}" -lt 4096 -a "${s3:-99999}" -lt 4096
# The frames as compiled scenes: patches all the same.
mkdir -p fb
for f in 1 2 3; do cp "still/f.$f.pfm.franja-job/scene.fbin" "fb/f.$f.fbin"; done
fr render 'fb/f.#.fbin' --frames 1-3 -o "fbo/f.#.pfm" --hosts hosts.a 2>log-fb || bad "fbin frames: $(cat log-fb)"
s2=$(sent log-fb a 2) s3=$(sent log-fb a 3)
check "a: .fbin frames 2 and 3 send a patch ($s2, $s3 bytes)" test -n "$s2" -a "${s2:-99999}" -lt 4096 -a "${s3:-99999}" -lt 4096
check "a: .fbin frame 3 equals the frame rendered alone" cmp -s fbo/f.3.pfm still/f.3.pfm
for f in 2 3; do
    hash=$("$WORKER" --scene "a/f.$f.pfm.franja-job/scene.fbin" --check)
    check "a: the cached scene of frame $f is the .fbin" cmp -s "a/work/scenes/$hash.fbin" "a/f.$f.pfm.franja-job/scene.fbin"
done
check "a: no patch or temporary file is left" test -z "$(ls -A a/work/scenes | grep -v '\.fbin$')"
check "a: no note of a failed patch" sh -c "! grep -q 'did not unpack' log-a"
for h in b c; do
    check "$h: the damaged patch is refused" grep -q "^franja: $h (.*the scene patch did not unpack (.*); sending the whole scene" "log-$h"
    s2=$(sent "log-$h" "$h" 2)
    check "$h: then the whole scene is sent ($s2 bytes)" test "${s2:-0}" -gt 100000
done
check "b: the rebuilt scene's hash is checked" grep -q "^franja: b (.*did not unpack (.*the rebuilt scene has hash" log-b
check "c: the missing base is named" grep -q "^franja: c (.*did not unpack (.*its base scene" log-c
s2=$(sent log-d d 2)
check "d: a worker without patches gets the whole scene ($s2 bytes)" test "${s2:-0}" -gt 100000
check "d: and is offered no patch" sh -c "! grep -q 'scene patch' log-d"

# A camera moving into a closed mesh with an interior medium.
"$ROOT/bin/gen/genmesh" sphere --tris 2000 -o ball.obj >/dev/null || bad "genmesh sphere"
cat >inside.json <<'JSON'
{ "image": { "width": 16, "height": 12, "spp": 1 },
  "camera": { "position": { "keys": [[1, [0, 0, -4]], [3, [0, 0, 0]]] }, "target": [0, 0, 1], "fov": 40 },
  "media": { "cloud": { "sigma_a": 0.1, "sigma_s": 0.5 } },
  "materials": { "cloud": { "type": "interface", "medium": "cloud" },
                 "w": { "type": "lambert", "albedo": [0.6, 0.6, 0.6] } },
  "lights": [ { "type": "point", "position": [0, 0, 0.5], "intensity": [5, 5, 5] } ],
  "shapes": [ { "type": "mesh", "file": "ball.obj", "material": "cloud" },
              { "type": "plane", "point": [0, -3, 0], "normal": [0, 1, 0], "material": "w" } ] }
JSON
"$FRANJA" render inside.json --frames 1-3 -o "in/f.#.pfm" --keep-job 2>log-in || bad "inside: $(cat log-in)"
"$FRANJA" render inside.json --frames 3 -o "in3/f.#.pfm" --keep-job 2>/dev/null || bad "inside, frame 3 alone"
check "inside: frame 3 compiled whole" grep -q "frame 3: scene compiled" log-in
check "inside: frame 3's scene is the full compile's" \
    cmp -s "in/f.3.pfm.franja-job/scene.fbin" "in3/f.3.pfm.franja-job/scene.fbin"
check "inside: frame 3 equals the frame rendered alone" cmp -s "in/f.3.pfm" "in3/f.3.pfm"

# A step key at frame 2.2: frames 1 and 2 have the mesh in one place, frame
# 2's shutter closes (2.25) with it moved.
sed -e 's|"camera": { "position": { "keys": \[\[1, \[0, 0, -4\]\], \[3, \[0, 0, 0\]\]\] }|"camera": { "position": [0, 0, -4], "shutter": 0.5|' \
    -e 's|"file": "ball.obj", "material": "cloud"|"file": "ball.obj", "material": "w", "translate": { "keys": [[1, [0, 0, 0]], [2.2, [1, 0, 0]]], "interpolation": "step" }|' \
    inside.json >step.json
"$FRANJA" render step.json --frames 1-2 -o "st/f.#.pfm" --keep-job 2>log-st || bad "step: $(cat log-st)"
"$FRANJA" render step.json --frames 2 -o "st2/f.#.pfm" --keep-job 2>/dev/null || bad "step, frame 2 alone"
check "step: the key folds the shutter (frame 2 compiled whole)" grep -q "frame 2: scene compiled" log-st
check "step: frame 2's scene is the full compile's" \
    cmp -s "st/f.2.pfm.franja-job/scene.fbin" "st2/f.2.pfm.franja-job/scene.fbin"

# glTF: blur.gltf's camera moves before a still quad; anim.gltf's box moves.
mkdir -p ga && python3 "$ROOT/tests/support/genanim.py" ga >/dev/null || bad "genanim.py"
for sc in blur anim; do
    for sh in 0 0.5; do
        "$FRANJA" render "ga/$sc.gltf" --frames 0-2 --shutter $sh -o "g-$sc-$sh/f.#.pfm" --size 32x16 --spp 1 \
            --keep-job 2>"log-$sc-$sh" || bad "$sc.gltf: $(cat "log-$sc-$sh")"
        "$FRANJA" render "ga/$sc.gltf" --frames 2 --shutter $sh -o "g1-$sc-$sh/f.#.pfm" --size 32x16 --spp 1 \
            --keep-job 2>/dev/null || bad "$sc.gltf, frame 2 alone"
        check "$sc.gltf (shutter $sh): frame 2's scene is the full compile's" \
            cmp -s "g-$sc-$sh/f.2.pfm.franja-job/scene.fbin" "g1-$sc-$sh/f.2.pfm.franja-job/scene.fbin"
        check "$sc.gltf (shutter $sh): frame 2 equals the frame rendered alone" \
            cmp -s "g-$sc-$sh/f.2.pfm" "g1-$sc-$sh/f.2.pfm"
    done
done
check "blur.gltf: frames 1 and 2 made of the frame before's" test "$(grep -c "scene made of" log-blur-0.5)" -eq 2
check "anim.gltf: the moving box, sharp (flattened), compiles every frame" \
    test "$(grep -c "scene compiled" log-anim-0)" -eq 3
check "anim.gltf: the moving box, blurred (an instance), is made of the frame before's" \
    test "$(grep -c "scene made of" log-anim-0.5)" -eq 2

# f.000N.json places ga/morphN.gltf: the same nodes, other vertices.
for i in 1 2; do
    cat >"ga/m.000$i.json" <<JSON
{ "image": { "width": 16, "height": 12, "spp": 1 },
  "camera": { "position": [0, 0, 4], "target": [0, 0, 0], "fov": 60 },
  "materials": {},
  "lights": [ { "type": "point", "position": [0, 0, 3], "intensity": [5, 5, 5] } ],
  "shapes": [ { "type": "gltf", "file": "morph$i.gltf" } ] }
JSON
done
"$FRANJA" render 'ga/m.####.json' --frames 1-2 -o "gm/f.#.pfm" 2>log-gm || bad "glTF shapes: $(cat log-gm)"
"$FRANJA" render ga/m.0002.json -o gm2.pfm 2>/dev/null || bad "ga/m.0002.json alone"
check "another glTF file under the same nodes compiles whole" grep -q "frame 2: scene compiled" log-gm
check "and renders as the frame alone" cmp -s gm/f.2.pfm gm2.pfm
summary
