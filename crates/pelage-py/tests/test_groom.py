"""Grooms from files and from Python values; growth part by part."""

import pathlib
import threading
import time

import numpy as np
import pytest

import pelage
from conftest import REPO, small_groom


def test_values_and_their_settings_text_grow_the_same_hairs(spot, tmp_path):
    from_values = small_groom(spot, finish={"points": 8}, base_dir=tmp_path)
    # The settings text is the groom file the values amount to; with the
    # mesh named instead of given, `pelage groom` would read it.
    text = 'mesh = { path = "spot" }\n' + from_values.settings
    from_text = pelage.Groom.from_text(text, path=tmp_path / "fur.toml")
    a, b = from_values.grow(), from_text.grow()
    assert a.curve_count == b.curve_count == 5_000
    assert np.array_equal(a.points, b.points)
    assert np.array_equal(a.widths, b.widths)


def test_all_parts_joined_equal_the_parts_one_by_one(groom):
    whole = groom.grow()
    parts = list(groom.parts())
    assert len(parts) == groom.part_count == 4
    assert sum(p.curve_count for p in parts) == whole.curve_count == 5_000
    assert np.array_equal(np.concatenate([p.points for p in parts]), whole.points)
    assert np.array_equal(groom.grow(2).points, parts[2].points)
    assert list(groom.part_hair_counts) == [p.curve_count for p in parts]
    with pytest.raises(IndexError, match="4 parts"):
        groom.grow(4)


def test_same_seed_same_hairs_and_another_seed_other_hairs(groom, spot):
    again = small_groom(spot)
    assert np.array_equal(groom.grow().points, again.grow().points)
    assert not np.array_equal(groom.grow(seed=4).points, groom.grow().points)


def test_curves_have_the_finish_and_views_share_memory(groom):
    curves = groom.grow(0)
    n = curves.curve_count
    assert curves.offsets.shape == (n + 1,) and curves.offsets[0] == 0
    assert np.all(np.diff(curves.offsets) == 8), "finish.points = 8"
    assert curves.points.shape == (8 * n, 3)
    assert curves.normals.shape == (8 * n, 3)
    assert np.allclose(np.linalg.norm(curves.normals, axis=1), 1, atol=1e-4)
    assert curves.root_uvs.shape == (n, 2)
    assert len(np.unique(curves.ids)) == n
    assert np.shares_memory(curves.points, curves.points)
    assert not curves.points.flags.writeable
    # Widths taper root to tip (finish default: 0.002 to 0.0002).
    w = curves.widths.reshape(n, 8)
    assert np.all(w[:, 0] > w[:, -1])


def test_roots_lie_on_the_mesh(groom, spot):
    curves = groom.grow(1)
    roots = curves.points[curves.offsets[:-1]]
    tri = spot.triangles[curves.root_triangles]
    p = spot.positions
    b = curves.root_barycentrics
    on_mesh = (1 - b[:, 0] - b[:, 1])[:, None] * p[tri[:, 0]] + b[:, :1] * p[tri[:, 1]] + b[:, 1:] * p[tri[:, 2]]
    assert np.allclose(roots, on_mesh, atol=1e-5)


