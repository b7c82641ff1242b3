//! Curves in and out: USD checked by Pixar's own library (usdcheck), round
//! trips through every format, `.hair` byte for byte, malformed files as
//! errors naming the file and the field or line.
//!
//! The usdcheck tests run `tools/usdcheck` (it installs usd-core
//! into a cached venv on first use). Where it is missing or cannot set
//! itself up they print SKIPPED; with `PELAGE_REQUIRE_USDCHECK=1` (CI) they
//! fail instead.

mod support;

use glam::Vec3;
use pelage::io::{
    AbcWriter, CurveBasis, CurvesExport, CurvesFormat, HairFile, UsdOptions, UsdWrap, UsdaWriter,
    UsdcWriter, read_curves, read_usd_curves, write_curves,
};
use pelage::{Curves, SurfacePoint};
use std::path::{Path, PathBuf};
use support::{blendercheck, numbers_after, usdcheck};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/good")
        .join(name)
}

/// A small groom on Spot with every attribute the USD writer knows.
fn small_groom(curves: u32, points: usize) -> Curves {
    let spot = pelage::assets::spot();
    let roots: Vec<SurfacePoint> = (0..curves)
        .map(|i| SurfacePoint::new(i * 37 % spot.triangle_count() as u32, [0.25, 0.5]))
        .collect();
    let c = Curves::along_normals(&spot, &roots, 0.1, points, 0.01, 0.002);
    let n = c.points().len();
    let uvs = roots.iter().map(|r| r.uv(&spot).unwrap()).collect();
    c.with_normals(
        (0..n)
            .map(|i| Vec3::new(1.0, 0.0, i as f32 * 1e-3).normalize())
            .collect(),
    )
    .unwrap()
    .with_colors(
        (0..n)
            .map(|i| Vec3::new(0.5, 0.3, (i % 7) as f32 / 7.0))
            .collect(),
    )
    .unwrap()
    .with_opacities((0..n).map(|i| 1.0 - (i % 5) as f32 * 0.1).collect())
    .unwrap()
    .with_root_uvs(uvs)
    .unwrap()
    .with_ids((0..curves as u64).map(|i| i * 7 + 3).collect())
    .unwrap()
    .with_roots(roots)
    .unwrap()
}

fn write_usd(path: &Path, parts: &[(&str, &Curves)], options: &UsdOptions, mesh: bool) {
    let spot = pelage::assets::spot();
    let export = CurvesExport {
        usd: options.clone(),
        mesh: mesh.then_some(&spot),
        guides: None,
    };
    write_curves(
        path,
        parts.iter().map(|(n, c)| (n.to_string(), *c)),
        &export,
    )
    .unwrap();
}

#[test]
fn usd_files_pass_pixars_validators_and_inconsistent_ones_fail() {
    let dir = tempfile::tempdir().unwrap();
    let groom = small_groom(40, 6);
    let second = small_groom(7, 4);
    let parts = [("part_0", &groom), ("part_1", &second)];
    let mut files = Vec::new();
    for (basis, wrap, label) in [
        (CurveBasis::Linear, UsdWrap::Pinned, "linear"),
        (CurveBasis::CatmullRom, UsdWrap::Pinned, "catmullrom_pinned"),
        (
            CurveBasis::CatmullRom,
            UsdWrap::Nonperiodic,
            "catmullrom_nonperiodic",
        ),
    ] {
        let options = UsdOptions {
            basis,
            wrap,
            ..UsdOptions::default()
        };
        for mesh in [false, true] {
            for ext in ["usda", "usdc"] {
                let path = dir.path().join(format!("{label}_mesh{}.{ext}", mesh as u8));
                write_usd(&path, &parts, &options, mesh);
                files.push(path);
            }
        }
    }
    let refs: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    let Some((ok, text)) = usdcheck(&refs) else {
        return;
    };
    assert!(ok, "{text}");
    for f in &files {
        let line = format!("{}: ok:", f.display());
        assert!(text.contains(&line), "no ok for {}:\n{text}", f.display());
        assert!(text.contains("2 BasisCurves prims, 47 curves"), "{text}");
    }

    // A test of the test: counts that do not add up must make usdcheck fail.
    let good = std::fs::read_to_string(&files[0]).unwrap();
    let bad = good.replacen(
        "int[] curveVertexCounts = [6, ",
        "int[] curveVertexCounts = [5, ",
        1,
    );
    assert_ne!(good, bad);
    let bad_path = dir.path().join("inconsistent.usda");
    std::fs::write(&bad_path, bad).unwrap();
    let (ok, text) = usdcheck(&[&bad_path]).unwrap();
    assert!(!ok, "usdcheck accepted inconsistent counts:\n{text}");
    assert!(text.contains("curveVertexCounts sum"), "{text}");
}

#[test]
fn usd_written_then_read_back_gives_the_same_curves() {
    let dir = tempfile::tempdir().unwrap();
    let groom = small_groom(25, 5);
    let second = small_groom(3, 4);
    let path = dir.path().join("groom.usda");
    write_usd(
        &path,
        &[("a", &groom), ("b", &second)],
        &UsdOptions::default(),
        true,
    );
    let back = read_curves(&path).unwrap();
    let joined = pelage::curves::join([&groom, &second]).unwrap();
    assert_eq!(back.offsets(), joined.offsets());
    for (a, b) in back.points().iter().zip(joined.points()) {
        assert!((*a - *b).abs().max_element() <= 1e-6, "{a} vs {b}");
    }
    assert_eq!(back.widths(), joined.widths());
}

