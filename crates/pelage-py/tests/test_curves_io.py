"""Curves in and out, every format pelage writes."""

import numpy as np
import pytest

import pelage


def two_curves():
    points = np.array(
        [[0, 0, 0], [0, 1, 0], [0, 2, 0.5], [1, 0, 0], [1, 1, 0], [1, 2, 0.5], [1, 3, 1]],
        dtype=np.float32,
    )
    return pelage.Curves.from_arrays(
        points,
        [0, 3, 7],
        widths=np.linspace(0.01, 0.002, 7),
        colors=np.tile([0.8, 0.5, 0.2], (7, 1)),
    )


@pytest.mark.parametrize("ext", ["usdc", "usda", "abc", "hair", "ply"])
def test_round_trip_keeps_points_and_counts(tmp_path, ext):
    curves = two_curves()
    path = tmp_path / f"c.{ext}"
    pelage.write_curves(curves, path)
    back = pelage.read_curves(path)
    assert back.curve_count == 2
    assert np.array_equal(back.offsets, curves.offsets)
    assert np.allclose(back.points, curves.points, atol=1e-6)


@pytest.mark.parametrize("ext", ["rib", "pbrt"])
def test_renderer_formats_are_written(tmp_path, ext):
    path = tmp_path / f"c.{ext}"
    two_curves().write(path, basis="linear")
    assert path.stat().st_size > 100


def test_unknown_format_and_bad_offsets_are_errors(tmp_path):
    with pytest.raises(pelage.PelageError, match=r"c\.xyz.*unknown curves format"):
        pelage.write_curves(two_curves(), tmp_path / "c.xyz")
    assert not (tmp_path / "c.xyz").exists()
    with pytest.raises(pelage.PelageError):
        pelage.Curves.from_arrays(np.zeros((4, 3)), [0, 3, 9])
    with pytest.raises(ValueError, match="basis"):
        two_curves().write(tmp_path / "c.usda", basis="bezier")


def test_a_damaged_file_is_an_error_naming_it(tmp_path):
    path = tmp_path / "broken.usda"
    path.write_text("#usda 1.0\ndef BasisCurves \"c\" {\n  int[] curveVertexCounts = [3,\n")
    with pytest.raises(pelage.PelageError, match="broken.usda"):
        pelage.read_curves(path)


def test_a_failed_write_leaves_no_file(tmp_path):
    target = tmp_path / "missing-folder" / "c.usdc"
    with pytest.raises(pelage.PelageError, match="missing-folder"):
        pelage.write_curves(two_curves(), target)
    assert not target.parent.exists()


def test_views_keep_their_curves_alive():
    points = two_curves().points  # the Curves object is gone from Python
    assert points.base is not None
    assert np.allclose(points[-1], [1, 3, 1])
