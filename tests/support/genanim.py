# genanim.py -- writes animated glTF scenes and their static twins for it_gltf_anim.sh.
#
#   python3 genanim.py DIR
#
# DIR/anim.gltf: a floor, a box on a node whose translation, rotation and
# scale are animated (LINEAR, keys at frames 0..3 of 24 frames per second:
# time f / 24 in single precision, as Blender's exporter writes them), a
# point light and the camera on animated nodes too.  DIR/pose0.gltf ..
# pose3.gltf: the same scene without animations, each node at frame k's
# key values.  DIR/bad_*.gltf: malformed animation data.  DIR/blur.gltf: a
# camera moving along +x at 96 units a second (keys at times 0 and 1)
# before an emissive quad 3 units wide at distance 4 centred on x = 48, with
# tan(yfov / 2) = 1/2 and aspectRatio 4: at 16 pixels high, 4 pixels a unit,
# so frame 12 (time 1/2) shows the quad 12 pixels wide centred in the image,
# and a shutter of half a frame (1/48 s) smears it over 8 pixels.
# DIR/morph.gltf: an emissive quad with two morph targets whose weights
# are animated (LINEAR, keys at frames 0, 1, 2); DIR/morph0.gltf ..
# morph2.gltf: the quad without targets, its positions those of frame k
# worked out here (base plus each weight times its target, in double as
# the reader does, rounded to single precision).  DIR/skin.gltf: an
# emissive strip skinned to two joints, the second (a child of the first)
# translated and scaled by an animation (keys at frames 0, 1, 2), the
# middle vertices weighted half and half, the mesh's node moved (which
# glTF ignores for a skinned mesh); DIR/skin0.gltf .. skin2.gltf: the strip
# unskinned with its positions at each frame, worked out here (every
# number exact in binary, so any order of the sums gives the same bits).
import base64
import json
import math
import os
import struct
import sys

out = sys.argv[1]
F32 = 5126


def f32(x):
    return struct.unpack('<f', struct.pack('<f', x))[0]


def quat(axis, deg):
    a = math.radians(deg) / 2
    n = math.sqrt(sum(c * c for c in axis))
    return [f32(c / n * math.sin(a)) for c in axis] + [f32(math.cos(a))]


FRAMES = 4
times = [f32(f / 24.0) for f in range(FRAMES)]
box_t = [[f32(0.3 * f - 0.4), f32(0.5 + 0.1 * f), f32(-0.2 * f)] for f in range(FRAMES)]
box_r = [quat([0.2, 1.0, 0.3], 25.0 * f + 10.0) for f in range(FRAMES)]
box_s = [[f32(0.6 + 0.1 * f), f32(0.5 + 0.05 * f), f32(0.7 - 0.1 * f)] for f in range(FRAMES)]
lamp_t = [[f32(1.5 - 0.5 * f), f32(2.5), f32(1.0 + 0.3 * f)] for f in range(FRAMES)]
cam_t = [[f32(0.2 * f), f32(1.2), f32(4.0 - 0.25 * f)] for f in range(FRAMES)]
cam_r = [quat([1.0, 0.1 * f, 0.0], -12.0 - 2.0 * f) for f in range(FRAMES)]

# A cube of side 2 (24 vertices, normals) and a floor quad.
pos, nrm, idx = [], [], []
for axis in range(3):
    for sgn in (1.0, -1.0):
        base = len(pos)
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            p = [0.0, 0.0, 0.0]
            p[axis], p[u], p[v] = sgn, a * sgn, b
            pos.append(p)
            n = [0.0, 0.0, 0.0]
            n[axis] = sgn
            nrm.append(n)
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
floor_pos = [[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5]]
floor_idx = [0, 2, 1, 0, 3, 2]

blob = bytearray()
views, accs = [], []


def add(values, comps, ctype=F32, typ=None):
    global blob
    while len(blob) % 4:
        blob += b'\0'
    off = len(blob)
    flat = [c for v in values for c in (v if isinstance(v, list) else [v])]
    blob += struct.pack('<%d%s' % (len(flat), 'f' if ctype == F32 else 'I'), *flat)
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(blob) - off})
    a = {"bufferView": len(views) - 1, "componentType": ctype, "count": len(values),
         "type": typ or {1: "SCALAR", 3: "VEC3", 4: "VEC4"}[comps]}
    if typ is None and comps == 3 and ctype == F32:
        a["min"] = [min(v[i] for v in values) for i in range(3)]
        a["max"] = [max(v[i] for v in values) for i in range(3)]
    accs.append(a)
    return len(accs) - 1


a_pos, a_nrm = add(pos, 3), add(nrm, 3)
a_idx = add(idx, 1, 5125)
a_fpos = add(floor_pos, 3)
a_fidx = add(floor_idx, 1, 5125)
a_time = add(times, 1)
a_bt, a_br, a_bs = add(box_t, 3), add(box_r, 4), add(box_s, 3)
a_lt, a_ct, a_cr = add(lamp_t, 3), add(cam_t, 3), add(cam_r, 4)
a_badtime = add([0.0, f32(0.2), f32(0.1), f32(0.3)], 1)