def test_guides_given_as_curves_are_reproduced_at_their_roots(spot):
    grown = small_groom(spot).guides
    groom = pelage.Groom(
        mesh=spot,
        guides={"curves": grown, "points": 6},
        roots={"count": 2_000},
        interpolation={"method": "style-mesh"},
        finish={"points": grown.point_count // grown.curve_count},
    )
    assert groom.guides.curve_count == grown.curve_count
    assert np.allclose(groom.guides.points, grown.points, atol=1e-5)


def test_a_bad_setting_names_the_key(spot):
    with pytest.raises(pelage.PelageError, match=r"ops\[1\]\.clump\.count"):
        small_groom(spot, ops=[pelage.ops.noise(amplitude=0.001), pelage.ops.clump(count=0)])
    with pytest.raises(pelage.PelageError, match=r"ops\[0\]\.curl\.turn.*unknown field"):
        small_groom(spot, ops=[{"curl": {"radius": 0.01, "turn": 3}}])
    with pytest.raises(pelage.PelageError, match=r"\[mesh\]: missing field `path`") as error:
        pelage.Groom(mesh={}, guides={"generate": {"count": 3, "length": 0.1}}, roots=10)
    assert "<python groom>:" not in str(error.value), "no line of a text the user never wrote"
    with pytest.raises(TypeError, match="finish.points"):
        small_groom(spot, finish={"points": object()})


def test_a_groom_file_error_names_file_and_line(tmp_path):
    path = tmp_path / "fur.toml"
    path.write_text(
        '[mesh]\npath = "spot"\n\n[roots]\ncount = 100\n\n'
        '[guides]\ngenerate = { count = 10, length = 0.05 }\n\n'
        "[[ops]]\nclump = { count = 10, rait = 0.5 }\n"
    )
    with pytest.raises(pelage.PelageError, match=r"fur\.toml:11:.*rait"):
        pelage.Groom.load(path)


def test_progress_is_called_per_part_and_its_exception_is_raised(groom, tmp_path):
    calls = []
    groom.grow(progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]
    calls.clear()
    summary = groom.write(tmp_path / "fur.usdc", progress=lambda d, t: calls.append((d, t)))
    assert calls[-1] == (4, 4)
    assert summary["hairs"] == 5_000 and summary["points"] == 40_000

    def stop(done, total):
        raise KeyError("stop")

    with pytest.raises(KeyError):
        groom.grow(progress=stop)


def test_an_animated_farms_runs_are_named_by_their_frames_and_assemble(tmp_path):
    # Each run writes its share of the parts over every frame, named as
    # `pelage groom --part` names it, so the assembly finds the runs.
    fox = REPO / "crates" / "pelage" / "assets" / "fox"
    groom = pelage.Groom(
        mesh=str(next(fox.glob("*.gl*"))),
        guides={"generate": {"count": 40, "length": 3.0}},
        roots={"count": 400, "parts": 2},
        animation={"frames": "1-3"},
    )
    out = tmp_path / "fox.usda"
    written = [groom.write(out, part=(k, 2))["path"] for k in (1, 2)]
    assert [p.name for p in written] == ["fox.part-1-of-2.f0001-0003.usdc", "fox.part-2-of-2.f0001-0003.usdc"]
    assert sum(pelage.read_curves(p, time=2).curve_count for p in written) == 400
    assembled = groom.assemble(out)
    assert assembled["files"] == 2, assembled
    layer = out.read_text()
    assert all(p.name in layer for p in written), "the stitching layer names both runs' files"


def test_write_refuses_what_the_cli_refuses_before_growing(groom, tmp_path):
    # The library's pre-flight, the same as `pelage groom`'s: a format
    # pelage writes and a path it may write, before any hair grows.
    grown = []
    with pytest.raises(pelage.PelageError, match=r"fur\.xyz: unknown curves format"):
        groom.write(tmp_path / "fur.xyz", progress=lambda done, total: grown.append(done))
    folder = tmp_path / "fur.usdc"
    folder.mkdir()
    with pytest.raises(pelage.PelageError, match="it is a folder"):
        groom.write(folder, progress=lambda done, total: grown.append(done))
    assert grown == [], "refused before growing"


def test_farm_runs_write_part_files(groom, tmp_path):
    out = tmp_path / "fur.usda"
    written = [groom.write(out, part=(k, 2))["path"] for k in (1, 2)]
    assert [p.name for p in written] == ["fur.part-1-of-2.usda", "fur.part-2-of-2.usda"]
    total = sum(pelage.read_curves(p).curve_count for p in written)
    assert total == 5_000
    with pytest.raises(ValueError, match="K must be 1 to N"):
        groom.write(out, part=(3, 2))
    # The library's assembly, as `pelage groom --assemble` runs it.
    assembled = groom.assemble(out)
    assert [p.name for p in assembled["files"]] == [p.name for p in written]
    layer = out.read_text()
    assert "fur.part-1-of-2.usda" in layer and "fur.part-2-of-2.usda" in layer
    lo, hi = assembled["extent"]
    assert all(a < b for a, b in zip(lo, hi))


def test_the_report_before_growing_has_the_guides_and_no_parts(groom):
    report = groom.report()
    assert report["guides"] == {"kept": 60, "dropped": [], "unused_by_style_mesh": []}
    assert report["parts"] == [] and report["hairs"] == 0


def test_write_returns_the_groom_report(groom, tmp_path):
    report = groom.write(tmp_path / "fur.usdc")["report"]
    assert report["hairs"] == 5_000
    assert [p["part"] for p in report["parts"]] == [0, 1, 2, 3]
    assert sum(p["hairs"] for p in report["parts"]) == 5_000
    assert report["guides"]["kept"] == 60
    assert report["guides"]["dropped"] == []
    assert report["output"].endswith("fur.usdc")
    assert report["seconds"]["grow_and_write"] > 0


def test_growth_releases_the_interpreter(spot):
    groom = small_groom(spot, count=150_000)
    done = threading.Event()
    ticks = 0

    def grow():
        groom.grow()
        done.set()

    worker = threading.Thread(target=grow)
    start = time.perf_counter()
    worker.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    seconds = time.perf_counter() - start
    # Holding the interpreter would leave this loop a handful of ticks at
    # the switch interval; released, it ticks about once a millisecond.
    assert ticks > 0.2 * seconds * 1000 / 2, (ticks, seconds)


def test_an_animated_groom_writes_every_frame(tmp_path):
    fox = REPO / "crates" / "pelage" / "assets" / "fox"
    gltf = next(fox.glob("*.gl*"))
    groom = pelage.Groom(
        mesh=str(gltf),
        guides={"generate": {"count": 40, "length": 3.0}},
        roots=500,
        animation={"frames": "1-3"},
    )
    assert groom.frames == [1.0, 2.0, 3.0]
    out = tmp_path / "fox.usdc"
    groom.write(out)
    first = pelage.read_curves(out, time=1)
    last = pelage.read_curves(out, time=3)
    assert first.curve_count == last.curve_count == 500
    assert not np.array_equal(first.points, last.points), "the fur moves with the walk"
    # One frame in memory equals that frame of the file.
    frame3 = groom.grow_frame(3)
    assert frame3.curve_count == 500
    assert np.allclose(frame3.points, last.points, atol=1e-4)
    with pytest.raises(IndexError):
        groom.grow_frame(3, part=99)


def test_a_simulated_groom_swings_away_from_the_deformed_one(tmp_path):
    fox = REPO / "crates" / "pelage" / "assets" / "fox" / "Fox.gltf"

    def groom_of(mode, simulation=None):
        return pelage.Groom(
            mesh=str(fox),
            guides={"generate": {"count": 40, "length": 10.0}},
            roots=300,
            animation={"frames": "1-4", "clip": "Run", "mode": mode},
            simulation=simulation,
        )

    deformed = groom_of("deform").grow_frame(4)
    swinging = groom_of("simulate", {"gravity": [0, -500, 0], "follow": 0, "preroll": 4})
    simulated = swinging.grow_frame(4)
    # The simulated guides, written for other tools: a sample a frame.
    guides = tmp_path / "guides.usdc"
    done = swinging.simulate(guides)
    assert done["frames"] == (1, 4) and done["guides"] == 40 and done["cache"] is None
    first, last = pelage.read_curves(guides, time=1), pelage.read_curves(guides, time=4)
    assert len(last.offsets) - 1 == 40
    assert not np.array_equal(first.points, last.points)
    with pytest.raises(pelage.PelageError, match="mode = .simulate."):
        groom_of("deform").simulate(tmp_path / "nothing.usdc")
    assert np.array_equal(deformed.ids, simulated.ids)
    tips = lambda c: c.points[c.offsets[1:] - 1]
    apart = np.linalg.norm(tips(deformed) - tips(simulated), axis=1).mean()
    assert apart > 1.0, apart
    with pytest.raises(pelage.PelageError, match=r"simulation\.bend"):
        pelage.Groom(
            mesh=str(fox),
            guides={"generate": {"count": 4, "length": 10.0}},
            roots=10,
            animation={"frames": "1-2", "mode": "simulate"},
            simulation={"bend": 2},
        )


def test_a_still_groom_has_no_frames(groom):
    assert groom.frames is None
    with pytest.raises(ValueError, match="not animated"):
        groom.grow_frame(1)


def test_a_mesh_value_replaces_the_files_mesh(tmp_path):
    path = tmp_path / "fur.toml"
    path.write_text(
        '[mesh]\npath = "spot"\n\n[roots]\ncount = 300\n\n'
        '[guides]\ngenerate = { count = 10, length = 0.05 }\n'
    )
    blub = pelage.Mesh.load(REPO / "tests" / "data" / "meshes" / "blub_triangulated.obj")
    groom = pelage.Groom.load(path, mesh=blub)
    assert groom.mesh.vertex_count == blub.vertex_count
    curves = groom.grow()
    assert curves.root_triangles.max() >= pelage.Mesh.spot().triangle_count, "roots on blub's triangles"


def test_regions_masks_and_stable_ids_from_python(spot):
    # A parting along a noise contour, a masked noise, stable ids: raising
    # the count keeps every hair of the smaller groom.
    def grown(count):
        return small_groom(
            spot,
            count=count,
            regions={"map": "noise:frequency=1,offset=0.5,scale=1"},
            ops=[pelage.ops.noise(amplitude=0.002, mask="noise:frequency=4")],
        ).grow()
    small, large = grown(2_000), grown(3_000)
    at = {int(i): k for k, i in enumerate(large.ids)}
    offsets = large.offsets
    for k, i in enumerate(small.ids):
        j = at[int(i)]
        a = small.points[small.offsets[k]:small.offsets[k + 1]]
        b = large.points[offsets[j]:offsets[j + 1]]
        assert np.array_equal(a, b), f"hair {i} changed"
    assert set(np.unique(large.regions)) == {0, 1}, "each hair's side of the parting"
    # A session's points alone, as curves() orders them, turned if asked.
    session = pelage.GroomSession(small_groom(spot, count=2_000))
    points = session.points()
    assert np.array_equal(points, session.curves().points)
    shift = np.eye(4)
    shift[:3, 3] = (1.0, 2.0, 3.0)
    assert np.allclose(session.points(shift), points + [1.0, 2.0, 3.0])
    with pytest.raises(pelage.PelageError, match="regions: the mesh has no face sets"):
        small_groom(spot, regions={"faces": "groups"}).grow()


def test_look_gives_each_hair_shader_values_written_as_usd_primvars(spot, tmp_path):
    groom = small_groom(spot, look={"melanin": 0.25, "roughness": 0.4, "jitter": 0.1,
                                    "tint": [1.0, 0.8, 0.6]})
    curves = groom.grow()
    shading = curves.shading
    n = curves.curve_count
    assert set(shading) == {"hair_melanin", "hair_melanin_redness", "hair_tint",
                            "hair_roughness", "hair_radial_roughness", "hair_random"}
    assert shading["hair_tint"].shape == (n, 3)
    assert np.allclose(shading["hair_tint"], [1.0, 0.8, 0.6])
    melanin = shading["hair_melanin"]
    assert melanin.shape == (n,) and melanin.min() >= 0.225 and melanin.max() <= 0.275
    assert len(np.unique(melanin)) > n // 2, "jitter gives each hair its own value"
    path = tmp_path / "fur.usda"
    groom.write(path)
    back = pelage.read_curves(path)
    assert np.array_equal(back.shading["hair_melanin"], melanin)
    assert 'rel material:binding = </groom/hair_material>' in path.read_text()
    assert small_groom(spot).grow().shading is None
    with pytest.raises(pelage.PelageError, match="look.roughness"):
        small_groom(spot, look={"roughness": 2.0}).grow()


def test_vertex_maps_and_face_sets_given_with_the_mesh_drive_density_and_regions():
    # A grid of 21 × 21 vertices in the XZ plane; the map is 1 on x > 0.
    xs = np.linspace(-1, 1, 21, dtype=np.float32)
    x, z = np.meshgrid(xs, xs)
    positions = np.stack([x.ravel(), np.zeros(x.size, np.float32), z.ravel()], axis=1)
    quads = [(i * 21 + j, (i + 1) * 21 + j, (i + 1) * 21 + j + 1, i * 21 + j + 1)
             for i in range(20) for j in range(20)]
    triangles = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], np.uint32)
    half = (positions[:, 0] > 0).astype(np.float32)
    mesh = pelage.Mesh.from_arrays(positions, triangles, vertex_maps={"half": half})
    curves = pelage.Groom(mesh=mesh, guides={"generate": {"count": 20, "length": 0.1}},
                          roots={"count": 4000, "density": "vertex:half"}).grow()
    roots = curves.points[curves.offsets[:-1]]
    assert (roots[:, 0] > 0).mean() >= 0.95
    with pytest.raises(pelage.PelageError, match="3 values for 441 vertices"):
        pelage.Mesh.from_arrays(positions, triangles, vertex_maps={"half": half[:3]})

    # Face sets as regions: guides on each side lean away from the line
    # between the sets; with the parting every hair leans its side's way.
    centres = positions[triangles].mean(axis=1)
    sides = np.where(centres[:, 0] > 0, 7, 3)
    parted = pelage.Mesh.from_arrays(positions, triangles, face_sets=sides)
    roots = np.array([[x, 0, z] for x in (-0.6, -0.2, 0.2, 0.6) for z in (-0.5, 0.5)], np.float32)
    lean = np.where(roots[:, :1] > 0, 1.0, -1.0) * np.array([[0.1, 0, 0]], np.float32)
    up = np.array([[0, 0.1, 0]], np.float32)
    guide_points = np.stack([roots, roots + up * 0.5 + lean * 0.5, roots + up + lean], axis=1)
    guides = pelage.Curves.from_arrays(guide_points.reshape(-1, 3), np.arange(0, 25, 3, dtype=np.uint32))
    hairs = pelage.Groom(mesh=parted, guides={"curves": guides, "points": 4},
                         roots=2000, regions={"faces": "groups"}).grow()
    starts, ends = hairs.points[hairs.offsets[:-1]], hairs.points[hairs.offsets[1:] - 1]
    lean_x = ends[:, 0] - starts[:, 0]
    assert np.all(np.sign(lean_x) == np.sign(starts[:, 0])), "a hair leans across the parting"
    # By the line, where guides of both sides are near, each hair still
    # leans fully its side's way (without the parting they blend to
    # nearly straight up).
    by_the_line = np.abs(starts[:, 0]) < 0.1
    assert by_the_line.sum() > 50 and np.all(np.abs(lean_x[by_the_line]) > 0.099)
    with pytest.raises(TypeError, match="face_sets: expected integer"):
        pelage.Mesh.from_arrays(positions, triangles, face_sets=sides.astype(np.float32))


