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
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_common as cc  # noqa: E402

args = cc.args()
scene_path, out, out_name = os.path.abspath(args[0]), args[1], args[2]
samples = int(args[3]) if len(args) > 3 else 1024
seed = int(args[4]) if len(args) > 4 else 1
with open(scene_path) as f:
    js = json.load(f)
base = os.path.dirname(scene_path)
scene = cc.empty_scene()


def fail(msg):
    raise SystemExit("cycles_scene.py: %s: %s" % (scene_path, msg))


# ---- environment ----
w = bpy.data.worlds.new("sky")
nodes, links = cc.nodes_of(w)
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
    nodes, links = cc.nodes_of(mat)
    kind = m["type"]
    if kind == "lambert":
        bsdf = cc.diffuse(nodes, m["albedo"])
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
        cc.sphere(s["center"], s["radius"], mats[s["material"]])
    elif s["type"] == "plane" and s["normal"] == [0, 1, 0]:
        bpy.ops.mesh.primitive_plane_add(size=4000, location=cc.blender(s["point"]))
        bpy.context.active_object.data.materials.append(mats[s["material"]])
    elif s["type"] == "quad":
        cc.quad(scene, i, s["vertices"], mats[s["material"]])
    else:
        fail("shapes[%d]: not a shape this script translates" % i)

# ---- camera and settings ----
cj, ij = js["camera"], js["image"]
if cj.get("up", [0, 1, 0]) != [0, 1, 0] or cj.get("aperture", 0) != 0:
    fail("camera: a pinhole with up [0, 1, 0] expected")
cam = cc.camera(scene, cj["fov"], clip=(1e-3, 1e7))
cc.aim(cam, cj["position"], cj["target"])

cc.settings(scene, samples, seed, ij["max_depth"] - 1)
scene.render.resolution_x = ij["width"]
scene.render.resolution_y = ij["height"]
path = os.path.join(out, out_name)
cc.render(scene, path + ".exr", path + ".pfm")
