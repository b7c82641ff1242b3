"""Blender's answer to a guide edit, timed: Distribute Points on Faces +
Interpolate Curves (geometry nodes) on the mesh and guides pelage wrote,
re-evaluated after one guide point moves (Blender regrows every hair on
every edit: its nodes cache nothing between evaluations).

Run by `pelage bench groom --edit --peer blender` with Blender as a Python
module:
    python blender_edit.py CASE_DIR
CASE_DIR holds case.json (counts, area, runs, the guide to move and by
how much), positions.f32, triangles.u32 and guides.f32 (guide points, root
first). Prints one JSON line: the median seconds from the edit to the
evaluated hairs, the hairs and points, Blender's version.
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
positions = np.fromfile(case_dir / "positions.f32", dtype=np.float32).reshape(-1, 3)
triangles = np.fromfile(case_dir / "triangles.u32", dtype=np.uint32).reshape(-1, 3)
guide_points = np.fromfile(case_dir / "guides.f32", dtype=np.float32)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

mesh = bpy.data.meshes.new("skin")
mesh.from_pydata(positions.tolist(), [], triangles.tolist())
mesh.update()
skin = bpy.data.objects.new("skin", mesh)
scene.collection.objects.link(skin)

guides = bpy.data.hair_curves.new("guides")
guides.add_curves([case["points_per_guide"]] * case["guides"])
guides.position_data.foreach_set("vector", guide_points)
guide_object = bpy.data.objects.new("guides", guides)
scene.collection.objects.link(guide_object)

tree = bpy.data.node_groups.new("pelage peer", "GeometryNodeTree")
tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
group_in = tree.nodes.new("NodeGroupInput")
group_out = tree.nodes.new("NodeGroupOutput")
distribute = tree.nodes.new("GeometryNodeDistributePointsOnFaces")
distribute.distribute_method = "RANDOM"
distribute.inputs["Density"].default_value = case["hairs"] / case["area"]
info = tree.nodes.new("GeometryNodeObjectInfo")
info.inputs["Object"].default_value = guide_object
interpolate = tree.nodes.new("GeometryNodeInterpolateCurves")
interpolate.inputs["Max Neighbors"].default_value = case["neighbours"]
links = tree.links
links.new(group_in.outputs["Geometry"], distribute.inputs["Mesh"])
links.new(info.outputs["Geometry"], interpolate.inputs["Guide Curves"])
links.new(distribute.outputs["Points"], interpolate.inputs["Points"])
links.new(interpolate.outputs["Curves"], group_out.inputs["Geometry"])
modifier = skin.modifiers.new("hair", "NODES")
modifier.node_group = tree

point = case["guide"] * case["points_per_guide"] + case["points_per_guide"] - 1
offset = case["offset"]
times = []
hairs = points = 0
for run in range(case["runs"] + 1):
    # The edit: one guide's tip moves (back and forth, so every run moves it).
    sign = 1.0 if run % 2 == 0 else -1.0
    start = time.perf_counter()
    tip = guides.position_data[point].vector
    guides.position_data[point].vector = (tip[0], tip[1] + sign * offset, tip[2])
    guides.update_tag()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    evaluated = skin.evaluated_get(depsgraph)
    geometry = evaluated.evaluated_geometry()
    curves = geometry.curves
    elapsed = time.perf_counter() - start
    hairs, points = len(curves.curves), len(curves.points)
    if run > 0:  # the first evaluation builds everything
        times.append(elapsed)

print(json.dumps({
    "seconds": statistics.median(times),
    "hairs": hairs,
    "points": points,
    "blender": bpy.app.version_string,
}))
