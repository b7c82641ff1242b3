"""Render fur grown by the add-on with Cycles, for the gallery:

    tools/bpy-python blender/render_gallery.py EXTENSION.zip OUT.png [--patches | --no-material | --workflow | --fox]

Installs the extension into a fresh user folder, grows fur on Suzanne with
"Grow pelage fur" (the panel's settings below) and renders 800×600 on the
CPU with Cycles (a few minutes on two cores). The fur is shaded by the
material the add-on makes, a Principled Hair BSDF reading each hair's
melanin, redness and roughness from the look (no material is set up
here). docs/gallery/blender-addon-suzanne.png is made this way; with
``--patches`` the settings come from a groom file whose ``[look]`` melanin
is a noise map (docs/gallery/blender-look-patches.png); with
``--no-material`` the add-on's material is taken off, for the picture
beside it (docs/gallery/blender-addon-suzanne-no-material.png). With
``--workflow`` the fur is groomed as docs/blender.md's workflow does it
(docs/gallery/blender-workflow-suzanne.png): guides in a hair Curves
object on the surface (placed and combed by this script, as a groomer's
brushes would: away from a parting down the middle of the head), a
density painted as a vertex group (none on the face), and face sets,
one a side, as the parting. With ``--fox`` the surface is the Khronos Fox
imported with Blender's glTF importer, posed at frame 9 of its Walk, with
the Short preset grown on it at that frame: the fur is grown on the rest
pose and carried to the pose by Deform Curves on Surface, and takes its
colour (and pigment) from the fox's own texture, Colour from Skin
(docs/gallery/blender-fox-posed.png).
"""

import math
import os
import sys
import tempfile

os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="pelage-blender-")

import bpy  # noqa: E402
import mathutils  # noqa: E402

patches = sys.argv[-1] == "--patches"
bare = sys.argv[-1] == "--no-material"
workflow = sys.argv[-1] == "--workflow"
posed_fox = sys.argv[-1] == "--fox"
args = sys.argv[:-1] if patches or bare or workflow or posed_fox else sys.argv
zip_path, out = os.path.abspath(args[-2]), os.path.abspath(args[-1])
assert bpy.ops.extensions.package_install_files(
    filepath=zip_path, repo="user_default", enable_on_install=True
) == {"FINISHED"}

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
scene = bpy.context.scene


def aimed(obj, location, target):
    """``obj`` at ``location``, looking at ``target``."""
    obj.location = location
    obj.rotation_euler = (target - obj.location).to_track_quat("-Z", "Y").to_euler()


def render(camera_at, target, lens, lights, lit, what):
    """A camera at ``camera_at`` looking at ``target``, area ``lights``
    ((name, energy, size, location)) aimed at ``lit``, a dark world, and
    Cycles on the CPU at 800×600 and 32 samples into OUT."""
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    aimed(camera, camera_at, target)
    camera.data.lens = lens
    for name, energy, size, location in lights:
        light = bpy.data.objects.new(name, bpy.data.lights.new(name, "AREA"))
        light.data.energy, light.data.size = energy, size
        aimed(light, location, lit)
        scene.collection.objects.link(light)
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.06, 0.08, 1)
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 32
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = 800, 600
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
    print(f"rendered {out}: {what}")


if posed_fox:
    here = os.path.dirname(os.path.abspath(__file__))
    bpy.ops.import_scene.gltf(filepath=os.path.join(here, "..", "crates", "pelage", "assets", "fox", "Fox.gltf"))
    fox = next(o for o in bpy.data.objects if o.type == "MESH")
    rig = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    walk = bpy.data.actions["Walk"]
    rig.animation_data.action = walk
    if hasattr(rig.animation_data, "action_slot") and walk.slots:
        rig.animation_data.action_slot = walk.slots[0]
    scene.frame_set(9)
    bpy.context.view_layer.objects.active = fox
    fox.pelage_fur.preset = "SHORT"
    fox.pelage_fur.count = 150_000
    assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
    fur = [o for o in bpy.data.objects if o.type == "CURVES" and o.parent == fox][0]
    # Framed from the side on the posed fox's bounds, in its world.
    corners = [fox.matrix_world @ mathutils.Vector(c) for c in fox.bound_box]
    low = mathutils.Vector([min(c[i] for c in corners) for i in range(3)])
    high = mathutils.Vector([max(c[i] for c in corners) for i in range(3)])
    centre, size = (low + high) / 2, max(high - low)
    lights = [(name, energy * size * size, size, centre + size * mathutils.Vector(offset))
              for name, energy, offset in (("key", 1500, (-1.2, -1.5, 1.8)), ("rim", 1000, (1.0, 1.8, 1.2)))]
    render(centre + size * mathutils.Vector((1.5, -1.0, 0.45)), centre, 55, lights, centre,
           f"{len(fur.data.curves):,} curves on the Fox at Walk frame 9")
    sys.exit(0)

