# cycles_furnace.py -- Cycles renders of a white furnace, for the max_depth
# convention (tests/it_conventions.sh): the camera inside a closed sphere
# whose surface both emits radiance 1 and reflects diffusely with albedo
# 0.5.  With N max bounces Cycles gives sum(0.5^k, k = 0 .. N + 1), whatever
# the tessellation of the sphere, so the renders say how Cycles counts.
#
#   blender -b --factory-startup --python tests/refs/cycles_furnace.py -- OUTDIR
#
# writes OUTDIR/cycles-furnace-b0.exr ... b3.exr (8x8 pixels, linear float;
# Cycles' default pixel filter, the furnace's radiance being the same in
# every direction).
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_common as cc  # noqa: E402

out = cc.args()[0]
scene = cc.empty_scene()

bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=4, radius=1.0, location=(0, 0, 0))
sphere = bpy.context.active_object
mat = bpy.data.materials.new("furnace")
nodes, links = cc.nodes_of(mat)
emit = nodes.new("ShaderNodeEmission")
emit.inputs["Color"].default_value = (1, 1, 1, 1)
emit.inputs["Strength"].default_value = 1.0
diffuse = cc.diffuse(nodes, (0.5, 0.5, 0.5))
add = nodes.new("ShaderNodeAddShader")
output = nodes.new("ShaderNodeOutputMaterial")
links.new(emit.outputs[0], add.inputs[0])
links.new(diffuse.outputs[0], add.inputs[1])
links.new(add.outputs[0], output.inputs["Surface"])
sphere.data.materials.append(mat)

cam = cc.camera(scene)
cam.location = (0, 0, 0)
cc.black_world(scene)

cc.settings(scene, 256, 1, 0, box_filter=False)
scene.render.resolution_x = 8
scene.render.resolution_y = 8
for n in range(4):
    cc.bounces(scene, n)
    cc.render(scene, os.path.join(out, "cycles-furnace-b%d.exr" % n))
