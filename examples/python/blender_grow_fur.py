"""Grow pelage fur in Blender from a script (the add-on installed).

    blender --background --python blender_grow_fur.py
    # or, with Blender as a Python module (pip install bpy):
    python blender_grow_fur.py

Enables the add-on (installed: see docs/blender.md, Edit > Preferences >
Get Extensions > Install from Disk, the zip that tools/blender-extension
builds), adds a UV sphere, sets the add-on's settings on it, runs "Grow
pelage fur" and saves pelage_fur.blend in the current folder.
"""

import os

import addon_utils
import bpy

# An installed extension is enabled in the preferences, not in a script's
# fresh session: enable it here.
EXTENSION = "bl_ext.user_default.pelage_fur"
if not hasattr(bpy.types.Object, "pelage_fur"):
    addon_utils.enable(EXTENSION, default_set=True)
if not hasattr(bpy.types.Object, "pelage_fur"):
    raise SystemExit(f"the pelage fur extension ({EXTENSION}) is not installed: see docs/blender.md")

bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0)
sphere = bpy.context.active_object
settings = sphere.pelage_fur  # the add-on's settings, one set per object
settings.count = 50_000
settings.length = 0.15
settings.clump = 0.5
settings.curl = 0.3
bpy.ops.pelage.grow_fur()
fur = next(o for o in bpy.data.objects if o.type == "CURVES" and o.parent == sphere)
print(f"{fur.name}: {len(fur.data.curves):,} curves, {len(fur.data.points):,} points")
bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath("pelage_fur.blend"))