def test_the_ops_builders_match_the_librarys_operator_schema():
    """`pelage.ops` is written by hand; this holds it to the operators the
    library declares, so a new operator or key without its builder fails
    here."""
    import inspect

    schema = pelage._pelage.operator_schema()
    builders = {
        name: fn
        for name, fn in vars(pelage.ops).items()
        if inspect.isfunction(fn) and not name.startswith("_")
    }
    assert sorted(builders) == sorted(op["name"] for op in schema)
    for op in schema:
        params = inspect.signature(builders[op["name"]]).parameters
        # Python puts required arguments first; the sets must agree.
        assert sorted(params) == sorted(op["fields"]), op["name"]
        required = [k for k, p in params.items() if p.default is inspect.Parameter.empty]
        assert sorted(required) == sorted(op["required"]), op["name"]
        assert builders[op["name"]].__doc__.strip() == op["summary"], op["name"]


def test_every_operator_grows_from_the_starts_its_schema_gives(spot):
    """The Blender panel starts a new operator from the schema's starts:
    built from them alone (lengths as they are, spot is about 1 across),
    every operator grows."""
    schema = pelage._pelage.operator_schema()
    for op in schema:
        settings = {s["name"]: s for s in op["settings"]}
        assert [s["name"] for s in op["settings"]] + ["mask"] == op["fields"]
        starts = {k: s["start"] for k, s in settings.items() if s["start"] is not None}
        assert set(op["required"]) <= set(starts), op["name"]
        assert all(s["doc"] for s in op["settings"]), op["name"]
        groom = small_groom(spot, count=200, ops=[{op["name"]: starts}])
        assert groom.grow().curve_count > 0, op["name"]
    clump = next(op for op in schema if op["name"] == "clump")
    count = next(s for s in clump["settings"] if s["name"] == "count")
    assert count["start"] == 200 and isinstance(count["start"], int)
    width = next(op for op in schema if op["name"] == "width")
    assert all(s["start_is_length"] for s in width["settings"] if s["required"])


