"""Render a USD file as Blender imports it (Workbench, 800x450), for the gallery:
    tools/bpy-python tools/blender_render.py FILE.usdc OUT.png
docs/gallery/blender-imports-demo-usdc.png is `pelage demo`'s groom.usdc
rendered this way (about two minutes on two cores)."""
import sys

import bpy
import mathutils
path, out = sys.argv[-2], sys.argv[-1]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.usd_import(filepath=path)
scene = bpy.context.scene
cam_data = bpy.data.cameras.new("cam"); cam = bpy.data.objects.new("cam", cam_data)
scene.collection.objects.link(cam); scene.camera = cam
cam.location = (3.6, -2.4, 1.5)
target = mathutils.Vector((0.0, 0.0, 0.15))
cam.rotation_euler = (target - cam.location).to_track_quat('-Z', 'Y').to_euler()
cam_data.lens = 45
scene.render.engine = 'BLENDER_WORKBENCH'
scene.display.shading.light = 'STUDIO'
scene.display.shading.color_type = 'VERTEX'
scene.render.resolution_x, scene.render.resolution_y = 800, 450
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
print("rendered", out)
