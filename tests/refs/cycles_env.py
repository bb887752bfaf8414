# cycles_env.py -- Cycles renders of scenes/textures/sky.hdr as the world's
# Environment Texture, for the environment's orientation and brightness
# (tests/it_envlight.sh renders the same views with Franja and compares).
#
#   blender -b --factory-startup --python tests/refs/cycles_env.py -- SKY.hdr OUTDIR
#
# Views are given in Franja's +y-up frame and placed in Blender's +z-up one
# as Blender = (x, -z, y) (how Blender's glTF exporter maps Blender to glTF,
# inverted).  Writes OUTDIR/cycles-env-NAME.exr (linear float) and the same
# RGB pixels as OUTDIR/cycles-env-NAME.pfm (little-endian float32, bottom row
# first, as the test tools read):
#   sun     48x32, camera at the origin looking at the map's sun (elevation
#           35, azimuth 60 from +x toward +z), vertical fov 20
#   wide    64x32, looking along +x, a little up, fov 90: sky, horizon, ground
#   rot     48x32, the map turned by a Mapping node (Point, Z rotation 90),
#           camera looking where Franja's rotation 90 puts the sun
#   ground  64x64, a diffuse sphere on a diffuse plane (albedo 0.5), direct
#           light only (max bounces 0), lit by the map alone.
import math
import os
import struct
import sys

import bpy
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
sky_path, out = os.path.abspath(args[0]), args[1]
scene = bpy.context.scene
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)


def blender(v):
    return Vector((v[0], -v[2], v[1]))


def world(rotation_deg):
    w = bpy.data.worlds.new("sky")
    w.use_nodes = True
    nodes, links = w.node_tree.nodes, w.node_tree.links
    nodes.clear()
    coord = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = (0, 0, math.radians(rotation_deg))
    env = nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(sky_path)
    env.interpolation = "Linear"
    env.projection = "EQUIRECTANGULAR"
    bg = nodes.new("ShaderNodeBackground")
    bg.inputs["Strength"].default_value = 1.0
    output = nodes.new("ShaderNodeOutputWorld")
    links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    links.new(env.outputs["Color"], bg.inputs["Color"])
    links.new(bg.outputs["Background"], output.inputs["Surface"])
    scene.world = w


cam_data = bpy.data.cameras.new("camera")
cam_data.sensor_fit = "VERTICAL"
cam = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(cam)
scene.camera = cam


def view(position, target, fov_deg, w, h):
    p, t = blender(position), blender(target)
    cam.location = p
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = (t - p).to_track_quat("-Z", "Y")
    cam_data.angle_y = math.radians(fov_deg)
    scene.render.resolution_x = w
    scene.render.resolution_y = h


scene.render.engine = "CYCLES"
c = scene.cycles
c.device = "CPU"
c.use_adaptive_sampling = False
c.use_denoising = False
c.sample_clamp_direct = 0.0
c.sample_clamp_indirect = 0.0
c.blur_glossy = 0.0
c.seed = 1
c.pixel_filter_type = "BOX"
c.filter_width = 1.0
c.max_bounces = 0
c.diffuse_bounces = 0
c.glossy_bounces = 0
c.transmission_bounces = 0
c.transparent_max_bounces = 0
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.exr_codec = "ZIP"


def render(name, samples):
    c.samples = samples
    path = os.path.join(out, "cycles-env-%s.exr" % name)
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    w, h = img.size
    px = list(img.pixels)  # RGBA, bottom row first
    with open(os.path.join(out, "cycles-env-%s.pfm" % name), "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        for i in range(w * h):
            f.write(struct.pack("<3f", *px[4 * i:4 * i + 3]))
    bpy.data.images.remove(img)


el, az = math.radians(35), math.radians(60)
sun = (math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az))
world(0)
view((0, 0, 0), sun, 20, 48, 32)
render("sun", 64)
view((0, 0, 0), (1, 0.15, 0), 90, 64, 32)
render("wide", 64)
world(90)
# Franja's rotation 90 looks up d' = (z, y, -x): the sun shows at (-sun.z, sun.y, sun.x).
view((0, 0, 0), (-sun[2], sun[1], sun[0]), 20, 48, 32)
render("rot", 64)

world(0)
mat = bpy.data.materials.new("diffuse")
mat.use_nodes = True
mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1)
nodes, links = mat.node_tree.nodes, mat.node_tree.links
nodes.clear()
diffuse = nodes.new("ShaderNodeBsdfDiffuse")
diffuse.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1)
diffuse.inputs["Roughness"].default_value = 0.0
output = nodes.new("ShaderNodeOutputMaterial")
links.new(diffuse.outputs[0], output.inputs["Surface"])
bpy.ops.mesh.primitive_plane_add(size=200, location=(0, 0, 0))
bpy.context.active_object.data.materials.append(mat)
bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=0.5, location=blender((0, 0.5, 0)))
bpy.ops.object.shade_smooth()
bpy.context.active_object.data.materials.append(mat)
view((3, 5, -3), (0, 0.3, 0), 40, 64, 64)
render("ground", 1024)
