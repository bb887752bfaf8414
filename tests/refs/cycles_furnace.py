# cycles_furnace.py -- Cycles renders of a white furnace, for the max_depth
# convention (tests/it_conventions.sh): the camera inside a closed sphere
# whose surface both emits radiance 1 and reflects diffusely with albedo
# 0.5.  With N max bounces Cycles gives sum(0.5^k, k = 0 .. N + 1), whatever
# the tessellation of the sphere, so the renders say how Cycles counts.
#
#   blender -b --factory-startup --python tests/refs/cycles_furnace.py -- OUTDIR
#
# writes OUTDIR/cycles-furnace-b0.exr ... b3.exr (8x8 pixels, linear float).
import os
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]
scene = bpy.context.scene
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)

bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=4, radius=1.0, location=(0, 0, 0))
sphere = bpy.context.active_object
mat = bpy.data.materials.new("furnace")
mat.use_nodes = True
nodes, links = mat.node_tree.nodes, mat.node_tree.links
nodes.clear()
emit = nodes.new("ShaderNodeEmission")
emit.inputs["Color"].default_value = (1, 1, 1, 1)
emit.inputs["Strength"].default_value = 1.0
diffuse = nodes.new("ShaderNodeBsdfDiffuse")
diffuse.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1)
diffuse.inputs["Roughness"].default_value = 0.0
add = nodes.new("ShaderNodeAddShader")
output = nodes.new("ShaderNodeOutputMaterial")
links.new(emit.outputs[0], add.inputs[0])
links.new(diffuse.outputs[0], add.inputs[1])
links.new(add.outputs[0], output.inputs["Surface"])
sphere.data.materials.append(mat)

cam_data = bpy.data.cameras.new("camera")
cam = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(cam)
cam.location = (0, 0, 0)
scene.camera = cam

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
c.caustics_reflective = True
c.caustics_refractive = True
c.blur_glossy = 0.0
c.seed = 1
scene.render.resolution_x = 8
scene.render.resolution_y = 8
scene.render.resolution_percentage = 100
scene.render.filter_size = 0.01
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.exr_codec = "ZIP"

for n in range(4):
    c.max_bounces = n
    c.diffuse_bounces = n
    c.glossy_bounces = n
    c.transmission_bounces = n
    c.volume_bounces = n
    c.transparent_max_bounces = n
    scene.render.filepath = os.path.join(out, "cycles-furnace-b%d.exr" % n)
    bpy.ops.render.render(write_still=True)
