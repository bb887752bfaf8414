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
import math
import os
import struct
import sys

import bpy
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
scene_path, out_path, spp = args[0], os.path.abspath(args[1]), int(args[2])
seed = int(args[3]) if len(args) > 3 else 0
desc = json.load(open(scene_path))
scene = bpy.context.scene
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)


def blender(v):
    return Vector((v[0], -v[2], v[1]))


def rgb(v):
    return (v, v, v) if isinstance(v, (int, float)) else tuple(v)


def material(name, m):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    kind = m["type"]
    if kind == "lambert":
        n = nodes.new("ShaderNodeBsdfDiffuse")
        n.inputs["Color"].default_value = rgb(m["albedo"]) + (1,)
        n.inputs["Roughness"].default_value = 0.0
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
        me = bpy.data.meshes.new("quad%d" % i)
        me.from_pydata([blender(v) for v in sh["vertices"]], [], [(0, 1, 2, 3)])
        ob = bpy.data.objects.new("quad%d" % i, me)
    elif sh["type"] == "sphere":
        bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=sh["radius"],
                                             location=blender(sh["center"]))
        ob = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        bpy.context.collection.objects.unlink(ob)
    else:
        raise SystemExit("cycles_noise.py: shape kind %s not supported" % sh["type"])
    ob.data.materials.append(mats[sh["material"]])
    scene.collection.objects.link(ob)

world = bpy.data.worlds.new("world")
world.use_nodes = True
nodes, links = world.node_tree.nodes, world.node_tree.links
nodes.clear()
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
cam_data = bpy.data.cameras.new("camera")
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(cam_desc["fov"])
cam_data.clip_start = 1e-3
cam_data.clip_end = 1e6
cam = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(cam)
scene.camera = cam
p, t = blender(cam_desc["position"]), blender(cam_desc["target"])
cam.location = p
cam.rotation_mode = "QUATERNION"
cam.rotation_quaternion = (t - p).to_track_quat("-Z", "Y")

img = desc["image"]
scene.render.engine = "CYCLES"
scene.render.resolution_x = img["width"]
scene.render.resolution_y = img["height"]
scene.render.resolution_percentage = 100
c = scene.cycles
c.device = "CPU"
c.samples = spp
c.use_adaptive_sampling = False
c.use_denoising = False
c.sample_clamp_direct = 0.0
c.sample_clamp_indirect = 0.0
c.blur_glossy = 0.0
c.caustics_reflective = True
c.caustics_refractive = True
c.seed = seed
c.pixel_filter_type = "BOX"
c.filter_width = 1.0
n = img.get("max_depth", 8) - 1
c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = n
c.volume_bounces = n
c.transparent_max_bounces = n
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
exr = out_path + ".exr"
scene.render.filepath = exr
bpy.ops.render.render(write_still=True)
im = bpy.data.images.load(exr)
w, h = im.size
px = list(im.pixels)  # RGBA, bottom row first
with open(out_path, "wb") as f:
    f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
    for i in range(w * h):
        f.write(struct.pack("<3f", *px[4 * i:4 * i + 3]))
os.remove(exr)
