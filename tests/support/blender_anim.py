# blender_anim.py -- exports an animated glTF from Blender for it_gltf_blender.sh.
#
# blender -b --factory-startup --python blender_anim.py -- OUTDIR FRAMES...
# Builds a scene at 24 frames per second, frames 1 to 10: a cube whose
# location, rotation and scale are keyed at frames 1, 4 and 10 (Blender's
# default Bezier curves, which its exporter bakes into one linear key a
# frame), a point light and a camera; exports it to OUTDIR/anim.glb; and for
# each of FRAMES writes OUTDIR/pose-F.json: the cube's location (glTF's
# axes: Blender's x, z, -y), rotation quaternion (w last, same axes) and
# scale, as Blender itself evaluates its curves at frame F.
import json
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
out, frames = argv[0], [int(f) for f in argv[1:]]
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.fps = 24
sc.render.fps_base = 1.0
sc.frame_start, sc.frame_end = 1, 10
bpy.ops.mesh.primitive_cube_add(size=1.0)
cube = bpy.context.object
cube.name = "Cube"
cube.rotation_mode = "QUATERNION"
for frame, loc, rot, scale in ((1, (-1.5, 0.0, 0.0), (1, 0, 0, 0), (1, 1, 1)),
                               (4, (0.0, 0.5, 0.3), (0.9238795, 0, 0, 0.3826834), (1.2, 0.8, 1.0)),
                               (10, (1.5, 0.0, 0.0), (0.7071068, 0.7071068, 0, 0), (0.6, 0.6, 0.6))):
    cube.location, cube.rotation_quaternion, cube.scale = loc, rot, scale
    for path in ("location", "rotation_quaternion", "scale"):
        cube.keyframe_insert(path, frame=frame)
light = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
light.data.energy = 1000.0
light.location = (2.0, -3.0, 4.0)
sc.collection.objects.link(light)
cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
cam.location = (0.0, -8.0, 1.0)
cam.rotation_euler = (1.4708, 0.0, 0.0)
sc.collection.objects.link(cam)
sc.camera = cam
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "anim.glb"), export_format="GLB", export_cameras=True, export_lights=True)
for f in frames:
    sc.frame_set(f)
    loc, rot, scale = cube.location, cube.rotation_quaternion, cube.scale
    pose = {"translation": [loc.x, loc.z, -loc.y],
            "rotation": [rot.x, rot.z, -rot.y, rot.w],
            "scale": [scale.x, scale.z, scale.y]}
    with open(os.path.join(out, "pose-%d.json" % f), "w") as fp:
        json.dump(pose, fp)
