"""The add-on under Blender as a Python module (bpy from PyPI), headless.

    tools/bpy-python blender/tests/test_addon.py EXTENSION.zip

Installs the extension zip (its bundled wheel included) into a fresh user
folder, runs "Grow pelage fur" on meshes with UVs, and checks what a user
would: curve and point counts, the attributes Blender's hair tools need,
roots on the surface, and that Blender's own Deform Curves on Surface
carries the fur when the mesh deforms. Exits non-zero on the first
failure; prints one line a check.
"""

import os
import sys
import tempfile

# A fresh user folder, so the test installs the add-on itself and never
# touches (or depends on) one already installed.
os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="pelage-blender-")

import bpy  # noqa: E402
import numpy as np  # noqa: E402

zip_path = os.path.abspath(sys.argv[1])
result = bpy.ops.extensions.package_install_files(
    filepath=zip_path, repo="user_default", enable_on_install=True
)
assert result == {"FINISHED"}, result
assert hasattr(bpy.ops.pelage, "grow_fur"), "the add-on registered its operator"
import pelage  # noqa: E402  (the wheel the extension bundles)

print(f"installed {os.path.basename(zip_path)}: pelage {pelage.__version__} in Blender {bpy.app.version_string}")

# Every function and class of the add-on says what it is for.
import ast  # noqa: E402

addon_folder = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "pelage_fur")
undocumented = [
    f"{name}:{node.lineno} {node.name}"
    for name in sorted(os.listdir(addon_folder)) if name.endswith(".py")
    for node in ast.walk(ast.parse(open(os.path.join(addon_folder, name)).read()))
    if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and not ast.get_docstring(node)
]
assert not undocumented, f"add-on code without a docstring: {undocumented}"
print("add-on: every function and class has a docstring")


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)


def fur_of(surface):
    found = [o for o in bpy.data.objects if o.type == "CURVES" and o.parent == surface]
    assert len(found) == 1, found
    return found[0]


def arrays(curves):
    points = np.empty(len(curves.points) * 3, np.float32)
    curves.position_data.foreach_get("vector", points)
    offsets = np.empty(len(curves.curves) + 1, np.int32)
    curves.curve_offset_data.foreach_get("value", offsets)
    return points.reshape(-1, 3), offsets


def evaluated_roots(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    # The geometry set owns the curves: keep it alive while reading.
    geometry = obj.evaluated_get(depsgraph).evaluated_geometry()
    curves = geometry.curves
    points = np.empty(len(curves.points) * 3, np.float32)
    curves.attributes["position"].data.foreach_get("vector", points)
    offsets = np.empty(len(curves.curves) + 1, np.int32)
    curves.curve_offset_data.foreach_get("value", offsets)
    return points.reshape(-1, 3)[offsets[:-1]]


# 1. A flat grid: counts, attributes, roots on the surface.
clear_scene()
bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=8, size=2.0)
grid = bpy.context.active_object
settings = grid.pelage_fur
settings.count, settings.points, settings.length, settings.seed = 3_000, 10, 0.1, 4
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
fur = fur_of(grid)
curves = fur.data
assert len(curves.curves) == 3_000, len(curves.curves)
assert len(curves.points) == 30_000, len(curves.points)
names = {a.name for a in curves.attributes}
for name in ("position", "radius", "hair_id", "surface_uv_coordinate"):
    assert name in names, (name, names)
assert curves.surface == grid and curves.surface_uv_map == grid.data.uv_layers.active.name
points, offsets = arrays(curves)
assert np.all(np.diff(offsets) == 10)
roots = points[offsets[:-1]]
assert np.allclose(roots[:, 2], 0.0, atol=1e-6), "roots lie on the grid (z = 0)"
assert np.all(np.abs(roots[:, :2]) <= 1.0 + 1e-6), "roots lie within the grid"
tips = points[offsets[1:] - 1]
assert np.all(tips[:, 2] > 0.02), "hairs grow out of the surface, along +Z"
radius = np.empty(len(curves.points), np.float32)
curves.attributes["radius"].data.foreach_get("value", radius)
assert np.all(radius > 0) and np.all(radius[offsets[:-1]] > radius[offsets[1:] - 1]), "radius tapers"
ids = np.empty(len(curves.curves), np.int32)
curves.attributes["hair_id"].data.foreach_get("value", ids)
assert len(np.unique(ids)) == len(ids), "hair ids are distinct"
uvs = np.empty(len(curves.curves) * 2, np.float32)
curves.attributes["surface_uv_coordinate"].data.foreach_get("vector", uvs)
uvs = uvs.reshape(-1, 2)
# The grid's UVs map [-1, 1]² to [0, 1]²: the root's UV says where it is.
assert np.allclose(uvs, (roots[:, :2] + 1) / 2, atol=1e-4), "surface UVs match the roots"
print("grid: 3,000 curves × 10 points; radius, hair_id, surface_uv_coordinate; roots on the surface")

# The look: per-hair shader values as curve attributes, read by a
# Principled Hair BSDF (Chiang, melanin) through Attribute nodes.
melanin = np.empty(len(curves.curves), np.float32)
curves.attributes["hair_melanin"].data.foreach_get("value", melanin)
want = settings.melanin
spread = settings.look_jitter * want
assert np.all(np.abs(melanin - want) <= spread + 1e-6), (melanin.min(), melanin.max())
assert len(np.unique(melanin)) > len(melanin) // 2, "each hair its own variation"
for name in ("hair_melanin_redness", "hair_roughness", "hair_radial_roughness", "hair_random", "hair_tint"):
    assert curves.attributes[name].domain == "CURVE", name