def _interrupt_after(seconds):
    """Sends this process SIGINT (Ctrl-C) after `seconds`, from a thread."""
    import os
    import signal
    import threading

    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def _stopped_by_ctrl_c(call, whole, share, tidy=lambda: None):
    """Seconds `call()` ran before a Ctrl-C sent `share` of `whole` into it
    stopped it with KeyboardInterrupt. On a loaded machine the call can
    finish before the signal (it ran faster than the `whole` it was timed
    against): then `tidy()` and a sooner signal, three times, before the
    test fails. A call that ignores Ctrl-C never raises."""
    import signal
    import time

    # Python's own Ctrl-C handler, as in a terminal: a process started in
    # the background (a CI job, nohup) inherits SIGINT ignored.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        for attempt in range(3):
            timer = _interrupt_after(whole * share / 4**attempt)
            started = time.perf_counter()
            try:
                call()
            except KeyboardInterrupt:
                stopped = time.perf_counter() - started
                timer.join()
                return stopped
            timer.cancel()
            timer.join()
            tidy()
    finally:
        signal.signal(signal.SIGINT, previous)
    pytest.fail(f"not stopped by Ctrl-C, even {whole * share / 16:.3f} s into it")


def test_ctrl_c_stops_write_and_grow_between_parts(spot, tmp_path):
    """Ctrl-C during a long write() stops it at the next part (the file is
    left absent, no temporary file stays), with or without a progress
    callback; grow() without a callback stops too."""
    import time

    groom = small_groom(spot, count=60_000, roots={"count": 60_000, "seed": 3, "parts": 64})
    out = tmp_path / "fur.usdc"
    started = time.perf_counter()
    groom.write(out)
    whole = time.perf_counter() - started
    out.unlink()
    for progress in [None, lambda done, total: None]:
        stopped = _stopped_by_ctrl_c(
            lambda: groom.write(out, progress=progress), whole, 1 / 8, tidy=out.unlink
        )
        assert stopped < whole * 0.8, f"stopped after {stopped:.2f} s of {whole:.2f}"
        assert not out.exists()
        assert [p.name for p in tmp_path.iterdir()] == []
    started = time.perf_counter()
    groom.grow()
    grown = time.perf_counter() - started
    _stopped_by_ctrl_c(groom.grow, grown, 1 / 8)


