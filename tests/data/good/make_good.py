#!/usr/bin/env python3
"""Writes small valid files for the loader tests next to this script.

cube.gltf / cube.glb: a unit cube exported the way glTF exporters do it,
24 vertices (4 per face, so every face has its own UVs and normals), 12
triangles, under a node scaled by 2. pelage must weld it back to 8
vertices with no open edges and an area of 24.
"""
import base64, json, os, struct

here = os.path.dirname(os.path.abspath(__file__))
faces = [  # (normal, tangent u, tangent v)
    ((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
    ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
    ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0)),
]
pos, nrm, uv, idx = [], [], [], []
for f, (n, u, v) in enumerate(faces):
    base = len(pos)
    for (su, sv) in [(-1, -1), (1, -1), (1, 1), (-1, 1)]:
        pos.append(tuple(0.5 * (n[k] + su * u[k] + sv * v[k]) for k in range(3)))
        nrm.append(n)
        uv.append(((f + (su + 1) / 2) / 6, (sv + 1) / 2))
    idx += [base, base + 1, base + 2, base, base + 2, base + 3]
blob = b"".join(struct.pack("<3f", *p) for p in pos)
blob += b"".join(struct.pack("<3f", *p) for p in nrm)
blob += b"".join(struct.pack("<2f", *p) for p in uv)
blob += b"".join(struct.pack("<H", i) for i in idx)
blob += b"\x00" * (-len(blob) % 4)
n = len(pos)
doc = {
    "asset": {"version": "2.0", "generator": "pelage tests/data/good/make_good.py"},
    "buffers": [{"byteLength": len(blob)}],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 12 * n},
        {"buffer": 0, "byteOffset": 12 * n, "byteLength": 12 * n},
        {"buffer": 0, "byteOffset": 24 * n, "byteLength": 8 * n},
        {"buffer": 0, "byteOffset": 32 * n, "byteLength": 2 * len(idx)},
    ],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
         "min": [-0.5] * 3, "max": [0.5] * 3},
        {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5123, "count": len(idx), "type": "SCALAR"},
    ],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                "indices": 3}]}],
    "nodes": [{"mesh": 0, "scale": [2, 2, 2]}],
    "scenes": [{"nodes": [0]}], "scene": 0,
}
gltf = dict(doc)
gltf["buffers"] = [{"byteLength": len(blob),
                    "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]
with open(os.path.join(here, "cube.gltf"), "w") as f:
    json.dump(gltf, f, indent=1)
js = json.dumps(doc).encode()
js += b" " * (-len(js) % 4)
glb = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(blob), 0x004E4942) + blob
with open(os.path.join(here, "cube.glb"), "wb") as f:
    f.write(b"glTF" + struct.pack("<II", 2, 12 + len(glb)) + glb)
