"""Grow a big groom in parts, in a pool of processes, one part file each.

    python farm_pool.py [--groom GROOM.toml] [--out FOLDER] [--workers 2] [--runs 4]

Each worker loads the groom and writes run k of n (`part=(k, n)`): the
same files `pelage groom --part K/N` writes on a render farm, and any run
alone gives exactly its share of the whole groom (docs/farm.md). Without a
groom file, a 400,000-hair groom on the embedded Spot is used. Memory per
worker stays at about two parts: USD is written as parts grow.
"""

import argparse
import os
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

import pelage

DEFAULT_GROOM = """
[mesh]
path = "spot"

[roots]
count = {hairs}
parts = 8

[guides]
generate = { count = 500, length = 0.05, comb = [0, -0.3, -1], gravity = 0.3 }

[[ops]]
clump = { count = 3000, rate = 0.5 }

[[ops]]
noise = { amplitude = 0.003, frequency = 25 }
"""


def run(job):
    groom_path, out, k, n = job
    groom = pelage.Groom.load(groom_path)
    summary = groom.write(out, part=(k, n))
    return k, str(summary["path"]), summary["hairs"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--groom", help="a groom file (default: one on the embedded Spot)")
    parser.add_argument("--out", help="the folder for the part files (default: a new temporary one)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--runs", type=int, default=4, help="farm runs (part files)")
    parser.add_argument("--hairs", type=int, default=400_000, help="hairs of the default groom")
    args = parser.parse_args()
    folder = args.out or tempfile.mkdtemp(prefix="pelage-farm-")
    os.makedirs(folder, exist_ok=True)
    groom_path = args.groom
    if groom_path is None:
        groom_path = os.path.join(folder, "fur.toml")
        with open(groom_path, "w") as f:
            f.write(DEFAULT_GROOM.replace("{hairs}", str(args.hairs)))
    out = os.path.join(folder, "fur.usdc")
    jobs = [(groom_path, out, k, args.runs) for k in range(1, args.runs + 1)]
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        results = sorted(pool.map(run, jobs))
    seconds = time.perf_counter() - start
    for k, path, hairs in results:
        print(f"run {k}/{args.runs}: {hairs:,} hairs → {path}")
    total = sum(h for _, _, h in results)
    whole = sum(pelage.Groom.load(groom_path).part_hair_counts)
    assert total == whole, (total, whole)
    print(f"{total:,} hairs in {args.runs} part files, {args.workers} processes, {seconds:.1f} s")


if __name__ == "__main__":
    main()