bpy.ops.mesh.primitive_monkey_add(size=1.6)
head = bpy.context.active_object
head.rotation_euler = (0, 0, math.radians(-15))
subsurf = head.modifiers.new("smooth", "SUBSURF")
subsurf.levels = subsurf.render_levels = 2
bpy.ops.object.shade_smooth()
skin = bpy.data.materials.new("skin")
skin.use_nodes = True
skin.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.25, 0.12, 0.06, 1)
head.data.materials.append(skin)

settings = head.pelage_fur
settings.count = 200_000
settings.guides = 800
settings.length = 0.05
settings.width = 0.0025
settings.gravity = 0.3
settings.points = 10
settings.clump = 0.35
settings.curl = 0.0
settings.noise = 0.15
settings.seed = 3
settings.melanin = 0.55
settings.melanin_redness = 0.8
settings.roughness = 0.35
settings.look_jitter = 0.2
if patches:
    # The same fur from a groom file, its melanin a noise map clamped to
    # 0 and 1 in places: a patched coat, each hair its own shade.
    groom = os.path.join(tempfile.mkdtemp(), "patches.toml")
    with open(groom, "w") as f:
        f.write(
            '[mesh]\npath = "spot"\n[roots]\ncount = 200000\nseed = 3\n'
            "[guides]\npoints = 10\ngenerate = { count = 800, length = 0.08, gravity = 0.3, comb = [0, 0, 1] }\n"
            "[finish]\npoints = 10\nwidth = { root = 0.0025, tip = 0.00025 }\n"
            '[[ops]]\nclump = { count = 2000, rate = 0.35 }\n[[ops]]\nnoise = { amplitude = 0.012, frequency = 80 }\n'
            '[look]\nmelanin = "noise:frequency=4,seed=4,offset=0.45,scale=3"\n'
            "melanin_redness = 0.9\nroughness = 0.3\njitter = 0.15\n"
        )
    settings.groom_file = groom
if workflow:
    import numpy as np

    # Density painted as a vertex group: none on the face (the front,
    # below the brow), full elsewhere.
    painted = head.vertex_groups.new(name="fur")
    for v in head.data.vertices:
        face = v.normal.y < -0.55 and v.co.z < 0.25
        painted.add([v.index], 0.0 if face else 1.0, "REPLACE")
    # Face sets, one a side of the head: the parting down its middle.
    sets = head.data.attributes.new(".sculpt_face_set", "INT", "FACE")
    centres = np.empty(len(head.data.polygons) * 3, np.float32)
    head.data.polygons.foreach_get("center", centres)
    sets.data.foreach_set("value", np.where(centres.reshape(-1, 3)[:, 0] < 0, 1, 2).astype(np.int32))
    # Guides on the surface as Blender evaluates it (subdivided): every
    # 40th vertex off the face, combed away from the parting and down.
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = head.evaluated_get(depsgraph).to_mesh()
    roots, ways = [], []
    for v in list(evaluated.vertices)[::40]:
        if v.normal.y < -0.55 and v.co.z < 0.25:
            continue
        side = -1.0 if v.co.x < 0 else 1.0
        way = mathutils.Vector((side * 0.6, 0.1, -0.3)) + 1.2 * v.normal
        roots.append(v.co.copy())
        ways.append(way.normalized())
    head.evaluated_get(depsgraph).to_mesh_clear()
    steps = 8
    guides = bpy.data.hair_curves.new("sculpted guides")
    guides.add_curves([steps] * len(roots))
    points = []
    for root, way in zip(roots, ways):
        p, w = root.copy(), way.copy()
        for _ in range(steps):
            points.extend(p)
            p = p + 0.018 * w
            w = (w + mathutils.Vector((0, 0, -0.12))).normalized()  # a droop toward the tip
    # Curves points are in the object's space: the guides ride the head.
    guides.position_data.foreach_set("vector", np.array(points, np.float32).ravel())
    guides_object = bpy.data.objects.new("sculpted guides", guides)
    scene.collection.objects.link(guides_object)
    guides_object.matrix_world = head.matrix_world
    guides_object.hide_render = True
    settings.guides_object = guides_object
    settings.density_group = "fur"
    settings.parting = "FACE_SETS"
    settings.count = 150_000
    settings.points = 12
    settings.clump = 0.3
    settings.noise = 0.08
    settings.melanin = 0.3
    settings.melanin_redness = 0.7
    settings.outside_skin = True
assert bpy.ops.pelage.grow_fur() == {"FINISHED"}
fur = [o for o in bpy.data.objects if o.type == "CURVES" and o.parent == head][0]
assert fur.data.materials[0].name == "pelage hair"
if bare:
    # The same fur as Cycles draws curves with no material: the other
    # half of the gallery pair.
    fur.data.materials.clear()

render(mathutils.Vector((1.6, -4.4, 1.1) if not workflow else (1.0, -3.4, 3.4)),
       mathutils.Vector((0.0, 0.0, 0.05 if not workflow else 0.2)), 60,
       [("key", 900, 3, mathutils.Vector((-3, -3, 4))), ("rim", 700, 2, mathutils.Vector((2.5, 3, 2.5)))],
       mathutils.Vector((0, 0, 0)), f"{len(fur.data.curves):,} curves grown by the add-on")
