"""The add-on's Live mode against Blender's own hair nodes, timed.

Run by `pelage bench blender` with Blender as a Python module (pelage
installed into its venv):
    python blender_live.py CASE_DIR
CASE_DIR holds case.json (the add-on's folder, hairs, guides a side,
edits). On a grid with guides in a hair Curves object it times (1) Grow
pelage fur with Live on (the session's start and the transfer), (2) each
guide edit followed by the add-on's `live_update` (pelage's incremental
regrowth, the points into the Curves object), median of the edits,
(2b) the same end to end: the edit, the add-on's handler as Blender runs
it after a depsgraph update, and Blender's own evaluation of the fur
object after it (its modifiers, what a redraw waits for), on the grid as
it is and again with a shape key (the fur then has Deform Curves on
Surface), and (3) the peer: Blender's Distribute Points on Faces + Interpolate Curves
(geometry nodes) re-evaluated after the same edits, median. Prints one
JSON line.
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
sys.path.insert(0, str(Path(case["addon_dir"]).parent))
import pelage_fur  # noqa: E402  (blender/pelage_fur)
from pelage_fur import fur  # noqa: E402

bpy.ops.wm.read_factory_settings(use_empty=True)
pelage_fur.register()
scene = bpy.context.scene
bpy.ops.mesh.primitive_grid_add(x_subdivisions=40, y_subdivisions=40, size=2.0)
grid = bpy.context.active_object

side = case["guides_a_side"]
g = np.linspace(-0.9, 0.9, side)
roots = np.array([[x, y, 0.0] for x in g for y in g])
points_per_guide = 7
steps = np.linspace(0, 0.2, points_per_guide)
guides = bpy.data.hair_curves.new("guides")
guides.add_curves([points_per_guide] * len(roots))
rest = (roots[:, None, :] + steps[None, :, None] * np.array([0, 0, 1.0])).reshape(-1, 3)
guides.position_data.foreach_set("vector", rest.astype(np.float32).ravel())
guide_object = bpy.data.objects.new("guides", guides)
scene.collection.objects.link(guide_object)

# The edits: one guide's curve combed sideways, the same for both.
rng = np.random.default_rng(7)
edits = []
for _ in range(case["edits"]):
    i = int(rng.integers(len(roots)))
    edits.append((i, rng.normal(size=3) * np.array([0.3, 0.3, 0.0])))


def apply(points, edit):
    i, by = edit
    moved = points.copy()
    moved[i * points_per_guide:(i + 1) * points_per_guide] += steps[:, None] * by
    guides.position_data.foreach_set("vector", moved.astype(np.float32).ravel())
    guides.update_tag()
    return moved


settings = grid.pelage_fur
settings.count, settings.points, settings.guides_object, settings.live = case["hairs"], 12, guide_object, True
settings.clump, settings.noise = 0.0, 0.0
start = time.perf_counter()
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
full = time.perf_counter() - start
fur_object = bpy.data.objects[fur.LIVE[grid.name].fur_name]
hairs = len(fur_object.data.curves)

pelage_times, points = [], rest
for edit in edits:
    points = apply(points, edit)
    start = time.perf_counter()
    done = fur.live_update(grid)
    pelage_times.append(time.perf_counter() - start)
    assert done is not None


def evaluated_fur_points():
    """The fur's points as Blender evaluates them for display."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    evaluated = fur_object.evaluated_get(depsgraph).data
    return len(evaluated.points)


# End to end: the comb as the user makes it. The edit, the depsgraph
# update that reports it (the add-on's handler schedules the regrow),
# the scheduled regrow, and Blender's evaluation of the moved fur.
def combs(points):
    """Each edit combed end to end; the seconds of each, and the guides'
    points after."""
    evaluated_fur_points()
    fur.PENDING.clear()
    times = []
    for edit in edits:
        points = apply(points, edit)
        start = time.perf_counter()
        bpy.context.evaluated_depsgraph_get().update()
        assert fur.PENDING.get(grid.name) is not None, "the handler saw the comb"
        fur.PENDING.pop(grid.name, None)
        assert fur.live_update(grid) is not None
        evaluated_fur_points()
        times.append(time.perf_counter() - start)
    return times, points


# Nothing deforms the grid: the fur has no Deform Curves on Surface.
assert fur.deform_modifier_of(fur_object) is None
comb_times, points = combs(points)
# A shape key on the grid: now the fur has the modifier, whose node
# recomputes every point of the fur after each comb.
grid.shape_key_add(name="Basis")
grid.shape_key_add(name="lifted").value = 0.5
bpy.context.view_layer.update()
assert fur.deform_modifier_of(fur_object) is not None
deforming_times, points = combs(points)

# The peer, on the same grid and guides (the live fur object removed).
bpy.data.objects.remove(fur_object)
fur.LIVE.clear()
points = apply(rest, (0, np.zeros(3)))
tree = bpy.data.node_groups.new("peer", "GeometryNodeTree")
tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
group_in, group_out = tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput")
distribute = tree.nodes.new("GeometryNodeDistributePointsOnFaces")
distribute.distribute_method = "RANDOM"
distribute.inputs["Density"].default_value = case["hairs"] / 4.0  # the grid is 2 × 2
info = tree.nodes.new("GeometryNodeObjectInfo")
info.inputs["Object"].default_value = guide_object
interpolate = tree.nodes.new("GeometryNodeInterpolateCurves")
interpolate.inputs["Max Neighbors"].default_value = 4
tree.links.new(group_in.outputs["Geometry"], distribute.inputs["Mesh"])
tree.links.new(info.outputs["Geometry"], interpolate.inputs["Guide Curves"])
tree.links.new(distribute.outputs["Points"], interpolate.inputs["Points"])
tree.links.new(interpolate.outputs["Curves"], group_out.inputs["Geometry"])
grid.modifiers.new("peer", "NODES").node_group = tree
blender_times, blender_hairs = [], 0
for edit in edits:
    points = apply(points, edit)
    start = time.perf_counter()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    geometry = grid.evaluated_get(depsgraph).evaluated_geometry()
    curves = geometry.curves
    blender_hairs = len(curves.curves) if curves is not None else 0
    blender_times.append(time.perf_counter() - start)

print(json.dumps({
    "hairs": hairs,
    "full_update_s": full,
    "edit_update_s": statistics.median(pelage_times),
    "edit_update_min_s": min(pelage_times),
    "edit_update_max_s": max(pelage_times),
    "live_comb_s": statistics.median(comb_times),
    "live_comb_deforming_s": statistics.median(deforming_times),
    "blender_interpolate_s": statistics.median(blender_times),
    "blender_hairs": blender_hairs,
    "edits": len(edits),
    "blender": bpy.app.version_string,
}))
