//! The groom generator end to end: determinism across threads and parts,
//! roots that follow the density, every operator in one chain, and errors
//! that name the groom file's line and key.

use glam::Vec3;
use pelage::Curves;
use pelage::groom::ops::{Color, Cut, RootToTip};
use pelage::groom::{
    ClumpParams, CurlParams, FlyawaysParams, FrizzParams, Groom, GroomError, GroomErrorKind,
    GroomOp, GroomSpec, LengthParams, NoiseParams, Ramp, RootsSpec, StrandsParams, TwistParams,
};
use pelage::guides::{GuideGrowth, Guides};
use pelage::map::{Map, MapErrorKind, NoiseMap};
use std::collections::HashSet;
use std::sync::Arc;

const EVERY_OPERATOR: &str = r#"
[mesh]
path = "spot"

[roots]
count = 6000
density = "noise:frequency=4,seed=3,offset=0.6,scale=0.4"
seed = 11
parts = 3

[guides]
points = 6
generate = { count = 120, length = 0.05, comb = [0, -1, 0], gravity = 0.2 }

[[ops]]
clump = { count = 300, rate = 0.6, ramp = "smooth" }

[[ops]]
clump = { count = 40, rate = 0.3, size = 0.2 }

[[ops]]
curl = { radius = 0.003, turns = 1.5 }

[[ops]]
noise = { amplitude = 0.003, frequency = "noise:frequency=2,offset=30,scale=10" }

[[ops]]
frizz = { amplitude = 0.002, fraction = 0.3 }

[[ops]]
twist = { angle = 60, jitter = 0.3 }

[[ops]]
flyaways = { spread = 0.01, fraction = 0.1 }

[[ops]]
length = { scale = 1.0, jitter = 0.2 }

[[ops]]
cut = { at = "noise:frequency=3,offset=0.9,scale=0.3" }

[[ops]]
strands = { count = 3, root_spread = 0.001, tip_spread = 0.004, twist = 0.5 }

[[ops]]
width = { root = 0.001, tip = 0.0001, jitter = 0.1 }

[[ops]]
color = { root = [0.2, 0.1, 0.05], tip = [0.8, 0.7, 0.5], jitter = 0.1 }

[[ops]]
opacity = { root = 1.0, tip = 0.5 }
"#;

