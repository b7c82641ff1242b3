"""Grooming by hand from Python: brushes, undo and redo, previews that
are subsets of the full groom, and saving a groom `pelage groom` grows."""

import numpy as np
import pytest

import pelage
from conftest import small_groom


@pytest.fixture()
def filed_groom(spot, tmp_path):
    """The small groom as a groom file on disk (the mesh named, not given)."""
    text = 'mesh = { path = "spot" }\n' + small_groom(spot, base_dir=tmp_path).settings
    path = tmp_path / "fur.toml"
    path.write_text(text)
    return pelage.Groom.load(path)


def by_id(curves):
    return {int(i): k for k, i in enumerate(curves.ids)}


def test_comb_moves_the_hairs_near_it_and_undo_redo_restore_exactly(filed_groom):
    s = pelage.GroomSession(filed_groom)
    before = s.curves()
    guide = s.guides().points[6 * 10 : 6 * 11]
    root = tuple(float(x) for x in guide[0])
    done = s.brush("comb", at=root, radius=0.1, direction=(0.0, 0.03, 0.0), strength=1.0)
    assert done is not None and 0 < done["regrown"] < done["hairs"]
    after = s.curves()
    assert np.array_equal(before.ids, after.ids)
    moved = np.any(before.points != after.points, axis=1)
    assert 0 < moved.sum() < len(moved)
    assert s.history == (1, 0)
    assert s.undo() is True
    assert np.array_equal(s.curves().points, before.points)
    assert s.undo() is False
    assert s.redo() is True
    assert np.array_equal(s.curves().points, after.points)


def test_a_preview_is_a_subset_of_the_full_groom(filed_groom):
    full = filed_groom.grow()
    s = pelage.GroomSession(filed_groom, fraction=0.2)
    preview = s.curves()
    assert 0 < preview.curve_count < full.curve_count / 3
    index = by_id(full)
    offsets = full.offsets
    for k, i in enumerate(preview.ids[:200]):
        j = index[int(i)]
        a = preview.points[preview.offsets[k] : preview.offsets[k + 1]]
        b = full.points[offsets[j] : offsets[j + 1]]
        assert np.array_equal(a, b)
    s.fraction = 1.0
    assert s.hair_count == full.curve_count


def test_painted_density_and_a_parting_are_saved_and_grow_again(filed_groom, tmp_path):
    s = pelage.GroomSession(filed_groom)
    guides = s.guides().points
    s.brush("paint", at=tuple(map(float, guides[0])), radius=0.3, layer="density", value=0.0)
    s.brush("part", at=tuple(map(float, guides[6 * 30])), radius=0.4, region=1, falloff="constant")
    assert set(s.layers) >= {"density", "region"}
    assert s.layer("density").min() < 0.5
    saved = s.save(tmp_path / "groomed.toml")
    again = pelage.Groom.load(saved["groom"]).grow()
    session = s.curves()
    assert again.curve_count == session.curve_count
    index = by_id(session)
    worst = 0.0
    for k, i in enumerate(again.ids):
        j = index[int(i)]
        a = again.points[again.offsets[k] : again.offsets[k + 1]]
        b = session.points[session.offsets[j] : session.offsets[j + 1]]
        worst = max(worst, float(np.abs(a - b).max()))
    assert worst < 1e-4


def test_a_session_on_a_mesh_from_arrays_saves_a_groom_that_loads(spot, tmp_path):
    """The mesh given as arrays (no file to name) is written beside the
    groom file, which `Groom.load` (and `pelage groom`) reads again; it
    used to save `path = "<python mesh>"`, which nothing could load."""
    arrays = pelage.Mesh.from_arrays(spot.positions, spot.triangles)
    groom = small_groom(arrays, count=500)
    s = pelage.GroomSession(groom)
    saved = s.save(tmp_path / "values.toml")
    assert saved["mesh"] is not None and str(saved["mesh"]).endswith("values.mesh.obj")
    again = pelage.Groom.load(saved["groom"])
    assert again.grow().curve_count == s.curves().curve_count


def test_a_dab_that_reaches_no_guide_says_so(filed_groom):
    """A comb where no guide is (a dab far off the groom) changes nothing
    and warns, saying how far the nearest guide was; a dab on a guide
    does not warn."""
    import warnings

    s = pelage.GroomSession(filed_groom)
    with pytest.warns(UserWarning, match=r"comb: no guide within the brush's radius 0.01 .*nearest guide point is \d"):
        assert s.brush("comb", at=(50.0, 50.0, 50.0), radius=0.01, direction=(0.0, 0.03, 0.0)) is None
    assert s.history == (0, 0)
    root = tuple(float(x) for x in s.guides().points[0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert s.brush("comb", at=root, radius=0.1, direction=(0.0, 0.03, 0.0)) is not None


def test_bad_brushes_say_what_to_do(filed_groom):
    s = pelage.GroomSession(filed_groom)
    with pytest.raises(ValueError, match="no brush 'kamm'.*comb"):
        s.brush("kamm", at=(0, 0, 0), radius=0.1)
    with pytest.raises(ValueError, match="positive brush radius"):
        s.brush("comb", at=(0, 0, 0), radius=0.0)
    with pytest.raises(ValueError, match="falloff 'soft'"):
        s.brush("comb", at=(0, 0, 0), radius=0.1, falloff="soft")
    with pytest.raises(pelage.PelageError, match="letters, digits"):
        s.brush("paint", at=(0, 0, 0), radius=0.1, layer="my layer")
    with pytest.raises(pelage.PelageError, match="share of the hairs"):
        pelage.GroomSession(filed_groom, fraction=0.0)
    assert s.history == (0, 0)


def test_a_loaded_fraction_is_a_subset_with_wider_hairs(filed_groom, tmp_path):
    path = tmp_path / "fur.toml"
    full = pelage.Groom.load(path).grow()
    tenth = pelage.Groom.load(path, fraction=0.1).grow()
    assert tenth.curve_count == round(full.curve_count / 10)
    index = by_id(full)
    for k, i in enumerate(tenth.ids):
        j = index[int(i)]
        a = tenth.points[tenth.offsets[k] : tenth.offsets[k + 1]]
        b = full.points[full.offsets[j] : full.offsets[j + 1]]
        assert np.array_equal(a, b)
        wa = tenth.widths[tenth.offsets[k] : tenth.offsets[k + 1]]
        wb = full.widths[full.offsets[j] : full.offsets[j + 1]]
        assert np.array_equal(wa, wb * np.float32(1 / np.sqrt(0.1)))
    with pytest.raises(pelage.PelageError, match="--fraction"):
        pelage.Groom.load(path, fraction=2.0)