#[test]
fn usdc_holds_the_usda_layer_and_round_trips_every_attribute_to_the_bit() {
    let dir = tempfile::tempdir().unwrap();
    let groom = small_groom(60, 6);
    let second = small_groom(9, 4).with_ids(vec![1 << 40; 9]).unwrap();
    let parts = [("part_0", &groom), ("part_1", &second)];
    let (usda, usdc) = (dir.path().join("g.usda"), dir.path().join("g.usdc"));
    write_usd(&usda, &parts, &UsdOptions::default(), true);
    write_usd(&usdc, &parts, &UsdOptions::default(), true);
    assert!(std::fs::read(&usdc).unwrap().starts_with(b"PXR-USDC"));

    // What pelage reads back: every attribute, the same from both files.
    let joined = pelage::curves::join([&groom, &second]).unwrap();
    let from_usdc = read_curves(&usdc).unwrap();
    assert!(from_usdc.normals().is_some() && from_usdc.colors().is_some());
    assert!(from_usdc.opacities().is_some() && from_usdc.root_uvs().is_some());
    assert_eq!(from_usdc.ids(), joined.ids());
    assert_eq!(from_usdc, read_curves(&usda).unwrap());
    assert_eq!(from_usdc.points(), joined.points());

    // usdc → usda → usdc: the same values, and the same bytes.
    let (back_a, back_c) = (dir.path().join("b.usda"), dir.path().join("b.usdc"));
    let again = dir.path().join("c.usdc");
    let one = [("p".to_string(), &from_usdc)];
    write_curves(
        &back_c,
        one.iter().map(|(n, c)| (n.clone(), *c)),
        &CurvesExport::default(),
    )
    .unwrap();
    write_curves(
        &back_a,
        one.iter().map(|(n, c)| (n.clone(), *c)),
        &CurvesExport::default(),
    )
    .unwrap();
    let through_text = read_curves(&back_a).unwrap();
    assert_eq!(through_text, from_usdc);
    let two = [("p".to_string(), &through_text)];
    write_curves(
        &again,
        two.iter().map(|(n, c)| (n.clone(), *c)),
        &CurvesExport::default(),
    )
    .unwrap();
    assert!(std::fs::read(&back_c).unwrap() == std::fs::read(&again).unwrap());

    // Pixar's library sees one layer in the text and the binary file.
    let Some((ok, text)) = usdcheck(&[Path::new("--same"), &usda, &usdc]) else {
        return;
    };
    assert!(ok, "{text}");
}

#[test]
fn animated_usdc_holds_each_frame_and_the_stage_time_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("moving.usdc");
    let frames: Vec<(f64, Curves)> = (0..4)
        .map(|f| {
            let c = small_groom(12, 5);
            let shifted: Vec<Vec3> = c.points().iter().map(|p| *p + Vec3::X * f as f32).collect();
            let moved = Curves::new(shifted, c.widths().to_vec(), c.offsets().to_vec()).unwrap();
            (
                10.0 + f as f64,
                moved.with_normals(c.normals().unwrap().to_vec()).unwrap(),
            )
        })
        .collect();
    pelage::io::write_atomically(&path, |out| {
        let mut usd =
            UsdcWriter::new(out, &UsdOptions::default()).map_err(std::io::Error::other)?;
        // Frame-major, as an animation grows: every part at each time.
        for (time, curves) in &frames {
            for part in ["a", "b"] {
                usd.write_part_at(part, *time, curves)
                    .map_err(std::io::Error::other)?;
            }
        }
        usd.finish().map_err(std::io::Error::other)?;
        Ok(())
    })
    .unwrap();
    // pelage reads the first frame.
    let first = read_curves(&path).unwrap();
    assert_eq!(
        &first.points()[..frames[0].1.points().len()],
        frames[0].1.points()
    );
    // Damaged copies read with every time sample: errors or curves, never
    // a panic or an allocation a corrupted count claims.
    let bytes = std::fs::read(&path).unwrap();
    let bad = dir.path().join("bad.usdc");
    for damaged in damaged_copies(&bytes, 11, 0, 0x0dd_ba11_5ca1_ab1e) {
        std::fs::write(&bad, &damaged).unwrap();
        let _ = pelage::io::read_usd_curves_at(&bad, Some(1.5));
    }
    // A frame with other curves is refused, naming the part and time.
    let mut usd =
        UsdcWriter::new(std::io::Cursor::new(Vec::new()), &UsdOptions::default()).unwrap();
    usd.write_part_at("a", 1.0, &frames[0].1).unwrap();
    let err = usd
        .write_part_at("a", 2.0, &small_groom(3, 5))
        .unwrap_err()
        .to_string();
    assert!(err.contains("part \"a\" at time 2: 3 curves"), "{err}");

    let Some((ok, text)) = usdcheck(&[&path]) else {
        return;
    };
    assert!(ok, "{text}");
    assert!(
        text.contains("2 BasisCurves prims, 24 curves, 120 points, 4 frames"),
        "{text}"
    );
    // Pixar's library reads each frame's own points.
    let values = usd_values(&path, &["/groom/a.points@10[7]", "/groom/b.points@13[7]"]);
    assert_eq!(values[0], frames[0].1.points()[7].to_array());
    assert_eq!(values[1], frames[3].1.points()[7].to_array());
    let (ok, text) = usdcheck(&[Path::new("--values"), &path]).unwrap();
    assert!(
        ok && text.contains("stage 10 to 13 at 24 per second"),
        "{text}"
    );

    // And Blender's importer, at the same two frames (USD keeps Y up).
    let expected = [frames[0].1.points()[7], frames[3].1.points()[7]];
    assert_blender_points(&path, 7, [10, 13], expected.map(|p| p.to_array()));
}

