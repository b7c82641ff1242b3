#!/usr/bin/env python3
"""Writes the hostile suite's binary and generated inputs into files/.

Not from here: the crafted usdc files (`cargo test -p pelage --lib --
--ignored write_hostile_suite_files`) and the farm folders `farm_*`
(written by `pelage groom --part` itself).

cases.toml names them; crates/pelage-cli/tests/hostile.rs copies each
case's files into a fresh folder and runs pelage there. Run this again
after adding a file here.
"""
import base64, json, os, struct, zlib

here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "files")
os.makedirs(here, exist_ok=True)


def write(name, data):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(here, name), "wb") as f:
        f.write(data)


def png(width, height, bit_depth, colour_type, rows):
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = b"".join(b"\0" + r for r in rows)
    header = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


# A decompression bomb: 20000 x 20000 one-bit pixels, all black, a valid
# PNG of a few kilobytes that expands to 400 MB of 8-bit texels (and to
# 6.4 GB as float RGBA).
side = 20000
row = bytes(side // 8)
write("bomb_20000.png", png(side, side, 1, 0, [row] * side))


def triangle_gltf(**extra):
    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"byteLength": len(pos),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(pos).decode()}],
        "bufferViews": [{"buffer": 0, "byteLength": len(pos)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
    }
    doc.update(extra)
    return doc


# POSITION names an accessor that does not exist (the gltf crate's own
# validation indexes it unchecked).
doc = triangle_gltf()
doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 5
write("gltf_missing_accessor.gltf", json.dumps(doc))
# Its sibling: a NORMAL naming a missing accessor.
doc = triangle_gltf()
doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 7
write("gltf_missing_normal_accessor.gltf", json.dumps(doc))
# A node that is its own grandparent.
write("gltf_node_cycle.gltf", json.dumps(triangle_gltf(
    nodes=[{"mesh": 0, "children": [1]}, {"children": [0]}])))
# A lattice: 40 levels, each node the child of both nodes above it, so
# 2^40 paths through a file of 80 nodes.
nodes = []
for level in range(40):
    children = [2 * level + 2, 2 * level + 3] if level < 39 else []
    nodes += [{"children": children}, {"children": children, "mesh": 0}]
write("gltf_node_lattice.gltf", json.dumps(triangle_gltf(
    nodes=nodes, scenes=[{"nodes": [0, 1]}])))

# Animation channels the gltf crate reads without checking: a target node
# out of range (it panics), and a target path it does not know (it
# unwraps). Times and values read from the triangle's own buffer.
def animated_gltf(node, path):
    doc = triangle_gltf()
    doc["accessors"] += [
        {"bufferView": 0, "componentType": 5126, "count": 1, "type": "SCALAR",
         "min": [0], "max": [0]},
        {"bufferView": 0, "componentType": 5126, "count": 1, "type": "VEC3"},
    ]
    doc["animations"] = [{"name": "Run",
                          "samplers": [{"input": 1, "output": 2}],
                          "channels": [{"sampler": 0, "target": {"node": node, "path": path}}]}]
    return doc
for name, doc in [("gltf_animation_missing_node.gltf", animated_gltf(999, "translation")),
                  ("gltf_animation_unknown_path.gltf", animated_gltf(0, "wobble"))]:
    write(name, json.dumps(doc))
    # Seeds of the glTF fuzz harness too.
    with open(os.path.join(os.path.dirname(here), "fuzz", "gltf", name), "w") as f:
        f.write(json.dumps(doc))

# Within the pixel ceiling (60 M pixels) but wider than most GPUs' texture
# limit (16384 on lavapipe).
write("wide_20000x3000.png", png(20000, 3000, 1, 0, [bytes(20000 // 8)] * 3000))

# A mesh as a PLY, for outputs that would overwrite it.
write("tri.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
# An OBJ saved by a Windows editor: a byte-order mark before `v`.
write("bom.obj", "\ufeffv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")

# Crashes the glTF fuzz harness found (the gltf crate's readers assert on
# or reach `unreachable!` for these); each is a seed of the harness too.
fuzz = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fuzz", "gltf")
doc = triangle_gltf()
doc["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 3, "type": "SCALAR"})
doc["meshes"][0]["primitives"][0]["indices"] = 1
with open(os.path.join(fuzz, "crash_float_indices.gltf"), "w") as f:
    f.write(json.dumps(doc))
doc = triangle_gltf()
doc["accessors"][0]["type"] = "VEC2"
with open(os.path.join(fuzz, "crash_position_vec2.gltf"), "w") as f:
    f.write(json.dumps(doc))
doc = triangle_gltf()
doc["bufferViews"][0]["byteStride"] = 4
with open(os.path.join(fuzz, "crash_stride_below_element.gltf"), "w") as f:
    f.write(json.dumps(doc))


# Alembic (Ogawa) objects that list themselves as their own child, under a
# long name: each level's path is longer than the last (quadratic memory:
# 300 KB names abort at 256 levels; 100 KB ones print a 25 MB error), and
# a name just under the name ceiling nested until the path ceiling.
def ogawa_self_listing(name_len):
    name = b"n" * name_len
    empty_data = 1 << 63
    out = bytearray(b"Ogawa\xff\x00\x01" + bytes(8))
    headers = len(out)
    body = struct.pack("<I", len(name)) + name + b"\x00" + bytes(32)
    out += struct.pack("<Q", len(body)) + body
    obj = len(out)
    out += struct.pack("<4Q", 3, 0, obj, headers | empty_data)
    top = len(out)
    out += struct.pack("<7Q", 6, empty_data, empty_data, obj, empty_data, empty_data, empty_data)
    out[8:16] = struct.pack("<Q", top)
    return bytes(out)
write("abc_self_listing_300k.abc", ogawa_self_listing(300_000))
write("abc_self_listing_100k.abc", ogawa_self_listing(100_000))
write("abc_self_listing_4000.abc", ogawa_self_listing(4000))


# Forty UDIM tiles of 8192 x 8192 one-bit pixels: each is within the
# per-image ceiling, together they are 2.7 G pixels (10 GB as texels).
udim = os.path.join(here, "udim_40_tiles")
os.makedirs(udim, exist_ok=True)
tile = png(8192, 8192, 1, 0, [bytes(1024)] * 8192)
for k in range(40):
    with open(os.path.join(udim, "density.%d.png" % (1001 + k)), "wb") as f:
        f.write(tile)
