"""Blender's blue noise, timed: Distribute Points on Faces in Poisson Disk
mode on the mesh pelage wrote, for pelage's count and minimum distance.

Run by `pelage bench sampler --peer blender` with Blender as a Python
module:
    python blender_poisson.py CASE_DIR
CASE_DIR holds case.json (count, distance, area, runs), positions.f32 and
triangles.u32. Blender's node scatters points at its Density Max, then
removes those closer than Distance Min to one kept before; its count
follows Density Max, so Density Max is first searched (bisection) for the
count asked, then the median of the runs timed, each with a new seed.
Prints one JSON line: the median seconds, the points, the density used,
Blender's version.
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

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
mesh = bpy.data.meshes.new("skin")
mesh.from_pydata(positions.tolist(), [], triangles.tolist())
mesh.update()
skin = bpy.data.objects.new("skin", mesh)
scene.collection.objects.link(skin)

tree = bpy.data.node_groups.new("pelage poisson peer", "GeometryNodeTree")
tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
group_in = tree.nodes.new("NodeGroupInput")
group_out = tree.nodes.new("NodeGroupOutput")
distribute = tree.nodes.new("GeometryNodeDistributePointsOnFaces")
distribute.distribute_method = "POISSON"
distribute.inputs["Distance Min"].default_value = case["distance"]
tree.links.new(group_in.outputs["Geometry"], distribute.inputs["Mesh"])
tree.links.new(distribute.outputs["Points"], group_out.inputs["Geometry"])
modifier = skin.modifiers.new("points", "NODES")
modifier.node_group = tree


def evaluate(density, seed):
    """Seconds and points of one evaluation."""
    distribute.inputs["Density Max"].default_value = density
    distribute.inputs["Seed"].default_value = seed
    start = time.perf_counter()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    geometry = skin.evaluated_get(depsgraph).evaluated_geometry()
    count = len(geometry.pointcloud.points) if geometry.pointcloud else 0
    return time.perf_counter() - start, count


wanted = case["count"]
low, high = wanted / case["area"], 64 * wanted / case["area"]
density = 2 * low
for step in range(24):
    _, count = evaluate(density, 1000 + step)
    if abs(count - wanted) <= 0.005 * wanted:
        break
    if count < wanted:
        low = density
    else:
        high = density
    density = 0.5 * (low + high)

times, counts = [], []
for run in range(case["runs"] + 1):
    seconds, count = evaluate(density, run)
    if run > 0:  # the first run warms up
        times.append(seconds)
        counts.append(count)

print(json.dumps({
    "seconds": statistics.median(times),
    "points": int(statistics.median(counts)),
    "density_max": density,
    "blender": bpy.app.version_string,
}))