/// Asserts that Blender's importer evaluates point `index` of the object
/// `a` of `file` at two frames to `want` (skipped where Blender cannot be
/// set up).
fn assert_blender_points(file: &Path, index: usize, frames: [i32; 2], want: [[f32; 3]; 2]) {
    let (index, list) = (index.to_string(), format!("{},{}", frames[0], frames[1]));
    let args = [
        file.as_os_str(),
        "--point".as_ref(),
        index.as_ref(),
        "--frames".as_ref(),
        list.as_ref(),
    ];
    let Some((ok, report)) = blendercheck(&args) else {
        return;
    };
    assert!(ok, "{report}");
    for (frame, want) in frames.iter().zip(want) {
        let got = numbers_after(&report, &format!("frame {frame}: a point[{index}] = "));
        for k in 0..3 {
            assert!(
                (got[k] as f32 - want[k]).abs() < 1e-6,
                "frame {frame}: {got:?} vs {want:?}\n{report}"
            );
        }
    }
}

/// The array elements `PATH@TIME[INDEX]` as Pixar's library reads them
/// (`usdcheck --values`), as `f32` triples.
fn usd_values(file: &Path, specs: &[&str]) -> Vec<[f32; 3]> {
    let mut args: Vec<&Path> = vec![Path::new("--values"), file];
    args.extend(specs.iter().map(Path::new));
    let (ok, text) = usdcheck(&args).expect("usdcheck ran before");
    assert!(ok, "{text}");
    specs
        .iter()
        .map(|spec| {
            let v = numbers_after(&text, &format!("{spec} = "));
            [v[0] as f32, v[1] as f32, v[2] as f32]
        })
        .collect()
}

#[test]
fn alembic_round_trips_what_it_holds_and_blender_imports_it() {
    let dir = tempfile::tempdir().unwrap();
    let groom = small_groom(60, 6);
    let second = small_groom(9, 4).with_ids(vec![1 << 40; 9]).unwrap();
    let abc = dir.path().join("g.abc");
    write_usd(
        &abc,
        &[("part_0", &groom), ("part_1", &second)],
        &UsdOptions::default(),
        false,
    );
    assert!(std::fs::read(&abc).unwrap().starts_with(b"Ogawa\xff\0\x01"));

    // Every attribute comes back exactly.
    let back = read_curves(&abc).unwrap();
    let joined = pelage::curves::join([&groom, &second]).unwrap();
    assert_eq!(back.offsets(), joined.offsets());
    assert_eq!(back.points(), joined.points());
    assert_eq!(back.widths(), joined.widths());
    assert_eq!(back.normals(), joined.normals());
    assert_eq!(back.colors(), joined.colors());
    assert_eq!(back.root_uvs(), joined.root_uvs());
    assert_eq!(back.ids(), joined.ids());
    assert_eq!(back.opacities(), joined.opacities());

    // abc → usdc → abc: the same values, the same bytes.
    let one = |c: &Curves| [("p".to_string(), c.clone())];
    let write = |path: &Path, c: &Curves| {
        let parts = one(c);
        write_curves(
            path,
            parts.iter().map(|(n, c)| (n.clone(), c)),
            &CurvesExport::default(),
        )
        .unwrap();
    };
    let (a1, usdc, a2) = (
        dir.path().join("1.abc"),
        dir.path().join("m.usdc"),
        dir.path().join("2.abc"),
    );
    write(&a1, &back);
    write(&usdc, &back);
    let through_usd = read_curves(&usdc).unwrap();
    write(&a2, &through_usd);
    assert!(std::fs::read(&a1).unwrap() == std::fs::read(&a2).unwrap());

    // The skin goes in as a polygon mesh beside the curves; pelage's
    // reader takes the curves and passes over it.
    let spot = pelage::assets::spot();
    let export = CurvesExport {
        mesh: Some(&spot),
        ..Default::default()
    };
    let parts = one(&groom);
    let with_skin = dir.path().join("x.abc");
    write_curves(
        &with_skin,
        parts.iter().map(|(n, c)| (n.clone(), c)),
        &export,
    )
    .unwrap();
    assert_eq!(read_curves(&with_skin).unwrap().points(), groom.points());

    // Blender's own importer makes the same curves, widths as radii.
    let Some((ok, report)) = blendercheck(&[&abc]) else {
        return;
    };
    assert!(ok, "{report}");
    assert!(
        report.contains("object part_0: 60 curves, 360 points"),
        "{report}"
    );
    assert!(
        report.contains("object part_1: 9 curves, 36 points"),
        "{report}"
    );
    let radius = numbers_after(&report, "object part_0: radius[0] = ")[0];
    assert_eq!(radius as f32, groom.widths()[0] / 2.0, "{report}");
}