material = curves.materials[0]
hair = next(n for n in material.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfHairPrincipled")
assert hair.model == "CHIANG" and hair.parametrization == "MELANIN"
fed = {link.to_socket.name: link.from_node.attribute_name
       for link in material.node_tree.links if link.to_node == hair}
assert fed == {"Melanin": "hair_melanin", "Melanin Redness": "hair_melanin_redness", "Tint": "hair_tint",
               "Roughness": "hair_roughness", "Radial Roughness": "hair_radial_roughness",
               "Random": "hair_random"}, fed
print(f"look: hair_melanin {melanin.min():.3f}-{melanin.max():.3f} per curve, read by {material.name!r}")

# Guides from Blender: a hair Curves object (as Add › Curves › Empty Hair
# and Blender's brushes make) whose four curves lean four ways shapes the
# fur; hairs rooted by a guide lean its way.
leans = np.array([[1, 0, 1], [-1, 0, 1], [0, 1, 1], [0, -1, 1]], np.float64)
leans /= np.linalg.norm(leans, axis=1)[:, None]
guide_roots = np.array([[0.5, 0.5, 0], [-0.5, 0.5, 0], [0.5, -0.5, 0], [-0.5, -0.5, 0]], np.float64)
sculpted = bpy.data.hair_curves.new("sculpted")
sculpted.add_curves([7] * 4)  # any point count: pelage resamples
steps = np.linspace(0, 0.2, 7)
guide_points = (guide_roots[:, None, :] + steps[None, :, None] * leans[:, None, :]).reshape(-1, 3)
sculpted.position_data.foreach_set("vector", guide_points.astype(np.float32).ravel())
guides_object = bpy.data.objects.new("sculpted", sculpted)
bpy.context.collection.objects.link(guides_object)
settings.guides_object = guides_object
shaping = settings.clump, settings.noise
settings.clump, settings.noise = 0.0, 0.0  # the guides' shape alone
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
guided = fur_of(grid)
guided_points, guided_offsets = arrays(guided.data)
guided_roots = guided_points[guided_offsets[:-1]]
guided_tips = guided_points[guided_offsets[1:] - 1]
for root, lean in zip(guide_roots, leans):
    near = np.linalg.norm(guided_roots - root, axis=1) < 0.08
    assert near.sum() >= 5, near.sum()
    ways = guided_tips[near] - guided_roots[near]
    length = np.linalg.norm(ways, axis=1)
    ways /= length[:, None]
    assert np.all(ways @ lean > 0.97), (root, (ways @ lean).min())
    assert np.allclose(length, 0.2, rtol=0.05), length
# The guides pelage binds are the sculpted curves, turned Y up (pelage's
# world) and resampled: the same roots and tips. (The library holds a
# hair at a guide's root to that guide exactly: crates/pelage/tests.)
addon_fur = next(m for name, m in sys.modules.items() if name.endswith("pelage_fur.fur"))
mesh_value, _ = addon_fur.mesh_to_pelage(grid, bpy.context.evaluated_depsgraph_get())
bound = addon_fur.groom_for(grid, settings, mesh_value, bpy.context.evaluated_depsgraph_get()).guides
ends = guide_points.reshape(4, 7, 3)[:, [0, -1]] @ addon_fur.Z_UP_TO_Y_UP.T
bound_points = bound.points.reshape(4, -1, 3)
assert np.allclose(bound_points[:, [0, -1]], ends, atol=1e-5), (bound_points[:, [0, -1]], ends)
print("guides from Blender: hairs by each sculpted guide lean its way, at its length")

# A face-set parting: the sculpted guides lean away from x = 0 on each
# side; with the face sets as regions, hairs by the line lean fully their
# side's way, never blended across it.
x_guides = np.array([[-0.6, 0.3, 0], [-0.2, -0.3, 0], [0.2, 0.3, 0], [0.6, -0.3, 0]])
sideways = np.where(x_guides[:, :1] > 0, 1.0, -1.0) * np.array([[1, 0, 0]]) + np.array([[0, 0, 1]])
sideways /= np.linalg.norm(sideways, axis=1)[:, None]
parting_guides = (x_guides[:, None, :] + steps[None, :, None] * sideways[:, None, :]).reshape(-1, 3)
sculpted.position_data.foreach_set("vector", parting_guides.astype(np.float32).ravel())
sets = grid.data.attributes.new(".sculpt_face_set", "INT", "FACE")
centres = np.empty(len(grid.data.polygons) * 3, np.float32)
grid.data.polygons.foreach_get("center", centres)
sets.data.foreach_set("value", np.where(centres.reshape(-1, 3)[:, 0] > 0, 2, 1).astype(np.int32))
settings.parting = "FACE_SETS"
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
parted = fur_of(grid)
parted_points, parted_offsets = arrays(parted.data)
starts, ends = parted_points[parted_offsets[:-1]], parted_points[parted_offsets[1:] - 1]
lean_x = (ends[:, 0] - starts[:, 0]) / np.linalg.norm(ends - starts, axis=1)
by_the_line = np.abs(starts[:, 0]) < 0.2
assert by_the_line.sum() > 50, by_the_line.sum()
assert np.all(lean_x[by_the_line] * np.sign(starts[by_the_line, 0]) > 0.65), lean_x[by_the_line].min()
# The panel says what grew, region by region.
lines = settings.last_grow.split("\n")
assert lines[0].startswith(f"{len(parted.data.curves):,} hairs"), lines
per_region = [int(line.split(": ")[1].split(" hairs")[0].replace(",", "")) for line in lines[1:]]
assert len(per_region) == 2 and sum(per_region) == len(parted.data.curves), lines
grid.data.attributes.remove(grid.data.attributes[".sculpt_face_set"])
print("parting: face sets keep each side's hairs leaning its own way by the line")
# The same parting from an integer face attribute of the user's own.
sides = grid.data.attributes.new("sides", "INT", "FACE")
sides.data.foreach_set("value", np.where(centres.reshape(-1, 3)[:, 0] > 0, 7, 3).astype(np.int32))
settings.parting, settings.parting_attribute = "ATTRIBUTE", "sides"
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
by_attribute, by_attribute_offsets = arrays(fur_of(grid).data)
starts = by_attribute[by_attribute_offsets[:-1]]
ends = by_attribute[by_attribute_offsets[1:] - 1]
lean_x = (ends[:, 0] - starts[:, 0]) / np.linalg.norm(ends - starts, axis=1)
by_the_line = np.abs(starts[:, 0]) < 0.2
assert np.all(lean_x[by_the_line] * np.sign(starts[by_the_line, 0]) > 0.65), lean_x[by_the_line].min()
grid.data.attributes.remove(grid.data.attributes["sides"])
settings.parting, settings.parting_attribute = "NONE", ""
print("parting: an integer face attribute parts the hair as face sets do")
settings.guides_object = None
settings.clump, settings.noise = shaping

# Live: with Live on, sculpting the guides object regrows only the hairs
# near the stroke; the rest keep every bit.
addon_fur = next(m for name, m in sys.modules.items() if name.endswith("pelage_fur.fur"))
grid5 = np.linspace(-0.8, 0.8, 5)
live_roots = np.array([[x, y, 0.0] for x in grid5 for y in grid5])
live_curves = bpy.data.hair_curves.new("live guides")
live_curves.add_curves([7] * 25)
live_points = (live_roots[:, None, :] + steps[None, :, None] * np.array([0, 0, 1.0])).reshape(-1, 3)
live_curves.position_data.foreach_set("vector", live_points.astype(np.float32).ravel())
live_object = bpy.data.objects.new("live guides", live_curves)
bpy.context.collection.objects.link(live_object)
settings.guides_object, settings.live = live_object, True
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
assert grid.name not in addon_fur.PENDING, "a Grow with Live on sets off no second regrow"
live_fur = fur_of(grid)
# A material the user gave the fur object stays through every live regrow.
live_material = bpy.data.materials.new("my live fur")
live_fur.data.materials.clear()
live_fur.data.materials.append(live_material)
before, live_offsets = arrays(live_fur.data)
# Guide 0 (at (-0.8, -0.8)) combed sideways.
combed = live_points.copy()
combed[0:7] += steps[:, None] * np.array([1.0, 0.0, 0.0])
live_curves.position_data.foreach_set("vector", combed.astype(np.float32).ravel())
bpy.context.view_layer.update()
assert grid.name in addon_fur.PENDING, "the depsgraph handler scheduled the regrow"
done = addon_fur.live_update(grid)
assert done is not None and 0 < done["regrown"] < done["hairs"] // 4, done
after, _ = arrays(live_fur.data)
live_starts = before[live_offsets[:-1]]
far = np.linalg.norm(live_starts[:, :2] - [-0.8, -0.8], axis=1) > 0.9
moved_by = np.array([np.abs(after[a:b] - before[a:b]).max() for a, b in zip(live_offsets[:-1], live_offsets[1:])])
assert far.sum() > 1000 and np.all(moved_by[far] == 0), "hairs far from the stroke keep every bit"
assert moved_by[~far].max() > 0.05, "hairs by the combed guide follow it"
assert addon_fur.live_update(grid) is None, "nothing changed since"
assert list(live_fur.data.materials) == [live_material], "a live update keeps the user's material"
# A guide edit that brings other hairs (a count that differs from the fur
# object's) gives the fur object a new datablock: the material stays.


class MoreHairs:
    """The live session, answering that the edit changed the hair count."""

    def __init__(self, session):
        self.session = session

    def set_guides(self, guides, tolerance):
        done = self.session.set_guides(guides, tolerance=tolerance)
        return None if done is None else dict(done, hairs=done["hairs"] + 1)

    def __getattr__(self, name):
        return getattr(self.session, name)


live_state = addon_fur.LIVE[grid.name]
live_state.session = MoreHairs(live_state.session)
combed[0:7] += steps[:, None] * np.array([0.0, 0.5, 0.0])
live_curves.position_data.foreach_set("vector", combed.astype(np.float32).ravel())
live_data_before = live_fur.data.name
assert addon_fur.live_update(grid) is not None
live_state.session = live_state.session.session
assert live_fur.data.name == live_data_before, "the new datablock takes the old one's name"
assert list(live_fur.data.materials) == [live_material], list(live_fur.data.materials)
print("live: the user's material stays through a live update that replaces the fur's datablock")
print(f"live: a combed guide regrew {done['regrown']:,} of {done['hairs']:,} hairs; far ones kept every bit")
# While live, a setting changed regrows the whole groom (at the display
# fraction), in the same fur object.
addon_fur.PENDING.pop(grid.name, None)
settings.count = 2_000
assert addon_fur.PENDING.get(grid.name) is True, "a setting schedules a whole regrow"
addon_fur.PENDING.pop(grid.name)  # as the scheduled timer does
assert addon_fur.live_regrow(grid) == {"hairs": 2_000}
# Blender's redraw after the regrow (its new datablock touches every ID)
# is not an edit: it schedules nothing.
bpy.context.view_layer.update()
assert grid.name not in addon_fur.PENDING, addon_fur.PENDING
assert fur_of(grid) == live_fur and len(live_fur.data.curves) == 2_000
assert list(live_fur.data.materials) == [live_material], "a whole live regrow keeps the material"
# So does an edit of the mesh (edit mode, sculpt, paint): the x > 0 half
# lifted 0.25, the roots there follow it.
addon_fur.PENDING.pop(grid.name, None)
flat = np.empty(len(grid.data.vertices) * 3, np.float32)
grid.data.vertices.foreach_get("co", flat)
lifted = flat.reshape(-1, 3).copy()
lifted[lifted[:, 0] > 1e-6, 2] += 0.25
grid.data.vertices.foreach_set("co", lifted.ravel())
grid.data.update()
bpy.context.view_layer.update()
assert addon_fur.PENDING.get(grid.name) is True, "a mesh edit schedules a whole regrow"
addon_fur.live_regrow(grid)
edited, edited_offsets = arrays(live_fur.data)
edited_roots = edited[edited_offsets[:-1]]
on_top = edited_roots[:, 0] > 0.26  # beyond the slanted faces by x = 0
assert on_top.sum() > 100 and np.allclose(edited_roots[on_top, 2], 0.25, atol=1e-5)
grid.data.vertices.foreach_set("co", flat)
grid.data.update()
addon_fur.PENDING.pop(grid.name, None)
settings.count = 3_000
print("live: a setting or a mesh edit regrows the whole groom in place")
# Live ticked after a Grow (not before it) arms the fur that grow made:
# no second Grow is needed for a comb to regrow the hairs near it.
settings.live = False
assert grid.name not in addon_fur.LIVE, "unticked, the live groom is let go"
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
settings.live = True
assert addon_fur.PENDING.get(grid.name) is True, "ticking Live schedules arming it"
armed = addon_fur.live_regrow(grid)
addon_fur.PENDING.pop(grid.name, None)
assert armed is not None and grid.name in addon_fur.LIVE, armed
combed = live_points.copy()
combed[0:7] += steps[:, None] * np.array([0.0, 1.0, 0.0])
live_curves.position_data.foreach_set("vector", combed.astype(np.float32).ravel())
again = addon_fur.live_update(grid)
assert again is not None and 0 < again["regrown"] < again["hairs"], again
live_curves.position_data.foreach_set("vector", live_points.astype(np.float32).ravel())
print("live: ticked after a Grow, a comb regrows the hairs near it")
addon_fur.PENDING.pop(grid.name, None)
settings.guides_object, settings.live = None, False

# A vertex group painted on half the grid (weight 1 for x > 0, none
# elsewhere) as the density puts the roots on that half.
half = grid.vertex_groups.new(name="half")
half.add([v.index for v in grid.data.vertices if v.co.x > 1e-6], 1.0, "REPLACE")
settings.density_group = "half"
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
painted = fur_of(grid)
painted_points, painted_offsets = arrays(painted.data)
share = (painted_points[painted_offsets[:-1], 0] > 0).mean()
assert share >= 0.95, share
settings.density_group = ""
print(f"density from a vertex group: {share:.1%} of the roots on the painted half")

# A colour attribute painted on face corners (Vertex Paint's), red on the
# other half (x < 0): its red channel as the density.
paint = grid.data.color_attributes.new("paint", "BYTE_COLOR", "CORNER")
corner_vertex = np.empty(len(grid.data.loops), np.int32)
grid.data.loops.foreach_get("vertex_index", corner_vertex)
xs = np.array([grid.data.vertices[i].co.x for i in corner_vertex])
rgba = np.zeros((len(corner_vertex), 4), np.float32)
rgba[:, 0] = (xs < -1e-6).astype(np.float32)
rgba[:, 3] = 1.0
paint.data.foreach_set("color", rgba.ravel())
settings.density_group = "paint:r"
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
red_points, red_offsets = arrays(fur_of(grid).data)
red_share = (red_points[red_offsets[:-1], 0] < 0).mean()
assert red_share >= 0.95, red_share
settings.density_group = ""
grid.data.color_attributes.remove(paint)
print(f"density from a colour attribute's red channel: {red_share:.1%} of the roots on the red half")

# An image painted in Blender and never saved: its pixels are the map.
# Red on the bottom half of the image (v < 0.5: the grid's y < 0), so a
# flipped image would put the roots on the wrong half.
painting = bpy.data.images.new("painting", 64, 64)
texels = np.zeros((64, 64, 4), np.float32)
texels[:32, :, 0] = 1.0  # Blender's first rows are the image's bottom
texels[:, :, 3] = 1.0
painting.pixels.foreach_set(texels.ravel())
settings.density_group = "image:painting:r"
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
image_points, image_offsets = arrays(fur_of(grid).data)
image_share = (image_points[image_offsets[:-1], 1] < 0).mean()
assert image_share >= 0.95, image_share
settings.density_group = ""
print(f"density from an unsaved Blender image: {image_share:.1%} of the roots where it is painted")

# The panel draws: every setting it shows exists, every button is an
# operator (a layout that checks what it is asked to draw).
class CheckedLayout:
    enabled = True

    def column(self, **_):
        return CheckedLayout()

    row = box = column

    def prop(self, data, name, **_):
        assert hasattr(data, name), name

    def prop_search(self, data, name, search_data, search_name, **_):
        assert hasattr(data, name) and hasattr(search_data, search_name), (name, search_name)

    def label(self, text="", **_):
        assert isinstance(text, str)

    def operator(self, idname, **_):
        category, name = idname.split(".")
        assert hasattr(getattr(bpy.ops, category), name), idname
        return type("OperatorProperties", (), {})()

    def template_list(self, list_type, _list_id, data, name, active_data, active_name, **_):
        assert hasattr(bpy.types, list_type), list_type
        assert hasattr(data, name) and hasattr(active_data, active_name), (name, active_name)


addon = next(m for name, m in sys.modules.items() if name.endswith("pelage_fur") and hasattr(m, "PELAGE_PT_fur"))
bpy.context.view_layer.objects.active = grid
for guides_set, motion in ((None, "DEFORM"), (bpy.data.objects["sculpted"], "SIMULATE")):
    settings.guides_object, settings.animation_mode = guides_set, motion
    addon.PELAGE_PT_fur.draw(type("Panel", (), {"layout": CheckedLayout()})(), bpy.context)
    # With an operator in the stack: its settings are drawn too.
    bpy.ops.pelage.op_add(kind="curl")
settings.ops.clear()
settings.guides_object, settings.animation_mode = None, "DEFORM"
print("panel: every drawn setting and button exists")

# The same seed grows the same fur (the operator is deterministic), and
# every grow regrows the one fur object in place: the material and the
# modifier a user gave it stay.
own = bpy.data.materials.new("my fur")
fur.data.materials.clear()
fur.data.materials.append(own)
fur.modifiers.new("my noise", "NODES")
bpy.ops.pelage.grow_fur()
second = fur_of(grid)
assert second == fur and second.name == "Grid fur", second.name
assert np.array_equal(arrays(second.data)[0], points)
assert list(second.data.materials) == [own], list(second.data.materials)
# (No Deform Curves on Surface: nothing deforms a bare grid.)
assert [m.name for m in second.modifiers] == ["my noise"], list(second.modifiers)
print("grid: the same settings grow the same points, in place: material and modifiers kept")

# Gravity pulls down in Blender's world (-Z), whatever the object's
# rotation: a wall (a grid stood up, facing -Y) grows hair that droops.
clear_scene()
bpy.ops.mesh.primitive_grid_add(size=2.0, rotation=(np.pi / 2, 0, 0))
wall = bpy.context.active_object
wall.pelage_fur.count, wall.pelage_fur.length, wall.pelage_fur.gravity = 1_000, 0.3, 1.0
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
local, offsets = arrays(fur_of(wall).data)
matrix = np.array(wall.matrix_world)
world = local @ matrix[:3, :3].T + matrix[:3, 3]
droop = world[offsets[1:] - 1, 2] - world[offsets[:-1], 2]
assert np.median(droop) < -0.05, np.median(droop)
print(f"wall: hair droops under gravity along world -Z (median {np.median(droop):.3f})")

# A preset fills the settings, sized to the object.
wall.pelage_fur.preset = "CURLY"
assert wall.pelage_fur.curl > 0 and abs(wall.pelage_fur.length - 0.06 * max(wall.dimensions)) < 1e-6
print("presets: Curly sets curl and a length sized to the object")

# 2. A sphere that grows under a shape key: Deform Curves on Surface
#    carries the fur.
clear_scene()
bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=24, ring_count=12)
sphere = bpy.context.active_object
sphere.pelage_fur.count = 2_000
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
fur = fur_of(sphere)
# Nothing deforms the sphere yet: no Deform Curves on Surface, whose node
# would recompute every point of the fur on each update for nothing.
assert addon_fur.deform_modifier_of(fur) is None, list(fur.modifiers)
rest = np.linalg.norm(evaluated_roots(fur), axis=1)
assert rest.min() > 0.95 and rest.max() < 1.0 + 1e-4, (rest.min(), rest.max())
sphere.shape_key_add(name="Basis")
grown = sphere.shape_key_add(name="grown")
co = np.empty(len(sphere.data.vertices) * 3, np.float32)
grown.data.foreach_get("co", co)
grown.data.foreach_set("co", co * 2.0)
grown.value = 1.0
# Shape keys added after the grow: the next update gives the fur the
# modifier, without another grow.
bpy.context.view_layer.update()
assert addon_fur.deform_modifier_of(fur) is not None, list(fur.modifiers)
moved = np.linalg.norm(evaluated_roots(fur), axis=1)
assert np.allclose(moved, 2 * rest, rtol=1e-3), (moved[:4], rest[:4])
print("sphere: the fur follows the surface when a shape key doubles it (Deform Curves on Surface)")

