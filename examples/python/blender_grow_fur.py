"""Grow pelage fur in Blender from a script (the add-on installed).

    blender --background --python blender_grow_fur.py
    # or, with Blender as a Python module (pip install bpy):
    python blender_grow_fur.py

Adds a UV sphere, sets the add-on's settings on it, runs "Grow pelage fur"
and saves the .blend. Install the add-on first (docs/blender.md):
Edit > Preferences > Get Extensions > Install from Disk, the zip that
tools/blender-extension builds.
"""

import bpy

bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0)
sphere = bpy.context.active_object
settings = sphere.pelage_fur  # the add-on's settings, one set per object
settings.count = 50_000
settings.length = 0.15
settings.clump = 0.5
settings.curl = 0.3
bpy.ops.pelage.grow_fur()
fur = [o for o in bpy.data.objects if o.type == "CURVES" and o.parent == sphere][0]
print(f"{fur.name}: {len(fur.data.curves):,} curves, {len(fur.data.points):,} points")
bpy.ops.wm.save_as_mainfile(filepath=bpy.path.abspath("//pelage_fur.blend") or "pelage_fur.blend")