#[test]
fn animated_alembic_holds_each_frame_for_blender() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("moving.abc");
    let rest = small_groom(12, 5);
    let frames: Vec<(f64, Curves)> = (0..4)
        .map(|f| {
            let shifted: Vec<Vec3> = rest
                .points()
                .iter()
                .map(|p| *p + Vec3::new(0.5, 0.0, 0.25) * f as f32)
                .collect();
            (
                10.0 + f as f64,
                Curves::new(shifted, rest.widths().to_vec(), rest.offsets().to_vec()).unwrap(),
            )
        })
        .collect();
    pelage::io::write_atomically(&path, |out| {
        let other = std::io::Error::other;
        let mut abc = AbcWriter::new(out, &UsdOptions::default()).map_err(other)?;
        for (time, curves) in &frames {
            abc.write_part_at("a", *time, curves).map_err(other)?;
        }
        abc.finish().map_err(other)?;
        Ok(())
    })
    .unwrap();
    // pelage reads the first frame, or the frame at a time (seconds at
    // 24 frames a second), held past the ends.
    assert_eq!(read_curves(&path).unwrap().points(), frames[0].1.points());
    let at = |t: f64| {
        pelage::io::read_abc_curves_at(&path, Some(t / 24.0))
            .unwrap()
            .points()
            .to_vec()
    };
    for (time, curves) in &frames {
        assert_eq!(at(*time), curves.points(), "frame {time}");
    }
    assert_eq!(at(0.0), frames[0].1.points());
    assert_eq!(at(99.0), frames[3].1.points());
    // Damaged copies of an animated file: errors or curves, never a panic.
    let bytes = std::fs::read(&path).unwrap();
    let bad = dir.path().join("bad.abc");
    for damaged in damaged_copies(&bytes, 11, 0, 0x51ed_2701_f00d_cafe) {
        std::fs::write(&bad, &damaged).unwrap();
        let _ = pelage::io::read_abc_curves_at(&bad, Some(0.5));
    }
    // Frames out of order are refused.
    let mut abc = AbcWriter::new(std::io::Cursor::new(Vec::new()), &UsdOptions::default()).unwrap();
    abc.write_part_at("a", 2.0, &rest).unwrap();
    let err = abc.write_part_at("a", 1.0, &rest).unwrap_err().to_string();
    assert!(err.contains("write frames in increasing time"), "{err}");

    // Blender turns Alembic's Y up into its Z up: (x, y, z) → (x, −z, y).
    let expected = [frames[0].1.points()[7], frames[3].1.points()[7]];
    assert_blender_points(&path, 7, [10, 13], expected.map(|p| [p.x, -p.z, p.y]));
}

#[test]
fn hostile_alembic_files_are_errors_naming_the_byte_and_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.abc");
    write_usd(
        &good,
        &[("part_0", &small_groom(20, 5))],
        &UsdOptions::default(),
        false,
    );
    let bytes = std::fs::read(&good).unwrap();
    let path = dir.path().join("bad.abc");
    let read = |b: &[u8]| {
        std::fs::write(&path, b).unwrap();
        read_curves(&path).map_err(|e| e.to_string())
    };

    // A root group that claims 2^40 children: refused before any allocation.
    let root = u64::from_le_bytes(bytes[8..16].try_into().unwrap()) as usize;
    let mut huge = bytes.clone();
    huge[root..root + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
    let err = read(&huge).unwrap_err();
    assert!(
        err.contains(&format!(
            "bad.abc: byte {root}: the archive: a group of 1099511627776 children, but only"
        )),
        "{err}"
    );
    // Cut short, or never finished by its writer.
    let err = read(&bytes[..bytes.len() / 2]).unwrap_err();
    assert!(err.contains("past the end of the file"), "{err}");
    let mut unfinished = bytes.clone();
    unfinished[5] = 0;
    assert!(
        read(&unfinished)
            .unwrap_err()
            .contains("was not completely written")
    );
    assert!(
        read(b"HDF5 file")
            .unwrap_err()
            .contains("not an Alembic file")
    );

    // Every 7th truncation and 600 corruptions: an error or curves, never
    // a panic or an allocation of a size the file only claims.
    for damaged in damaged_copies(&bytes, 7, 0, 0x9e37_79b9_7f4a_7c15) {
        let _ = read(&damaged);
    }
}

#[test]
fn hostile_usdc_files_are_errors_naming_the_byte_and_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.usdc");
    write_usd(
        &good,
        &[("part_0", &small_groom(20, 5))],
        &UsdOptions::default(),
        true,
    );
    let bytes = std::fs::read(&good).unwrap();
    let path = dir.path().join("bad.usdc");
    let read = |b: &[u8]| {
        std::fs::write(&path, b).unwrap();
        read_curves(&path).map_err(|e| e.to_string())
    };
    assert!(read(&bytes).is_ok());

    // A table of contents past the end, a section claiming 2^40 entries.
    let mut far = bytes.clone();
    far[16..24].copy_from_slice(&(1u64 << 40).to_le_bytes());
    let err = read(&far).unwrap_err();
    assert!(
        err.contains("bad.usdc: byte 1099511627776: the table of contents: 8 bytes past the end"),
        "{err}"
    );
    let toc = u64::from_le_bytes(bytes[16..24].try_into().unwrap()) as usize;
    let tokens = u64::from_le_bytes(bytes[toc + 8 + 16..toc + 8 + 24].try_into().unwrap()) as usize;
    let mut huge = bytes.clone();
    huge[tokens..tokens + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
    let err = read(&huge).unwrap_err();
    assert!(err.contains("TOKENS:"), "{err}");
    assert!(read(&bytes[..bytes.len() - 40]).is_err());
    assert!(
        read(b"PXR-USDC")
            .unwrap_err()
            .contains("past the end of the file")
    );

    // Every 97th truncation and 600 corruptions, half aimed at the
    // structure at the end: an error or curves, never a panic or an
    // allocation of a size the file only claims.
    for damaged in damaged_copies(&bytes, 97, toc.saturating_sub(2000), 0x2545_f491_4f6c_dd1d) {
        let _ = read(&damaged);
    }
}

