//! The `pelage` binary as a user runs it: output, errors, exit codes.

#[path = "../../pelage/tests/support/mod.rs"]
mod support;

use std::path::Path;
use std::process::{Command, Output};
use support::{blendercheck, repo, usdcheck};

fn pelage(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pelage"))
        .args(args)
        .output()
        .expect("the pelage binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn blub() -> String {
    repo("tests/data/meshes/blub_triangulated.obj")
        .display()
        .to_string()
}

/// The value column of `pelage info`'s row `label`.
fn row<'a>(table: &'a str, label: &str) -> &'a str {
    table
        .lines()
        .find(|l| l.starts_with(label) && l[label.len()..].starts_with("  "))
        .unwrap_or_else(|| panic!("no row {label:?} in\n{table}"))[label.len()..]
        .trim()
}

#[test]
fn info_on_blub_reports_its_counts() {
    let out = pelage(&["info", &blub()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = stdout(&out);
    assert_eq!(row(&table, "triangles"), "14,208");
    assert_eq!(row(&table, "vertices"), "7,106");
    assert!(row(&table, "UVs").starts_with("yes"));
    assert_eq!(row(&table, "boundary edges"), "0");
}

#[test]
fn info_on_subdivided_blub_has_four_times_the_triangles_and_the_same_area() {
    let json = |args: &[&str]| -> serde_json::Value {
        let out = pelage(args);
        assert!(out.status.success(), "{}", stderr(&out));
        serde_json::from_str(&stdout(&out)).expect("one JSON object")
    };
    let base = json(&["info", "--json", &blub()]);
    let fine = json(&["info", "--json", "--subdivide", "1", &blub()]);
    let field = |v: &serde_json::Value, key: &str| v[key].as_f64().unwrap();
    assert_eq!(field(&fine, "triangles"), 4.0 * field(&base, "triangles"));
    let (a0, a1) = (field(&base, "surface_area"), field(&fine, "surface_area"));
    assert!((a1 - a0).abs() / a0 < 1e-5, "{a0} vs {a1}");
    assert_eq!(base["uvs"], "per corner");
    assert_eq!(base["bounds_min"].as_array().map(Vec::len), Some(3));
    assert!(
        base["mesh"]
            .as_str()
            .unwrap()
            .ends_with("blub_triangulated.obj")
    );
}

#[test]
fn info_without_a_mesh_describes_the_embedded_spot() {
    let out = pelage(&["info"]);
    assert!(out.status.success());
    let table = stdout(&out);
    assert_eq!(row(&table, "mesh"), "embedded spot");
    assert_eq!(row(&table, "triangles"), "5,856");
}

#[test]
fn a_bad_file_is_an_error_with_its_name_and_line_and_exit_code_2() {
    let bad = repo("tests/data/bad/obj_index_zero.obj");
    let out = pelage(&["info", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.starts_with("error: cannot load the mesh: "), "{err}");
    assert!(
        err.contains("obj_index_zero.obj:5: vertex index 0 is out of range"),
        "{err}"
    );
    assert!(stdout(&out).is_empty());
}

#[test]
fn version_and_help_work() {
    let out = pelage(&["--version"]);
    assert!(out.status.success());
    assert_eq!(
        stdout(&out).trim(),
        format!("pelage {}", env!("CARGO_PKG_VERSION"))
    );
    let out = pelage(&["--help"]);
    assert!(out.status.success());
    for command in ["info", "demo"] {
        assert!(stdout(&out).contains(command));
    }
}

#[test]
fn demo_runs_on_the_embedded_asset_from_any_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_pelage"))
        .arg("demo")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("embedded spot"));
    assert!(
        text.contains("200,000 hairs, 2,400,000 points → pelage-demo/groom.usdc"),
        "{text}"
    );
    // The groom file it used is there for the user to edit and rerun.
    let groom = std::fs::read_to_string(dir.path().join("pelage-demo/demo.toml")).unwrap();
    assert!(groom.contains("[[ops]]\nclump"));
    assert!(dir.path().join("pelage-demo/spot.png").exists());
    let path = dir.path().join("pelage-demo/groom.usdc");
    let usd = std::fs::read(&path).unwrap();
    assert!(usd.starts_with(b"PXR-USDC"));
    // 2.4 M points, widths and colours as 4-byte floats: 48 MB at least.
    assert!(usd.len() > 48_000_000, "{} bytes", usd.len());
    drop(usd);
    // Pixar's library validates it; Blender imports every hair of it.
    if let Some((ok, report)) = usdcheck(&[&path]) {
        assert!(ok, "{report}");
        assert!(report.contains("200000 curves, 2400000 points"), "{report}");
    }
    if let Some((ok, report)) = blendercheck(&[&path]) {
        assert!(ok, "{report}");
        let curves: u64 = report
            .lines()
            .filter_map(|l| l.split_once(": ")?.1.split_once(" curves, "))
            .map(|(n, _)| n.parse::<u64>().unwrap())
            .sum();
        assert_eq!(curves, 200_000, "{report}");
        assert!(
            report.contains("mesh skin: 2930 vertices, 5856 faces"),
            "{report}"
        );
    }
    // The preview needs a GPU adapter; in CI (PELAGE_REQUIRE_GPU) it must be there.
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_some() {
        let png = image::open(dir.path().join("pelage-demo/preview.png")).expect("a preview PNG");
        assert_eq!((png.width(), png.height()), (1280, 720));
    }
}

#[test]
fn demo_fox_grows_fur_that_walks_with_the_fox() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_pelage"))
        .args(["demo", "fox"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("60,000 hairs, 480,000 points × 24 frames → pelage-fox/fox.usdc"),
        "{text}"
    );
    let folder = dir.path().join("pelage-fox");
    for name in ["fox.toml", "Fox.gltf", "fox.png", "LICENSE-fox.md"] {
        assert!(folder.join(name).exists(), "{name} missing");
    }
    let licence = std::fs::read_to_string(folder.join("LICENSE-fox.md")).unwrap();
    assert!(licence.contains("CC BY 4.0") && licence.contains("@tomkranis"));
    let usdc = folder.join("fox.usdc");
    let at = |t: f64| pelage::io::read_usd_curves_at(&usdc, Some(t)).unwrap();
    let (a, b) = (at(1.0), at(12.0));
    assert_eq!(a.curve_count(), 60_000);
    assert_eq!(a.ids(), b.ids());
    assert_ne!(a.points(), b.points(), "the fur moves");
    let skin = pelage::anim::AnimatedSkin::load(&usdc, &Default::default()).unwrap();
    assert_eq!(
        skin.sample_times().len(),
        24,
        "the walking skin is in the file"
    );
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_some() {
        let gif = folder.join("frames/fox.gif");
        assert!(gif.exists(), "{text}");
        let png = image::open(folder.join("frames/fox.0024.png")).unwrap();
        assert_eq!((png.width(), png.height()), (640, 400));
    }
}

#[test]
fn sample_gives_byte_identical_files_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let run = |threads: &str, name: &str| {
        let path = dir.path().join(name);
        let out = Command::new(env!("CARGO_BIN_EXE_pelage"))
            .args([
                "sample",
                "-n",
                "300000",
                "--seed",
                "9",
                "--density",
                "noise:frequency=5",
            ])
            .arg("-o")
            .arg(&path)
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(stdout(&out).starts_with("wrote 300,000 points on embedded spot"));
        std::fs::read(path).unwrap()
    };
    let one = run("1", "one.ply");
    let two = run("2", "two.ply");
    assert!(one == two, "the files differ between 1 and 2 threads");
    // Header + 300,000 × (xyz, normal, st, triangle).
    assert!(one.len() > 300_000 * 36);

    // The same points as USD Points prims, binary and text.
    let usdc = run("2", "roots.usdc");
    assert!(usdc.starts_with(b"PXR-USDC"));
    assert!(
        run("1", "roots.usdc") == usdc,
        "the usdc differs between 1 and 2 threads"
    );
    run("2", "roots.usda");
    let ply = pelage::io::read_points_ply(&dir.path().join("one.ply")).unwrap();
    let (usdc, usda) = (dir.path().join("roots.usdc"), dir.path().join("roots.usda"));
    if let Some((ok, report)) = usdcheck(&[Path::new("--same"), &usda, &usdc]) {
        assert!(ok, "{report}");
        let (ok, report) = usdcheck(&[&usdc]).unwrap();
        assert!(ok, "{report}");
        let spec = "/groom/points_0000.points@0[12345]";
        let (ok, values) = usdcheck(&[Path::new("--values"), &usdc, Path::new(spec)]).unwrap();
        assert!(ok, "{values}");
        let p = support::numbers_after(&values, &format!("{spec} = "));
        assert_eq!(
            [p[0] as f32, p[1] as f32, p[2] as f32],
            ply[12345].to_array()
        );
    }
}

