"""Blender's own hair dynamics, timed: the Khronos Fox imported with
Blender's glTF importer, running (its "Run" action on the armature), with
a particle hair system of as many guides of as many points as pelage
simulates (Blender's hair dynamics: the cloth solver on hair, `quality`
substeps a frame), colliding with the body through a Collision modifier.

Run by `pelage bench dynamics --strands --peer blender` with Blender as a
Python module:
    python blender_strands.py CASE_DIR
CASE_DIR holds case.json (the glTF's path, guides, points a guide, frames,
substeps, hair length and collision distance as fractions of the Fox's
size). Blender places its own roots (particle hair emitted from faces,
random): the same count, points, length and body, not the same roots.
Prints one JSON line: the median seconds a frame with hair dynamics and
without (the armature, the collision modifier and static hair alone),
and Blender's version.
"""
import json
import statistics
import sys
import time
from pathlib import Path

import bpy

case = json.loads((Path(sys.argv[1]) / "case.json").read_text())
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=case["gltf"])
scene = bpy.context.scene
armature = next(o for o in scene.objects if o.type == "ARMATURE")
fox = next(o for o in scene.objects if o.type == "MESH" and o.find_armature() == armature)
armature.animation_data.action = bpy.data.actions["Run"]
size = max(fox.dimensions)

fox.modifiers.new("collision", "COLLISION")
fox.modifiers.new("hair", "PARTICLE_SYSTEM")
psys = fox.particle_systems[0]
settings = psys.settings
settings.type = "HAIR"
settings.count = case["guides"]
settings.hair_length = case["length"] * size
settings.hair_step = case["points"] - 1
settings.child_type = "NONE"
psys.use_hair_dynamics = True
psys.cloth.settings.quality = case["substeps"]
psys.cloth.collision_settings.use_collision = True
psys.cloth.collision_settings.distance_min = case["thickness"] * size


def seconds_a_frame(frames):
    """Median seconds of a frame change, the depsgraph evaluated (the
    skin posed, the hair moved) from frame 1 on."""
    scene.frame_set(1)
    times = []
    for frame in range(2, frames + 2):
        start = time.perf_counter()
        scene.frame_set(frame)
        fox.evaluated_get(bpy.context.evaluated_depsgraph_get())
        times.append(time.perf_counter() - start)
    return statistics.median(times)


with_dynamics = seconds_a_frame(case["frames"])
moved = fox.evaluated_get(bpy.context.evaluated_depsgraph_get()).particle_systems[0]
keys = len(moved.particles[0].hair_keys) if len(moved.particles) else 0
psys.use_hair_dynamics = False
without = seconds_a_frame(case["frames"])
print(
    json.dumps(
        {
            "frame_s": with_dynamics,
            "static_frame_s": without,
            "guides": len(moved.particles),
            "points_per_guide": keys,
            "frames": case["frames"],
            "blender": bpy.app.version_string,
        }
    )
)