/// Damaged copies of `bytes`: cut every `step` bytes, then 600 with 8
/// bytes overwritten or one bit flipped, every other one after `focus`.
fn damaged_copies(bytes: &[u8], step: usize, focus: usize, seed: u64) -> Vec<Vec<u8>> {
    let mut state = seed;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut copies: Vec<Vec<u8>> = (0..bytes.len())
        .step_by(step)
        .map(|cut| bytes[..cut].to_vec())
        .collect();
    for k in 0..600 {
        let mut b = bytes.to_vec();
        let from = if k % 2 == 0 { focus } else { 0 };
        let at = from + next() as usize % (b.len() - 8 - from);
        if next() % 2 == 0 {
            b[at..at + 8].copy_from_slice(&(next() >> (next() % 64)).to_le_bytes());
        } else {
            b[at] ^= 1 << (next() % 8);
        }
        copies.push(b);
    }
    copies
}

#[test]
fn usda_bytes_do_not_depend_on_the_number_of_threads() {
    // Large enough for several formatting blocks.
    let groom = small_groom(6000, 16);
    let write = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut out = Vec::new();
            let mut usd = UsdaWriter::new(&mut out, &UsdOptions::default()).unwrap();
            usd.write_part("part_0", &groom).unwrap();
            usd.finish().unwrap();
            out
        })
    };
    let one = write(1);
    assert!(one.len() > 1 << 20);
    assert!(one == write(2), "1 and 2 threads wrote different bytes");
}

#[test]
fn blender_style_usd_is_read_with_its_transforms_from_usda_and_usdc() {
    // Expected world positions computed by Pixar's library
    // (UsdGeom.Xformable.ComputeLocalToWorldTransform) for this file.
    let want = [
        Vec3::new(11.0, 3.0, 3.0),
        Vec3::new(11.0, 3.0, 4.0),
        Vec3::new(11.0, 3.0, 5.0),
        Vec3::new(10.0, 2.0, 3.0),
        Vec3::new(10.0, 2.5, 3.5),
    ];
    // The .usdc was written from the .usda by usd-core (Sdf.Layer.Export).
    for name in ["blender_curves.usda", "blender_curves.usdc"] {
        let curves = read_usd_curves(&data(name)).unwrap();
        assert_eq!(curves.offsets(), &[0, 3, 5], "{name}");
        for (a, b) in curves.points().iter().zip(want) {
            assert!((*a - b).length() < 1e-6, "{name}: {a} vs {b}");
        }
        assert_eq!(curves.widths(), &[0.1, 0.05, 0.01, 0.1, 0.01], "{name}");
    }
}

#[test]
fn blenders_alembic_export_is_read_in_world_space() {
    // blender_curves.abc is Blender 5.0.1's Alembic export of
    // blender_curves.usda as Blender imports it: the object keeps its own
    // transform (rotated a quarter turn about Z, moved by (1, 2, 3)) but
    // not the root's (10, 0, 0), and the export turns Z up into Y up:
    // (x, y, z) → (x, z, −y). Its curves sit under an Xform with a matrix.
    let want = [
        Vec3::new(1.0, 3.0, -3.0),
        Vec3::new(1.0, 4.0, -3.0),
        Vec3::new(1.0, 5.0, -3.0),
        Vec3::new(0.0, 3.0, -2.0),
        Vec3::new(0.0, 3.5, -2.5),
    ];
    let curves = read_curves(&data("blender_curves.abc")).unwrap();
    assert_eq!(curves.offsets(), &[0, 3, 5]);
    for (a, b) in curves.points().iter().zip(want) {
        assert!((*a - b).length() < 1e-6, "{a} vs {b}");
    }
    assert_eq!(curves.widths(), &[0.1, 0.05, 0.01, 0.1, 0.01]);
}

#[test]
fn malformed_usd_is_an_error_naming_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("blender_curves.usda")).unwrap();
    let broken = text.replace(
        "int[] curveVertexCounts = [3, 2]",
        "int[] curveVertexCounts = [3, 2,",
    );
    let path = dir.path().join("broken.usda");
    std::fs::write(&path, broken).unwrap();
    let err = read_curves(&path).unwrap_err().to_string();
    assert!(err.starts_with(&format!("{}:32:", path.display())), "{err}");

    let wrong = text.replace(
        "int[] curveVertexCounts = [3, 2]",
        "int[] curveVertexCounts = [3, 3]",
    );
    std::fs::write(&path, wrong).unwrap();
    let err = read_curves(&path).unwrap_err().to_string();
    assert!(
        err.contains("/root/Curves/Curves: curveVertexCounts add up to 6 but there are 5 points"),
        "{err}"
    );

    let path = dir.path().join("nothing.usda");
    std::fs::write(&path, "#usda 1.0\ndef Xform \"x\"\n{\n}\n").unwrap();
    let err = read_curves(&path).unwrap_err().to_string();
    assert!(
        err.contains("nothing.usda: the file holds no curves"),
        "{err}"
    );

    let err = read_curves(Path::new("guides.fbx"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("unknown curves format \"fbx\""), "{err}");
}