fn groom(text: &str) -> Groom {
    Groom::from_text("test.toml", text).expect("the groom loads")
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn output_is_identical_on_one_and_two_threads() {
    let g = groom(EVERY_OPERATOR);
    let grow_all = |threads| {
        in_pool(threads, || {
            let generator = g.generator(None).unwrap();
            (0..generator.parts().len())
                .map(|p| generator.part(p).unwrap())
                .collect::<Vec<Curves>>()
        })
    };
    let one = grow_all(1);
    let two = grow_all(2);
    assert_eq!(one.len(), 3);
    for (a, b) in one.iter().zip(&two) {
        assert!(a.curve_count() > 0);
        // Bit-identical: compare the bits, not approximate values.
        let bits = |c: &Curves| -> Vec<u32> {
            c.points()
                .iter()
                .flat_map(|p| p.to_array())
                .chain(c.widths().iter().copied())
                .chain(c.normals().unwrap().iter().flat_map(|n| n.to_array()))
                .chain(c.colors().unwrap().iter().flat_map(|n| n.to_array()))
                .chain(c.opacities().unwrap().iter().copied())
                .map(f32::to_bits)
                .collect()
        };
        assert_eq!(bits(a), bits(b));
        assert_eq!(a.ids(), b.ids());
        assert_eq!(a.offsets(), b.offsets());
    }
}

/// [`EVERY_OPERATOR`] written as Rust values, with no file.
fn every_operator_in_code() -> GroomSpec {
    let mesh = Arc::new(pelage::assets::spot());
    let noise = |frequency, seed, offset, scale| {
        // A noise spec's default octaves: 4.
        Map::Noise(NoiseMap::new(frequency, 4, seed, offset, scale))
    };
    let c = Map::Constant;
    let guides = Guides::grow(
        &mesh,
        &GuideGrowth {
            count: 120,
            length: c(0.05),
            comb: Vec3::new(0.0, -1.0, 0.0),
            gravity: 0.2,
            points: 6,
            width: 0.004,
            seed: 1,
            ..Default::default()
        },
    )
    .unwrap();
    let roots = RootsSpec::new(6000)
        .with_density(noise(4.0, 3, 0.6, 0.4))
        .with_seed(11)
        .with_parts(3);
    let mut width = RootToTip::new(c(0.001), c(0.0001));
    width.jitter = c(0.1);
    let color = Color {
        root: [c(0.2), c(0.1), c(0.05)],
        tip: [c(0.8), c(0.7), c(0.5)],
        ramp: Ramp::default(),
        jitter: c(0.1),
        seed: 0,
    };
    GroomSpec::new(mesh, guides, roots)
        .with_op(GroomOp::Clump(ClumpParams {
            rate: c(0.6),
            ramp: Ramp::Smooth,
            ..ClumpParams::new(300)
        }))
        .with_op(GroomOp::Clump(ClumpParams {
            rate: c(0.3),
            size: Some(c(0.2)),
            ..ClumpParams::new(40)
        }))
        .with_op(GroomOp::Curl(CurlParams::new(c(0.003), c(1.5))))
        .with_op(GroomOp::Noise(NoiseParams {
            frequency: noise(2.0, 0, 30.0, 10.0),
            ..NoiseParams::new(c(0.003))
        }))
        .with_op(GroomOp::Frizz(FrizzParams {
            fraction: c(0.3),
            ..FrizzParams::new(c(0.002))
        }))
        .with_op(GroomOp::Twist(TwistParams {
            jitter: c(0.3),
            ..TwistParams::new(c(60.0))
        }))
        .with_op(GroomOp::Flyaways(FlyawaysParams {
            fraction: c(0.1),
            ..FlyawaysParams::new(c(0.01))
        }))
        .with_op(GroomOp::Length(LengthParams {
            jitter: c(0.2),
            ..LengthParams::new(c(1.0))
        }))
        .with_op(GroomOp::Cut(Cut::new(noise(3.0, 0, 0.9, 0.3))))
        .with_op(GroomOp::Strands(StrandsParams {
            root_spread: c(0.001),
            twist: c(0.5),
            ..StrandsParams::new(3, c(0.004))
        }))
        .with_op(GroomOp::Width(width))
        .with_op(GroomOp::Color(color))
        .with_op(GroomOp::Opacity(RootToTip::new(c(1.0), c(0.5))))
}

#[test]
fn a_groom_built_in_code_equals_the_same_groom_file() {
    let from_file = groom(EVERY_OPERATOR).generator(None).unwrap();
    let from_code = every_operator_in_code().generator().unwrap();
    assert_eq!(from_code.parts(), from_file.parts());
    for p in 0..3 {
        let (a, b) = (from_code.part(p).unwrap(), from_file.part(p).unwrap());
        assert!(a.curve_count() > 1000);
        assert_eq!(a, b, "part {p}");
    }
    // Both paths check the same things: a count of zero, named by key
    // (and, from a file, by line).
    let mut zero = every_operator_in_code();
    zero.roots.count = 0;
    let err = zero.generator().unwrap_err();
    assert!(matches!(err.kind, GroomErrorKind::OutOfRange(_)), "{err}");
    assert_eq!(err.at.key.as_deref(), Some("roots.count"));
    assert_eq!(
        err.to_string(),
        "<groom>: roots.count: the hair count must be at least 1"
    );
    let mut no_strand = every_operator_in_code();
    no_strand.ops[9] = GroomOp::Strands(StrandsParams::new(0, Map::Constant(0.1)));
    let err = no_strand.generator().unwrap_err();
    assert!(matches!(err.kind, GroomErrorKind::OutOfRange(_)), "{err}");
    assert_eq!(err.at.key.as_deref(), Some("ops[9].strands.count"), "{err}");
}

#[test]
fn a_negative_density_scale_is_blamed_on_the_scale_at_its_line() {
    // The roots are drawn from the density times its scale: where only
    // the product goes negative, the scale is named, not the density.
    let message = |density: &str, scale: &str| {
        let text = format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 10\ndensity = \"{density}\"\ndensity_scale = \"{scale}\"\n[guides]\ngenerate = {{ count = 5, length = 0.1 }}\n"
        );
        groom(&text).generator(None).unwrap_err().to_string()
    };
    let scale = message("noise:frequency=3", "noise:offset=-2");
    assert!(
        scale.starts_with("test.toml:6:17: roots.density_scale: ") && scale.contains("negative"),
        "{scale}"
    );
    let density = message("noise:offset=-2", "noise:frequency=3");
    assert!(
        density.starts_with("test.toml:5:11: roots.density: "),
        "{density}"
    );
}

#[test]
fn errors_say_each_cause_once_and_keep_it_typed() {
    let text = "[mesh]\npath = \"spot\"\n[roots]\ncount = 10\ndensity = \"missing.png:r\"\n[guides]\ngenerate = { count = 5, length = 0.1 }\n";
    let err = groom(text).generator(None).unwrap_err();
    let message = err.to_string();
    assert!(
        message.starts_with("test.toml:5:11: roots.density: "),
        "{message}"
    );
    // The message says the map's file once and the system's reason, and
    // no cause is handed on to be said again.
    assert_eq!(message.matches("missing.png").count(), 1, "{message}");
    assert!(std::error::Error::source(&err).is_none());
    // Programs still reach the cause, typed.
    let GroomErrorKind::Map(map) = &err.kind else {
        panic!("{:?}", err.kind)
    };
    let MapErrorKind::Io(io) = &map.kind else {
        panic!("{:?}", map.kind)
    };
    assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
}

#[test]
fn a_part_grown_alone_equals_that_part_of_the_full_run() {
    let g = groom(EVERY_OPERATOR);
    let full = g.generator(None).unwrap();
    let parts: Vec<Curves> = (0..3).map(|p| full.part(p).unwrap()).collect();
    // A fresh generator (another process, another machine) asked for the
    // last part only.
    let alone = g.generator(None).unwrap().part(2).unwrap();
    assert_eq!(alone, parts[2]);
    // Hair ids are unique over the whole groom and strands multiply them.
    let ids: HashSet<u64> = parts
        .iter()
        .flat_map(|c| c.ids().unwrap().to_vec())
        .collect();
    let total: usize = parts.iter().map(Curves::curve_count).sum();
    assert_eq!(ids.len(), total);
    assert!(total > 3 * 6000 / 2 && total <= 3 * 6000, "{total}");
    // Each hair carries its root UV (spot has UVs), for USD's `st`.
    let c = &parts[1];
    let uvs = c.root_uvs().expect("root UVs on a mesh with UVs");
    for (uv, root) in uvs.iter().zip(c.roots().unwrap()).step_by(97) {
        assert_eq!(Some(*uv), root.uv(g.mesh()));
    }
    // A different seed gives a different groom.
    let other = g.generator(Some(12)).unwrap().part(2).unwrap();
    assert_ne!(other.points(), parts[2].points());
}

