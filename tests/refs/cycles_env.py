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
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_common as cc  # noqa: E402

args = cc.args()
sky_path, out = os.path.abspath(args[0]), args[1]
scene = cc.empty_scene()


def world(rotation_deg):
    w = bpy.data.worlds.new("sky")
    nodes, links = cc.nodes_of(w)
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


cam = cc.camera(scene, 20)


def view(position, target, fov_deg, w, h):
    cc.aim(cam, position, target)
    cam.data.angle_y = math.radians(fov_deg)
    scene.render.resolution_x = w
    scene.render.resolution_y = h


cc.settings(scene, 64, 1, 0)


def render(name, samples):
    scene.cycles.samples = samples
    path = os.path.join(out, "cycles-env-" + name)
    cc.render(scene, path + ".exr", path + ".pfm")


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
nodes, links = cc.nodes_of(mat)
diffuse = cc.diffuse(nodes, (0.5, 0.5, 0.5))
output = nodes.new("ShaderNodeOutputMaterial")
links.new(diffuse.outputs[0], output.inputs["Surface"])
bpy.ops.mesh.primitive_plane_add(size=200, location=(0, 0, 0))
bpy.context.active_object.data.materials.append(mat)
cc.sphere((0, 0.5, 0), 0.5, mat)
view((3, 5, -3), (0, 0.3, 0), 40, 64, 64)
render("ground", 1024)
