#!/usr/bin/env python3
"""Writes the malformed-input corpus next to this script.

Each file is broken in one specific way; crates/pelage/tests/bad_input.rs
asserts that loading it gives an error naming the file, the line or element,
and what is wrong, and never a panic. Run it again after adding a case.
"""
import base64, json, os, struct

here = os.path.dirname(os.path.abspath(__file__))

def write(name, data):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(here, name), "wb") as f:
        f.write(data)

TRI = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"

# --- OBJ -------------------------------------------------------------------
write("obj_index_zero.obj", "# OBJ indices start at 1\n" + TRI + "f 0 1 2\n")
write("obj_index_past_end.obj", TRI + "f 1 2 3\nf 1 2 9\n")
write("obj_negative_index_past_start.obj", TRI + "f -1 -2 -4\n")
write("obj_nan_vertex.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
write("obj_inf_vertex.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n")
write("obj_bad_number.obj", "v 0 0 0\nv 1.0 abc 0\nv 0 1 0\nf 1 2 3\n")
write("obj_too_few_coordinates.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n")
write("obj_two_vertex_face.obj", TRI + "f 1 2\n")
write("obj_empty.obj", "# nothing but a comment\n\n")
write("obj_no_faces.obj", TRI)
write("obj_mixed_uvs.obj", TRI + "v 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\nf 2 4 3\n")
write("obj_uv_index_past_end.obj", TRI + "vt 0 0\nf 1/1 2/1 3/5\n")
write("obj_not_text.obj", TRI.encode() + b"f 1 2 3\n\xff\xfe\x00\x01binary\n")

# --- PLY -------------------------------------------------------------------
HEADER = ("ply\nformat {fmt} 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n"
          "property float z\nelement face {nf}\nproperty list uchar int vertex_indices\nend_header\n")
write("ply_wrong_magic.ply", "plx\nformat ascii 1.0\nend_header\n")
write("ply_unknown_format.ply", HEADER.format(fmt="ascii_v2", nv=3, nf=1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
body = b"".join(struct.pack("<fff", *p) for p in [(0, 0, 0), (1, 0, 0), (0, 1, 0)])
write("ply_truncated_binary.ply", HEADER.format(fmt="binary_little_endian", nv=8, nf=2).encode() + body)
write("ply_face_index_out_of_range.ply", HEADER.format(fmt="ascii", nv=3, nf=2) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 7\n")
write("ply_nan_ascii.ply", HEADER.format(fmt="ascii", nv=3, nf=1) + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n")
nan_body = b"".join(struct.pack("<fff", *p) for p in [(0, 0, 0), (1, float("nan"), 0), (0, 1, 0)])
write("ply_nan_binary.ply", HEADER.format(fmt="binary_little_endian", nv=3, nf=1).encode() + nan_body
      + struct.pack("<Biii", 3, 0, 1, 2))
write("ply_bad_token.ply", HEADER.format(fmt="ascii", nv=3, nf=1) + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n")
write("ply_no_face_element.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n")
write("ply_no_x_property.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float a\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n")

# --- glTF ------------------------------------------------------------------
write("gltf_not_json.gltf", "this is not JSON {\n")
write("glb_truncated.glb", b"glTF" + struct.pack("<II", 2, 4096) + b"\x00" * 20)
buf = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)[:24]  # 2 of the 3 vertices
gltf = {
    "asset": {"version": "2.0"},
    "buffers": [{"byteLength": 24, "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0,
}
write("gltf_accessor_past_buffer.gltf", json.dumps(gltf, indent=1))

# --- images ----------------------------------------------------------------
write("png_not_a_png.png", "I am a text file with a .png name.\n")
png = open(os.path.join(here, "..", "..", "..", "crates", "pelage", "assets", "spot_texture.png"), "rb").read()
write("png_truncated.png", png[:200])
write("exr_not_an_exr.exr", b"\x76\x2f\x31\x01" + b"\x02\x00\x00\x00" + b"garbage header")

# --- other -----------------------------------------------------------------
write("mesh_unknown_extension.stl", "solid nothing\nendsolid\n")
