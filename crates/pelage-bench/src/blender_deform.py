"""Blender's own way of moving fur with an animated skin, timed: hair
curves bound to the surface by UV, moved by the Deform Curves on Surface
geometry node as the skin twists (a Simple Deform modifier, keyed over
the frames).

Run by `pelage bench animation --peer blender` with Blender as a Python
module:
    python blender_deform.py CASE_DIR
CASE_DIR holds case.json (counts, frames, twist, the add-on's folder,
whose fur.py makes the Deform Curves on Surface modifier), positions.f32,
triangles.u32, corner_uvs.f32 (a UV per triangle corner), points.f32 (the
groom grown at rest, every curve `points_per_hair` points) and
root_uvs.f32 (a UV per curve). Prints one JSON line: the median seconds a
frame (frame change, the skin deformed, every curve moved and read back),
the curves and points it moved, and Blender's version.
"""
import json
import statistics
import sys
import time
from pathlib import Path

import bpy
import numpy as np

case_dir = Path(sys.argv[1])
case = json.loads((case_dir / "case.json").read_text())
sys.path.insert(0, case["addon_dir"])
import fur as addon_fur  # noqa: E402  (blender/pelage_fur/fur.py)
read = lambda name, dtype: np.fromfile(case_dir / name, dtype=dtype)
positions = read("positions.f32", np.float32).reshape(-1, 3)
triangles = read("triangles.u32", np.uint32).reshape(-1, 3)
corner_uvs = read("corner_uvs.f32", np.float32)
points = read("points.f32", np.float32)
root_uvs = read("root_uvs.f32", np.float32)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, case["frames"]

mesh = bpy.data.meshes.new("skin")
mesh.from_pydata(positions.tolist(), [], triangles.tolist())
uv = mesh.uv_layers.new(name="UVMap")
uv.data.foreach_set("uv", corner_uvs)
mesh.update()
skin = bpy.data.objects.new("skin", mesh)
scene.collection.objects.link(skin)
# The evaluated skin keeps its rest positions, which the node needs.
skin.add_rest_position_attribute = True
twist = skin.modifiers.new("twist", "SIMPLE_DEFORM")
twist.deform_method = "TWIST"
twist.deform_axis = "Y"
twist.angle = 0.0
twist.keyframe_insert("angle", frame=1)
twist.angle = case["twist_radians"]
twist.keyframe_insert("angle", frame=case["frames"])

curves = bpy.data.hair_curves.new("fur")
curves.add_curves([case["points_per_hair"]] * case["hairs"])
curves.position_data.foreach_set("vector", points)
attribute = curves.attributes.new("surface_uv_coordinate", "FLOAT2", "CURVE")
attribute.data.foreach_set("vector", root_uvs)
curves.surface = skin
curves.surface_uv_map = "UVMap"
fur = bpy.data.objects.new("fur", curves)
scene.collection.objects.link(fur)

# The add-on's modifier: Deform Curves on Surface in a node group.
addon_fur.deform_on_surface_modifier(fur)

times = []
moved = 0
out = np.empty(points.size, dtype=np.float32)
for frame in range(1, case["frames"] + 1):
    start = time.perf_counter()
    scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    geometry = fur.evaluated_get(depsgraph).evaluated_geometry()
    evaluated = geometry.curves
    # Read the moved points back, as pelage hands them to its writer.
    evaluated.attributes["position"].data.foreach_get("vector", out)
    elapsed = time.perf_counter() - start
    moved = len(evaluated.curves)
    if frame > 1:
        times.append(elapsed)
    if frame == case["frames"]:
        # How far the fur moved from rest: proof the node did its work.
        travel = float(np.abs(out - points).max())

print(json.dumps({
    "seconds": statistics.median(times),
    "hairs": moved,
    "points": int(out.size // 3),
    "frames": len(times),
    "max_travel": travel,
    "blender": bpy.app.version_string,
}))