#[test]
fn strands_of_strands_masked_here_and_there_keep_every_hair_id_distinct() {
    // Where the mask is 0 a hair stays whole; its id must not be one a
    // split hair elsewhere takes (ids match hairs across frames and
    // files).
    let text = "[mesh]\npath = \"spot\"\n[roots]\ncount = 4000\nseed = 3\n\
        [guides]\ngenerate = { count = 40, length = 0.05 }\n\
        [[ops]]\nstrands = { count = 3, tip_spread = 0.004, mask = \"noise:frequency=3,offset=0.0,scale=1.0\" }\n\
        [[ops]]\nstrands = { count = 2, tip_spread = 0.002, mask = \"noise:frequency=3,seed=2,offset=0.0,scale=1.0\" }\n";
    let g = Groom::from_text("fur/strands.toml", text).unwrap();
    let curves = g.generator(None).unwrap().part(0).unwrap();
    let ids: HashSet<u64> = curves.ids().unwrap().iter().copied().collect();
    assert_eq!(ids.len(), curves.curve_count(), "every hair id once");
    // Both masks are 0 somewhere and 1 somewhere: roots grew 1, 2, 3 and
    // 6 hairs.
    let total = curves.curve_count();
    assert!(total > 4000 * 2 && total < 4000 * 5, "{total} hairs");
}

#[test]
fn roots_follow_the_density_across_parts() {
    // Constant density on spot: each triangle's share of roots is its
    // share of the area. Chi-square over 64 groups of triangles.
    let g = groom(
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 200000\nparts = 5\n[guides]\npoints = 2\ngenerate = { count = 50, length = 0.02 }\n[finish]\npoints = 2\nnormals = false\n",
    );
    let generator = g.generator(None).unwrap();
    let mesh = g.mesh();
    let groups = 64;
    let group_of = |t: u32| t as usize * groups / mesh.triangle_count();
    let mut observed = vec![0f64; groups];
    let mut hairs = 0;
    for p in 0..generator.parts().len() {
        let part = &generator.parts()[p];
        let curves = generator.part(p).unwrap();
        assert_eq!(curves.curve_count() as u64, part.hair_count);
        for root in curves.roots().unwrap() {
            assert!(
                part.triangles.binary_search(&root.tri).is_ok(),
                "root outside its part"
            );
            observed[group_of(root.tri)] += 1.0;
            hairs += 1;
        }
    }
    assert_eq!(hairs, 200_000);
    let area = mesh.surface_area();
    let mut expected = vec![0f64; groups];
    for (t, a) in mesh.triangle_areas().iter().enumerate() {
        expected[group_of(t as u32)] += f64::from(*a) / area * hairs as f64;
    }
    let chi2: f64 = observed
        .iter()
        .zip(&expected)
        .map(|(o, e)| (o - e).powi(2) / e)
        .sum();
    // 63 degrees of freedom: P(χ² > 110) ≈ 2·10⁻⁴.
    assert!(chi2 < 110.0, "χ² = {chi2}");
}

#[test]
fn clumped_tips_meet_at_their_centres() {
    let g = groom(
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 5000\n[guides]\ngenerate = { count = 80, length = 0.05 }\n[[ops]]\nclump = { count = 25, rate = 1.0 }\n",
    );
    let curves = g.generator(None).unwrap().part(0).unwrap();
    let tips: HashSet<[u32; 3]> = (0..curves.curve_count())
        .map(|i| {
            let tip = curves.points()[curves.range(i).end - 1];
            (tip * 1e4).round().to_array().map(|x| x as i32 as u32)
        })
        .collect();
    assert!(tips.len() <= 25, "{} distinct tips", tips.len());
    // Roots stay on the skin.
    for (i, root) in curves.roots().unwrap().iter().enumerate() {
        let p = curves.points()[curves.range(i).start];
        assert!((p - root.position(g.mesh())).length() < 1e-5);
    }
}

#[test]
fn normals_are_unit_and_perpendicular_to_the_hair() {
    let g = groom(EVERY_OPERATOR);
    let curves = g.generator(None).unwrap().part(1).unwrap();
    let normals = curves.normals().unwrap();
    for i in 0..curves.curve_count() {
        let r = curves.range(i);
        let pts = &curves.points()[r.clone()];
        for j in 1..pts.len() - 1 {
            let tangent = (pts[j + 1] - pts[j - 1]).normalize_or_zero();
            let n = normals[r.start + j];
            assert!((n.length() - 1.0).abs() < 1e-4);
            if tangent != Vec3::ZERO {
                assert!(n.dot(tangent).abs() < 1e-3, "hair {i} point {j}");
            }
        }
    }
}

