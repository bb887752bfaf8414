#!/bin/sh
# it_cycles_principled.sh -- tests the principled material against Cycles.
#
# The principled (glTF metallic-roughness) material against Cycles 3.4's
# Principled BSDF: tests/data/cycles-principled.json (a red dielectric of
# roughness 0.25, a blue one of roughness 0.7, a half-metallic gold, a
# metallic copper and a transmissive sphere of ior 1.45 on a diffuse plane
# under scenes/textures/sky.hdr, every principled material with "coupling":
# "cycles" and separable masking), 256x256, rendered by Franja at 128 spp
# in two slabs against Cycles' render of the same scene
# (tests/data/cycles-principled.exr, Blender 3.4.1, 256 spp, `make refs`).
# Limits (issue 11): each channel's mean within 1.5 %, the worst 64x64
# block's mean within 3 %.  Noise: two Franja renders of 128 spp (seeds 0
# and 1) differ by 0.51 % in the worst block.  Measured against Cycles:
# means within 0.1 %, worst block 0.58 %, each sphere's centre within
# 0.4 % (42 CPU-s for the test here).  Franja's own model is measurably
# different: with "coupling": "albedo" the worst block (the blue dielectric
# of roughness 0.7) is 5.1 % darker, the red mean 1.7 % lower.
# The comparison can fail: Franja's own coupling (a Lambert base under the
# specular layer, "coupling": "albedo") does not pass, nor does the
# metallic copper made a dielectric.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
. tests/support/cycles.sh
need oiiotool
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

cycles_compare principled 128

abs='s|"\.\./\.\./scenes/|"'"$(pwd)"'/scenes/|'
sed "s/\"coupling\": \"cycles\"/\"coupling\": \"albedo\"/; $abs" tests/data/cycles-principled.json >"$T/albedo.json"
cycles_differs "$T/albedo.json" 64 principled "Franja's default coupling (a Lambert base)"
sed "s/\"metallic\": 1,/\"metallic\": 0,/; $abs" tests/data/cycles-principled.json >"$T/dielectric.json"
cycles_differs "$T/dielectric.json" 32 principled "the copper made a dielectric"
summary