# A long grow is cancelled between parts (the panel's button grows on a
# worker thread; Esc makes its progress callback raise): nothing changes.
sphere.pelage_fur.count = 400_000
prepared = addon_fur.PreparedGrow(bpy.context, sphere, sphere.pelage_fur)
shown_before = arrays(fur.data)[0].copy()


def cancel_after_first(done, total):
    assert total > 1, total
    raise addon_fur.Cancelled()


try:
    addon_fur.grow_curves(prepared, cancel_after_first)
except addon_fur.Cancelled:
    pass
else:
    raise AssertionError("the grow must stop when its progress callback raises Cancelled")
assert np.array_equal(arrays(fur_of(sphere).data)[0], shown_before), "the fur is as it was"
assert hasattr(addon.PELAGE_OT_grow_fur, "modal") and hasattr(addon.PELAGE_OT_grow_fur, "invoke")
sphere.pelage_fur.count = 2_000
print("cancel: a 400,000-hair grow stops after its first part, the fur as it was")

# A mesh without a UV map grows, from object-space noise and a vertex
# group, and the user is told it will not follow deformation.
clear_scene()
bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3)
bare = bpy.context.active_object
while bare.data.uv_layers:
    bare.data.uv_layers.remove(bare.data.uv_layers[0])
top = bare.vertex_groups.new(name="top")
top.add([v.index for v in bare.data.vertices if v.co.z > 0], 1.0, "REPLACE")
bare.pelage_fur.count, bare.pelage_fur.noise, bare.pelage_fur.density_group = 1_500, 0.5, "top"
_, grown_bare, bare_warnings = addon_fur.grow_on_object(bpy.context, bare, bare.pelage_fur)
assert grown_bare.curve_count == 1_500
bare_roots = grown_bare.points[grown_bare.offsets[:-1]]
assert (bare_roots[:, 1] > 0).mean() >= 0.95, "the painted top (Y-up in pelage's world)"
assert any("no UV map" in w for w in bare_warnings), bare_warnings
assert not any(m.type == "NODES" for m in fur_of(bare).modifiers)
# Length and Width never set: sized to the object on its first grow.
size = max(bare.dimensions)
assert abs(bare.pelage_fur.length - 0.04 * size) < 1e-6, (bare.pelage_fur.length, size)
assert abs(bare.pelage_fur.width - 0.0006 * size) < 1e-7, bare.pelage_fur.width
print("no UV map: grown from noise and a vertex group; the user is told it will not follow deformation")