def test_ctrl_c_stops_a_simulation_in_simulate_write_and_grow_frame(tmp_path):
    """Ctrl-C while the guides are simulated (before any frame is grown)
    stops simulate(), an animated write() and grow_frame() within a frame
    of the simulation, and simulate() writes no file."""
    import time

    fox = REPO / "crates" / "pelage" / "assets" / "fox" / "Fox.gltf"

    def simulated():
        return pelage.Groom(
            mesh=str(fox),
            guides={"generate": {"count": 600, "length": 10.0}},
            roots=200,
            animation={"frames": "1-40", "clip": "Run", "mode": "simulate"},
            simulation={"gravity": [0, -500, 0], "preroll": 8},
        )

    started = time.perf_counter()
    simulated().simulate()
    whole = time.perf_counter() - started
    guides = tmp_path / "guides.usdc"
    def tidy():
        for p in tmp_path.iterdir():
            p.unlink()

    for run in [lambda g: g.simulate(guides), lambda g: g.write(tmp_path / "fox.usdc"),
                lambda g: g.grow_frame(20)]:
        # A fresh groom each try: a finished one has its guides simulated.
        stopped = _stopped_by_ctrl_c(lambda: run(simulated()), whole, 1 / 5, tidy=tidy)
        assert stopped < whole * 0.6, f"stopped after {stopped:.2f} s of {whole:.2f}"
    assert [p.name for p in tmp_path.iterdir()] == []


