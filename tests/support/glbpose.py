# glbpose.py -- a still copy of a glTF binary file with one node posed.
#
# python3 glbpose.py IN.glb NODE POSE.json OUT.glb: OUT.glb is IN.glb
# without its animations, node NODE (by name) given the translation,
# rotation and scale of POSE.json (it_gltf_blender.sh).
import json
import struct
import sys

src, name, pose_file, dst = sys.argv[1:5]
data = open(src, "rb").read()
magic, version, _ = struct.unpack_from("<4sII", data, 0)
assert magic == b"glTF" and version == 2, "not a glTF 2 binary file"
jlen, jtype = struct.unpack_from("<I4s", data, 12)
assert jtype == b"JSON"
doc = json.loads(data[20:20 + jlen])
rest = data[20 + jlen:]
doc.pop("animations", None)
pose = json.load(open(pose_file))
node = [n for n in doc["nodes"] if n.get("name") == name][0]
node.pop("matrix", None)
node.update(pose)
text = json.dumps(doc).encode()
text += b" " * (-len(text) % 4)
out = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + len(rest)) + struct.pack("<I4s", len(text), b"JSON") + text + rest
open(dst, "wb").write(out)
