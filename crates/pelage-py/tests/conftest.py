"""Shared fixtures: small grooms that grow in well under a second."""

import pathlib

import pytest

import pelage

REPO = pathlib.Path(__file__).resolve().parents[3]
MESHES = REPO / "tests" / "data" / "meshes"


@pytest.fixture(scope="session")
def spot():
    return pelage.Mesh.spot()


def small_groom(mesh, count=5_000, **extra):
    """A groom on `mesh` with grown guides, a clump and noise."""
    settings = dict(
        mesh=mesh,
        guides={"points": 6, "generate": {"count": 60, "length": 0.05, "comb": [0, 0, -0.5]}},
        roots={"count": count, "seed": 3, "parts": 4},
        ops=[pelage.ops.clump(count=50, rate=0.5), pelage.ops.noise(amplitude=0.002)],
        finish={"points": 8},
    )
    settings.update(extra)
    return pelage.Groom(**settings)


@pytest.fixture()
def groom(spot):
    return small_groom(spot)