#[test]
fn operator_settings_out_of_range_built_in_code_are_refused_as_a_file_refuses_them() {
    let c = Map::Constant;
    let cases = [
        (
            "flyaways = { spread = 0.01, fraction = 1.5 }",
            GroomOp::Flyaways(FlyawaysParams {
                fraction: c(1.5),
                ..FlyawaysParams::new(c(0.01))
            }),
        ),
        ("clump = { count = 0 }", GroomOp::Clump(ClumpParams::new(0))),
        (
            "noise = { amplitude = 0.01, frequency = -2 }",
            GroomOp::Noise(NoiseParams {
                frequency: c(-2.0),
                ..NoiseParams::new(c(0.01))
            }),
        ),
        (
            "length = { scale = -1 }",
            GroomOp::Length(LengthParams::new(c(-1.0))),
        ),
    ];
    let mesh = Arc::new(pelage::assets::spot());
    let guides = Arc::new(Guides::grow(&mesh, &GuideGrowth::default()).unwrap());
    for (table, op) in cases {
        let text = format!("[mesh]\npath = \"spot\"\n[roots]\ncount = 100\n[[ops]]\n{table}\n");
        let from_file = Groom::from_text("fur/t.toml", text)
            .and_then(|g| g.generator(None).map(drop))
            .unwrap_err();
        let spec = GroomSpec::new(mesh.clone(), guides.clone(), RootsSpec::new(100)).with_op(op);
        let from_code = spec.generator().map(drop).unwrap_err();
        assert_eq!(from_code.at.key, from_file.at.key, "{table}");
        match (&from_code.kind, &from_file.kind) {
            (GroomErrorKind::OutOfRange(code), GroomErrorKind::OutOfRange(file)) => {
                assert_eq!(code, file, "{table}")
            }
            kinds => panic!("{table}: {kinds:?}"),
        }
    }
}

fn error(text: &str) -> String {
    typed_error(text).to_string()
}

fn typed_error(text: &str) -> GroomError {
    Groom::from_text("fur/test.toml", text)
        .and_then(|g| g.generator(None).map(|_| ()))
        .unwrap_err()
}

#[test]
fn errors_name_the_file_line_and_key() {
    let missing_mesh = error(
        "[mesh]\npath = \"nowhere.obj\"\n[roots]\ncount = 10\n[guides]\ngenerate = { count = 5, length = 0.1 }\n",
    );
    assert!(
        missing_mesh.starts_with("fur/test.toml:2:8: mesh.path: "),
        "{missing_mesh}"
    );
    assert!(missing_mesh.contains("nowhere.obj"), "{missing_mesh}");

    let method = error(
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 10\n[guides]\ngenerate = { count = 5, length = 0.1 }\n[interpolation]\nmethod = \"shepherd\"\n",
    );
    assert!(
        method.starts_with("fur/test.toml:8:10: interpolation.method: unknown variant `shepherd`"),
        "{method}"
    );
    assert!(
        method.contains("`shepard`") && method.contains("`style-mesh`"),
        "{method}"
    );

    let guides =
        typed_error("[mesh]\npath = \"spot\"\n[roots]\ncount = 10\n[guides]\npoints = 4\n");
    assert!(
        matches!(guides.kind, GroomErrorKind::Conflict(_)),
        "{guides}"
    );
    assert!(
        guides.to_string().contains("guides: give exactly one of"),
        "{guides}"
    );

    let zero = error(
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 10\n[guides]\ngenerate = { count = 5, length = 0.1 }\n[[ops]]\nstrands = { count = 0, tip_spread = 0.1 }\n",
    );
    assert!(
        zero.starts_with("fur/test.toml:8:21: ops[0].strands.count:"),
        "{zero}"
    );
}

/// A groom whose second operator takes hairs past the float range (each
/// noise alone stays finite; the second doubles it), grown `parts` at a
/// time, with `last` as a third operator.
fn overflowing(last: &str) -> String {
    format!(
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 300\nparts = 2\n[guides]\ngenerate = {{ count = 20, length = 0.05 }}\n\
         [[ops]]\nnoise = {{ amplitude = 3e38, frequency = 30 }}\n\
         [[ops]]\nnoise = {{ amplitude = 3e38, frequency = 30 }}\n\
         [[ops]]\n{last}\n"
    )
}