#[test]
fn usd_writer_refuses_what_usd_cannot_hold() {
    let short = Curves::new(vec![Vec3::ZERO, Vec3::Y, Vec3::X], vec![0.1; 3], vec![0, 3]).unwrap();
    let nonperiodic = UsdOptions {
        wrap: UsdWrap::Nonperiodic,
        ..UsdOptions::default()
    };
    let mut usd = UsdaWriter::new(Vec::new(), &nonperiodic).unwrap();
    let err = usd.write_part("p", &short).unwrap_err().to_string();
    assert!(
        err.contains("curve 0 has 3 points; nonperiodic Catmull-Rom curves need at least 4"),
        "{err}"
    );
    // A scale or frame rate that is not a positive number, in every format.
    for (meters_per_unit, time_codes_per_second) in [(f64::NAN, 24.0), (0.0, 24.0), (1.0, -24.0)] {
        let bad = UsdOptions {
            meters_per_unit,
            time_codes_per_second,
            ..UsdOptions::default()
        };
        let export = CurvesExport {
            usd: bad,
            mesh: None,
            guides: None,
        };
        for ext in ["usda", "usdc", "abc"] {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join(format!("x.{ext}"));
            let parts = [("p".to_string(), &short)];
            let err = write_curves(&path, parts.iter().map(|(n, c)| (n.clone(), *c)), &export)
                .unwrap_err()
                .to_string();
            assert!(err.contains("must be a positive number"), "{ext}: {err}");
            assert!(!path.exists(), "{ext}: a file was left");
        }
    }
    let mut usd = UsdaWriter::new(Vec::new(), &UsdOptions::default()).unwrap();
    assert!(usd.write_part("9lives", &short).is_err());
    assert!(usd.write_part("has space", &short).is_err());
    usd.write_part("ok", &short).unwrap();
    assert!(
        usd.write_part("ok", &short)
            .unwrap_err()
            .to_string()
            .contains("already written")
    );
}

/// A `.hair` file made field by field: no segments array (every hair has
/// the default count), transparency and colours, info text.
fn foreign_hair_file() -> Vec<u8> {
    let (hairs, segments) = (3u32, 4u32);
    let points = hairs * (segments + 1);
    let mut b = b"HAIR".to_vec();
    for v in [hairs, points, 2 | 8 | 16, segments] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [0.05f32, 0.25, 0.9, 0.6, 0.3] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    let mut info = [0u8; 88];
    info[..19].copy_from_slice(b"made by hand, 2026\0");
    b.extend_from_slice(&info);
    for i in 0..points {
        for v in [i as f32, (i * i) as f32 * 0.5, -1.0 / (i + 1) as f32] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    for i in 0..points {
        b.extend_from_slice(&(i as f32 / 100.0).to_le_bytes());
    }
    for i in 0..points * 3 {
        b.extend_from_slice(&(1.0 / (i + 2) as f32).to_le_bytes());
    }
    b
}

#[test]
fn hair_files_round_trip_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    // A file laid out differently from ours, and one we wrote.
    let ours = HairFile::from_curves(&small_groom(20, 7))
        .unwrap()
        .to_bytes();
    for (name, bytes) in [("foreign.hair", foreign_hair_file()), ("ours.hair", ours)] {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        let hair = HairFile::read(&path).unwrap();
        let again = dir.path().join(format!("again_{name}"));
        hair.write(&again).unwrap();
        assert!(
            std::fs::read(&again).unwrap() == bytes,
            "{name} changed on the round trip"
        );
    }
    let foreign = HairFile::parse(&foreign_hair_file(), Path::new("f.hair")).unwrap();
    let curves = foreign.to_curves(Path::new("f.hair")).unwrap();
    assert_eq!((curves.curve_count(), curves.points().len()), (3, 15));
    assert_eq!(curves.widths()[3], 0.05, "no thickness array: the default");
    assert_eq!(curves.opacities().unwrap()[1], 1.0 - 0.01);
    // Curves → .hair → curves keeps points, widths, colours and opacities.
    let groom = small_groom(10, 5);
    let path = dir.path().join("groom.hair");
    write_curves(&path, [("p".to_string(), &groom)], &CurvesExport::default()).unwrap();
    let back = read_curves(&path).unwrap();
    assert_eq!(
        (back.points(), back.widths(), back.offsets()),
        (groom.points(), groom.widths(), groom.offsets())
    );
    assert_eq!(back.colors(), groom.colors());
    for (a, b) in back
        .opacities()
        .unwrap()
        .iter()
        .zip(groom.opacities().unwrap())
    {
        assert!((a - b).abs() < 1e-6);
    }
}