def test_an_exception_in_progress_stops_the_write(spot, tmp_path):
    groom = small_groom(spot, count=20_000, roots={"count": 20_000, "seed": 3, "parts": 16})
    calls = []

    def progress(done, total):
        calls.append(done)
        if done == 2:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        groom.write(tmp_path / "fur.usdc", progress=progress)
    assert calls == [1, 2], "the write went on after the callback failed"
    assert not (tmp_path / "fur.usdc").exists()


def test_python_values_of_the_wrong_kind_are_refused_in_python_terms(spot, tmp_path):
    guides = {"generate": {"count": 20, "length": 0.05}}
    # A whole number written as a float is a count; anything else is not.
    assert pelage.Groom(mesh=spot, guides=guides, roots=1e3).part_hair_counts == [1000]
    with pytest.raises(ValueError, match=r"roots = 1000.5: a whole number of hairs"):
        pelage.Groom(mesh=spot, guides=guides, roots=1000.5)
    with pytest.raises(TypeError, match="not a bool"):
        pelage.Groom(mesh=spot, guides=guides, roots=True)
    with pytest.raises(pelage.PelageError, match=r"guides: invalid type: integer `5`, expected a table \(a dict\)"):
        pelage.Groom(mesh=spot, guides=5, roots=100)
    # No file name to write beside: a path is needed.
    groom = pelage.Groom(mesh=spot, guides=guides, roots=100)
    with pytest.raises(ValueError, match=r"write\(\): give a path"):
        groom.write()
    assert not any(p.name.startswith("<python groom>") for p in pathlib.Path(".").iterdir())
    # The folder of the output is made; more runs than parts is an error.
    assert groom.write(tmp_path / "a" / "b" / "fur.usdc")["hairs"] == 100
    with pytest.raises(ValueError, match=r"part = \(2, 5\): run 2/5: the groom has 1 parts"):
        groom.write(tmp_path / "farm" / "fur.usdc", part=(2, 5))
    assert not (tmp_path / "farm").exists() or not any((tmp_path / "farm").iterdir())