#[test]
fn a_hair_grown_past_the_float_range_is_an_error_at_the_operator_not_a_panic() {
    // One hair a root (grown in place) and strands (grown hair by hair).
    for last in [
        "width = { root = 0.001, tip = 0.0001 }",
        "strands = { count = 2, tip_spread = 0.01 }",
    ] {
        let g = Groom::from_text("fur/huge.toml", overflowing(last)).unwrap();
        let generator = g.generator(None).unwrap();
        let message = generator.part(0).unwrap_err().to_string();
        // Line 10 holds the second `[[ops]]`.
        assert!(
            message.starts_with("fur/huge.toml:10:1: ops[1].noise: hair "),
            "{message}"
        );
        assert!(message.contains("no longer finite"), "{message}");
        // The same for the whole file written: an error, and no file.
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("huge.usda");
        let export = pelage::io::CurvesExport::default();
        let written = generator.write(&out, 0..2, &export, |_, _| {});
        let message = written.unwrap_err().to_string();
        assert!(message.starts_with("fur/huge.toml:10:1: "), "{message}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}

/// A program hands the mesh and the guide curves over as values
/// (the Python binding and the Blender add-on do).
#[test]
fn a_mesh_and_guides_given_as_values_replace_the_files() {
    use pelage::groom::GroomInputs;
    use pelage::settings::SettingsSource;
    let text = "[mesh]\npath = \"no-such-mesh.obj\"\n\n[roots]\ncount = 400\n\n[guides]\ngenerate = { count = 12, length = 0.05 }\n";
    let source = |text: &str| SettingsSource {
        path: "values.toml".into(),
        text: text.to_string(),
    };
    // Without a value the file's mesh is read, and is missing.
    let missing = Groom::from_source_with_inputs(source(text), None, GroomInputs::default())
        .expect_err("the mesh file does not exist");
    assert!(
        missing.to_string().contains("no-such-mesh.obj"),
        "{missing}"
    );
    // A mesh value replaces [mesh]: roots land on it.
    let blub = Arc::new(
        pelage::Mesh::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/data/meshes/blub_triangulated.obj"
        ))
        .unwrap(),
    );
    let inputs = GroomInputs {
        mesh: Some(blub.clone()),
        ..GroomInputs::default()
    };
    let on_blub = Groom::from_source_with_inputs(source(text), None, inputs).unwrap();
    let curves = on_blub.generator(None).unwrap().part(0).unwrap();
    assert_eq!(on_blub.mesh().triangle_count(), blub.triangle_count());
    assert!(
        curves
            .roots()
            .unwrap()
            .iter()
            .all(|r| r.is_valid_for(&blub))
    );
    // Guide curves as a value, with [guides] points: bound to the mesh.
    let guides = on_blub.guides().curves().clone();
    let no_guides = "[roots]\ncount = 400\n\n[guides]\npoints = 8\n";
    let inputs = GroomInputs {
        mesh: Some(blub.clone()),
        guides: Some(guides.clone()),
        ..GroomInputs::default()
    };
    let bound = Groom::from_source_with_inputs(source(no_guides), None, inputs).unwrap();
    assert_eq!(bound.guides().len(), 12);
    // Binding projects roots onto the surface and resamples: the same
    // curves to float rounding.
    let bound_points = bound.guides().curves().points();
    assert_eq!(bound_points.len(), guides.points().len());
    let worst = bound_points
        .iter()
        .zip(guides.points())
        .map(|(a, b)| (*a - *b).abs().max_element())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "{worst}");
    // Curves and a [guides] source together, or no mesh at all: errors
    // naming the setting.
    let twice = GroomInputs {
        mesh: Some(blub),
        guides: Some(guides),
        ..GroomInputs::default()
    };
    let e = Groom::from_source_with_inputs(source(text), None, twice).unwrap_err();
    assert_eq!(e.at.key.as_deref(), Some("guides"), "{e}");
    assert!(matches!(e.kind, GroomErrorKind::Conflict(_)), "{e}");
    let e = Groom::from_source_with_inputs(source(no_guides), None, GroomInputs::default())
        .unwrap_err();
    assert_eq!(e.at.key.as_deref(), Some("mesh"), "{e}");
    assert!(matches!(e.kind, GroomErrorKind::Conflict(_)), "{e}");
}

/// The groom's hairs, all parts joined.
fn grown(text: &str) -> Curves {
    let generator = groom(text).generator(None).unwrap();
    let parts: Vec<Curves> = (0..generator.parts().len())
        .map(|p| generator.part(p).unwrap())
        .collect();
    pelage::curves::join(parts.iter()).unwrap()
}

#[test]
fn flyaways_move_only_their_fraction_and_nothing_under_a_zero_mask() {
    let base = "[mesh]\npath = \"spot\"\n[roots]\ncount = 4000\n[guides]\ngenerate = { count = 40, length = 0.05 }\n[finish]\npoints = 6\n[[ops]]\nclump = { count = 40 }\n";
    let plain = grown(base);
    let strays = grown(&format!(
        "{base}[[ops]]\nflyaways = {{ spread = 0.02, fraction = 0.25 }}\n"
    ));
    assert_eq!(plain.ids(), strays.ids(), "the same hairs");
    let moved = (0..plain.curve_count())
        .filter(|&i| plain.points()[plain.range(i)] != strays.points()[strays.range(i)])
        .count();
    // Binomial(4000, 0.25): mean 1000, σ ≈ 27; ±5σ.
    assert!((865..=1135).contains(&moved), "{moved} hairs moved");
    let masked = grown(&format!(
        "{base}[[ops]]\nflyaways = {{ spread = 0.02, fraction = 0.25, mask = 0 }}\n"
    ));
    assert_eq!(
        masked.points(),
        plain.points(),
        "a zero mask keeps every hair"
    );
}

#[test]
fn twist_turns_hairs_about_their_chord_keeping_roots_and_tips() {
    let base = "[mesh]\npath = \"spot\"\n[roots]\ncount = 500\n[guides]\ngenerate = { count = 40, length = 0.05, comb = [0, -0.6, -1], gravity = 0.3 }\n[finish]\npoints = 9\n";
    let plain = grown(base);
    let twisted = grown(&format!(
        "{base}[[ops]]\ntwist = {{ angle = 90, ramp = \"constant\" }}\n"
    ));
    for i in 0..plain.curve_count() {
        let (a, b) = (
            &plain.points()[plain.range(i)],
            &twisted.points()[twisted.range(i)],
        );
        let (root, tip) = (a[0], a[a.len() - 1]);
        assert!((b[0] - root).length() < 1e-6 && (b[b.len() - 1] - tip).length() < 1e-5);
        let axis = (tip - root).normalize();
        for (p, q) in a.iter().zip(b) {
            // A quarter turn about the chord: the same height along it and
            // distance from it, and the offset from it turned by 90°.
            let (u, v) = (*p - root, *q - root);
            let (pu, pv) = (u - axis * u.dot(axis), v - axis * v.dot(axis));
            assert!((u.dot(axis) - v.dot(axis)).abs() < 1e-5);
            assert!((pu.length() - pv.length()).abs() < 1e-5);
            if pu.length() > 1e-4 {
                let cos = pu.dot(pv) / (pu.length() * pv.length());
                assert!(cos.abs() < 1e-2, "hair {i}: cos {cos}");
            }
        }
    }
}

