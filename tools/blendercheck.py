"""Import a USD or Alembic file with Blender's own importer and print what it made.

Lines (for tests to read):
    import S seconds                       (the median of --repeat imports)
    blender VERSION
    object NAME: C curves, P points, attributes a b c
    object NAME: radius[0] = R
    object NAME: color[0] = R G B          (the first colour attribute, if any)
    mesh NAME: V vertices, F faces
    mesh NAME: volume X                    (signed, world space: > 0 when faces wind outward)
    frame F: NAME point[I] = X Y Z         (evaluated, with --frames and --point)
    frame F: mesh NAME vertex[I] = X Y Z   (evaluated, world space, likewise)
"""
import argparse
import sys
import time

import bpy

parser = argparse.ArgumentParser()
parser.add_argument("file")
parser.add_argument("--point", type=int, default=0)
parser.add_argument("--frames", default="")
parser.add_argument("--repeat", type=int, default=1,
                    help="import this many times into an empty scene; print the median time")
args = parser.parse_args(sys.argv[1:])


def import_once():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    start = time.perf_counter()
    try:
        if args.file.lower().endswith(".abc"):
            result = bpy.ops.wm.alembic_import(filepath=args.file, as_background_job=False)
        else:
            result = bpy.ops.wm.usd_import(filepath=args.file)
    except RuntimeError as e:
        print(f"{args.file}: Blender cannot import it: {e}")
        sys.exit(1)
    seconds = time.perf_counter() - start
    if "FINISHED" not in result:
        print(f"{args.file}: Blender's importer returned {result}")
        sys.exit(1)
    return seconds


times = sorted(import_once() for _ in range(max(1, args.repeat)))
print(f"import {times[len(times) // 2]:.4f} seconds")
print(f"blender {bpy.app.version_string}")

def signed_volume(ob):
    """The divergence theorem's volume of the faces' fans, world space."""
    m = ob.matrix_world
    co = [m @ v.co for v in ob.data.vertices]
    total = 0.0
    for poly in ob.data.polygons:
        vs = [co[i] for i in poly.vertices]
        for k in range(1, len(vs) - 1):
            total += vs[0].dot(vs[k].cross(vs[k + 1])) / 6.0
    return total


meshes = sorted((o for o in bpy.data.objects if o.type == "MESH"), key=lambda o: o.name)
for ob in meshes:
    print(f"mesh {ob.name}: {len(ob.data.vertices)} vertices, {len(ob.data.polygons)} faces")
    print(f"mesh {ob.name}: volume {signed_volume(ob)!r}")
curves = sorted((o for o in bpy.data.objects if o.type == "CURVES"), key=lambda o: o.name)
if not curves:
    print(f"{args.file}: Blender made no curves object")
    sys.exit(1)
for ob in curves:
    data = ob.data
    names = sorted(a.name for a in data.attributes if not a.name.startswith("."))
    print(f"object {ob.name}: {len(data.curves)} curves, {len(data.points)} points, "
          f"attributes {' '.join(names)}")
    if "radius" in data.attributes and len(data.points):
        print(f"object {ob.name}: radius[0] = {data.attributes['radius'].data[0].value!r}")
    for a in data.attributes:
        if a.data_type in ("FLOAT_COLOR", "BYTE_COLOR") and len(a.data):
            c = a.data[0].color
            print(f"object {ob.name}: color[0] = {c[0]!r} {c[1]!r} {c[2]!r} ({a.name}, {a.domain})")
            break
for frame in [f for f in args.frames.split(",") if f]:
    bpy.context.scene.frame_set(int(frame))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for ob in curves:
        data = ob.evaluated_get(depsgraph).data
        if args.point < len(data.points):
            p = data.points[args.point].position
            print(f"frame {frame}: {ob.name} point[{args.point}] = {p[0]!r} {p[1]!r} {p[2]!r}")
    for ob in meshes:
        evaluated = ob.evaluated_get(depsgraph)
        if args.point < len(evaluated.data.vertices):
            p = evaluated.matrix_world @ evaluated.data.vertices[args.point].co
            print(f"frame {frame}: mesh {ob.name} vertex[{args.point}] = {p[0]!r} {p[1]!r} {p[2]!r}")