#[test]
fn truncated_or_inconsistent_hair_files_are_errors_naming_the_field() {
    let path = Path::new("cut.hair");
    let bytes = foreign_hair_file();
    for cut in 0..bytes.len() {
        let err = HairFile::parse(&bytes[..cut], path)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("cut.hair: "), "{err}");
        if cut >= 128 {
            assert!(
                err.contains("truncated or its counts are wrong"),
                "cut at {cut}: {err}"
            );
        }
    }
    // The point count disagrees with hairs × (default segments + 1).
    let mut wrong = bytes.clone();
    wrong[16..20].copy_from_slice(&5u32.to_le_bytes());
    let err = HairFile::parse(&wrong, path).unwrap_err().to_string();
    assert!(
        err.contains(
            "header field 'point count' says 15 points but the default segment count implies 18"
        ),
        "{err}"
    );
    let mut extra = bytes.clone();
    extra.extend_from_slice(&[0; 8]);
    let err = HairFile::parse(&extra, path).unwrap_err().to_string();
    assert!(err.contains("8 bytes follow the last array"), "{err}");
    let mut magic = bytes;
    magic[0] = b'h';
    assert!(
        HairFile::parse(&magic, path)
            .unwrap_err()
            .to_string()
            .contains("does not start with \"HAIR\"")
    );
}

#[test]
fn ply_curves_round_trip_and_edges_in_any_order_make_the_same_chains() {
    let dir = tempfile::tempdir().unwrap();
    let groom = small_groom(12, 5);
    let path = dir.path().join("groom.ply");
    write_curves(&path, [("p".to_string(), &groom)], &CurvesExport::default()).unwrap();
    let back = read_curves(&path).unwrap();
    assert_eq!(
        (back.points(), back.widths(), back.offsets()),
        (groom.points(), groom.widths(), groom.offsets())
    );

    // Edges listed backwards still chain root to tip.
    let ascii = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                 element edge 2\nproperty int vertex1\nproperty int vertex2\nend_header\n\
                 0 0 0\n0 1 0\n0 2 0\n5 5 5\n1 2\n0 1\n";
    let path = dir.path().join("ascii.ply");
    std::fs::write(&path, ascii).unwrap();
    let c = read_curves(&path).unwrap();
    assert_eq!(c.offsets(), &[0, 3, 4]);
    assert_eq!(c.points()[2], Vec3::new(0.0, 2.0, 0.0));
    // A branch is an error naming the edge.
    std::fs::write(&path, ascii.replace("1 2\n0 1\n", "0 2\n0 1\n")).unwrap();
    let err = read_curves(&path).unwrap_err().to_string();
    assert!(
        err.contains("ascii.ply: edge 1: edge 0–1 makes a branch"),
        "{err}"
    );
}

#[test]
fn rib_and_pbrt_are_written_for_every_curve() {
    let dir = tempfile::tempdir().unwrap();
    let groom = small_groom(30, 5);
    for ext in ["rib", "pbrt"] {
        let path = dir.path().join(format!("groom.{ext}"));
        write_curves(&path, [("p".to_string(), &groom)], &CurvesExport::default()).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        if ext == "pbrt" {
            assert_eq!(text.matches("Shape \"curve\"").count(), 30);
            // 4 segments of 3 control points + 1, 3 numbers each.
            let first = text.lines().nth(1).unwrap();
            let p = first.split('[').nth(1).unwrap().split(']').next().unwrap();
            assert_eq!(p.split_whitespace().count(), 13 * 3, "{first}");
        } else {
            assert!(text.contains("Curves \"cubic\" [7 7 7"), "{}", &text[..200]);
            assert!(text.contains("\"varying color Cs\""));
        }
    }
    assert_eq!(
        CurvesFormat::from_path(Path::new("x.USDA")),
        Some(CurvesFormat::Usda)
    );
    // `.usd` is binary, as in Pixar's tools.
    assert_eq!(
        CurvesFormat::from_path(Path::new("x.usd")),
        Some(CurvesFormat::Usdc)
    );
}

#[test]
fn root_uvs_and_ids_reach_the_usd_file() {
    let mut out = Vec::new();
    let groom = small_groom(3, 2);
    let mut usd = UsdaWriter::new(&mut out, &UsdOptions::default()).unwrap();
    usd.write_part("p", &groom).unwrap();
    usd.finish().unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains(
            "int[] primvars:hair_id = [3, 10, 17] (\n            interpolation = \"uniform\""
        ),
        "{text}"
    );
    let uv = groom.root_uvs().unwrap()[0];
    assert!(
        text.contains(&format!("texCoord2f[] primvars:st = [({}, {})", uv.x, uv.y)),
        "{text}"
    );
    let big = groom.clone().with_ids(vec![1 << 40, 0, 1]).unwrap();
    let mut out = Vec::new();
    let mut usd = UsdaWriter::new(&mut out, &UsdOptions::default()).unwrap();
    usd.write_part("p", &big).unwrap();
    assert!(
        String::from_utf8(out)
            .unwrap()
            .contains("int64[] primvars:hair_id = [1099511627776, 0, 1]")
    );
}