/// A groom with a `[look]` over `parts` parts.
fn looked(parts: u32, look: &str) -> String {
    format!(
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 3000\nseed = 5\nparts = {parts}\n\
         [guides]\ngenerate = {{ count = 40, length = 0.05 }}\n[finish]\npoints = 4\n[look]\n{look}"
    )
}

#[test]
fn look_maps_are_read_at_each_root_and_jitter_stays_in_its_band() {
    let melanin_map = "noise:frequency=3,seed=2,offset=0.5,scale=0.4";
    let exact = grown(&looked(
        2,
        &format!("melanin = \"{melanin_map}\"\nroughness = 0.45\ntint = [1.0, 0.5, 0.25]\n"),
    ));
    let spot = pelage::assets::spot();
    let map = Map::parse(melanin_map).unwrap();
    let shading = exact.shading().expect("a [look] groom carries shading");
    let roots = exact.roots().unwrap();
    assert_eq!(shading.len(), exact.curve_count());
    for (i, root) in roots.iter().enumerate() {
        let want = map
            .at(&pelage::map::MapSite::on(&spot, *root))
            .clamp(0.0, 1.0);
        assert_eq!(shading.melanin[i], want, "hair {i}");
        assert_eq!(shading.roughness[i], 0.45);
        assert_eq!(shading.melanin_redness[i], 1.0, "the Cycles default");
        assert_eq!(shading.tint[i], Vec3::new(1.0, 0.5, 0.25));
    }
    let spread = shading
        .melanin
        .iter()
        .fold((1.0f32, 0.0f32), |(lo, hi), &m| (lo.min(m), hi.max(m)));
    assert!(
        spread.1 - spread.0 > 0.2,
        "the map varies over Spot: {spread:?}"
    );

    // Jitter moves each value within ±jitter of the map's, each hair its
    // own draw; the random number is uniform on [0, 1).
    let jittered = grown(&looked(2, "roughness = 0.5\njitter = 0.2\n"));
    let s = jittered.shading().unwrap();
    assert!(s.roughness.iter().all(|&r| (0.4..=0.6).contains(&r)));
    let distinct: HashSet<u32> = s.roughness.iter().map(|r| r.to_bits()).collect();
    assert!(
        distinct.len() > s.len() * 9 / 10,
        "{} distinct of {}",
        distinct.len(),
        s.len()
    );
    assert!(s.roughness.iter().any(|&r| r < 0.45) && s.roughness.iter().any(|&r| r > 0.55));
    assert!(s.random.iter().all(|&r| (0.0..1.0).contains(&r)));
    let mean = s.random.iter().sum::<f32>() / s.len() as f32;
    assert!((mean - 0.5).abs() < 0.03, "mean of hair_random {mean}");

    // A hair's values follow its id, not the part it was grown in.
    let one_part = grown(&looked(1, "roughness = 0.5\njitter = 0.2\n"));
    let by_id = |c: &Curves| -> std::collections::HashMap<u64, (u32, u32, u32)> {
        let s = c.shading().unwrap();
        let ids = c.ids().unwrap();
        (0..c.curve_count())
            .map(|i| {
                (
                    ids[i],
                    (
                        s.melanin[i].to_bits(),
                        s.roughness[i].to_bits(),
                        s.random[i].to_bits(),
                    ),
                )
            })
            .collect()
    };
    assert_eq!(by_id(&one_part), by_id(&jittered));

    // Without [look], no values (and no material) are written.
    let plain = grown(&looked(1, "").replace("[look]\n", ""));
    assert!(plain.shading().is_none());
}

#[test]
fn look_values_out_of_range_are_errors_at_their_line() {
    let melanin = error(&looked(1, "melanin = 1.5\n"));
    assert!(
        melanin.starts_with("fur/test.toml:12:11: look.melanin:"),
        "{melanin}"
    );
    let unknown = error(&looked(1, "colour = 0.5\n"));
    assert!(
        unknown.contains("look") && unknown.contains("colour"),
        "{unknown}"
    );
}

/// How far the deepest point of `curves` (roots left out) is inside the
/// skin of `mesh`: the exact closest point, signed by the interpolated
/// vertex normal.
fn deepest_inside(mesh: &pelage::Mesh, curves: &Curves) -> f32 {
    let bvh = pelage::mesh::TriangleBvh::new(mesh.positions(), mesh.triangles());
    (0..curves.curve_count())
        .flat_map(|c| curves.range(c).skip(1))
        .map(|i| {
            let p = curves.points()[i];
            let hit = bvh.closest(p).unwrap();
            let t = mesh.triangles()[hit.triangle as usize];
            let n: Vec3 = (0..3)
                .map(|k| hit.weights[k] * mesh.normals()[t[k] as usize])
                .sum();
            if (p - hit.point).dot(n) < 0.0 {
                hit.distance_squared.sqrt()
            } else {
                0.0
            }
        })
        .fold(0.0, f32::max)
}

