"""pelage's Python package growing the Stubble figure, timed.

Run by `pelage bench python` with a Python that has pelage installed:
    python python_grow.py GROOM.toml RUNS
Loads the groom (its generator is prepared there) and grows every part
through `Groom.parts()`, RUNS times after one warm-up run; prints one JSON
line: the median seconds, hairs and points grown, pelage's version and
build profile.
"""
import json
import statistics
import sys
import time

import pelage

path, runs = sys.argv[1], int(sys.argv[2])


def grow():
    groom = pelage.Groom.load(path)
    hairs = points = 0
    for curves in groom.parts():
        hairs += curves.curve_count
        points += curves.point_count
    return hairs, points


grow()
times = []
for _ in range(runs):
    start = time.perf_counter()
    hairs, points = grow()
    times.append(time.perf_counter() - start)
print(json.dumps({
    "seconds": statistics.median(times),
    "hairs": hairs,
    "points": points,
    "version": pelage.__version__,
    "profile": getattr(pelage._pelage, "__build_profile__", "unknown"),
}))