# 3. A groom file drives the add-on; its errors reach the user.
with tempfile.TemporaryDirectory() as folder:
    good = os.path.join(folder, "fur.toml")
    with open(good, "w") as f:
        f.write('[mesh]\npath = "spot"\n[roots]\ncount = 700\n'
                '[guides]\ngenerate = { count = 20, length = 0.05 }\n[finish]\npoints = 5\n'
                '[look]\nmelanin = 0.4\n')
    clear_scene()
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3)
    ico = bpy.context.active_object
    bpy.ops.mesh.uv_texture_add()
    ico.pelage_fur.groom_file = good
    assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
    assert len(fur_of(ico).data.curves) == 700 and len(fur_of(ico).data.points) == 3_500
    bad = os.path.join(folder, "bad.toml")
    with open(bad, "w") as f:
        f.write('[mesh]\npath = "spot"\n[roots]\ncount = 700\ncolour = 3\n')
    ico.pelage_fur.groom_file = bad
    try:
        bpy.ops.pelage.grow_fur()
    except RuntimeError as error:
        assert "bad.toml:5" in str(error) and "colour" in str(error), error
    else:
        raise AssertionError("a bad groom file must fail the operator")
    print("groom file: grown on the active mesh; a bad key is reported with file and line")

    # 4. Export buttons write pelage's own files.
    ico.pelage_fur.groom_file = good
    for ext in ("usdc", "abc"):
        out = os.path.join(folder, f"fur.{ext}")
        op = bpy.ops.pelage.export_usd if ext == "usdc" else bpy.ops.pelage.export_alembic
        assert op(filepath=out) == {"FINISHED"}
        assert pelage.read_curves(out).curve_count == 700
    print("export: USD and Alembic written, 700 curves each")

    # Blender's USD importer brings the look in as the attributes the
    # add-on's material reads.
    bpy.ops.wm.usd_import(filepath=os.path.join(folder, "fur.usdc"))
    imported = [o for o in bpy.context.selected_objects if o.type == "CURVES"]
    assert imported, "the USD import made curves"
    melanin = np.empty(len(imported[0].data.curves), np.float32)
    imported[0].data.attributes["hair_melanin"].data.foreach_get("value", melanin)
    assert np.allclose(melanin, 0.4), melanin[:4]
    assert bpy.ops.pelage.shade_hair() == {"FINISHED"}
    assert all(o.data.materials[0].name == "pelage hair" for o in imported)
    print("USD import: hair_melanin arrives as a curve attribute; Shade with pelage hair binds the material")

    # 5. The guides a groom leaves out reach the user, from the library's report.
    # The add-on's module, wherever Blender installed the extension.
    fur = next(m for name, m in sys.modules.items() if name.endswith("pelage_fur.fur"))

    report = pelage.Groom.load(good).report()
    assert fur.guide_warnings(report) == [], report
    report["guides"]["dropped"] = [{"guide": 3, "why": "its root is 0.2 from the surface"}]
    assert fur.guide_warnings(report) == ["guide 3 left out: its root is 0.2 from the surface"]
    print("guides left out: reported from the library's report")

