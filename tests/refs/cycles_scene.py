# cycles_scene.py -- the Cycles reference of one of Franja's JSON scenes
# (tests/data/cycles-*.json; tests/it_cycles_*.sh compare Franja with them).
#
#   blender -b --factory-startup --python tests/refs/cycles_scene.py -- SCENE.json OUTDIR NAME [SAMPLES [SEED]]
#
# (SAMPLES: 1024 by default; SEED: Cycles' seed, 1 by default).
#
# The scene is read from Franja's JSON file, so both renderers see the same
# numbers; only what the comparison scenes use is understood (a pinhole
# camera; an environment image or none; lambert, emitter, conductor with
# "fresnel": "none", glass and untextured principled materials; spheres,
# planes and quads), anything else stops the script.  Franja's
# +y-up frame is placed in Blender's +z-up one as Blender = (x, -z, y).
# Materials: lambert -> Diffuse BSDF (roughness 0); conductor without
# Fresnel -> Glossy BSDF, GGX (Cycles 3.4: separable masking, no Fresnel
# factor); rough glass -> Glass BSDF, GGX (Fresnel once with the shading
# normal); principled -> Principled BSDF, GGX, Specular from ior (the same
# model with "coupling": "cycles" and separable masking; otherwise Franja's
# model differs, and tests/bench/showcase.sh uses it only to measure noise).  Max bounces N = max_depth - 1 for every kind (NOTES: Franja's
# max_depth = Cycles' N + 1); no clamping, denoising, adaptive sampling or
# glossy filter; a box pixel filter of width 1.  An emitter is an Emission
# shader of strength 1 and the emission as colour (radiance); Cycles' mesh
# lights emit from both sides, so the scene's emitters must be
# "two_sided": true.  Writes OUTDIR/NAME.exr (linear float
# RGBA) and its RGB pixels as OUTDIR/NAME.pfm (little-endian float32,
# bottom row first).
import json
import math
import os
import struct
import sys

import bpy
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
scene_path, out, out_name = os.path.abspath(args[0]), args[1], args[2]
samples = int(args[3]) if len(args) > 3 else 1024
seed = int(args[4]) if len(args) > 4 else 1
with open(scene_path) as f:
    js = json.load(f)
base = os.path.dirname(scene_path)
scene = bpy.context.scene
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)


def blender(v):
    return Vector((v[0], -v[2], v[1]))


def fail(msg):
    raise SystemExit("cycles_scene.py: %s: %s" % (scene_path, msg))


# ---- environment ----
w = bpy.data.worlds.new("sky")
w.use_nodes = True
nodes, links = w.node_tree.nodes, w.node_tree.links
nodes.clear()
bg = nodes.new("ShaderNodeBackground")
output = nodes.new("ShaderNodeOutputWorld")
links.new(bg.outputs["Background"], output.inputs["Surface"])
env_js = js.get("environment")
if env_js is None:
    bg.inputs["Strength"].default_value = 0.0
else:
    tex = js["textures"][env_js["color"]]
    if tex.get("type") != "image" or env_js.get("rotation", 0) != 0:
        fail("environment: an image texture without rotation expected")
    env = nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(os.path.join(base, tex["file"]))
    env.interpolation = "Linear"
    env.projection = "EQUIRECTANGULAR"
    bg.inputs["Strength"].default_value = env_js.get("strength", 1.0)
    links.new(env.outputs["Color"], bg.inputs["Color"])
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
    elif kind == "principled" and all(isinstance(m.get(k, 0), (int, float))
                                      for k in ("roughness", "metallic", "transmission")) and (
            m.get("coupling") == "cycles" or m.get("transmission", 0) == 0):
        # With "coupling": "cycles" and separable masking this is the same
        # model (Principled BSDF, GGX: Disney diffuse, Fresnel interpolated
        # from the dielectric's, glass with Fresnel on the shading normal);
        # otherwise only for the noise benches, which compare each renderer
        # with itself.
        bsdf = nodes.new("ShaderNodeBsdfPrincipled")
        bsdf.distribution = "GGX"
        bsdf.inputs["Base Color"].default_value = tuple(m.get("base_color", [1, 1, 1])) + (1,)
        bsdf.inputs["Metallic"].default_value = m.get("metallic", 1)
        bsdf.inputs["Roughness"].default_value = m.get("roughness", 1)
        bsdf.inputs["Transmission"].default_value = m.get("transmission", 0)
        ior = m.get("ior", 1.5)
        bsdf.inputs["IOR"].default_value = ior
        # Cycles' specular layer: F0 = 0.08 * Specular (0.5: F0 0.04, ior 1.5)
        bsdf.inputs["Specular"].default_value = ((ior - 1) / (ior + 1)) ** 2 / 0.08
    elif kind == "emitter" and m.get("two_sided"):
        bsdf = nodes.new("ShaderNodeEmission")
        bsdf.inputs["Color"].default_value = tuple(m["emission"]) + (1,)
        bsdf.inputs["Strength"].default_value = 1.0
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
        bpy.ops.mesh.primitive_plane_add(size=4000, location=blender(s["point"]))
    elif s["type"] == "quad":
        mesh = bpy.data.meshes.new("quad%d" % i)
        mesh.from_pydata([blender(v) for v in s["vertices"]], [], [(0, 1, 2, 3)])
        obj = bpy.data.objects.new("quad%d" % i, mesh)
        scene.collection.objects.link(obj)
        bpy.context.view_layer.objects.active = obj
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
cam_data.clip_start = 1e-3
cam_data.clip_end = 1e7
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
c.seed = seed
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

path = os.path.join(out, out_name + ".exr")
scene.render.filepath = path
bpy.ops.render.render(write_still=True)
img = bpy.data.images.load(path)
w, h = img.size
px = list(img.pixels)  # RGBA, bottom row first
with open(os.path.join(out, out_name + ".pfm"), "wb") as f:
    f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
    for i in range(w * h):
        f.write(struct.pack("<3f", *px[4 * i:4 * i + 3]))