#[test]
fn sample_with_zero_density_fails_naming_the_mesh_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("roots.ply");
    let out = Command::new(env!("CARGO_BIN_EXE_pelage"))
        .args(["sample", "-n", "10", "--density", "0", "-o"])
        .arg(&path)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).starts_with("error: embedded spot: the density is zero everywhere"),
        "{}",
        stderr(&out)
    );
    assert!(!path.exists());
}

#[test]
fn convert_goes_through_every_format_and_keeps_the_curves() {
    let dir = tempfile::tempdir().unwrap();
    let input = repo("crates/pelage/tests/data/good/blender_curves.usdc");
    let original = pelage::io::read_curves(&input).unwrap();
    let mut from = input.display().to_string();
    for ext in ["hair", "ply", "usda", "usdc", "abc", "usd"] {
        let to = dir.path().join(format!("c.{ext}")).display().to_string();
        let out = pelage(&["convert", &from, &to]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(
            stdout(&out).contains("2 curves, 5 points, 2–3 points a curve"),
            "{}",
            stdout(&out)
        );
        let back = pelage::io::read_curves(Path::new(&to)).unwrap();
        assert_eq!(
            (back.points(), back.widths(), back.offsets()),
            (original.points(), original.widths(), original.offsets()),
            "{ext}"
        );
        from = to;
    }
    for ext in ["rib", "pbrt"] {
        let to = dir.path().join(format!("c.{ext}")).display().to_string();
        assert!(pelage(&["convert", &from, &to]).status.success());
    }
    let usd = dir.path().join("m.usda").display().to_string();
    let out = pelage(&[
        "convert",
        &from,
        &usd,
        "--with-mesh",
        "spot",
        "--basis",
        "linear",
        "--up-axis",
        "z",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&usd).unwrap();
    assert!(
        text.contains("def Mesh \"skin\"")
            && text.contains("upAxis = \"Z\"")
            && text.contains("type = \"linear\"")
    );

    let out = pelage(&["convert", &from, "x.fbx"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).matches("unknown curves format").count(),
        1,
        "{}",
        stderr(&out)
    );
    let out = pelage(&["convert", "missing.hair", "x.usda"]);
    assert!(
        stderr(&out).contains("missing.hair: cannot read the file"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn render_draws_a_curves_file() {
    // Needs a GPU adapter; in CI (PELAGE_REQUIRE_GPU) it must be there.
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_none() {
        eprintln!("SKIPPED: set PELAGE_REQUIRE_GPU=1 to run render tests through the CLI");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("curves.png");
    let input = repo("crates/pelage/tests/data/good/blender_curves.usda");
    // As over ssh or in a container: no XDG_RUNTIME_DIR. Mesa's Vulkan
    // layer made libwayland print an alarming "error:" line then.
    let out = Command::new(env!("CARGO_BIN_EXE_pelage"))
        .args([
            "render",
            input.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--size",
            "160x120",
        ])
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("error"), "{}", stderr(&out));
    assert!(stdout(&out).contains("2 curves"), "{}", stdout(&out));
    let image = image::open(&png).unwrap().to_rgba8();
    // Background in the corner, hair somewhere.
    let background = *image.get_pixel(0, 0);
    assert!(image.pixels().any(|p| {
        p.0[..3]
            .iter()
            .zip(&background.0[..3])
            .any(|(a, b)| a.abs_diff(*b) > 60)
    }));
}

#[test]
fn guides_are_grown_and_bound_back_with_far_ones_reported() {
    let dir = tempfile::tempdir().unwrap();
    let grown = dir.path().join("g.usda").display().to_string();
    let out = pelage(&[
        "guides", "-n", "50", "--comb", "0,0,1", "--points", "5", "-o", &grown,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("grew 50 guides of 5 points on embedded spot"),
        "{}",
        stdout(&out)
    );
    // Move one guide's root off the surface: it is left out, by index.
    let mut text = std::fs::read_to_string(&grown).unwrap();
    let start = text.find("point3f[] points = [").unwrap() + "point3f[] points = [".len();
    let end = start + text[start..].find(')').unwrap() + 1;
    text.replace_range(start..end, "(50, 50, 50)");
    let moved = dir.path().join("moved.usda");
    std::fs::write(&moved, text).unwrap();
    let bound = dir.path().join("b.hair").display().to_string();
    let out = pelage(&["guides", "--from", moved.to_str().unwrap(), "-o", &bound]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("bound 49 of 50 guides"),
        "{}",
        stdout(&out)
    );
    assert!(
        stderr(&out).contains("warning:") && stderr(&out).contains("guide 0 left out: its root is"),
        "{}",
        stderr(&out)
    );
    assert_eq!(
        pelage::io::read_curves(Path::new(&bound))
            .unwrap()
            .curve_count(),
        49
    );
}

/// A small groom with every kind of operator path (strands and cut change
/// hair counts), in three parts.
const SMALL_GROOM: &str = r#"
[mesh]
path = "spot"
[roots]
count = 3000
parts = 3
density = "noise:frequency=3,offset=0.6,scale=0.4"
[guides]
generate = { count = 60, length = 0.05, comb = [0, -1, 0] }
[[ops]]
clump = { count = 100, rate = 0.5 }
[[ops]]
noise = { amplitude = 0.002, frequency = 20 }
[[ops]]
cut = { at = "noise:frequency=2,offset=0.9,scale=0.2" }
[[ops]]
strands = { count = 2, tip_spread = 0.003 }
[finish]
points = 8
color = { root = [0.2, 0.1, 0.1], tip = [0.9, 0.8, 0.7] }
"#;

/// The prims of a pelage USD file: everything inside the default prim.
fn usd_body(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let start = text
        .find("def Xform \"groom\"\n{\n")
        .expect("the default prim")
        + 19;
    let end = text.rfind('}').unwrap();
    // Prims are separated by blank lines; compare them without. Every
    // file has its own hair material (a part file too): left out.
    let mut in_material = false;
    text[start..end]
        .lines()
        .filter(|l| !l.is_empty())
        .filter(|l| {
            if l.starts_with("    def Material \"hair_material\"") {
                in_material = true;
            }
            let keep = !in_material;
            if in_material && *l == "    }" {
                in_material = false;
            }
            keep
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

#[test]
fn an_alembic_farm_joins_into_the_file_one_run_writes_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("fur.toml");
    // With the skin and the guides (run 1 writes them), regions, opacity
    // and a look: every kind of object and attribute the Alembic writer
    // knows.
    let text = format!(
        "{SMALL_GROOM}opacity = {{ root = 1.0, tip = 0.4 }}\n[output]\nwith_mesh = true\nguides = true\n\
         [look]\nmelanin = 0.3\njitter = 0.2\n[regions]\nmap = \"noise:frequency=1,offset=0.5,scale=1\"\n"
    );
    std::fs::write(&groom, text).unwrap();
    let g = groom.to_str().unwrap();
    let (one, farm) = (dir.path().join("one.abc"), dir.path().join("farm.abc"));
    let run = |args: &[&str]| {
        let out = pelage(args);
        assert!(out.status.success(), "{}", stderr(&out));
        stdout(&out)
    };
    run(&["groom", g, "--quiet", "-o", one.to_str().unwrap()]);
    for k in 1..=2 {
        let part = format!("{k}/2");
        run(&[
            "groom",
            g,
            "--quiet",
            "-o",
            farm.to_str().unwrap(),
            "--part",
            &part,
        ]);
    }
    let said = run(&["groom", g, "--assemble", "-o", farm.to_str().unwrap()]);
    assert!(said.contains("2 part files joined"), "{said}");
    assert!(
        std::fs::read(&one).unwrap() == std::fs::read(&farm).unwrap(),
        "the joined parts differ from the single run's file"
    );
    // The guides are one object flagged groom_guide, the hairs the parts,
    // each curve with its region as groom_group_id; a reader of the hairs
    // passes over the guides.
    let objects = pelage::io::read_abc_objects(&one).unwrap();
    let guides: Vec<_> = objects.iter().filter(|o| o.2).collect();
    assert_eq!(guides.len(), 1);
    assert_eq!(
        (guides[0].0.as_str(), guides[0].1.curve_count()),
        ("guides", 60)
    );
    let regions: std::collections::HashSet<u32> = objects
        .iter()
        .flat_map(|o| {
            o.1.regions()
                .expect("every object has its regions")
                .to_vec()
        })
        .collect();
    assert_eq!(regions.len(), 2, "{regions:?}");
    let hairs: usize = objects
        .iter()
        .filter(|o| !o.2)
        .map(|o| o.1.curve_count())
        .sum();
    assert_eq!(pelage::io::read_curves(&one).unwrap().curve_count(), hairs);
    // A USD layer cannot reference Alembic parts, and says what to do.
    let out = pelage(&[
        "groom",
        g,
        "--assemble",
        "-o",
        dir.path().join("farm.usda").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("assemble with `-o NAME.abc`"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn groom_parts_run_separately_concatenate_to_the_full_run_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("fur.toml");
    std::fs::write(&groom, SMALL_GROOM).unwrap();
    let full = dir.path().join("full.usda");
    let run = |extra: &[&str]| {
        let mut args = vec!["groom", groom.to_str().unwrap(), "--quiet"];
        args.extend_from_slice(extra);
        let out = pelage(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        stdout(&out)
    };
    let summary = run(&["-o", full.to_str().unwrap(), "--threads", "1"]);
    assert!(summary.contains("in 3 parts"), "{summary}");
    let two = dir.path().join("two.usda");
    run(&["-o", two.to_str().unwrap(), "--threads", "2"]);
    assert!(
        std::fs::read(&full).unwrap() == std::fs::read(&two).unwrap(),
        "1 and 2 threads wrote different bytes"
    );

    let farm = dir.path().join("farm.usda");
    for k in 1..=3 {
        run(&["-o", farm.to_str().unwrap(), "--part", &format!("{k}/3")]);
    }
    let joined: String = (1..=3)
        .map(|k| usd_body(&dir.path().join(format!("farm.part-{k}-of-3.usda"))))
        .collect();
    assert!(
        joined == usd_body(&full),
        "parts concatenated ≠ the full run"
    );

    // Two runs of three parts: the first run grows part 0, the second 1 and 2.
    let halves = dir.path().join("halves.usda");
    run(&["-o", halves.to_str().unwrap(), "--part", "1/2"]);
    run(&["-o", halves.to_str().unwrap(), "--part", "2/2"]);
    let joined: String = (1..=2)
        .map(|k| usd_body(&dir.path().join(format!("halves.part-{k}-of-2.usda"))))
        .collect();
    assert!(
        joined == usd_body(&full),
        "two runs concatenated ≠ the full run"
    );

    // The assembly references every run's file with its extent.
    let out = pelage(&[
        "groom",
        groom.to_str().unwrap(),
        "--assemble",
        "-o",
        farm.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let layer = std::fs::read_to_string(&farm).unwrap();
    for k in 1..=3 {
        assert!(
            layer.contains(&format!("@./farm.part-{k}-of-3.usda@")),
            "{layer}"
        );
    }
    assert_eq!(layer.matches("extentsHint").count(), 4);
    if let Some((ok, report)) = usdcheck(&[&farm, &full]) {
        assert!(ok, "{report}");
    }

    // Runs that write binary USD are tied together the same way; the
    // root layer is text, and says so when named otherwise.
    let binary = dir.path().join("binary.usdc");
    for k in 1..=3 {
        run(&["-o", binary.to_str().unwrap(), "--part", &format!("{k}/3")]);
    }
    let root = dir.path().join("binary.usda");
    let assemble = |to: &Path| {
        pelage(&[
            "groom",
            groom.to_str().unwrap(),
            "--assemble",
            "-o",
            to.to_str().unwrap(),
        ])
    };
    let out = assemble(&binary);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("the assembly layer is text USD: name it .usda"),
        "{}",
        stderr(&out)
    );
    let out = assemble(&root);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&root).unwrap();
    assert!(text.contains("@./binary.part-2-of-3.usdc@"), "{text}");
    assert_eq!(text.matches("extentsHint").count(), 4, "{text}");
    let whole = |t: &str| {
        t.split("extentsHint")
            .nth(1)
            .and_then(|r| r.split(']').next())
            .map(str::to_string)
    };
    assert_eq!(
        whole(&text),
        whole(&layer),
        "the same bounds from binary parts"
    );
    if let Some((ok, report)) = usdcheck(&[&root]) {
        assert!(ok, "{report}");
        assert!(report.contains("3 BasisCurves prims"), "{report}");
    }

    // Asking for more runs than parts says what to do.
    let out = pelage(&[
        "groom",
        groom.to_str().unwrap(),
        "--part",
        "2/5",
        "-o",
        farm.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("the groom has 3 parts"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn groom_file_errors_name_the_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("typo.toml");
    std::fs::write(
        &groom,
        SMALL_GROOM.replace(
            "clump = { count = 100, rate = 0.5 }",
            "clump = { count = 100, rtae = 0.5 }",
        ),
    )
    .unwrap();
    let out = pelage(&["groom", groom.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("typo.toml:11:"), "{err}");
    assert!(err.contains("ops[0].clump.rtae"), "{err}");
    assert!(err.contains("unknown field `rtae`"), "{err}");
}

#[test]
fn a_groom_that_overflows_is_an_error_at_its_operator_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("huge.toml");
    // Two noises of 3e38: the second takes the hairs past f32's range.
    std::fs::write(
        &groom,
        SMALL_GROOM
            .replace(
                "clump = { count = 100, rate = 0.5 }",
                "noise = { amplitude = 3e38, frequency = 30 }",
            )
            .replace(
                "noise = { amplitude = 0.002, frequency = 20 }",
                "noise = { amplitude = 3e38, frequency = 30 }",
            ),
    )
    .unwrap();
    let output = dir.path().join("huge.usda");
    let out = pelage(&[
        "groom",
        groom.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("huge.toml:12:1: ops[1].noise: hair "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "only the groom file"
    );
}

#[test]
fn groom_preview_draws_the_hairs() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("fur.toml");
    // Blue hair, thick enough to cover pixels: nothing else in the
    // picture is blue.
    let blue = SMALL_GROOM.replace(
        "color = { root = [0.2, 0.1, 0.1], tip = [0.9, 0.8, 0.7] }",
        "color = { root = [0.05, 0.1, 0.9], tip = [0.05, 0.1, 0.9] }\nwidth = { root = 0.01, tip = 0.005 }",
    );
    assert_ne!(blue, SMALL_GROOM);
    std::fs::write(&groom, blue).unwrap();
    let png = dir.path().join("fur.png");
    let out = pelage(&[
        "groom",
        groom.to_str().unwrap(),
        "--quiet",
        "--preview",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    // The preview needs a GPU adapter; in CI (PELAGE_REQUIRE_GPU) it must be there.
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_some() {
        assert!(stdout(&out).contains("preview of"), "{}", stdout(&out));
        let image = image::open(&png).expect("a preview PNG").to_rgb8();
        assert_eq!(image.dimensions(), (1280, 720));
        // Something is drawn over the background (the corner pixel), and
        // much of it in the hairs' blue.
        let background = *image.get_pixel(0, 0);
        let drawn = image.pixels().filter(|p| **p != background).count();
        assert!(drawn > 1280 * 720 / 20, "{drawn} pixels drawn");
        let blue = image
            .pixels()
            .filter(|p| i32::from(p.0[2]) > i32::from(p.0[0]) + 60)
            .count();
        assert!(blue > drawn / 4, "{blue} blue of {drawn} drawn pixels");
    }
}

#[test]
fn guides_follow_a_comb_map() {
    let dir = tempfile::tempdir().unwrap();
    // Red 1, green 0.5: comb along +U everywhere.
    let flow = dir.path().join("flow.png");
    image::RgbImage::from_pixel(4, 4, image::Rgb([255, 128, 0]))
        .save(&flow)
        .unwrap();
    let grow = |extra: &[&str], name: &str| {
        let out_path = dir.path().join(name);
        let mut args = vec![
            "guides",
            "-n",
            "40",
            "--points",
            "4",
            "-o",
            out_path.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = pelage(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        pelage::io::read_curves(&out_path).unwrap()
    };
    let straight = grow(&[], "straight.usda");
    let combed = grow(
        &["--comb-map", flow.to_str().unwrap(), "--comb-strength", "2"],
        "combed.usda",
    );
    // Same roots, bent tips.
    assert_eq!(straight.curve_count(), combed.curve_count());
    let moved = (0..straight.curve_count())
        .filter(|&i| {
            let (a, b) = (straight.range(i), combed.range(i));
            assert_eq!(straight.points()[a.start], combed.points()[b.start]);
            (straight.points()[a.end - 1] - combed.points()[b.end - 1]).length() > 1e-3
        })
        .count();
    assert!(moved > 30, "{moved} of 40 guides bent");
    // --comb and --comb-map together are refused.
    let out = pelage(&[
        "guides",
        "--comb",
        "0,0,1",
        "--comb-map",
        "x.png",
        "-o",
        "g.usda",
    ]);
    assert!(!out.status.success());
}

#[test]
fn grooms_with_more_parts_than_hairs_write_valid_usd() {
    // 4 hairs in 40 parts: most parts, and likely whole runs, grow nothing.
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("sparse.toml");
    std::fs::write(
        &groom,
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 4\nparts = 40\n[guides]\ngenerate = { count = 10, length = 0.05 }\n",
    )
    .unwrap();
    let out_path = dir.path().join("sparse.usda");
    let out = out_path.to_str().unwrap();
    let full = pelage(&["groom", groom.to_str().unwrap(), "-q", "-o", out]);
    assert!(full.status.success(), "{}", stderr(&full));
    assert!(stdout(&full).contains("4 hairs"), "{}", stdout(&full));
    for k in 1..=8 {
        let run = pelage(&[
            "groom",
            groom.to_str().unwrap(),
            "-q",
            "-o",
            out,
            "--part",
            &format!("{k}/8"),
        ]);
        assert!(run.status.success(), "{}", stderr(&run));
    }
    let assembled = dir.path().join("farm.usda");
    for k in 1..=8 {
        std::fs::rename(
            dir.path().join(format!("sparse.part-{k}-of-8.usda")),
            dir.path().join(format!("farm.part-{k}-of-8.usda")),
        )
        .unwrap();
    }
    let out = pelage(&[
        "groom",
        groom.to_str().unwrap(),
        "--assemble",
        "-o",
        assembled.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    if let Some((ok, report)) = usdcheck(&[&out_path, &assembled]) {
        assert!(ok, "{report}");
        assert!(report.contains("4 curves"), "{report}");
    }
}

#[test]
fn shells_reports_a_bad_scene_at_its_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("rain.toml");
    std::fs::write(&scene, "[fur]\nlayers = 16\n\n[clump]\nstrenght = 3\n").unwrap();
    let png = dir.path().join("rain.png");
    let out = pelage(&[
        "shells",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("rain.toml:5:1: clump.strenght: unknown field `strenght`"),
        "{err}"
    );
    assert!(!png.exists());
}

#[test]
fn shells_sequence_dries_and_writes_frames_and_a_gif() {
    // Needs a GPU adapter; in CI (PELAGE_REQUIRE_GPU) it must be there.
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_none() {
        eprintln!("SKIPPED: set PELAGE_REQUIRE_GPU=1 to run render tests through the CLI");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("rain.toml");
    // Wet at t = 0, drying fast: by frame 2 (t = 2 s, ρ ≈ e^−6) it is dry.
    std::fs::write(
        &scene,
        "[fur]\nlayers = 8\n[texture]\nresolution = 64\n[curl]\nradius = 0.5\n\
         [wetness]\nresolution = 64\ndrying_rate = 3.0\n\
         [[droplets]]\ncount = 300\nradius = [0.03, 0.05]\n[animation]\nfps = 1\n",
    )
    .unwrap();
    let frames = dir.path().join("rain");
    shells_sequence(&scene, &frames, &["--mask"]);
    assert!(frames.join("shells.gif").exists());
    let frame = |k: u32| {
        image::open(frames.join(format!("frame-{k:04}.png")))
            .unwrap()
            .to_rgba8()
    };
    let mask = |k: u32| {
        image::open(frames.join(format!("frame-{k:04}-mask.png")))
            .unwrap()
            .to_rgba8()
    };
    // Wet at first (blue in the mask), dry at the end (all black).
    assert!(mask(0).pixels().any(|p| p.0[2] > 80));
    assert!(mask(2).pixels().all(|p| p.0[..3] == [0, 0, 0]));
    // The fur changed as it dried (clumps opened, curls came back).
    let changed = frame(0)
        .pixels()
        .zip(frame(2).pixels())
        .filter(|(a, b)| (0..3).any(|c| a.0[c].abs_diff(b.0[c]) > 8))
        .count();
    assert!(changed > 160 * 120 / 50, "{changed} pixels changed");
}

#[test]
fn shells_with_dynamics_move_in_the_wind_and_still_fur_does_not() {
    // Needs a GPU adapter; in CI (PELAGE_REQUIRE_GPU) it must be there.
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_none() {
        eprintln!("SKIPPED: set PELAGE_REQUIRE_GPU=1 to run render tests through the CLI");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let base =
        "[fur]\nlayers = 8\nlength = 0.08\n[texture]\nresolution = 64\n[animation]\nfps = 4\n";
    let run = |name: &str, extra: &str| {
        let scene = dir.path().join(format!("{name}.toml"));
        std::fs::write(&scene, format!("{base}{extra}")).unwrap();
        let frames = dir.path().join(name);
        shells_sequence(&scene, &frames, &[]);
        let frame = |k: u32| {
            image::open(frames.join(format!("frame-{k:04}.png")))
                .unwrap()
                .to_rgba8()
        };
        frame(0)
            .pixels()
            .zip(frame(2).pixels())
            .filter(|(a, b)| (0..3).any(|c| a.0[c].abs_diff(b.0[c]) > 8))
            .count()
    };
    assert_eq!(run("still", ""), 0, "fur without dynamics does not move");
    let windy = "[dynamics]\ntopology = \"prisms\"\n[dynamics.wind]\nvelocity = [6, 0, 2]\nturbulence = 3\n";
    let moved = run("windy", windy);
    assert!(
        moved > 160 * 120 / 100,
        "{moved} pixels changed in the wind"
    );
}

#[test]
fn shells_play_the_fox_running_from_the_example_scene() {
    // Needs a GPU adapter; in CI (PELAGE_REQUIRE_GPU) it must be there.
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_none() {
        eprintln!("SKIPPED: set PELAGE_REQUIRE_GPU=1 to run render tests through the CLI");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/shells/fox.toml");
    let frames = dir.path().join("run");
    shells_sequence(&scene, &frames, &[]);
    let frame = |k: u32| {
        image::open(frames.join(format!("frame-{k:04}.png")))
            .unwrap()
            .to_rgba8()
    };
    // Frames are 1/24 s apart: the legs and the fur have moved.
    let changed = frame(0)
        .pixels()
        .zip(frame(2).pixels())
        .filter(|(a, b)| (0..3).any(|c| a.0[c].abs_diff(b.0[c]) > 24))
        .count();
    assert!(changed > 160 * 120 / 100, "{changed} pixels changed");
    assert!(frames.join("shells.gif").exists());
}

/// `pelage shells SCENE --frames 3 -o FRAMES --size 160x120 -q EXTRA…`,
/// which must succeed.
fn shells_sequence(scene: &Path, frames: &Path, extra: &[&str]) {
    let mut args = vec![
        "shells",
        scene.to_str().unwrap(),
        "--frames",
        "3",
        "-o",
        frames.to_str().unwrap(),
        "--size",
        "160x120",
        "-q",
    ];
    args.extend_from_slice(extra);
    let out = pelage(&args);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[cfg(not(feature = "viewer"))]
#[test]
fn view_without_the_viewer_feature_says_how_to_get_it() {
    let out = pelage(&["view"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--features viewer"), "{stderr}");
}

/// A small groom on the walking Khronos Fox (tests/data/fox), `extra`
/// appended to its `[animation]`.
fn fox_groom(dir: &Path, extra: &str) -> std::path::PathBuf {
    let fox = repo("crates/pelage/assets/fox/Fox.gltf");
    let text = format!(
        r#"[mesh]
path = "{}"
[roots]
count = 2000
parts = 4
[guides]
generate = {{ count = 100, length = 5, comb = [0, 0, -0.6], gravity = 0.3 }}
[[ops]]
noise = {{ amplitude = 0.5, frequency = 0.2 }}
[finish]
points = 6
width = {{ root = 0.3, tip = 0.05 }}
[output]
with_mesh = true
[animation]
frames = "1-6"
clip = "Walk"
{extra}
"#,
        fox.display()
    );
    let path = dir.join("fox.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn an_animated_alembic_groom_holds_its_skin_which_blender_imports_as_from_usd() {
    let dir = tempfile::tempdir().unwrap();
    let groom = fox_groom(dir.path(), "");
    let (abc, usdc) = (dir.path().join("fox.abc"), dir.path().join("fox.usdc"));
    for out_path in [&abc, &usdc] {
        let out = pelage(&[
            "groom",
            groom.to_str().unwrap(),
            "-o",
            out_path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    // The curves are the same in both files (the skin object is skipped).
    let (from_abc, from_usd) = (
        pelage::io::read_curves(&abc).unwrap(),
        pelage::io::read_curves(&usdc).unwrap(),
    );
    assert_eq!(from_abc.points(), from_usd.points());
    // Blender's Alembic importer makes the same skin, frame by frame, as
    // its USD importer: positions, and faces that wind outward (Alembic's
    // clockwise faces turned back).
    let args = |f: &Path| {
        [
            f.to_str().unwrap().to_string(),
            "--frames".into(),
            "1,5".into(),
        ]
    };
    let Some((ok, from_abc)) = blendercheck(&args(&abc)) else {
        return;
    };
    assert!(ok, "{from_abc}");
    let (ok, from_usd) = blendercheck(&args(&usdc)).unwrap();
    assert!(ok, "{from_usd}");
    for prefix in [
        "mesh skin: volume ",
        "frame 1: mesh skin vertex[0] = ",
        "frame 5: mesh skin vertex[0] = ",
    ] {
        let (a, u) = (
            support::numbers_after(&from_abc, prefix),
            support::numbers_after(&from_usd, prefix),
        );
        for (x, y) in a.iter().zip(&u) {
            assert!(
                (x - y).abs() <= 1e-4 * y.abs().max(1.0),
                "{prefix}{a:?} vs {u:?}"
            );
        }
    }
    assert!(support::numbers_after(&from_abc, "mesh skin: volume ")[0] > 0.0);
    let moved = |text: &str| {
        let (a, b) = (
            support::numbers_after(text, "frame 1: mesh skin vertex[0] = "),
            support::numbers_after(text, "frame 5: mesh skin vertex[0] = "),
        );
        a.iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    assert!(moved(&from_abc) > 0.1, "the skin walks in Alembic too");
}

#[test]
fn an_animated_groom_is_one_time_sampled_file_that_usd_and_blender_read_frame_by_frame() {
    let dir = tempfile::tempdir().unwrap();
    let groom = fox_groom(dir.path(), "");
    let out_path = dir.path().join("fox.usdc");
    let out = pelage(&[
        "groom",
        groom.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("frames 1-6 (6 samples, rest frame 1, deform, clip \"Walk\""),
        "{text}"
    );
    // Every frame holds the same hairs, in the same order.
    let frame = |t: f64| pelage::io::read_usd_curves_at(&out_path, Some(t)).unwrap();
    let (first, later) = (frame(1.0), frame(5.0));
    assert_eq!(first.curve_count(), 2000);
    assert_eq!(first.offsets(), later.offsets());
    assert_eq!(first.ids(), later.ids());
    let moved = farthest_apart(first.points(), later.points());
    assert!(moved > 1.0, "the fur walks with the fox ({moved})");
    if let Some((ok, report)) = usdcheck(&[&out_path]) {
        assert!(ok, "{report}");
        assert!(
            report.contains("2000 curves") && report.contains("6 frames"),
            "{report}"
        );
    }
    // Blender's importer: the same points at frames 1 and 5 (point 0 of
    // the first part object).
    let index = "0";
    let args = [
        out_path.to_str().unwrap(),
        "--point",
        index,
        "--frames",
        "1,5",
    ];
    if let Some((ok, report)) = blendercheck(&args) {
        assert!(ok, "{report}");
        let counts: Vec<&str> = report
            .lines()
            .filter(|l| l.starts_with("object part_") && l.contains(" curves, "))
            .collect();
        assert_eq!(counts.len(), 4, "{report}");
        for (t, want) in [(1, first.points()[0]), (5, later.points()[0])] {
            let got = support::numbers_after(&report, &format!("frame {t}: part_0000 point[0] = "));
            for k in 0..3 {
                assert!(
                    (got[k] as f32 - want[k]).abs() < 1e-4,
                    "frame {t}: Blender reads {got:?}, pelage wrote {want}\n{report}"
                );
            }
        }
        assert!(
            report.contains("mesh skin:"),
            "the walking skin imports too\n{report}"
        );
    }
    // The preview renders the frames from one camera, and a GIF.
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_some() {
        let frames = dir.path().join("frames");
        let out = pelage(&[
            "render",
            out_path.to_str().unwrap(),
            "--frames",
            "1-6x5",
            "--size",
            "320x200",
            "-o",
            frames.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        for name in ["fox.0001.png", "fox.0006.png", "fox.gif"] {
            assert!(
                frames.join(name).exists(),
                "{name} missing: {}",
                stdout(&out)
            );
        }
        let a = image::open(frames.join("fox.0001.png")).unwrap().to_rgba8();
        let b = image::open(frames.join("fox.0006.png")).unwrap().to_rgba8();
        assert_eq!(a.dimensions(), (320, 200));
        assert_ne!(a.as_raw(), b.as_raw(), "the frames differ");
    }
}

#[test]
fn frame_files_and_a_farm_of_parts_by_frame_ranges_stitch_to_the_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let groom = fox_groom(dir.path(), "motion_blur = [-0.25, 0.25]");
    let g = groom.to_str().unwrap();
    let run = |args: &[&str]| {
        let mut all = vec!["groom", g, "--quiet"];
        all.extend_from_slice(args);
        let out = pelage(&all);
        assert!(out.status.success(), "{}", stderr(&out));
        stdout(&out)
    };
    let single = dir.path().join("single.usdc");
    run(&["-o", single.to_str().unwrap(), "--threads", "2"]);
    // One process, one file a frame.
    let frames = dir.path().join("frames.usda");
    let text = run(&[
        "-o",
        frames.to_str().unwrap(),
        "--frame-files",
        "--threads",
        "1",
    ]);
    assert!(
        text.contains("6 frame files stitched with value clips"),
        "{text}"
    );
    assert!(dir.path().join("frames.f0003.usdc").exists());
    // A farm: 2 runs × 2 frame ranges, in any order.
    let farm = dir.path().join("farm.usda");
    for (part, range) in [("2/2", "4-6"), ("1/2", "1-3"), ("2/2", "1-3")] {
        run(&[
            "-o",
            farm.to_str().unwrap(),
            "--part",
            part,
            "--frames",
            range,
        ]);
    }
    let assemble = || pelage(&["groom", g, "--assemble", "-o", farm.to_str().unwrap()]);
    let out = assemble();
    assert_eq!(out.status.code(), Some(2), "a missing task is an error");
    assert!(
        stderr(&out).contains("frame 4 of run 1 of 2 is in 0 files"),
        "{}",
        stderr(&out)
    );
    run(&[
        "-o",
        farm.to_str().unwrap(),
        "--part",
        "1/2",
        "--frames",
        "4-6",
    ]);
    let out = assemble();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("4 files of 2 runs"),
        "{}",
        stdout(&out)
    );
    for stitched in [&frames, &farm] {
        if let Some((ok, report)) = usdcheck(&[Path::new("--same-stage"), stitched, &single]) {
            assert!(ok, "{} ≠ the single run:\n{report}", stitched.display());
        }
    }
}

#[test]
fn animated_grooms_refuse_what_they_cannot_write_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let groom = fox_groom(dir.path(), "");
    let g = groom.to_str().unwrap();
    let text_out = dir.path().join("fox.usda");
    let out = pelage(&["groom", g, "-o", text_out.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out)
            .contains("animated grooms are written with time samples to .usdc, .usd or .abc"),
        "{}",
        stderr(&out)
    );
    let out = pelage(&["groom", g, "--frames", "9-2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("9-2 runs backwards"),
        "{}",
        stderr(&out)
    );
    let out = pelage(&["groom", g, "--preview", "p.png"]);
    assert!(
        stderr(&out).contains("pelage render FILE --frames 1-6"),
        "{}",
        stderr(&out)
    );
    // A clip the file does not have names the ones it has, at the clip's
    // line (the setting to fix), not the mesh's.
    let text = std::fs::read_to_string(&groom).unwrap();
    let clip_line = 1 + text.lines().position(|l| l.contains("\"Walk\"")).unwrap();
    std::fs::write(&groom, text.replace("\"Walk\"", "\"Dance\"")).unwrap();
    let out = pelage(&["groom", g]);
    assert!(
        stderr(&out).contains(&format!("fox.toml:{clip_line}:"))
            && stderr(&out).contains("animation.clip")
            && stderr(&out).contains("no animation called \"Dance\""),
        "{}",
        stderr(&out)
    );
}

#[test]
fn regrow_follows_time_sampled_guides_from_usd_and_alembic_alike() {
    let dir = tempfile::tempdir().unwrap();
    // Animated guides: a sparse deforming groom of the fox, written as
    // time-sampled curves (usdc and Alembic), then the guides of a
    // regrown groom.
    let guides_groom = fox_groom(dir.path(), "");
    let text = std::fs::read_to_string(&guides_groom)
        .unwrap()
        .replace("count = 2000\nparts = 4", "count = 80\nparts = 1")
        .replace("with_mesh = true", "with_mesh = false");
    let guide_toml = dir.path().join("guides.toml");
    std::fs::write(&guide_toml, text).unwrap();
    let fox = repo("crates/pelage/assets/fox/Fox.gltf");
    let mut regrown = Vec::new();
    for ext in ["usdc", "abc"] {
        let guides = dir.path().join(format!("guides.{ext}"));
        let out = pelage(&[
            "groom",
            guide_toml.to_str().unwrap(),
            "-o",
            guides.to_str().unwrap(),
            "-q",
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let regrow = dir.path().join(format!("regrow-{ext}.toml"));
        std::fs::write(
            &regrow,
            format!(
                "[mesh]\npath = \"{}\"\n[roots]\ncount = 1500\n[guides]\nfile = \"guides.{ext}\"\n[finish]\npoints = 6\n[animation]\nframes = \"1-4\"\nclip = \"Walk\"\nmode = \"regrow\"\n",
                fox.display()
            ),
        )
        .unwrap();
        let out_path = dir.path().join(format!("regrown-{ext}.usdc"));
        let out = pelage(&[
            "groom",
            regrow.to_str().unwrap(),
            "-o",
            out_path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(stdout(&out).contains("regrow"), "{}", stdout(&out));
        let a = pelage::io::read_usd_curves_at(&out_path, Some(1.0)).unwrap();
        let b = pelage::io::read_usd_curves_at(&out_path, Some(4.0)).unwrap();
        assert_eq!(a.curve_count(), 1500);
        assert_eq!(a.ids(), b.ids());
        assert_ne!(a.points(), b.points());
        if let Some((ok, report)) = usdcheck(&[&out_path]) {
            assert!(ok, "{report}");
        }
        regrown.push(b);
    }
    // The same guides, frame for frame, from either file.
    assert_eq!(
        regrown[0].points(),
        regrown[1].points(),
        "regrown from usdc ≠ from Alembic at frame 4"
    );
}

#[test]
fn groom_reports_unused_guides_regions_and_part_counts() {
    // Style mesh with guides denser than spot's vertices: some share a
    // vertex and go unused; a parting map splits the skin in two.
    let dir = tempfile::tempdir().unwrap();
    let toml = dir.path().join("g.toml");
    std::fs::write(
        &toml,
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 3000\nparts = 3\n[guides]\ngenerate = { count = 3000, length = 0.04 }\n[interpolation]\nmethod = \"style-mesh\"\n[regions]\nmap = \"noise:frequency=1,offset=0.5,scale=1\"\n[[ops]]\nnoise = { amplitude = 0.002, mask = \"noise:frequency=4\" }\n[output]\npath = \"g.usdc\"\n",
    )
    .unwrap();
    let report = dir.path().join("report.json");
    let out = pelage(&[
        "groom",
        toml.to_str().unwrap(),
        "-q",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let warnings = stderr(&out);
    assert!(
        warnings.contains("warning: style mesh: guide "),
        "{warnings}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["hairs"], 3000);
    let parts = json["parts"].as_array().unwrap();
    assert_eq!(parts.len(), 3);
    let hairs: u64 = parts.iter().map(|p| p["hairs"].as_u64().unwrap()).sum();
    assert_eq!(hairs, 3000);
    let unused = json["guides"]["unused_by_style_mesh"].as_array().unwrap();
    assert_eq!(
        unused.len(),
        warnings.matches("warning: style mesh:").count(),
        "each unused guide printed once"
    );
    let regions = json["regions"].as_array().unwrap();
    assert!(regions.len() >= 2, "{regions:?}");
    let guides: u64 = regions.iter().map(|r| r["guides"].as_u64().unwrap()).sum();
    assert_eq!(guides, json["guides"]["kept"].as_u64().unwrap());
    let region_hairs: u64 = regions.iter().map(|r| r["hairs"].as_u64().unwrap()).sum();
    assert_eq!(region_hairs, 3000);
}

#[test]
fn groom_fraction_writes_a_subset_of_the_full_groom_with_wider_hairs() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("fur.toml");
    std::fs::write(&groom, SMALL_GROOM).unwrap();
    let write = |name: &str, extra: &[&str]| {
        let path = dir.path().join(name);
        let mut args = vec![
            "groom",
            groom.to_str().unwrap(),
            "-o",
            path.to_str().unwrap(),
            "-q",
        ];
        args.extend_from_slice(extra);
        let out = pelage(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        pelage::io::read_curves(&path).unwrap()
    };
    let full = write("full.usdc", &[]);
    let tenth = write("tenth.usdc", &["--fraction", "0.1"]);
    let index: std::collections::HashMap<u64, usize> = full
        .ids()
        .unwrap()
        .iter()
        .enumerate()
        .map(|(i, id)| (*id, i))
        .collect();
    // strands = 2: two curves a root.
    assert_eq!(tenth.curve_count(), 600);
    let scale = (1.0 / 0.1f64.sqrt()) as f32;
    for i in 0..tenth.curve_count() {
        let j = index[&tenth.ids().unwrap()[i]];
        assert_eq!(tenth.points()[tenth.range(i)], full.points()[full.range(j)]);
        let widened: Vec<f32> = full.widths()[full.range(j)]
            .iter()
            .map(|w| w * scale)
            .collect();
        assert_eq!(tenth.widths()[tenth.range(i)], widened[..]);
    }
    // The groom file's own fraction, checked at its line.
    std::fs::write(&groom, format!("{SMALL_GROOM}[output]\nfraction = 0\n")).unwrap();
    let out = pelage(&["groom", groom.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("fur.toml:22:12: output.fraction"),
        "{}",
        stderr(&out)
    );
    std::fs::write(&groom, SMALL_GROOM).unwrap();
    let out = pelage(&["groom", groom.to_str().unwrap(), "--fraction", "1.5"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--fraction"), "{}", stderr(&out));
}

#[test]
fn simulate_writes_the_guides_once_into_the_cache_and_for_other_tools() {
    let dir = tempfile::tempdir().unwrap();
    let fox = repo("crates/pelage/assets/fox/Fox.gltf");
    let groom = dir.path().join("fox.toml");
    std::fs::write(
        &groom,
        format!(
            "[mesh]\npath = {:?}\n[roots]\ncount = 500\n[guides]\ngenerate = {{ count = 60, length = 10.0 }}\n\
             [animation]\nframes = \"1-4\"\nclip = \"Run\"\nmode = \"simulate\"\n\
             [simulation]\ngravity = [0, -500, 0]\npreroll = 2\ncache = \"fox.sim.usdc\"\n",
            fox.display()
        ),
    )
    .unwrap();
    let file = groom.to_str().unwrap();
    let first = pelage(&["simulate", file]);
    assert!(first.status.success(), "{}", stderr(&first));
    assert!(stdout(&first).contains("written"), "{}", stdout(&first));
    let again = pelage(&["simulate", file]);
    assert!(stdout(&again).contains("up to date"), "{}", stdout(&again));
    // For other tools: time-sampled guide curves Pixar's USD reads.
    let guides = dir.path().join("guides.usdc");
    let out = pelage(&["simulate", file, "-o", guides.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("60 guides over frames 1-4"),
        "{}",
        stdout(&out)
    );
    let (one, four) = (
        pelage::io::read_usd_curves_at(&guides, Some(1.0)).unwrap(),
        pelage::io::read_usd_curves_at(&guides, Some(4.0)).unwrap(),
    );
    assert_eq!(one.curve_count(), 60);
    assert_ne!(one.points(), four.points(), "the guides move");
    if let Some((ok, report)) = usdcheck(&[&guides]) {
        assert!(ok, "{report}");
    }
    // A still groom has nothing to simulate, and says so.
    let still = dir.path().join("still.toml");
    std::fs::write(
        &still,
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 10\n[guides]\ngenerate = { count = 5, length = 0.05 }\n",
    )
    .unwrap();
    let x = dir.path().join("x.usdc");
    let out = pelage(&[
        "simulate",
        still.to_str().unwrap(),
        "-o",
        x.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("mode = \"simulate\""),
        "{}",
        stderr(&out)
    );
}

#[test]
fn an_assembly_refuses_a_part_grown_from_an_earlier_version_of_the_groom() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("fur.toml");
    let g = groom.to_str().unwrap();
    for ext in ["usda", "abc"] {
        let farm = dir.path().join(format!("farm.{ext}"));
        let farm = farm.to_str().unwrap();
        let grow = |text: &str, part: &str| {
            std::fs::write(&groom, text).unwrap();
            let out = pelage(&["groom", g, "--quiet", "-o", farm, "--part", part]);
            assert!(out.status.success(), "{}", stderr(&out));
        };
        // Both runs of the groom, then the groom edited (more hairs) and
        // only run 1 grown again: run 2's file is stale.
        grow(SMALL_GROOM, "1/2");
        grow(SMALL_GROOM, "2/2");
        let edited = SMALL_GROOM.replacen("count = ", "count = 1", 1);
        assert_ne!(edited, SMALL_GROOM);
        grow(&edited, "1/2");
        let out = pelage(&["groom", g, "--assemble", "-o", farm]);
        assert_eq!(out.status.code(), Some(2), "{ext}: {}", stderr(&out));
        let said = stderr(&out);
        assert!(
            said.contains("farm.part-2-of-2") && said.contains("another version of the groom"),
            "{ext}: {said}"
        );
        assert!(said.contains("--part 2/2"), "{ext}: {said}");
        // Grown again, it assembles.
        grow(&edited, "2/2");
        let out = pelage(&["groom", g, "--assemble", "-o", farm]);
        assert!(out.status.success(), "{ext}: {}", stderr(&out));
        // pelage reads the assembled layer back as the hairs one run
        // grows (the layer references the part files), and converts it.
        let one = dir.path().join(format!("one.{ext}"));
        let out = pelage(&["groom", g, "--quiet", "-o", one.to_str().unwrap()]);
        assert!(out.status.success(), "{}", stderr(&out));
        let (a, b) = (
            pelage::io::read_curves(&one).unwrap(),
            pelage::io::read_curves(Path::new(farm)).unwrap(),
        );
        assert_eq!(a.ids(), b.ids(), "{ext}");
        assert_eq!(a.points(), b.points(), "{ext}");
        let converted = dir.path().join(format!("{ext}.ply"));
        let out = pelage(&["convert", farm, converted.to_str().unwrap()]);
        assert!(out.status.success(), "{ext}: {}", stderr(&out));
    }
}

#[test]
fn an_animated_farms_assembly_refuses_frame_files_of_an_earlier_groom() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("fur.toml");
    let g = groom.to_str().unwrap();
    let text = |count: u32| {
        format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = {count}\nparts = 2\n\
             [guides]\ngenerate = {{ count = 10, length = 0.05 }}\n[animation]\nframes = \"1-2\"\n"
        )
    };
    let farm = dir.path().join("farm.usda");
    let farm = farm.to_str().unwrap();
    let grow = |count: u32, part: &str| {
        std::fs::write(&groom, text(count)).unwrap();
        let out = pelage(&["groom", g, "--quiet", "-o", farm, "--part", part]);
        assert!(out.status.success(), "{}", stderr(&out));
    };
    grow(200, "1/2");
    grow(200, "2/2");
    grow(300, "1/2");
    let out = pelage(&["groom", g, "--assemble", "-o", farm]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let said = stderr(&out);
    assert!(
        said.contains("farm.part-2-of-2") && said.contains("another version of the groom"),
        "{said}"
    );
    grow(300, "2/2");
    let out = pelage(&["groom", g, "--assemble", "-o", farm]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn converting_an_animated_file_says_it_writes_the_first_sample() {
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("fur.toml");
    std::fs::write(
        &groom,
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 100\n[guides]\ngenerate = { count = 10, length = 0.05 }\n\
         [animation]\nframes = \"1-3\"\n",
    )
    .unwrap();
    for ext in ["abc", "usdc"] {
        let animated = dir.path().join(format!("fur.{ext}"));
        let out = pelage(&[
            "groom",
            groom.to_str().unwrap(),
            "--quiet",
            "-o",
            animated.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let ply = dir.path().join(format!("{ext}.ply"));
        let out = pelage(&["convert", animated.to_str().unwrap(), ply.to_str().unwrap()]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(
            stderr(&out).contains("is animated (3 time samples): convert writes its first"),
            "{ext}: {}",
            stderr(&out)
        );
        // The first sample, as the ordinary reader reads it (convert
        // parses a USD file once for both the curves and the count).
        let first = pelage::io::read_curves(&animated).unwrap();
        let written = pelage::io::read_curves(&ply).unwrap();
        assert_eq!(written.points(), first.points(), "{ext}");
        assert_eq!(written.offsets(), first.offsets(), "{ext}");
        let (read, samples) = pelage::io::read_curves_and_sample_count(&animated).unwrap();
        assert_eq!((read.points(), samples), (first.points(), 3), "{ext}");
    }
    // A still file converts without a word.
    let still_groom = dir.path().join("still.toml");
    let text = std::fs::read_to_string(&groom).unwrap();
    std::fs::write(&still_groom, &text[..text.find("[animation]").unwrap()]).unwrap();
    let still = dir.path().join("still.usda");
    let out = pelage(&[
        "groom",
        still_groom.to_str().unwrap(),
        "--quiet",
        "-o",
        still.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = pelage(&[
        "convert",
        still.to_str().unwrap(),
        dir.path().join("still.ply").to_str().unwrap(),
    ]);
    assert!(
        out.status.success() && !stderr(&out).contains("animated"),
        "{}",
        stderr(&out)
    );
    let written = pelage::io::read_curves(&dir.path().join("still.ply")).unwrap();
    let read = pelage::io::read_curves(&still).unwrap();
    assert_eq!(written.points(), read.points());
    assert_eq!(written.widths(), read.widths());
}

/// The largest distance between matching points of `a` and `b`.
fn farthest_apart(a: &[glam::Vec3], b: &[glam::Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0f32, f32::max)
}

/// `pelage groom GROOM` written to `cpu` and, with `--gpu`, to `gpu`;
/// both must succeed. Returns the GPU run.
fn groom_on_cpu_and_gpu(groom: &Path, cpu: &Path, gpu: &Path) -> Output {
    let mut on_gpu = None;
    for (out, extra) in [(cpu, None), (gpu, Some("--gpu"))] {
        let mut args = vec![
            "groom",
            groom.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ];
        args.extend(extra);
        let o = pelage(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        on_gpu = Some(o);
    }
    on_gpu.expect("the GPU run is the last")
}

#[test]
fn groom_on_the_gpu_writes_what_the_cpu_writes() {
    // Needs a GPU adapter; in CI (PELAGE_REQUIRE_GPU) it must be there.
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_none() {
        eprintln!("SKIPPED: set PELAGE_REQUIRE_GPU=1 to grow on the GPU through the CLI");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let groom = dir.path().join("fur.toml");
    // Two parts, clumps at two levels, masks, a map, colours and normals,
    // a cut that takes some hairs away whole, strands of strands (the first
    // masked): what a file carries beside the points.
    std::fs::write(
        &groom,
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 6000\nparts = 2\n\
         [guides]\npoints = 6\ngenerate = { count = 80, length = 0.06, comb = [0, -0.5, -1] }\n\
         [[ops]]\nclump = { count = 30, rate = 0.6 }\n\
         [[ops]]\nclump = { count = 200, rate = 0.4, mask = \"noise:frequency=3\" }\n\
         [[ops]]\ncurl = { radius = 0.002, turns = 2 }\n\
         [[ops]]\nnoise = { amplitude = \"noise:frequency=2,scale=0.01\", frequency = 20 }\n\
         [[ops]]\ncut = { at = \"noise:frequency=4,offset=0.1,scale=1.0\" }\n\
         [[ops]]\nstrands = { count = 2, tip_spread = 0.003, mask = \"noise:frequency=3,offset=0.0,scale=1.0\" }\n\
         [[ops]]\nstrands = { count = 2, tip_spread = 0.001 }\n\
         [finish]\npoints = 9\nnormals = true\n\
         color = { root = [0.3, 0.2, 0.1], tip = [0.8, 0.7, 0.5], jitter = 0.1 }\n",
    )
    .unwrap();
    let cpu = dir.path().join("cpu.usdc");
    let gpu = dir.path().join("gpu.usdc");
    groom_on_cpu_and_gpu(&groom, &cpu, &gpu);
    let (a, b) = (
        pelage::io::read_curves(&cpu).unwrap(),
        pelage::io::read_curves(&gpu).unwrap(),
    );
    // Every root grows 2 hairs (the first split masked there) or 4, less
    // the cut's; each id once.
    assert!(a.curve_count() < 24000, "the cut takes some hairs away");
    assert_eq!(a.curve_count() % 2, 0, "two hairs a strand");
    let ids: std::collections::HashSet<u64> = a.ids().unwrap().iter().copied().collect();
    assert_eq!(ids.len(), a.curve_count(), "every hair id once");
    assert_eq!(a.offsets(), b.offsets());
    assert_eq!(a.ids(), b.ids(), "the same hairs in the same order");
    assert_eq!(a.roots(), b.roots());
    assert_eq!(a.colors(), b.colors());
    let near =
        |x: &[glam::Vec3], y: &[glam::Vec3], tolerance: f32| farthest_apart(x, y) <= tolerance;
    // Spot is about a unit across: 1e-4 of the groom's size.
    assert!(near(a.points(), b.points(), 1e-4));
    assert!(near(a.normals().unwrap(), b.normals().unwrap(), 1e-2));
    let widths = a
        .widths()
        .iter()
        .zip(b.widths())
        .all(|(x, y)| (x - y).abs() <= 1e-7);
    assert!(widths, "widths are the CPU operators' own");
}

#[test]
fn an_animated_groom_grown_on_the_gpu_writes_what_the_cpu_writes() {
    if std::env::var_os("PELAGE_REQUIRE_GPU").is_none() {
        eprintln!("SKIPPED: set PELAGE_REQUIRE_GPU=1 to grow on the GPU through the CLI");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let fox = repo("crates/pelage/assets/fox/Fox.gltf");
    // Deform: the hairs grown once at rest and carried to each pose.
    // Simulate: every frame's own guides, so every frame's own growth.
    for mode in ["deform", "simulate"] {
        let groom = dir.path().join(format!("{mode}.toml"));
        std::fs::write(
            &groom,
            format!(
                "[mesh]\npath = {:?}\n[roots]\ncount = 1500\n\
                 [guides]\ngenerate = {{ count = 60, length = 10.0, comb = [0, -0.5, -1] }}\n\
                 [[ops]]\nclump = {{ count = 40, rate = 0.5 }}\n\
                 [[ops]]\nnoise = {{ amplitude = 0.5, frequency = 0.2 }}\n\
                 [finish]\npoints = 8\n\
                 [animation]\nframes = \"1-3\"\nclip = \"Run\"\nmode = \"{mode}\"\n{simulation}",
                fox.display(),
                simulation = match mode {
                    "simulate" => "[simulation]\ngravity = [0, -500, 0]\npreroll = 1\n",
                    _ => "",
                }
            ),
        )
        .unwrap();
        let cpu = dir.path().join(format!("{mode}-cpu.usdc"));
        let gpu = dir.path().join(format!("{mode}-gpu.usdc"));
        let on_gpu = groom_on_cpu_and_gpu(&groom, &cpu, &gpu);
        assert!(
            stdout(&on_gpu).contains("growing on"),
            "{}",
            stdout(&on_gpu)
        );
        let first = pelage::io::read_usd_curves_at(&cpu, Some(1.0)).unwrap();
        let (lo, hi) = first
            .points()
            .iter()
            .fold((glam::Vec3::MAX, glam::Vec3::MIN), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let size = (hi - lo).length();
        let mut moved = 0.0f32;
        for frame in [1.0, 2.0, 3.0] {
            let (a, b) = (
                pelage::io::read_usd_curves_at(&cpu, Some(frame)).unwrap(),
                pelage::io::read_usd_curves_at(&gpu, Some(frame)).unwrap(),
            );
            assert_eq!(a.curve_count(), 1500);
            assert_eq!(a.ids(), b.ids(), "{mode} frame {frame}: the same hairs");
            let worst = farthest_apart(a.points(), b.points());
            assert!(
                worst <= 1e-4 * size,
                "{mode} frame {frame}: a point {worst} from the CPU's (size {size})"
            );
            moved = moved.max(farthest_apart(a.points(), first.points()));
        }
        assert!(moved > 0.01 * size, "{mode}: the Fox runs, the hairs move");
    }
}
