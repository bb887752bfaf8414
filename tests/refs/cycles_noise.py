# cycles_noise.py -- Cycles renders of a Franja JSON scene, for noise
# comparisons at equal samples per pixel (tests/bench/noise.sh).
#
#   blender -b --factory-startup --python tests/refs/cycles_noise.py -- \
#       SCENE.json OUT.pfm SPP [SEED]
#
# Reads the subset of the scene format the noise benches use: a pinhole
# camera, quads and spheres, lambert / mirror / glass / emitter materials,
# a scene-wide homogeneous medium ("medium" naming one of "media").  The
# scene's +y-up frame is placed in Blender's +z-up one as Blender = (x, -z, y).
# Franja's max_depth d is Cycles' Max Bounces d - 1 for every bounce type
# (/work/shared/NOTES-cycles.md).  No denoising, no adaptive sampling, no
# clamping, box pixel filter 1 px wide.  Writes the linear RGB pixels as a
# little-endian float32 PFM, bottom row first (as the test tools read it).
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_common as cc  # noqa: E402

args = cc.args()
scene_path, out_path, spp = args[0], os.path.abspath(args[1]), int(args[2])
seed = int(args[3]) if len(args) > 3 else 0
desc = json.load(open(scene_path))
scene = cc.empty_scene()


def rgb(v):
    return (v, v, v) if isinstance(v, (int, float)) else tuple(v)


def material(name, m):
    mat = bpy.data.materials.new(name)
    nodes, links = cc.nodes_of(mat)
    out = nodes.new("ShaderNodeOutputMaterial")
    kind = m["type"]
    if kind == "lambert":
        n = cc.diffuse(nodes, rgb(m["albedo"]))
    elif kind == "mirror":
        n = nodes.new("ShaderNodeBsdfGlossy")
        n.distribution = "SHARP"
        n.inputs["Color"].default_value = rgb(m.get("albedo", 1.0)) + (1,)
    elif kind == "glass":
        n = nodes.new("ShaderNodeBsdfGlass")
        n.distribution = "SHARP"
        n.inputs["IOR"].default_value = m.get("ior", 1.5)
        n.inputs["Color"].default_value = (1, 1, 1, 1)
    elif kind == "emitter":
        n = nodes.new("ShaderNodeEmission")
        n.inputs["Color"].default_value = rgb(m["emission"]) + (1,)
        n.inputs["Strength"].default_value = 1.0
    else:
        raise SystemExit("cycles_noise.py: material kind %s not supported" % kind)
    links.new(n.outputs[0], out.inputs["Surface"])
    return mat


mats = {k: material(k, v) for k, v in desc["materials"].items()}
for i, sh in enumerate(desc["shapes"]):
    if sh["type"] == "quad":
        cc.quad(scene, i, sh["vertices"], mats[sh["material"]])
    elif sh["type"] == "sphere":
        # every object in the scene's own collection
        ob = cc.sphere(sh["center"], sh["radius"], mats[sh["material"]])
        bpy.context.collection.objects.unlink(ob)
        scene.collection.objects.link(ob)
    else:
        raise SystemExit("cycles_noise.py: shape kind %s not supported" % sh["type"])

world = bpy.data.worlds.new("world")
nodes, links = cc.nodes_of(world)
wout = nodes.new("ShaderNodeOutputWorld")
bg = nodes.new("ShaderNodeBackground")
bg.inputs["Color"].default_value = (0, 0, 0, 1)
links.new(bg.outputs[0], wout.inputs["Surface"])
if "medium" in desc:
    md = desc["media"][desc["medium"]]
    sa, ss = rgb(md.get("sigma_a", 0.0)), rgb(md.get("sigma_s", 0.0))
    if len(set(sa)) != 1 or len(set(ss)) != 1:
        raise SystemExit("cycles_noise.py: only grey media")
    scat = nodes.new("ShaderNodeVolumeScatter")
    scat.inputs["Color"].default_value = (1, 1, 1, 1)
    scat.inputs["Density"].default_value = ss[0]
    scat.inputs["Anisotropy"].default_value = md.get("g", 0.0)
    absn = nodes.new("ShaderNodeVolumeAbsorption")
    absn.inputs["Color"].default_value = (0, 0, 0, 1)
    absn.inputs["Density"].default_value = sa[0]
    add = nodes.new("ShaderNodeAddShader")
    links.new(scat.outputs[0], add.inputs[0])
    links.new(absn.outputs[0], add.inputs[1])
    links.new(add.outputs[0], wout.inputs["Volume"])
    world.cycles.volume_sampling = "MULTIPLE_IMPORTANCE"
    world.cycles.homogeneous_volume = True
scene.world = world

cam_desc = desc["camera"]
cam = cc.camera(scene, cam_desc["fov"], clip=(1e-3, 1e6))
cc.aim(cam, cam_desc["position"], cam_desc["target"])

img = desc["image"]
cc.settings(scene, spp, seed, img.get("max_depth", 8) - 1)
scene.render.resolution_x = img["width"]
scene.render.resolution_y = img["height"]
exr = out_path + ".exr"
cc.render(scene, exr, out_path)
os.remove(exr)