# 6. Animated export: the fur over the scene's frames on the surface as
#    Blender evaluates it (object motion and a keyed twist), deformed or
#    simulated, one file with a sample a frame.
clear_scene()
bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=24, ring_count=12)
ball = bpy.context.active_object
ball.pelage_fur.count, ball.pelage_fur.length, ball.pelage_fur.points = 1_500, 0.3, 8
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 4
ball.location = (0.0, 0.0, 0.0)
ball.keyframe_insert("location", frame=1)
ball.location = (0.6, 0.0, 0.0)
ball.keyframe_insert("location", frame=4)
twist = ball.modifiers.new("twist", "SIMPLE_DEFORM")
twist.deform_method, twist.deform_axis, twist.angle = "TWIST", "Z", 0.0
twist.keyframe_insert("angle", frame=1)
twist.angle = 1.0
twist.keyframe_insert("angle", frame=4)
scene.frame_set(2)
from mathutils import Vector  # noqa: E402
from mathutils.bvhtree import BVHTree  # noqa: E402


def off_surface(curves, frame):
    """How far the roots of ``curves`` (pelage's Y-up world) lie from the
    ball as Blender evaluates it at ``frame``: the largest distance."""
    scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    tree = BVHTree.FromObject(ball, depsgraph)
    to_local = ball.matrix_world.inverted()
    roots = curves.points[curves.offsets[:-1]]
    worst = 0.0
    for x, y, z in roots:
        _, _, _, distance = tree.find_nearest(to_local @ Vector((x, -z, y)))
        worst = max(worst, distance)
    return worst


