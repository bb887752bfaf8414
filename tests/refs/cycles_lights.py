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
import struct
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]
scene = bpy.context.scene

LIGHTS = {
    "point": dict(type="POINT", energy=1000.0, location=(0.3, 0.2, 1.0), rotation=(0, 0, 0)),
    "spot": dict(type="SPOT", energy=1000.0, location=(0.0, 0.0, 1.5), rotation=(0, 0, 0),
                 spot_size=math.radians(60.0), spot_blend=0.3),
    "sun": dict(type="SUN", energy=3.0, location=(0.0, 0.0, 5.0), rotation=(math.radians(30.0), 0, 0)),
}


def clear():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.lights, bpy.data.cameras, bpy.data.materials):
        for block in list(coll):
            coll.remove(block)


def build(name, spec):
    clear()
    bpy.ops.mesh.primitive_plane_add(size=10.0, location=(0, 0, 0))
    plane = bpy.context.active_object
    plane.name = "floor"
    mat = bpy.data.materials.new("white")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (0.8, 0.8, 0.8, 1)
    bsdf.inputs["Roughness"].default_value = 0.0
    output = nodes.new("ShaderNodeOutputMaterial")
    links.new(bsdf.outputs[0], output.inputs["Surface"])
    plane.data.materials.append(mat)

    cam_data = bpy.data.cameras.new("camera")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(60.0)
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    cam.location = (0, 0, 3)
    scene.camera = cam

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


world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
scene.world = world

scene.render.engine = "CYCLES"
c = scene.cycles
c.device = "CPU"
c.samples = 256
c.use_adaptive_sampling = False
c.use_denoising = False
c.sample_clamp_direct = 0.0
c.sample_clamp_indirect = 0.0
c.blur_glossy = 0.0
c.seed = 1
for attr in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
             "transparent_max_bounces"):
    setattr(c, attr, 0)
scene.render.resolution_x = 32
scene.render.resolution_y = 32
scene.render.resolution_percentage = 100
scene.render.filter_size = 1.0
c.pixel_filter_type = "BOX"
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.exr_codec = "ZIP"

for name, spec in LIGHTS.items():
    build(name, spec)
    path = os.path.join(out, "cycles-light-%s.exr" % name)
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    w, h = img.size
    px = list(img.pixels)  # RGBA, bottom row first
    with open(os.path.join(out, "cycles-light-%s.pfm" % name), "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        for i in range(w * h):
            f.write(struct.pack("<3f", *px[4 * i:4 * i + 3]))
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, "blender-light-%s.gltf" % name),
                              export_format="GLTF_EMBEDDED", export_cameras=True, export_lights=True)
