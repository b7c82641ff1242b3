"""Meshes from files and arrays, and root sampling (Sik §3)."""

import numpy as np
import pytest

import pelage
from conftest import MESHES


def quad(uvs=True):
    """Two triangles with areas 1 and 4, flat in z = 0."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [4, 2, 0], [0, 2, 0]], dtype=np.float32)
    triangles = np.array([[0, 1, 3], [1, 2, 3]])
    uv = positions[:, :2] / 4 if uvs else None
    return pelage.Mesh.from_arrays(positions, triangles, uvs=uv)


def test_version_is_the_crates():
    assert pelage.__version__.count(".") == 2


def test_load_reports_what_pelage_info_prints():
    mesh = pelage.Mesh.load(MESHES / "blub_triangulated.obj")
    info = mesh.info()
    assert (info["vertices"], info["triangles"]) == (7106, 14208)
    assert info["boundary_edges"] == 0 and info["non_manifold_edges"] == 0
    assert info["uvs"] == "per corner"
    assert mesh.positions.shape == (7106, 3) and mesh.triangles.shape == (14208, 3)


def test_arrays_are_read_only_views_of_the_mesh():
    mesh = quad()
    a, b = mesh.positions, mesh.positions
    assert np.shares_memory(a, b), "a view of pelage's memory, not a copy"
    assert not a.flags.writeable
    with pytest.raises(ValueError):
        a[0, 0] = 1.0


def test_from_arrays_checks_indices_and_shapes():
    positions = np.zeros((3, 3), dtype=np.float32)
    positions[1, 0] = positions[2, 1] = 1
    with pytest.raises(pelage.PelageError, match="triangle 0"):
        pelage.Mesh.from_arrays(positions, [[0, 1, 7]])
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        pelage.Mesh.from_arrays(positions[:, :2], [[0, 1, 2]])
    with pytest.raises(ValueError, match="between 0 and"):
        pelage.Mesh.from_arrays(positions, [[0, 1, -2]])
    with pytest.raises(ValueError, match="one per vertex"):
        pelage.Mesh.from_arrays(positions, [[0, 1, 2]], uvs=np.zeros((5, 2)))
    # Indices that are not integers are refused, not truncated or cast.
    with pytest.raises(TypeError, match="triangles: expected integer indices, got an array of float64"):
        pelage.Mesh.from_arrays(positions, [[0, 1.7, 2]])
    with pytest.raises(TypeError, match="got an array of bool"):
        pelage.Mesh.from_arrays(positions, np.array([[True, False, True]]))
    with pytest.raises(TypeError, match="offsets: expected integer indices"):
        pelage.Curves.from_arrays(positions, [0.0, 3.0])
    # Integer arrays of any width still work.
    assert pelage.Mesh.from_arrays(positions, np.array([[0, 1, 2]], dtype=np.int16)).triangle_count == 1


def test_a_missing_file_is_an_error_naming_it():
    with pytest.raises(pelage.PelageError, match="no-such-mesh.obj"):
        pelage.Mesh.load("no-such-mesh.obj")


def test_subdivide_too_far_is_refused_not_attempted(spot):
    with pytest.raises(ValueError, match="triangles"):
        spot.subdivided(20)


def test_uniform_samples_follow_area_chi_square():
    mesh = quad()
    n = 40_000
    s = pelage.sample(mesh, n, seed=5)
    counts = np.bincount(s.triangles, minlength=2)
    expected = np.array([0.2, 0.8]) * n
    chi2 = (((counts - expected) ** 2) / expected).sum()
    # One degree of freedom: 10.83 is the 0.1 % critical value.
    assert chi2 < 10.83, (counts, chi2)
    assert np.allclose(s.positions[:, 2], 0)
    assert np.allclose(s.normals, [0, 0, 1], atol=1e-5)


def test_a_density_map_moves_roots_and_zero_density_is_an_error(spot):
    uniform = pelage.sample(spot, 5_000, seed=2)
    noisy = pelage.sample(spot, 5_000, density="noise:frequency=4,offset=0.5,scale=0.5", seed=2)
    assert not np.array_equal(uniform.triangles, noisy.triangles)
    with pytest.raises(pelage.PelageError, match="zero"):
        pelage.sample(spot, 10, density=0.0)


def test_same_seed_same_roots_and_batches_add_up(spot):
    whole = pelage.sample(spot, 3_000, seed=9)
    again = pelage.sample(spot, 3_000, seed=9)
    first = pelage.sample(spot, 1_000, seed=9)
    rest = pelage.sample(spot, 2_000, seed=9, first=1_000)
    assert np.array_equal(whole.positions, again.positions)
    assert np.array_equal(whole.positions, np.concatenate([first.positions, rest.positions]))
    other = pelage.sample(spot, 3_000, seed=10)
    assert not np.array_equal(whole.positions, other.positions)


def test_roots_lie_on_their_triangles(spot):
    s = pelage.sample(spot, 500, seed=1)
    tri = spot.triangles[s.triangles]
    p = spot.positions
    u, v = s.barycentrics[:, 0], s.barycentrics[:, 1]
    rebuilt = (1 - u - v)[:, None] * p[tri[:, 0]] + u[:, None] * p[tri[:, 1]] + v[:, None] * p[tri[:, 2]]
    assert np.allclose(rebuilt, s.positions, atol=1e-5)


def test_a_numpy_density_image_follows_the_uvs():
    mesh = quad()  # UVs: positions / 4
    # Two columns: density 0 on the left texel, 1 on the right (repeated
    # past the UV square and bilinear, as an image file's texels are).
    image = np.array([[0.0, 1.0]] * 4, dtype=np.float32)
    painted = pelage.sample(mesh, 20_000, density=image, seed=1)
    uniform = pelage.sample(mesh, 20_000, seed=1)
    right = lambda s: float(np.mean(s.uvs[:, 0] >= 0.5))
    assert right(painted) > right(uniform) + 0.15, (right(painted), right(uniform))
    with pytest.raises(ValueError, match="2-D"):
        pelage.sample(mesh, 10, density=np.zeros((2, 2, 2)))


def test_blue_noise_roots_keep_their_distance(spot):
    blue = pelage.sample(spot, 2000, seed=5, distribution="blue-noise")
    random = pelage.sample(spot, 2000, seed=5)
    assert len(blue) == 2000

    def closest(points):
        d = np.linalg.norm(points[:, None, :] - points[None, :, :], axis=-1)
        np.fill_diagonal(d, np.inf)
        return np.percentile(d.min(axis=1), 1)

    assert closest(blue.positions) > 2 * closest(random.positions)
    again = pelage.sample(spot, 2000, seed=5, distribution="blue-noise")
    assert np.array_equal(blue.positions, again.positions)
    with pytest.raises(ValueError, match="cannot be drawn in batches"):
        pelage.sample(spot, 10, first=10, distribution="blue-noise")
    with pytest.raises(ValueError, match='use "random" or "blue-noise"'):
        pelage.sample(spot, 10, distribution="poisson")