def test_a_groom_too_large_for_memory_raises_memory_error(spot):
    big = pelage.Groom(
        mesh=spot, guides={"generate": {"count": 20, "length": 0.05}}, roots=1_000_000_000
    )
    with pytest.raises(MemoryError, match=r"1,000,000,000 hairs .* groom.parts\(\)"):
        big.grow()
    # Counted after `strands`: a million roots of 1,024 hairs each is a
    # billion hairs (the estimate counted the roots), and a grooming
    # session, which holds every hair, is refused as grow() is.
    stranded = pelage.Groom(
        mesh=spot,
        guides={"generate": {"count": 20, "length": 0.05}},
        roots=1_000_000,
        ops=[{"strands": {"count": 1024, "tip_spread": 0.01}}],
    )
    with pytest.raises(MemoryError, match=r"1,024,000,000 hairs"):
        stranded.grow()
    with pytest.raises(MemoryError, match=r"grooming session"):
        pelage.GroomSession(big)


def test_the_build_profile_is_exported():
    assert pelage.__build_profile__ in ("debug", "release")


def test_a_painted_mesh_moved_by_a_skin_writes_animated(spot, tmp_path):
    """Vertex maps and face sets of the mesh a skin moves are kept: the
    animated write used to fail with "no vertex attribute 'belly'"."""
    rest = np.asarray(spot.positions, dtype=np.float32)
    belly = (rest[:, 1] < 0).astype(np.float32)
    painted = pelage.Mesh.from_arrays(rest, spot.triangles, vertex_maps={"belly": belly})
    skin = {f: rest + (f - 1) * np.array([0.02, 0, 0], dtype=np.float32) for f in (1, 2, 3)}
    groom = pelage.Groom(
        mesh=painted,
        skin=skin,
        guides={"generate": {"count": 30, "length": 0.05}},
        roots={"count": 500, "density": "vertex:belly"},
        animation={"frames": "1-3"},
    )
    out = tmp_path / "a.usdc"
    groom.write(out)
    assert out.exists() and groom.grow_frame(2).curve_count > 100


