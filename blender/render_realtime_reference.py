"""The offline reference beside the real-time still, for the gallery:

    tools/bpy-python blender/render_realtime_reference.py FUR.usdc REALTIME.png OUT.png

FUR.usdc is the groom of docs/gallery/realtime-fox.png at the same frame,
grown on the CPU and written with its posed skin
(crates/pelage-gpu/examples/realtime_gallery.rs writes it). Blender
imports it, shades the hairs with the Principled Hair BSDF reading each
hair's melanin, redness, roughness and random number from pelage's
primvars (the add-on's material, `pelage_fur.fur.hair_material`, built
here without the add-on), and Cycles renders it from the real-time still's
camera, under its key light, at its size. OUT is the two side by side:
REALTIME (pelage's GPU strands) on the left, Cycles on the right.
"""

import math
import os
import sys
import tempfile

import bpy
import mathutils
import numpy

usd_path, realtime_path, out = (os.path.abspath(a) for a in sys.argv[-3:])

# The real-time still's camera and light (realtime_gallery.rs; ShellView's
# default key light: toward the camera, up, and to its side), in the
# groom's Y-up space.
EYE = mathutils.Vector((190.0, 85.0, 140.0))
TARGET = mathutils.Vector((0.0, 40.0, -10.0))
FOV_Y = math.radians(32.0)
view = (EYE - TARGET).normalized()
side = view.cross(mathutils.Vector((0.0, 1.0, 0.0))).normalized()
LIGHT = (view + 0.9 * mathutils.Vector((0.0, 1.0, 0.0)) + 0.6 * side).normalized()

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
scene = bpy.context.scene
assert bpy.ops.wm.usd_import(filepath=usd_path) == {"FINISHED"}
scene.frame_set(8)
skin = next(o for o in scene.objects if o.type == "MESH")
curves = [o for o in scene.objects if o.type == "CURVES"]
assert curves, "the USD file has hair curves"
# From the groom's space to Blender's world: the importer's turn of a
# Y-up stage, as the skin (written in world space) received it.
to_world = skin.matrix_world.copy()
turn = to_world.to_3x3()


def aimed(obj, location, target, up):
    """``obj`` at ``location`` looking at ``target``, ``up`` up."""
    obj.location = location
    forward = (target - location).normalized()
    right = forward.cross(up).normalized()
    true_up = right.cross(forward)
    obj.rotation_euler = mathutils.Matrix((right, true_up, -forward)).transposed().to_euler()


camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(camera)
scene.camera = camera
up = turn @ mathutils.Vector((0.0, 1.0, 0.0))
aimed(camera, to_world @ EYE, to_world @ TARGET, up)
camera.data.sensor_fit = "VERTICAL"
camera.data.angle_y = FOV_Y
camera.data.clip_end = 5000.0

# The key light: a sun shining along −LIGHT.
sun = bpy.data.objects.new("key", bpy.data.lights.new("key", "SUN"))
sun.data.energy = 3.0
sun.data.angle = math.radians(5.0)
scene.collection.objects.link(sun)
light = turn @ LIGHT
aimed(sun, to_world @ TARGET + 100.0 * light, to_world @ TARGET, up)

# The background of the real-time picture, and a little of its light.
world = bpy.data.worlds.new("world")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.62, 0.66, 0.72, 1)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.35
scene.world = world

# pelage's hair material: Principled Hair (Chiang, melanin), per hair.
material = bpy.data.materials.new("pelage hair")
material.use_nodes = True
nodes, links = material.node_tree.nodes, material.node_tree.links
nodes.clear()
output = nodes.new("ShaderNodeOutputMaterial")
hair = nodes.new("ShaderNodeBsdfHairPrincipled")
hair.model = "CHIANG"
hair.parametrization = "MELANIN"
links.new(hair.outputs["BSDF"], output.inputs["Surface"])
for socket, name in [("Melanin", "hair_melanin"), ("Melanin Redness", "hair_melanin_redness"),
                     ("Roughness", "hair_roughness"), ("Random", "hair_random")]:
    attribute = nodes.new("ShaderNodeAttribute")
    attribute.attribute_type = "GEOMETRY"
    attribute.attribute_name = name
    links.new(attribute.outputs["Fac"], hair.inputs[socket])
for obj in curves:
    obj.data.materials.clear()
    obj.data.materials.append(material)

realtime = bpy.data.images.load(realtime_path)
width, height = realtime.size
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 24
scene.cycles.use_denoising = False
scene.render.resolution_x, scene.render.resolution_y = width, height
scene.render.resolution_percentage = 100
scene.render.film_transparent = False
scene.view_settings.view_transform = "Standard"
rendered_path = os.path.join(tempfile.mkdtemp(prefix="pelage-cycles-"), "cycles.png")
scene.render.filepath = rendered_path
bpy.ops.render.render(write_still=True)

# Side by side: pelage's GPU strands, then Cycles.
rendered = bpy.data.images.load(rendered_path)
left = numpy.array(realtime.pixels[:]).reshape(height, width, 4)
right = numpy.array(rendered.pixels[:]).reshape(height, width, 4)
both = numpy.concatenate([left, right], axis=1)
image = bpy.data.images.new("side by side", 2 * width, height)
image.pixels = both.ravel().tolist()
image.filepath_raw = out
image.file_format = "PNG"
image.save()
print(f"wrote {out}")