with tempfile.TemporaryDirectory() as folder:
    # Export USD at another frame than the grow's: the fur on screen (grown
    # at frame 1, carried by Deform Curves on Surface), not a new groom.
    scene.frame_set(1)
    assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
    scene.frame_set(3)
    shown = fur_of(ball)
    shown_ids = np.empty(len(shown.data.curves), np.int32)
    shown.data.attributes["hair_id"].data.foreach_get("value", shown_ids)
    local = evaluated_roots(shown)
    world = np.array([ball.matrix_world @ Vector(p) for p in local])
    shown_roots = world @ addon_fur.Z_UP_TO_Y_UP.T
    still = os.path.join(folder, "still.usdc")
    assert bpy.ops.pelage.export_usd(filepath=still) == {"FINISHED"}
    exported = pelage.read_curves(still)
    assert np.array_equal(exported.ids & 0x7FFFFFFF, shown_ids), "the hairs on screen"
    apart = np.linalg.norm(exported.points[exported.offsets[:-1]] - shown_roots, axis=1).max()
    assert apart < 1e-3, apart
    print(f"export at frame 3: the fur on screen, the same hairs, roots within {apart:.1e} of Blender's")
    bpy.data.objects.remove(shown)
    scene.frame_set(2)
    moved = os.path.join(folder, "ball.usdc")
    assert bpy.ops.pelage.export_animated_usd(filepath=moved) == {"FINISHED"}
    assert scene.frame_current == 2, "the scene is left at its frame"
    frames = [pelage.read_curves(moved, time=f) for f in (1, 2, 3, 4)]
    assert all(c.curve_count == 1_500 for c in frames)
    assert all(np.array_equal(c.ids, frames[0].ids) for c in frames), "the same hairs every frame"
    for f, curves in zip((1, 2, 3, 4), frames):
        worst = off_surface(curves, f)
        assert worst < 1e-4, (f, worst)
    assert not np.allclose(frames[0].points, frames[3].points)
    # Pixar's USD (usd-core, tools/usdcheck's venv) finds a stage of frames
    # 1 to 4 with a sample a frame, the points pelage wrote, and no error.
    import subprocess  # noqa: E402

    usdcheck = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "usdcheck")
    specs = [f"/groom/part_0000.points@{f}[0]" for f in (1, 2, 3, 4)]
    told = subprocess.run([usdcheck, "--values", moved, *specs], capture_output=True, text=True)
    if told.returncode == 2 and os.environ.get("PELAGE_REQUIRE_USDCHECK") != "1":
        print(f"usd-core unavailable, not checked: {told.stderr.strip()}")
    else:
        assert told.returncode == 0, told.stderr
        lines = told.stdout.splitlines()
        assert lines[0].startswith("stage 1 to 4 at 24 per second"), lines
        for f, line in zip((1, 2, 3, 4), lines[1:]):
            read = [float(x) for x in line.split(" = ")[1].split()]
            assert np.allclose(read, frames[f - 1].points[0], rtol=0, atol=0), (f, read)
        valid = subprocess.run([usdcheck, moved], capture_output=True, text=True)
        assert valid.returncode == 0, valid.stdout + valid.stderr
    print("animated export: 4 frames in one usdc (usd-core: a sample a frame), the same hairs, "
          "roots on the evaluated surface every frame")
    ball.pelage_fur.animation_mode = "SIMULATE"
    ball.pelage_fur.sim_follow, ball.pelage_fur.sim_preroll = 0.0, 2
    swung = os.path.join(folder, "ball.abc")
    assert bpy.ops.pelage.export_animated_alembic(filepath=swung) == {"FINISHED"}
    last = pelage.read_curves(swung, time=4 / scene.render.fps)
    assert off_surface(last, 4) < 1e-4
    tips = lambda c: c.points[c.offsets[1:] - 1]
    lag = np.linalg.norm(tips(last) - tips(frames[3]), axis=1).mean()
    assert lag > 0.01, lag
    print(f"animated export, simulated: Alembic, roots on the surface, tips {lag:.3f} from the deformed ones")