def test_a_skin_given_as_frames_moves_the_groom(spot):
    """A DCC's evaluated mesh at every frame (the add-on's animated
    export): the fur rides it, and simulates on it."""
    rest = np.asarray(spot.positions, dtype=np.float32)
    shift = np.array([0.05, 0.0, 0.0], dtype=np.float32)
    skin = {f: rest + (f - 1) * shift for f in (1, 2, 3)}

    def groom_of(mode, **extra):
        return pelage.Groom(
            mesh=spot,
            skin=skin,
            guides={"generate": {"count": 30, "length": 0.05}},
            roots=400,
            animation={"frames": "1-3", "mode": mode},
            **extra,
        )

    carried = groom_of("deform")
    first, third = carried.grow_frame(1), carried.grow_frame(3)
    assert np.array_equal(first.ids, third.ids)
    assert np.allclose(third.points, first.points + 2 * shift, atol=1e-5)
    # Between two frames given, the skin is blended: half a shift.
    assert np.allclose(carried.grow_frame(1.5).points, first.points + 0.5 * shift, atol=1e-5)
    # Simulated on it: the roots ride the skin, the tips lag.
    swung = groom_of("simulate", simulation={"gravity": [0, 0, 0], "follow": 0, "preroll": 0}).grow_frame(3)
    roots = lambda c: c.points[c.offsets[:-1]]
    assert np.allclose(roots(swung), roots(third), atol=1e-5)
    tips = lambda c: c.points[c.offsets[1:] - 1]
    assert np.linalg.norm(tips(swung) - tips(third), axis=1).mean() > 1e-3
    with pytest.raises(ValueError, match=r"skin\[2(\.0)?\]: 3 vertices"):
        pelage.Groom(
            mesh=spot, skin={1: rest, 2: rest[:3]}, guides={"generate": {"count": 3, "length": 0.05}},
            roots=10, animation={"frames": "1-2"},
        )
    with pytest.raises(pelage.PelageError, match=r"\[animation\]"):
        pelage.Groom(mesh=spot, skin=skin, guides={"generate": {"count": 3, "length": 0.05}}, roots=10)
    # Past the frame limit, refused before a frame is copied (a million
    # frames aborted the interpreter); the same array shared costs nothing.
    many = dict.fromkeys(range(100_001), rest)
    with pytest.raises(ValueError, match=r"skin: 100,001 frames; pelage's limit is 100,000"):
        pelage.Groom(
            mesh=spot, skin=many, guides={"generate": {"count": 3, "length": 0.05}},
            roots=10, animation={"frames": "1-2"},
        )


def test_the_gpu_grows_the_cpus_hairs(groom, tmp_path):
    # The real-time evaluator, headless (lavapipe serves); without an
    # adapter it says so, unless CI requires one.
    import os

    try:
        on_gpu = groom.grow(gpu=True)
    except RuntimeError as e:
        if os.environ.get("PELAGE_REQUIRE_GPU"):
            raise
        assert "no GPU" in str(e)
        pytest.skip(f"no GPU adapter: {e}")
    on_cpu = groom.grow()
    assert on_gpu.curve_count == on_cpu.curve_count == 5_000
    assert np.array_equal(on_gpu.ids, on_cpu.ids)
    # Spot is about a unit across: within 1e-4 of the groom's size.
    assert np.abs(on_gpu.points - on_cpu.points).max() < 1e-4
    assert np.abs(on_gpu.widths - on_cpu.widths).max() < 1e-7
    written = groom.write(tmp_path / "gpu.usdc", gpu=True)
    assert written["hairs"] == 5_000
    back = pelage.read_curves(tmp_path / "gpu.usdc")
    assert np.abs(back.points - on_cpu.points).max() < 1e-4


def test_an_animated_groom_written_on_the_gpu_is_the_cpus(tmp_path):
    # Every frame of the walking Fox, its hairs grown at rest on the GPU
    # and carried to each pose as on the CPU.
    import os

    fox = REPO / "crates" / "pelage" / "assets" / "fox"
    groom = pelage.Groom(
        mesh=str(next(fox.glob("*.gl*"))),
        guides={"generate": {"count": 40, "length": 3.0}},
        roots=500,
        animation={"frames": "1-3"},
    )
    try:
        groom.write(tmp_path / "gpu.usdc", gpu=True)
    except RuntimeError as e:
        if os.environ.get("PELAGE_REQUIRE_GPU"):
            raise
        assert "no GPU" in str(e)
        pytest.skip(f"no GPU adapter: {e}")
    groom.write(tmp_path / "cpu.usdc")
    for frame in (1, 3):
        on_gpu = pelage.read_curves(tmp_path / "gpu.usdc", time=frame)
        on_cpu = pelage.read_curves(tmp_path / "cpu.usdc", time=frame)
        assert np.array_equal(on_gpu.ids, on_cpu.ids)
        size = np.linalg.norm(on_cpu.points.max(axis=0) - on_cpu.points.min(axis=0))
        assert np.abs(on_gpu.points - on_cpu.points).max() < 1e-4 * size