#[test]
fn outside_skin_pushes_noisy_curly_hair_out_of_spot_keeping_lengths() {
    let text = |outside: bool| {
        format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 4000\n\
             [guides]\ngenerate = {{ count = 100, length = 0.06, comb = [0, -1, 0], gravity = 0.6 }}\n\
             [[ops]]\ncurl = {{ radius = 0.02, turns = 2 }}\n\
             [[ops]]\nnoise = {{ amplitude = 0.03, frequency = 20 }}\n\
             [finish]\npoints = 12\noutside_skin = {outside}\n"
        )
    };
    let grown = |outside: bool| {
        let groom = groom(&text(outside));
        let generator = groom.generator(None).unwrap();
        let part = generator.part(0).unwrap();
        (groom.mesh().clone(), part)
    };
    let (spot, free) = grown(false);
    let (_, kept) = grown(true);
    let size = {
        let (lo, hi) = spot.bounds();
        (hi - lo).max_element()
    };
    let tolerance = 1e-4 * size;
    let free_depth = deepest_inside(&spot, &free);
    assert!(
        free_depth > 10.0 * tolerance,
        "strong noise and curl should put points inside Spot (deepest {free_depth})"
    );
    let depth = deepest_inside(&spot, &kept);
    assert!(depth <= tolerance, "a point is {depth} inside the skin");
    // The same hairs, each segment as long as before (within float
    // rounding) but where a crease leaves no room at its length, and
    // hairs that were clear of the skin untouched.
    assert_eq!(free.ids(), kept.ids());
    let (mut untouched, mut segments, mut shortened) = (0, 0, 0);
    for c in 0..free.curve_count() {
        let (a, b) = (&free.points()[free.range(c)], &kept.points()[kept.range(c)]);
        for i in 1..a.len() {
            let (la, lb) = ((a[i] - a[i - 1]).length(), (b[i] - b[i - 1]).length());
            assert!(
                lb <= la * (1.0 + 1e-3) + 1e-6,
                "hair {c} segment {i} grew: {la} → {lb}"
            );
            segments += 1;
            if (la - lb).abs() > 1e-3 * la + 1e-6 {
                shortened += 1;
            }
        }
        untouched += usize::from(a == b);
    }
    assert!(
        shortened * 1000 <= segments,
        "{shortened} of {segments} segments shortened"
    );
    assert!(
        untouched > 0 && untouched < free.curve_count(),
        "{untouched} untouched"
    );
}

#[test]
fn a_z_up_usd_guide_file_is_turned_to_the_meshs_y_up() {
    // Blender's USD export of guides grown on spot: Z up, so a point
    // (x, y, z) of pelage's Y-up world is written (x, −z, y).
    let dir = tempfile::tempdir().unwrap();
    let grown = "[mesh]\npath = \"spot\"\n[roots]\ncount = 100\n\
                 [guides]\ngenerate = { count = 30, length = 0.05 }\n";
    let groom = pelage::groom::Groom::from_text(dir.path().join("grown.toml"), grown).unwrap();
    let guides = groom.guides().curves().clone();
    let z_up = pelage::groom::AxisTurn::YUpToZUp.curves(guides.clone());
    let write = |name: &str, up_axis| {
        let export = pelage::io::CurvesExport {
            usd: pelage::io::UsdOptions {
                up_axis,
                ..Default::default()
            },
            mesh: None,
            guides: None,
        };
        pelage::io::write_curves(&dir.path().join(name), [("guides".into(), &z_up)], &export)
            .unwrap();
    };
    write("blender.usda", pelage::io::UpAxis::Z);
    let from_file = |name: &str| {
        let text =
            format!("[mesh]\npath = \"spot\"\n[roots]\ncount = 100\n[guides]\nfile = \"{name}\"\n");
        pelage::groom::Groom::from_text(dir.path().join("from_file.toml"), text)
    };
    let bound = from_file("blender.usda").unwrap();
    assert_eq!(bound.guides().len(), 30, "every guide bound");
    let worst = bound
        .guides()
        .curves()
        .points()
        .iter()
        .zip(guides.points())
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "{worst}");
    // The same points in a file that says nothing of Z up stay as they
    // are, off the mesh: the turn is what binds them.
    write("unturned.usda", pelage::io::UpAxis::Y);
    let e = from_file("unturned.usda").unwrap_err();
    assert!(matches!(e.kind, GroomErrorKind::Mismatch(_)), "{e}");
    assert!(
        e.to_string().contains("no guide is within the tolerance"),
        "{e}"
    );
}

#[test]
fn a_tiny_fraction_widens_its_one_hair_by_the_share_actually_kept() {
    // A fraction of a hair still grows one; its width is scaled by the
    // share kept (1 of 1,000), not by 1/√F, which for 1e-300 was infinite.
    let full = groom(
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 1000\n[guides]\ngenerate = { count = 5, length = 0.1 }\n[output]\nfraction = 1\n",
    );
    let whole = full.spec().unwrap().generator().unwrap();
    let base = whole.part(0).unwrap().widths()[0];
    for fraction in ["1e-9", "1e-300"] {
        let text = format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 1000\n[guides]\ngenerate = {{ count = 5, length = 0.1 }}\n[output]\nfraction = {fraction}\n"
        );
        let generator = groom(&text).spec().unwrap().generator().unwrap();
        let kept: Vec<pelage::Curves> = (0..generator.parts().len())
            .map(|p| generator.part(p).unwrap())
            .collect();
        let hairs: usize = kept.iter().map(|c| c.curve_count()).sum();
        assert_eq!(hairs, 1, "{fraction}");
        let widths: Vec<f32> = kept.iter().flat_map(|c| c.widths().to_vec()).collect();
        assert!(
            widths.iter().all(|w| w.is_finite()),
            "{fraction}: {widths:?}"
        );
        let expected = base * 1000f32.sqrt();
        assert!(
            (widths[0] - expected).abs() < 1e-4 * expected,
            "{fraction}: {} where {expected}",
            widths[0]
        );
    }
}

