# anim_gltf.py -- a glTF twin of anim_camera.sh's MOVE=instance scene.
#
#   python3 anim_gltf.py KNOT.obj OUT.gltf
#
# OUT.gltf (its buffer in OUT.bin): the OBJ's positions and triangles
# (the first index of each `f` corner) as one mesh drawn by two nodes, the
# first translated from (0, 0, 0) at time 0 to (1, 0, 0) at time 1 s
# (LINEAR), the second at (-1.5, 0, 1); a camera and a point light on
# nodes of their own, as the JSON scene places them.
import json
import math
import os
import struct
import sys
from array import array

src, out = sys.argv[1], sys.argv[2]
pos, idx = array('f'), array('I')
with open(src) as f:
    for line in f:
        if line.startswith('v '):
            pos.extend(float(x) for x in line.split()[1:4])
        elif line.startswith('f '):
            idx.extend(int(c.split('/')[0]) - 1 for c in line.split()[1:4])
n = len(pos) // 3
lo = [min(pos[i::3]) for i in range(3)]
hi = [max(pos[i::3]) for i in range(3)]
times, moves = array('f', [0.0, 1.0]), array('f', [0, 0, 0, 1, 0, 0])
blob = pos.tobytes() + idx.tobytes() + times.tobytes() + moves.tobytes()
offs = [0, len(pos) * 4, len(pos) * 4 + len(idx) * 4, len(pos) * 4 + len(idx) * 4 + 8]
lens = [len(pos) * 4, len(idx) * 4, 8, 24]
# The camera at (0, 1, -3.4) looking at (0, 0.3, 0): a rotation of pi
# about y (glTF cameras look down -z), then a pitch down.
pitch = math.atan2(0.7, 3.4)
q = [0.0, math.cos(pitch / 2), math.sin(pitch / 2), 0.0]
d = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1, 2, 3]}],
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 250.0}]}},
    "nodes": [{"name": "knot", "mesh": 0}, {"name": "knot2", "mesh": 0, "translation": [-1.5, 0, 1]},
              {"name": "cam", "camera": 0, "translation": [0, 1, -3.4], "rotation": q},
              {"name": "lamp", "translation": [0, 4, -3], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": math.radians(34), "aspectRatio": 1, "znear": 0.01}}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.2, 1], "metallicFactor": 0}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi},
                  {"bufferView": 1, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
                  {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                  {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}],
    "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": l} for o, l in zip(offs, lens)],
    "buffers": [{"byteLength": len(blob), "uri": os.path.basename(out)[:-5] + ".bin"}],
    "animations": [{"samplers": [{"input": 2, "output": 3}],
                    "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}],
}
with open(out[:-5] + ".bin", 'wb') as f:
    f.write(blob)
with open(out, 'w') as f:
    json.dump(d, f)
