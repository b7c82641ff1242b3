"""A grown groom into Blender as a hair Curves object, timed two ways.

Run by `pelage bench python --blender` with Blender as a Python module:
    python blender_curves.py CASE_DIR
CASE_DIR holds case.json (the add-on's folder, counts), points.f32,
offsets.u32, widths.f32, root_uvs.f32, ids.u64 and groom.usdc (the same
curves written by pelage). Times (1) the add-on's `curves_to_blender`,
bulk transfers from arrays, median of 3, and (2) the peer: Blender's own
USD importer reading groom.usdc into a Curves object. Prints one JSON line.
"""
import json
import statistics
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import bpy
import numpy as np

case_dir = Path(sys.argv[1])
case = json.loads((case_dir / "case.json").read_text())
sys.path.insert(0, case["addon_dir"])
import fur  # noqa: E402  (blender/pelage_fur/fur.py)

read = lambda name, dtype: np.fromfile(case_dir / name, dtype=dtype)
points = read("points.f32", np.float32).reshape(-1, 3)
curves = SimpleNamespace(
    points=points,
    offsets=read("offsets.u32", np.uint32),
    widths=read("widths.f32", np.float32),
    root_uvs=read("root_uvs.f32", np.float32).reshape(-1, 2),
    ids=read("ids.u64", np.uint64),
    colors=None,
    point_count=len(points),
)

bpy.ops.wm.read_factory_settings(use_empty=True)
times = []
for _ in range(3):
    start = time.perf_counter()
    data = fur.curves_to_blender("fur", curves)
    times.append(time.perf_counter() - start)
    made = (len(data.curves), len(data.points))
    bpy.data.hair_curves.remove(data)

start = time.perf_counter()
bpy.ops.wm.usd_import(filepath=str(case_dir / "groom.usdc"))
usd_import = time.perf_counter() - start
imported = [o for o in bpy.data.objects if o.type == "CURVES"]
imported_points = sum(len(o.data.points) for o in imported)

print(json.dumps({
    "seconds": statistics.median(times),
    "curves": made[0],
    "points": made[1],
    "usd_import_seconds": usd_import,
    "usd_import_points": imported_points,
    "blender": bpy.app.version_string,
}))