#[test]
fn paint_layers_of_vertices_alone_are_read_and_another_meshs_are_refused_by_their_header() {
    let dir = tempfile::tempdir().unwrap();
    let spot = pelage::assets::spot();
    let n = spot.vertex_count();
    // Vertices only, no faces: the layers are all a layers file needs.
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nproperty float belly\nend_header\n"
    );
    for p in spot.positions() {
        ply.push_str(&format!(
            "{} {} {} {}\n",
            p.x,
            p.y,
            p.z,
            if p.y < 0.0 { 1 } else { 0 }
        ));
    }
    std::fs::write(dir.path().join("layers.ply"), ply).unwrap();
    let text = "[mesh]\npath = \"spot\"\nlayers = \"layers.ply\"\n[roots]\ncount = 500\ndensity = \"vertex:belly\"\n[guides]\ngenerate = { count = 5, length = 0.05 }\n";
    std::fs::write(dir.path().join("fur.toml"), text).unwrap();
    let groom = Groom::load(&dir.path().join("fur.toml")).unwrap();
    assert!(groom.mesh().vertex_attribute("belly").is_some());
    // A header declaring another mesh's vertices is refused before a
    // vertex is read (the body here is not even there).
    std::fs::write(
        dir.path().join("layers.ply"),
        "ply\nformat ascii 1.0\nelement vertex 30000000\nproperty float x\nproperty float y\nproperty float z\nproperty float belly\nend_header\n",
    )
    .unwrap();
    let e = Groom::load(&dir.path().join("fur.toml"))
        .map(drop)
        .unwrap_err();
    assert!(matches!(e.kind, GroomErrorKind::Mesh(_)), "{e}");
    assert!(
        e.to_string()
            .contains("30000000 vertices where the mesh has"),
        "{e}"
    );
}

#[test]
fn guides_of_one_point_each_are_said_to_be_too_short_not_too_far() {
    let spot = pelage::assets::spot();
    let roots: Vec<glam::Vec3> = spot.positions().iter().step_by(300).copied().collect();
    let n = roots.len();
    let curves = pelage::Curves::new(roots, vec![0.01; n], (0..=n as u32).collect()).unwrap();
    let source = pelage::settings::SettingsSource {
        path: "dots.toml".into(),
        text: "[roots]\ncount = 100\n[guides]\npoints = 4\n".into(),
    };
    let inputs = pelage::groom::GroomInputs {
        mesh: Some(std::sync::Arc::new(spot)),
        guides: Some(curves),
        ..Default::default()
    };
    let e = Groom::from_source_with_inputs(source, None, inputs)
        .map(drop)
        .unwrap_err();
    assert!(matches!(e.kind, GroomErrorKind::Mismatch(_)), "{e}");
    assert!(e.to_string().contains("fewer than two points"), "{e}");
    assert!(!e.to_string().contains("tolerance"), "{e}");
}

#[test]
fn a_gltf_skins_base_colour_texture_colours_the_fur_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let fox = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/fox/Fox.gltf");
    std::fs::write(dir.path().join("fox.png"), pelage::assets::FOX_TEXTURE_PNG).unwrap();
    let text = |mesh: &str, finish: &str| {
        format!(
            "[mesh]\npath = {fox:?}\n{mesh}[roots]\ncount = 500\n\
             [guides]\ngenerate = {{ count = 30, length = 5.0 }}\n[finish]\npoints = 4\n{finish}"
        )
    };
    let grow = |text: String| {
        let groom = pelage::groom::Groom::from_text(dir.path().join("fox.toml"), text).unwrap();
        groom.generator(None).unwrap().part(0).unwrap()
    };
    // No colour given: the glTF material's baseColorTexture at each root,
    // as the same texture named by hand colours it, made linear (the
    // texture is sRGB-encoded).
    let by_default = grow(text("", ""));
    let named = grow(text(
        "",
        "color = { root = [\"fox.png:r\", \"fox.png:g\", \"fox.png:b\"], tip = [\"fox.png:r\", \"fox.png:g\", \"fox.png:b\"] }\n",
    ));
    let (a, b) = (by_default.colors().unwrap(), named.colors().unwrap());
    assert_eq!(a.len(), b.len());
    // (Filtered between texels after, not before, the decoding: close,
    // not equal, where neighbouring texels differ.)
    let linear = |c: Vec3| Vec3::from(c.to_array().map(pelage::groom::srgb_to_linear));
    let apart: Vec<f32> = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x - linear(*y)).abs().max_element())
        .collect();
    let close = apart.iter().filter(|d| **d < 0.02).count() as f64 / apart.len() as f64;
    assert!(
        close > 0.97,
        "{:.1} % of the points within 0.02",
        close * 100.0
    );
    // The fox is orange and white: not one grey.
    let spread =
        a.iter().fold(Vec3::ZERO, |m, c| m.max(*c)) - a.iter().fold(Vec3::ONE, |m, c| m.min(*c));
    assert!(spread.max_element() > 0.3, "{spread}");
    // Turned off, the hairs have no colour of their own.
    let plain = grow(text("base_color = false\n", ""));
    assert!(plain.colors().is_none());
}