#[test]
fn look_grooms_write_shading_primvars_and_a_materialx_hair_material() {
    let dir = tempfile::tempdir().unwrap();
    let text = |material: bool| {
        format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 300\nparts = 2\n\
             [guides]\ngenerate = {{ count = 30, length = 0.05 }}\n[finish]\npoints = 4\n\
             [look]\nmelanin = 0.3\nmelanin_redness = 0.6\njitter = 0.1\nmaterial = {material}\n\
             [regions]\nmap = \"noise:frequency=1,offset=0.5,scale=1\"\n[output]\nguides = true\n"
        )
    };
    let mut files = Vec::new();
    for material in [true, false] {
        let groom = pelage::groom::Groom::from_text("look.toml", text(material)).unwrap();
        let generator = groom.generator(None).unwrap();
        let parts: Vec<Curves> = (0..2).map(|p| generator.part(p).unwrap()).collect();
        for ext in ["usda", "usdc"] {
            let path = dir.path().join(format!("material{}.{ext}", material as u8));
            let named = parts
                .iter()
                .enumerate()
                .map(|(i, c)| (format!("part_{i}"), c));
            write_curves(&path, named, &groom.export_for(&generator, None)).unwrap();
            // pelage reads its own primvars back, all parts joined (the
            // guides, `purpose = "guide"`, are not hairs).
            let back = read_usd_curves(&path).unwrap();
            let want = pelage::curves::join(parts.iter()).unwrap();
            assert_eq!(back.shading(), want.shading(), "{}", path.display());
            assert_eq!(back.regions(), want.regions());
            let regions = want.regions().unwrap();
            assert!(regions.contains(&0) && regions.contains(&1));
            files.push(path);
        }
        // Alembic carries them as per-curve arbitrary parameters.
        let path = dir.path().join(format!("material{}.abc", material as u8));
        let named = parts
            .iter()
            .enumerate()
            .map(|(i, c)| (format!("part_{i}"), c));
        write_curves(&path, named, &groom.export_for(&generator, None)).unwrap();
        let want = pelage::curves::join(parts.iter()).unwrap();
        let back = read_curves(&path).unwrap();
        assert_eq!(back.shading(), want.shading());
        assert_eq!(back.regions(), want.regions());
    }
    let Some((ok, out)) = usdcheck(&files) else {
        return;
    };
    // usdcheck checks the network against MaterialX's own node library
    // (ids, input and output types, connections) and that every primvar
    // the material reads is on the curves it is bound to.
    assert!(ok, "{out}");
    for f in &files[..2] {
        let line = format!("{}: ok:", f.display());
        let line = out.lines().find(|l| l.starts_with(&line)).unwrap();
        assert!(
            line.ends_with("2 curves prims bound to a material"),
            "{line}"
        );
    }
    for f in &files[2..] {
        let line = format!("{}: ok:", f.display());
        let line = out.lines().find(|l| l.starts_with(&line)).unwrap();
        assert!(
            line.ends_with("0 warnings"),
            "material = false binds nothing: {line}"
        );
    }
    let (same, out) = usdcheck(&[Path::new("--same"), &files[0], &files[1]]).unwrap();
    assert!(same, "the usda and usdc writers disagree:\n{out}");

    // A test of the test: a material reading a primvar the curves lack.
    let good = std::fs::read_to_string(&files[0]).unwrap();
    let bad = good.replacen("\"hair_melanin_redness\"", "\"hair_redness\"", 1);
    assert_ne!(good, bad);
    let bad_path = dir.path().join("missing_primvar.usda");
    std::fs::write(&bad_path, bad).unwrap();
    let (ok, out) = usdcheck(&[&bad_path]).unwrap();
    assert!(!ok && out.contains("reads primvar hair_redness"), "{out}");
}

#[test]
fn grooms_without_a_look_are_bound_to_the_hair_material_shaded_by_their_colours() {
    let dir = tempfile::tempdir().unwrap();
    let text = |finish: &str| {
        format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 200\n\
             [guides]\ngenerate = {{ count = 20, length = 0.05 }}\n[finish]\npoints = 4\n{finish}"
        )
    };
    // Red-orange hairs, a fox's: melanin fitted to the colour at each root,
    // mostly pheomelanin. No pigment mix is as saturated as this orange:
    // the colour it gives back is the nearest one, orange, red first.
    let orange = "color = { root = [0.6, 0.2, 0.05], tip = [0.6, 0.2, 0.05] }\n";
    let mut files = Vec::new();
    for (name, finish) in [("plain", ""), ("orange", orange)] {
        let groom = pelage::groom::Groom::from_text("fur.toml", text(finish)).unwrap();
        let generator = groom.generator(None).unwrap();
        let part = generator.part(0).unwrap();
        let path = dir.path().join(format!("{name}.usda"));
        write_curves(
            &path,
            [("part_0".to_string(), &part)],
            &groom.export_for(&generator, None),
        )
        .unwrap();
        let written = std::fs::read_to_string(&path).unwrap();
        assert!(written.contains("rel material:binding"), "{name}: bound");
        match part.shading() {
            None => {
                assert_eq!(name, "plain");
                // The material's defaults, once for the prim.
                assert!(
                    written.contains("float[] primvars:hair_melanin = [0.8]"),
                    "{written}"
                );
            }
            Some(shading) => {
                assert_eq!(name, "orange");
                for (&m, &r) in shading.melanin.iter().zip(&shading.melanin_redness) {
                    let back = pelage::groom::color_of_melanin(m, r, 0.3);
                    let apart = (back.to_array().map(f32::ln)[0] - 0.6f32.ln()).abs();
                    assert!(back.x > back.y && back.y > back.z && apart < 1.0, "{back}");
                    assert!(r > 0.8, "mostly pheomelanin: {r}");
                }
            }
        }
        files.push(path);
    }
    // usdcheck: every primvar the material reads is on the curves.
    if let Some((ok, out)) = usdcheck(&files) {
        assert!(ok, "{out}");
    }
}