# 8. The operator stack: any of pelage's operators with all its settings
#    and a mask from a vertex group, reordered and removed; the panel
#    saved as a groom file and loaded into another object's panel, which
#    saves the same file.
clear_scene()
bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=8, size=2.0)
stacked = bpy.context.active_object
panel = stacked.pelage_fur
panel.count, panel.points, panel.interpolation_k = 2_000, 8, 6
back = stacked.vertex_groups.new(name="back")
back.add([v.index for v in stacked.data.vertices if v.co.y > 0], 1.0, "REPLACE")
for kind in ("clump", "curl", "noise", "width"):
    assert bpy.ops.pelage.op_add(kind=kind) == {"FINISHED"}
schema = {op["name"]: op["fields"] for op in pelage._pelage.operator_schema()}
assert [s.name for s in panel.ops[2].settings] == schema["noise"], "every setting of the operator"
next(x for x in panel.ops[2].settings if x.name == "mask").value = "vertex:back"
panel.active_op = 1
assert bpy.ops.pelage.op_move(direction="UP") == {"FINISHED"}
panel.active_op = 3
assert bpy.ops.pelage.op_remove() == {"FINISHED"}
assert [o.kind for o in panel.ops] == ["curl", "clump", "noise"], [o.kind for o in panel.ops]
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
grown_text = fur_of(stacked)["pelage_settings"]
assert "[interpolation]" in grown_text and "k = 6" in grown_text, grown_text
order = [grown_text.index(f"[ops.{k}]") for k in ("curl", "clump", "noise")]
assert order == sorted(order) and 'mask = "vertex:back"' in grown_text, grown_text


def stack_of(settings):
    return [(o.kind, o.enabled, [(x.name, x.value) for x in o.settings]) for o in settings.ops]


with tempfile.TemporaryDirectory() as folder:
    saved, again = os.path.join(folder, "panel.toml"), os.path.join(folder, "again.toml")
    assert bpy.ops.pelage.save_groom(filepath=saved) == {"FINISHED"}
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=8, size=2.0, location=(5, 0, 0))
    other = bpy.context.active_object
    other.vertex_groups.new(name="back")
    assert bpy.ops.pelage.load_groom(filepath=saved) == {"FINISHED"}
    assert stack_of(other.pelage_fur) == stack_of(panel), (stack_of(other.pelage_fur), stack_of(panel))
    assert other.pelage_fur.count == 2_000 and other.pelage_fur.points == 8
    assert other.pelage_fur.interpolation == "SHEPARD" and other.pelage_fur.interpolation_k == 6
    assert bpy.ops.pelage.save_groom(filepath=again) == {"FINISHED"}
    with open(saved) as a, open(again) as b:
        assert a.read() == b.read(), "the groom file round-trips through the panel"
    # Into a folder that is not there yet (typed in Blender's file
    # browser): made, not a raw error about a temporary file.
    nested = os.path.join(folder, "new", "deeper", "panel.toml")
    assert bpy.ops.pelage.save_groom(filepath=nested) == {"FINISHED"}
    with open(saved) as a, open(nested) as b:
        assert a.read() == b.read(), "a save into a new folder writes the same file"
    # The style mesh (Furtility) from the panel.
    other.pelage_fur.interpolation = "STYLE_MESH"
    assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
    assert 'method = "style-mesh"' in fur_of(other)["pelage_settings"]
print("operator stack: add, reorder, remove, a vertex-group mask; the groom file round-trips through the panel")

# 9. docs/blender.md's workflow, top to bottom, on a character that
#    moves: the Khronos Fox imported with Blender's glTF importer and
#    posed at frame 9 of its Walk, far from its rest pose. Guides in an
#    Empty Hair object, Grow (the Short preset), Live, Paint, Save and
#    Load, Export still and animated; after each, the fur's roots lie on
#    the posed skin. The fur is grown on the rest pose and carried to the
#    pose once by Deform Curves on Surface (grown on the posed skin, it
#    was deformed twice and floated 12 % of the fox's size off it).
clear_scene()
fox_path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "crates", "pelage", "assets",
                        "fox", "Fox.gltf")
bpy.ops.import_scene.gltf(filepath=fox_path)
fox = next(o for o in bpy.data.objects if o.type == "MESH")
rig = next(o for o in bpy.data.objects if o.type == "ARMATURE")
walk = bpy.data.actions["Walk"]
rig.animation_data.action = walk
if hasattr(rig.animation_data, "action_slot") and walk.slots:
    rig.animation_data.action_slot = walk.slots[0]
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 8, 10
scene.frame_set(9)
fox_size = max(fox.dimensions)


def fox_off_skin(roots_world_z_up, frame=None):
    """The largest distance of roots (Blender's world) from the fox's
    skin as it is posed at ``frame`` (default the one on screen), as a
    share of the fox's size."""
    if frame is not None:
        scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    tree = BVHTree.FromObject(fox, depsgraph)
    to_local = fox.matrix_world.inverted()
    worst = max(tree.find_nearest(to_local @ Vector(p))[3] for p in roots_world_z_up)
    return worst * max(fox.matrix_world.to_scale()) / fox_size


def shown_off_skin():
    """How far the roots of the fur on screen lie from the posed skin."""
    local = evaluated_roots(addon_fur.fur_object_of(fox))
    return fox_off_skin([fox.matrix_world @ Vector(p) for p in local])


def written_off_skin(curves, frame=None):
    """How far the roots of curves pelage wrote lie from the skin."""
    y_up_to_z_up = np.linalg.inv(addon_fur.Z_UP_TO_Y_UP)
    return fox_off_skin(curves.points[curves.offsets[:-1]] @ y_up_to_z_up.T, frame)


# 1. Guides: Add › Curves › Empty Hair on the fox; curves where the
#    brushes would put them (in the rest pose, as sculpt mode edits them):
#    every 25th vertex, along its normal, 5 % of the fox's size.
bpy.context.view_layer.objects.active = fox
fox.select_set(True)
assert bpy.ops.object.curves_empty_hair_add() == {"FINISHED"}
fox_guides = bpy.context.active_object
assert fox_guides.type == "CURVES" and fox_guides.data.surface == fox
to_guides = fox_guides.matrix_world.inverted() @ fox.matrix_world
guide_roots = [(to_guides @ v.co, (to_guides.to_3x3() @ v.normal).normalized()) for v in list(fox.data.vertices)[::25]]
fox_guides.data.add_curves([6] * len(guide_roots))
guide_points = np.array([root + t * 0.05 * fox_size * normal for root, normal in guide_roots
                         for t in np.linspace(0.0, 1.0, 6).tolist()], np.float32)