def doc(frame):
    """The scene: animated (frame None) or static at key `frame`."""
    k = 0 if frame is None else frame
    d = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 2000.0}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [
            {"name": "floor", "mesh": 1},
            {"name": "box", "mesh": 0, "translation": box_t[k], "rotation": box_r[k], "scale": box_s[k]},
            {"name": "lamp", "translation": lamp_t[k], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "cam", "camera": 0, "translation": cam_t[k], "rotation": cam_r[k]},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "aspectRatio": 1.5, "znear": 0.1}}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1], "metallicFactor": 0}},
                      {"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1], "metallicFactor": 0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": a_pos, "NORMAL": a_nrm}, "indices": a_idx,
                                    "material": 0}]},
                   {"primitives": [{"attributes": {"POSITION": a_fpos}, "indices": a_fidx, "material": 1}]}],
        "accessors": accs,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }
    if frame is None:
        d["animations"] = [
            {"name": "box", "samplers": [{"input": a_time, "output": a_bt}, {"input": a_time, "output": a_br},
                                         {"input": a_time, "output": a_bs, "interpolation": "LINEAR"}],
             "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}},
                          {"sampler": 1, "target": {"node": 1, "path": "rotation"}},
                          {"sampler": 2, "target": {"node": 1, "path": "scale"}}]},
            {"name": "rig", "samplers": [{"input": a_time, "output": a_lt}, {"input": a_time, "output": a_ct},
                                         {"input": a_time, "output": a_cr}],
             "channels": [{"sampler": 0, "target": {"node": 2, "path": "translation"}},
                          {"sampler": 1, "target": {"node": 3, "path": "translation"}},
                          {"sampler": 2, "target": {"node": 3, "path": "rotation"}}]}]
    return d


def write(name, d):
    with open(os.path.join(out, name), 'w') as f:
        json.dump(d, f)


write("anim.gltf", doc(None))
for k in range(FRAMES):
    write("pose%d.gltf" % k, doc(k))

# Malformed animation data: each file breaks one thing.
d = doc(None)
d["animations"][0]["channels"][1]["sampler"] = 7
write("bad_sampler.gltf", d)
d = doc(None)
d["animations"][1]["channels"][0]["target"]["node"] = 99
write("bad_node.gltf", d)
d = doc(None)
d["animations"][0]["samplers"][2]["output"] = a_br
write("bad_type.gltf", d)
d = doc(None)
d["animations"][1]["samplers"][0]["interpolation"] = "CUBICSPLINE"
write("bad_count.gltf", d)
d = doc(None)
d["animations"][0]["channels"][0]["target"]["path"] = "weights"
write("bad_weights.gltf", d)
d = doc(None)
d["animations"][0]["samplers"][0]["input"] = a_badtime
write("bad_times.gltf", d)

# The motion blur scene (its own buffer).
blob, views, accs = bytearray(), [], []
q_pos = add([[46.5, -5, -4], [49.5, -5, -4], [49.5, 5, -4], [46.5, 5, -4]], 3)
q_idx = add([0, 1, 2, 0, 2, 3], 1, 5125)
b_time = add([0.0, 1.0], 1)
b_cam = add([[0.0, 0.0, 0.0], [96.0, 0.0, 0.0]], 3)
write("blur.gltf", {
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"name": "quad", "mesh": 0}, {"name": "cam", "camera": 0}],
    "cameras": [{"type": "perspective",
                 "perspective": {"yfov": 2 * math.atan(0.5), "aspectRatio": 4.0, "znear": 0.1}}],
    "materials": [{"emissiveFactor": [1, 1, 1],
                   "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": q_pos}, "indices": q_idx, "material": 0}]}],
    "animations": [{"samplers": [{"input": b_time, "output": b_cam}],
                    "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}],
    "accessors": accs,
    "bufferViews": views,
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
})

