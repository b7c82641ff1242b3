"""Grow fur on a mesh made with NumPy, and write it as binary USD.

    python grow_numpy_mesh.py [OUT.usdc]

A torus is built as arrays (positions, triangles, UVs), handed to pelage,
and groomed: 400 grown guides combed around the tube, 100,000 hairs
clumped and curled. The curves come back as NumPy arrays (views of
pelage's memory) and are written to USD (validated by Pixar's usd-core in
pelage's CI; Blender, Houdini and usdview open it).
"""

import sys
import time

import numpy as np

import pelage


def torus(major=1.0, minor=0.35, rings=96, sides=48):
    """A torus as (positions, triangles, per-vertex UVs), seamless in
    positions (the UV seam duplicates one ring and one side)."""
    u = np.linspace(0, 1, rings + 1, dtype=np.float32)
    v = np.linspace(0, 1, sides + 1, dtype=np.float32)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    a, b = uu * 2 * np.pi, vv * 2 * np.pi
    positions = np.stack(
        [(major + minor * np.cos(b)) * np.cos(a), minor * np.sin(b), (major + minor * np.cos(b)) * np.sin(a)],
        axis=-1,
    ).reshape(-1, 3)
    uvs = np.stack([uu, vv], axis=-1).reshape(-1, 2)
    index = np.arange((rings + 1) * (sides + 1)).reshape(rings + 1, sides + 1)
    q00, q10 = index[:-1, :-1], index[1:, :-1]
    q01, q11 = index[:-1, 1:], index[1:, 1:]
    triangles = np.concatenate(
        [np.stack([q00, q01, q11], -1).reshape(-1, 3), np.stack([q00, q11, q10], -1).reshape(-1, 3)]
    )
    return positions, triangles, uvs


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "torus_fur.usdc"
    positions, triangles, uvs = torus()
    mesh = pelage.Mesh.from_arrays(positions, triangles, uvs=uvs, name="numpy torus")
    print(mesh, "surface area", round(mesh.info()["surface_area"], 3))

    groom = pelage.Groom(
        mesh=mesh,
        guides={"generate": {"count": 400, "length": 0.12, "comb": [0, -0.6, 0], "gravity": 0.2}},
        roots={"count": 100_000, "seed": 7},
        ops=[
            pelage.ops.clump(count=1_500, rate=0.55),
            pelage.ops.curl(radius=0.004, turns=2.5),
            pelage.ops.noise(amplitude=0.004, frequency=20),
        ],
        finish={"points": 12, "width": {"root": 0.003, "tip": 0.0003},
                "color": {"root": [0.35, 0.2, 0.1], "tip": [0.9, 0.75, 0.5]}},
    )
    start = time.perf_counter()
    curves = groom.grow()
    grown = time.perf_counter() - start
    tips = curves.points[curves.offsets[1:] - 1]
    roots = curves.points[curves.offsets[:-1]]
    print(f"grew {curves.curve_count:,} hairs ({curves.point_count:,} points) in {grown:.2f} s;"
          f" mean hair reach {np.linalg.norm(tips - roots, axis=1).mean():.3f}")
    pelage.write_curves(curves, out, mesh=mesh)
    back = pelage.read_curves(out)
    assert back.curve_count == curves.curve_count
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
