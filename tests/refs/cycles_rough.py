# cycles_rough.py -- the Cycles reference of tests/data/cycles-rough.json:
# a rough metal and a rough glass sphere on a diffuse plane under
# scenes/textures/sky.hdr (tests/it_cycles_rough.sh compares Franja with it).
#
#   blender -b --factory-startup --python tests/refs/cycles_rough.py -- SCENE.json OUTDIR [SAMPLES]
#
# (SAMPLES: 1024 by default, what the committed reference has).
#
# The scene is read from Franja's JSON file, so both renderers see the same
# numbers; only what that scene uses is understood (a camera, an
# environment image, lambert, conductor with "fresnel": "none" and glass
# materials, spheres and a plane), anything else stops the script.  Franja's
# +y-up frame is placed in Blender's +z-up one as Blender = (x, -z, y).
# Materials: lambert -> Diffuse BSDF (roughness 0); conductor without
# Fresnel -> Glossy BSDF, GGX (Cycles 3.4: separable masking, no Fresnel
# factor); rough glass -> Glass BSDF, GGX (Fresnel once with the shading
# normal).  Max bounces N = max_depth - 1 for every kind (NOTES: Franja's
# max_depth = Cycles' N + 1); no clamping, denoising, adaptive sampling or
# glossy filter; a box pixel filter of width 1.  Writes
# OUTDIR/cycles-rough.exr (linear float RGBA) and its RGB pixels as
# OUTDIR/cycles-rough.pfm (little-endian float32, bottom row first).
import json
import math
import os
import struct
import sys

import bpy
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
scene_path, out = os.path.abspath(args[0]), args[1]
samples = int(args[2]) if len(args) > 2 else 1024
with open(scene_path) as f:
    js = json.load(f)
base = os.path.dirname(scene_path)
scene = bpy.context.scene
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)


def blender(v):
    return Vector((v[0], -v[2], v[1]))


def fail(msg):
    raise SystemExit("cycles_rough.py: %s: %s" % (scene_path, msg))


# ---- environment ----
env_js = js["environment"]
tex = js["textures"][env_js["color"]]
if tex.get("type") != "image" or env_js.get("rotation", 0) != 0:
    fail("environment: an image texture without rotation expected")
w = bpy.data.worlds.new("sky")
w.use_nodes = True
nodes, links = w.node_tree.nodes, w.node_tree.links
nodes.clear()
env = nodes.new("ShaderNodeTexEnvironment")
env.image = bpy.data.images.load(os.path.join(base, tex["file"]))
env.interpolation = "Linear"
env.projection = "EQUIRECTANGULAR"
bg = nodes.new("ShaderNodeBackground")
bg.inputs["Strength"].default_value = env_js.get("strength", 1.0)
output = nodes.new("ShaderNodeOutputWorld")
links.new(env.outputs["Color"], bg.inputs["Color"])
links.new(bg.outputs["Background"], output.inputs["Surface"])
scene.world = w

# ---- materials ----
mats = {}
for name, m in js["materials"].items():
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    kind = m["type"]
    if kind == "lambert":
        bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Color"].default_value = tuple(m["albedo"]) + (1,)
        bsdf.inputs["Roughness"].default_value = 0.0
    elif kind == "conductor" and m.get("fresnel") == "none" and m.get("masking") == "separable":
        bsdf = nodes.new("ShaderNodeBsdfGlossy")
        bsdf.distribution = "GGX"
        bsdf.inputs["Color"].default_value = tuple(m["reflectance"]) + (1,)
        bsdf.inputs["Roughness"].default_value = m["roughness"]
    elif kind == "glass" and m.get("fresnel") == "normal" and m.get("masking") == "separable":
        bsdf = nodes.new("ShaderNodeBsdfGlass")
        bsdf.distribution = "GGX"
        bsdf.inputs["Color"].default_value = tuple(m.get("tint", [1, 1, 1])) + (1,)
        bsdf.inputs["Roughness"].default_value = m["roughness"]
        bsdf.inputs["IOR"].default_value = m["ior"]
    else:
        fail("materials.%s: not a material this script translates" % name)
    o = nodes.new("ShaderNodeOutputMaterial")
    links.new(bsdf.outputs[0], o.inputs["Surface"])
    mats[name] = mat

# ---- shapes ----
for i, s in enumerate(js["shapes"]):
    if s["type"] == "sphere":
        bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=s["radius"],
                                             location=blender(s["center"]))
        bpy.ops.object.shade_smooth()
    elif s["type"] == "plane" and s["normal"] == [0, 1, 0]:
        bpy.ops.mesh.primitive_plane_add(size=400, location=blender(s["point"]))
    else:
        fail("shapes[%d]: not a shape this script translates" % i)
    bpy.context.active_object.data.materials.append(mats[s["material"]])

# ---- camera and settings ----
cj, ij = js["camera"], js["image"]
if cj.get("up", [0, 1, 0]) != [0, 1, 0] or cj.get("aperture", 0) != 0:
    fail("camera: a pinhole with up [0, 1, 0] expected")
cam_data = bpy.data.cameras.new("camera")
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(cj["fov"])
cam = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(cam)
scene.camera = cam
p, t = blender(cj["position"]), blender(cj["target"])
cam.location = p
cam.rotation_mode = "QUATERNION"
cam.rotation_quaternion = (t - p).to_track_quat("-Z", "Y")

scene.render.engine = "CYCLES"
scene.render.resolution_x = ij["width"]
scene.render.resolution_y = ij["height"]
scene.render.resolution_percentage = 100
c = scene.cycles
c.device = "CPU"
c.samples = samples
c.use_adaptive_sampling = False
c.use_denoising = False
c.sample_clamp_direct = 0.0
c.sample_clamp_indirect = 0.0
c.blur_glossy = 0.0
c.caustics_reflective = True
c.caustics_refractive = True
c.seed = 1
c.pixel_filter_type = "BOX"
c.filter_width = 1.0
n = ij["max_depth"] - 1
c.max_bounces = n
c.diffuse_bounces = n
c.glossy_bounces = n
c.transmission_bounces = n
c.transparent_max_bounces = n
c.volume_bounces = n
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.exr_codec = "ZIP"

path = os.path.join(out, "cycles-rough.exr")
scene.render.filepath = path
bpy.ops.render.render(write_still=True)
img = bpy.data.images.load(path)
w, h = img.size
px = list(img.pixels)  # RGBA, bottom row first
with open(os.path.join(out, "cycles-rough.pfm"), "wb") as f:
    f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
    for i in range(w * h):
        f.write(struct.pack("<3f", *px[4 * i:4 * i + 3]))