# The morphed quad (its own buffer).
blob, views, accs = bytearray(), [], []
m_base = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]]
m_t0 = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.3, 0.5, 0.0], [0.0, 0.0, 0.0]]
m_t1 = [[0.0, -0.3, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [-0.4, 0.2, 0.0]]
m_w = [[0.0, 0.0], [1.0, f32(0.25)], [f32(0.5), 1.0]]


def morph_doc(pos, targets, weights):
    global blob, views, accs
    blob, views, accs = bytearray(), [], []
    a_p = add(pos, 3)
    a_i = add([0, 1, 2, 0, 2, 3], 1, 5125)
    prim = {"attributes": {"POSITION": a_p}, "indices": a_i, "material": 0}
    d = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": "quad", "mesh": 0}, {"name": "cam", "camera": 0, "translation": [0, 0, 4]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.0, "znear": 0.1}}],
        "materials": [{"emissiveFactor": [1, 0.5, 0.25], "doubleSided": True,
                       "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}}],
        "meshes": [{"primitives": [prim]}],
    }
    if targets:
        prim["targets"] = [{"POSITION": add(t, 3)} for t in targets]
        d["meshes"][0]["weights"] = [0.0, 0.0]
        a_t = add([f32(k / 24.0) for k in range(len(weights))], 1)
        a_w = add([w for k in weights for w in k], 1)
        d["animations"] = [{"samplers": [{"input": a_t, "output": a_w}],
                            "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}]
    d["accessors"], d["bufferViews"] = accs, views
    d["buffers"] = [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}]
    return d


write("morph.gltf", morph_doc(m_base, [m_t0, m_t1], m_w))
for k, w in enumerate(m_w):
    pos = []
    for v in range(4):
        p = list(m_base[v])
        for t, wt in zip((m_t0, m_t1), w):
            if wt != 0.0:
                for j in range(3):
                    p[j] += wt * t[v][j]
        pos.append([f32(c) for c in p])
    write("morph%d.gltf" % k, morph_doc(pos, None, None))
write("bad_morph.gltf", morph_doc(m_base, [m_t0, m_t1], [w + [0.0] for w in m_w]))

# The skinned strip (its own buffer).
s_pos = [[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [-0.5, 1.0, 0.0], [0.5, 1.0, 0.0], [-0.5, 2.0, 0.0], [0.5, 2.0, 0.0]]
s_idx = [0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4]
s_joint = [[0, 0, 0, 0], [0, 0, 0, 0], [0, 1, 0, 0], [0, 1, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0]]
s_weight = [[1, 0, 0, 0], [1, 0, 0, 0], [0.5, 0.5, 0, 0], [0.5, 0.5, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0]]
s_t = [[0.0, 1.0, 0.0], [0.5, 2.0, 0.0], [-0.5, 1.5, 0.0]]
s_s = [[1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [1.0, 0.5, 1.0]]


def skin_doc(pos, skinned):
    global blob, views, accs
    blob, views, accs = bytearray(), [], []
    a_p = add(pos, 3)
    a_i = add(s_idx, 1, 5125)
    prim = {"attributes": {"POSITION": a_p}, "indices": a_i, "material": 0}
    d = {
        "asset": {"version": "2.0"}, "scene": 0,
        "nodes": [{"name": "strip", "mesh": 0}, {"name": "cam", "camera": 0, "translation": [0, 1, 6]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "aspectRatio": 1.0, "znear": 0.1}}],
        "materials": [{"emissiveFactor": [0.3, 1, 0.5], "doubleSided": True,
                       "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}}],
        "meshes": [{"primitives": [prim]}],
    }
    d["scenes"] = [{"nodes": [0, 1]}]
    if skinned:
        # joints as bytes, weights as floats
        while len(blob) % 4:
            blob += b"\0"
        off = len(blob)
        blob += bytes(c for j in s_joint for c in j)
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(blob) - off})
        accs.append({"bufferView": len(views) - 1, "componentType": 5121, "count": 6, "type": "VEC4"})
        prim["attributes"]["JOINTS_0"] = len(accs) - 1
        prim["attributes"]["WEIGHTS_0"] = add(s_weight, 4)
        ibm = add([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1],
                   [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, -1, 0, 1]], 1, typ="MAT4")
        accs[ibm]["count"] = 2
        d["nodes"][0]["skin"] = 0
        d["nodes"][0]["translation"] = [5, 0, 0]
        d["nodes"] += [{"name": "root", "children": [3]}, {"name": "tip", "translation": s_t[0]}]
        d["scenes"][0]["nodes"].append(2)
        d["skins"] = [{"joints": [2, 3], "inverseBindMatrices": ibm}]
        a_k = add([f32(k / 24.0) for k in range(3)], 1)
        a_t, a_s = add(s_t, 3), add(s_s, 3)
        d["animations"] = [{"samplers": [{"input": a_k, "output": a_t}, {"input": a_k, "output": a_s}],
                            "channels": [{"sampler": 0, "target": {"node": 3, "path": "translation"}},
                                         {"sampler": 1, "target": {"node": 3, "path": "scale"}}]}]
    d["accessors"], d["bufferViews"] = accs, views
    d["buffers"] = [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}]
    return d


write("skin.gltf", skin_doc(s_pos, True))
for k in range(3):
    # joint 0: identity; joint 1: scale s and translation t, times the
    # inverse bind matrix (a translation by -1 in y)
    pos = []
    for v in range(6):
        p0 = s_pos[v]
        p1 = [s_s[k][j] * p0[j] + s_t[k][j] + (-s_s[k][1] if j == 1 else 0.0) for j in range(3)]
        w = s_weight[v]
        js = s_joint[v]
        placed = [0.0, 0.0, 0.0]
        for i in range(4):
            if w[i] != 0:
                q = p0 if js[i] == 0 else p1
                placed = [placed[j] + w[i] * q[j] for j in range(3)]
        pos.append(placed)
    write("skin%d.gltf" % k, skin_doc(pos, False))
d = skin_doc(s_pos, True)
d["skins"][0] = {"joints": [2]}
write("bad_skin.gltf", d)