fox_guides.data.position_data.foreach_set("vector", guide_points.ravel())
bpy.context.view_layer.objects.active = fox
panel = fox.pelage_fur
panel.preset = "SHORT"
panel.count, panel.guides_object = 20_000, fox_guides
# 2. Grow, at the posed frame.
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
worst = shown_off_skin()
assert worst < 1e-3, f"fur grown at a posed frame lies {worst:.1%} of the fox's size off its skin"
# The fur takes the fox's own texture (its material's Base Color image,
# as the glTF importer set it up), and its pigment from that colour: an
# orange and white fox, mostly red pigment, not the panel's one brown.
assert addon_fur.skin_color_image(fox) is not None
fox_fur = addon_fur.fur_object_of(fox).data
assert addon_fur.COLOR in fox_fur.attributes
fox_melanin = np.empty(len(fox_fur.curves), np.float32)
fox_fur.attributes["hair_melanin"].data.foreach_get("value", fox_melanin)
fox_redness = np.empty(len(fox_fur.curves), np.float32)
fox_fur.attributes["hair_melanin_redness"].data.foreach_get("value", fox_redness)
assert fox_melanin.max() - fox_melanin.min() > 0.1, (fox_melanin.min(), fox_melanin.max())
assert np.median(fox_redness) > 0.5, np.median(fox_redness)
# 3. Live, ticked after the grow; a guide combed sideways regrows the
#    hairs near it, and they stay on the posed skin.
panel.live = True
assert addon_fur.live_regrow(fox) is not None and fox.name in addon_fur.LIVE
addon_fur.PENDING.pop(fox.name, None)
combed = guide_points.copy().reshape(-1, 6, 3)
combed[0] += np.linspace(0.0, 0.04 * fox_size, 6)[:, None] * np.array([1.0, 0.0, 0.0])
fox_guides.data.position_data.foreach_set("vector", combed.ravel())
combed_done = addon_fur.live_update(fox)
assert combed_done is not None and 0 < combed_done["regrown"] < combed_done["hairs"], combed_done
live_worst = shown_off_skin()
assert live_worst < 1e-3, live_worst
# 4. Paint: a vertex group over the fox's front half (in its rest pose) as
#    the density; with Live on, the whole groom regrows there.
front = fox.vertex_groups.new(name="front")
middle = np.median([v.co.z for v in fox.data.vertices])
front.add([v.index for v in fox.data.vertices if v.co.z > middle], 1.0, "REPLACE")
panel.density_group = "front"
assert addon_fur.PENDING.get(fox.name) is True, "painting schedules a whole regrow"
addon_fur.live_regrow(fox)
addon_fur.PENDING.pop(fox.name, None)
grown_live = addon_fur.LIVE[fox.name].session.curves()
rest_roots = addon_fur.transform_points(np.linalg.inv(addon_fur.to_pelage_space(fox)),
                                        grown_live.points[grown_live.offsets[:-1]])
front_share = (rest_roots[:, 2] > middle - 0.02 * fox_size).mean()
assert front_share > 0.95, front_share
assert shown_off_skin() < 1e-3
panel.live = False
# 5. Save the panel as a groom file (the guides beside it), and load it
#    into the panel again.
with tempfile.TemporaryDirectory() as folder:
    fox_file = os.path.join(folder, "fox.toml")
    assert bpy.ops.pelage.save_groom(filepath=fox_file) == {"FINISHED"}
    saved_guides = pelage.read_curves(os.path.join(folder, "fox.guides.usdc"))
    assert saved_guides.curve_count == len(guide_roots)
    assert written_off_skin(saved_guides) > 0.01, "saved guides are in the rest pose, not the posed one"
    assert bpy.ops.pelage.load_groom(filepath=fox_file) == {"FINISHED"}
    again_file = os.path.join(folder, "again.toml")
    assert bpy.ops.pelage.save_groom(filepath=again_file) == {"FINISHED"}
    with open(fox_file) as a, open(again_file) as b:
        assert a.read() == b.read().replace("again.guides.usdc", "fox.guides.usdc"), "the file round-trips"
    # 6. Export the fur on screen, and the frame range animated.
    posed_file = os.path.join(folder, "posed.usdc")
    assert bpy.ops.pelage.export_usd(filepath=posed_file) == {"FINISHED"}
    exported_worst = written_off_skin(pelage.read_curves(posed_file))
    assert exported_worst < 1e-3, exported_worst
    walking = os.path.join(folder, "walking.usdc")
    assert bpy.ops.pelage.export_animated_usd(filepath=walking) == {"FINISHED"}
    for frame in (8, 9, 10):
        on_frame = written_off_skin(pelage.read_curves(walking, time=frame), frame)
        assert on_frame < 1e-3, (frame, on_frame)
scene.frame_set(9)
print(f"docs/blender.md's workflow on the Fox at Walk frame 9: guides, grow, live comb "
      f"({combed_done['regrown']:,} hairs), paint ({front_share:.1%} where painted), save and load, export "
      f"still and animated; roots within {max(worst, live_worst, exported_worst):.1e} of its size of the posed skin")

# 7. The scripting example runs as written, enabling the extension itself
#    (a script's fresh session has it installed but not enabled).
import addon_utils  # noqa: E402
import runpy  # noqa: E402

clear_scene()
addon_utils.disable("bl_ext.user_default.pelage_fur")
assert not hasattr(bpy.types.Object, "pelage_fur")
example = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "python",
                       "blender_grow_fur.py")
with tempfile.TemporaryDirectory() as folder:
    here = os.getcwd()
    os.chdir(folder)
    try:
        runpy.run_path(example, run_name="__main__")
    finally:
        os.chdir(here)
    assert os.path.exists(os.path.join(folder, "pelage_fur.blend"))
print("examples/python/blender_grow_fur.py: enables the extension, grows 50,000 hairs, saves")

print("add-on: all checks passed")
