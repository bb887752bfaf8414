# cycles_lights.py -- Blender's light units, as Cycles renders them and as
# Blender's glTF exporter writes them (tests/it_lightunits.sh compares).
#
#   blender -b --factory-startup --python tests/refs/cycles_lights.py -- OUTDIR
#
# One scene per light: a 10 m square plane at z = 0 (Diffuse BSDF, colour
# 0.8, roughness 0), a camera 3 m above it looking straight down (vertical
# field of view 60 degrees, 32x32 pixels) and one light of Blender's units:
#
#   point  1000 W at (0.3, 0.2, 1), radius 0
#   spot   1000 W at (0, 0, 1.5) pointing down, size 60 degrees, blend 0.3,
#          radius 0
#   sun    strength 3 W/m^2, angle 0, turned 30 degrees about x
#
# For each it renders OUTDIR/cycles-light-NAME.exr (Cycles, 256 spp, direct
# light only, a box pixel filter of width 1, linear float RGBA; its RGB
# pixels as OUTDIR/cycles-light-NAME.pfm, little-endian float32, bottom row
# first) and exports
# the scene with Blender's glTF exporter (io_scene_gltf2, its defaults;
# camera and lights included) to OUTDIR/blender-light-NAME.gltf, so the
# test sees the exporter's own numbers.
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_common as cc  # noqa: E402

out = cc.args()[0]
scene = bpy.context.scene

LIGHTS = {
    "point": dict(type="POINT", energy=1000.0, location=(0.3, 0.2, 1.0), rotation=(0, 0, 0)),
    "spot": dict(type="SPOT", energy=1000.0, location=(0.0, 0.0, 1.5), rotation=(0, 0, 0),
                 spot_size=math.radians(60.0), spot_blend=0.3),
    "sun": dict(type="SUN", energy=3.0, location=(0.0, 0.0, 5.0), rotation=(math.radians(30.0), 0, 0)),
}


def clear():
    cc.empty_scene()
    for coll in (bpy.data.meshes, bpy.data.lights, bpy.data.cameras, bpy.data.materials):
        for block in list(coll):
            coll.remove(block)


def build(name, spec):
    clear()
    bpy.ops.mesh.primitive_plane_add(size=10.0, location=(0, 0, 0))
    plane = bpy.context.active_object
    plane.name = "floor"
    mat = bpy.data.materials.new("white")
    nodes, links = cc.nodes_of(mat)
    bsdf = cc.diffuse(nodes, (0.8, 0.8, 0.8))
    output = nodes.new("ShaderNodeOutputMaterial")
    links.new(bsdf.outputs[0], output.inputs["Surface"])
    plane.data.materials.append(mat)

    cam = cc.camera(scene, 60.0)
    cam.location = (0, 0, 3)

    light = bpy.data.lights.new(name, spec["type"])
    light.energy = spec["energy"]
    light.color = (1, 1, 1)
    if spec["type"] == "SUN":
        light.angle = 0.0
    else:
        light.shadow_soft_size = 0.0
    if spec["type"] == "SPOT":
        light.spot_size = spec["spot_size"]
        light.spot_blend = spec["spot_blend"]
        light.show_cone = False
    obj = bpy.data.objects.new(name, light)
    scene.collection.objects.link(obj)
    obj.location = spec["location"]
    obj.rotation_euler = spec["rotation"]


cc.black_world(scene)
cc.settings(scene, 256, 1, 0)
scene.render.resolution_x = 32
scene.render.resolution_y = 32

for name, spec in LIGHTS.items():
    build(name, spec)
    path = os.path.join(out, "cycles-light-" + name)
    cc.render(scene, path + ".exr", path + ".pfm")
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, "blender-light-%s.gltf" % name),
                              export_format="GLTF_EMBEDDED", export_cameras=True, export_lights=True)
