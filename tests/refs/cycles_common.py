# cycles_common.py -- what the Cycles reference scripts of tests/refs share:
# their arguments, Franja's frame placed in Blender's, the emptied start-up
# scene, a camera, the render settings every reference is made with and
# the output (linear float EXR, and its RGB pixels as a PFM).  Not run by
# itself; each script imports it from its own directory:
#
#   sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
#   import cycles_common as cc
#
# Franja's +y-up frame is placed in Blender's +z-up one as
# Blender = (x, -z, y) (how Blender's glTF exporter maps Blender to glTF,
# inverted).
import math
import struct
import sys
import time

import bpy
from mathutils import Vector


def args():
    """The script's own arguments: those after Blender's "--"."""
    return sys.argv[sys.argv.index("--") + 1:]


def blender(v):
    """A point or direction of Franja's frame in Blender's."""
    return Vector((v[0], -v[2], v[1]))


def empty_scene():
    """The start-up scene with every object removed."""
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    return bpy.context.scene


def nodes_of(block):
    """Turns on the node tree of block (a material or a world) and empties
    it; returns its (nodes, links)."""
    block.use_nodes = True
    block.node_tree.nodes.clear()
    return block.node_tree.nodes, block.node_tree.links


def diffuse(nodes, albedo):
    """A Diffuse BSDF node of colour albedo (r, g, b), roughness 0."""
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = tuple(albedo) + (1,)
    bsdf.inputs["Roughness"].default_value = 0.0
    return bsdf


def black_world(scene):
    """A world that gives no light: the default Background at strength 0."""
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world


def quad(scene, i, vertices, mat):
    """Object quadI: the quad of four vertices (Franja's frame), with
    material mat, in the scene's own collection."""
    mesh = bpy.data.meshes.new("quad%d" % i)
    mesh.from_pydata([blender(v) for v in vertices], [], [(0, 1, 2, 3)])
    obj = bpy.data.objects.new("quad%d" % i, mesh)
    obj.data.materials.append(mat)
    scene.collection.objects.link(obj)
    return obj


def sphere(center, radius, mat):
    """A smooth UV sphere (256 segments, 128 rings; Franja's frame) with
    material mat, in the active collection."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=radius,
                                         location=blender(center))
    bpy.ops.object.shade_smooth()
    obj = bpy.context.active_object
    obj.data.materials.append(mat)
    return obj


def camera(scene, fov_deg=None, clip=None):
    """The scene's camera, object and data named "camera"; with fov_deg, a
    vertical field of view of fov_deg degrees (sensor fit VERTICAL), with
    clip, its (start, end) clipping distances in metres."""
    data = bpy.data.cameras.new("camera")
    if fov_deg is not None:
        data.sensor_fit = "VERTICAL"
        data.angle_y = math.radians(fov_deg)
    if clip is not None:
        data.clip_start, data.clip_end = clip
    cam = bpy.data.objects.new("camera", data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam


def aim(cam, position, target):
    """Puts cam at position looking at target (Franja's frame), up +y."""
    p, t = blender(position), blender(target)
    cam.location = p
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = (t - p).to_track_quat("-Z", "Y")


def bounces(scene, n):
    """Cycles' Max Bounces n for every kind of bounce (Franja's max_depth
    n + 1)."""
    c = scene.cycles
    c.max_bounces = n
    c.diffuse_bounces = n
    c.glossy_bounces = n
    c.transmission_bounces = n
    c.volume_bounces = n
    c.transparent_max_bounces = n


def settings(scene, samples, seed, max_bounces, box_filter=True):
    """Cycles on the CPU, samples per pixel with seed, no adaptive sampling,
    denoising, clamping or glossy filter, caustics on, bounces(max_bounces);
    with box_filter a box pixel filter 1 pixel wide, else Cycles' default
    filter.  The image at 100 % of its resolution, the Standard view
    transform, written as EXR of 32-bit floats (ZIP)."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    c.seed = seed
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    if box_filter:
        c.pixel_filter_type = "BOX"
        c.filter_width = 1.0
    bounces(scene, max_bounces)
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    out = scene.render.image_settings
    out.file_format = "OPEN_EXR"
    out.color_depth = "32"
    out.exr_codec = "ZIP"


def render(scene, exr_path, pfm_path=None):
    """Renders the scene to exr_path (linear float RGBA); with pfm_path, also
    writes the image's RGB pixels there as a little-endian float32 PFM,
    bottom row first (as the test tools read it)."""
    scene.render.filepath = exr_path
    # CPU seconds of the render alone (every thread of the process: scene
    # sync, BVH, sampling, the file), without blender's start-up.
    t0 = time.process_time()
    bpy.ops.render.render(write_still=True)
    print("render CPU seconds: %.3f" % (time.process_time() - t0), flush=True)
    if pfm_path is None:
        return
    img = bpy.data.images.load(exr_path)
    w, h = img.size
    px = list(img.pixels)  # RGBA, bottom row first
    with open(pfm_path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        for i in range(w * h):
            f.write(struct.pack("<3f", *px[4 * i:4 * i + 3]))
    bpy.data.images.remove(img)
