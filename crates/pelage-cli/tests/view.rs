//! The viewer in a real window: a script drops water on the fur and takes
//! screenshots before and after. Needs the `viewer` feature and an X
//! display; CI runs it under Xvfb on lavapipe (`.ci/run`):
//! `xvfb-run -a cargo test -p pelage-cli --features viewer --test view`.
//! Without a display it skips with a message, unless
//! `PELAGE_REQUIRE_DISPLAY=1` (CI), where it fails.
#![cfg(feature = "viewer")]

use std::path::Path;
use std::process::{Command, Output};

fn pelage(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pelage"))
        .args(args)
        .env(
            "XDG_RUNTIME_DIR",
            std::env::var("XDG_RUNTIME_DIR").unwrap_or("/tmp".into()),
        )
        .output()
        .expect("pelage runs")
}

fn has_display() -> bool {
    let present = std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty());
    if !present {
        assert!(
            std::env::var("PELAGE_REQUIRE_DISPLAY").as_deref() != Ok("1"),
            "PELAGE_REQUIRE_DISPLAY=1 but DISPLAY is not set (run under xvfb-run)"
        );
        eprintln!("skipped: no X display (run under `xvfb-run -a`)");
    }
    present
}

const SIZE: (u32, u32) = (480, 360);

/// Writes `input` and `script` into `dir` and views the one with the
/// other in a `SIZE` window; panics with the output if it fails.
fn view_scripted(dir: &Path, input: &str, script: &str) -> String {
    let (input_path, script_path) = (dir.join("input.toml"), dir.join("script.toml"));
    std::fs::write(&input_path, input).unwrap();
    std::fs::write(&script_path, script).unwrap();
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let out = pelage(&[
        "view",
        input_path.to_str().unwrap(),
        "--script",
        script_path.to_str().unwrap(),
        "--size",
        &size,
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(!stderr.contains("missed the mesh"), "{stderr}");
    stdout
}

#[test]
fn a_drop_of_water_changes_the_fur_where_it_falls_and_nowhere_else() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (cx, cy) = (SIZE.0 as f32 / 2.0, SIZE.1 as f32 / 2.0);
    // Curly fur with wet clumps: a wet patch both straightens and clumps.
    let stdout = view_scripted(
        dir.path(),
        "[fur]\nlayers = 16\n[curl]\nradius = 0.6\nturns = 2\n[clump]\nw = 0.6\n",
        &format!(
            "ui = false\n\
             [[step]]\nwait = 2\n\
             [[step]]\nscreenshot = \"before.png\"\n\
             [[step]]\ndrop = {{ at = [{cx}, {cy}], radius = 0.05, wetness = 1.0 }}\n\
             [[step]]\nwait = 2\n\
             [[step]]\nscreenshot = \"after.png\"\n"
        ),
    );
    assert!(stdout.contains("frame time median"), "{stdout}");
    eprintln!("{stdout}");

    let read = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgb8();
    let (before, after) = (read("before.png"), read("after.png"));
    assert_eq!(before.dimensions(), SIZE);
    assert_eq!(after.dimensions(), SIZE);
    let (near, far) = changed_near_and_far(&before, &after, (cx, cy), 0.25 * SIZE.1 as f32);
    let total = SIZE.0 * SIZE.1;
    eprintln!("changed pixels: {near} near the drop, {far} elsewhere, of {total}");
    assert!(
        near > 300,
        "the wet patch must show: {near} pixels changed near the drop"
    );
    // The rest: unchanged but for noise (a UV chart next to the drop's in
    // the texture may catch a rim of the droplet elsewhere on the body).
    assert!(
        (far as f32) < 0.005 * total as f32 && far < near / 10,
        "{far} pixels changed away from the drop ({near} near it)"
    );
}

/// Pixels that differ by more than 24 of 255 in any channel, near `at`
/// (within `radius`) and elsewhere.
fn changed_near_and_far(
    a: &image::RgbImage,
    b: &image::RgbImage,
    at: (f32, f32),
    radius: f32,
) -> (usize, usize) {
    let (mut near, mut far) = (0, 0);
    for (x, y, p) in a.enumerate_pixels() {
        let q = b.get_pixel(x, y);
        if p.0.iter().zip(q.0).any(|(&u, v)| u.abs_diff(v) > 24) {
            if (x as f32 - at.0).hypot(y as f32 - at.1) <= radius {
                near += 1;
            } else {
                far += 1;
            }
        }
    }
    (near, far)
}

#[test]
fn dragging_with_the_push_tool_moves_the_fur_under_the_pointer() {
    if !has_display() {
        return;
    }
    // Stepped on the CPU (implicit, the default) and on the GPU
    // (explicit, `gpu = true`): the push must show alike.
    for solver in ["", "solver = \"explicit\"\ngpu = true\n"] {
        push_moves_the_fur_under_the_pointer(solver);
    }
}

fn push_moves_the_fur_under_the_pointer(solver: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (cx, cy) = (SIZE.0 as f32 / 2.0, SIZE.1 as f32 / 2.0);
    // No gravity and no wind: the fur is at rest until pushed.
    view_scripted(
        dir.path(),
        &format!("[fur]\nlayers = 16\n[dynamics]\ngravity = [0, 0, 0]\n{solver}"),
        &format!(
            "ui = false\n\
             [[step]]\nwait = 3\n[[step]]\nscreenshot = \"before.png\"\n\
             [[step]]\npush = {{ from = [{cx}, {cy}], to = [{}, {cy}], frames = 4 }}\n\
             [[step]]\nscreenshot = \"after.png\"\n",
            cx + 60.0
        ),
    );
    let read = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgb8();
    let (near, far) = changed_near_and_far(
        &read("before.png"),
        &read("after.png"),
        (cx + 30.0, cy),
        0.25 * SIZE.1 as f32,
    );
    eprintln!("{solver:?}: changed pixels: {near} near the push, {far} elsewhere");
    assert!(near > 100, "{solver:?}: the push must show: {near}");
    assert!(
        far < near / 10,
        "{solver:?}: {far} pixels changed away from the push ({near} near it)"
    );
}

#[test]
fn a_bad_script_is_an_error_at_its_line() {
    // Read before any window opens: no display needed.
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("bad.toml");
    std::fs::write(
        &script,
        "[[step]]\nwait = 2\n[[step]]\ndorp = { at = [1, 2] }\n",
    )
    .unwrap();
    let out = pelage(&["view", "--script", script.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.toml:4:"), "{stderr}");
}

#[test]
fn a_screenshot_without_a_script_shows_the_panel_and_the_fur() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("shot.png");
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let out = pelage(&[
        "view",
        "--screenshot",
        shot.to_str().unwrap(),
        "--size",
        &size,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let image = image::open(Path::new(&shot)).unwrap().to_rgb8();
    // The panel is dark on the left; the background is grey-blue on the
    // right, with the fur in between.
    let dark = |x: u32, y: u32| image.get_pixel(x, y).0.iter().all(|&c| c < 60);
    assert!(dark(5, SIZE.1 - 5), "no panel at the bottom left");
    let corner = image.get_pixel(SIZE.0 - 3, 3).0;
    assert!(corner[2] > corner[0], "background is bluish: {corner:?}");
}

#[test]
fn a_groom_file_is_grown_and_drawn_with_its_guides_in_orange() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    view_scripted(
        dir.path(),
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 3000\n\
         [guides]\ngenerate = { count = 80, length = 0.12, comb = [0, -1, 0] }\n",
        "ui = false\n\
         [[step]]\nshow = { skin = false, hairs = false, guides = true }\n\
         [[step]]\nwait = 2\n[[step]]\nscreenshot = \"guides.png\"\n\
         [[step]]\nshow = { guides = false }\n\
         [[step]]\nwait = 2\n[[step]]\nscreenshot = \"nothing.png\"\n\
         [[step]]\nshow = { skin = true, hairs = true }\n\
         [[step]]\nwait = 2\n[[step]]\nscreenshot = \"groom.png\"\n",
    );
    let read = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgb8();
    let background = read("nothing.png");
    let differing = |image: &image::RgbImage| {
        image
            .pixels()
            .zip(background.pixels())
            .filter(|(a, b)| a.0.iter().zip(b.0).any(|(&x, y)| x.abs_diff(y) > 24))
            .map(|(a, _)| a.0)
            .collect::<Vec<_>>()
    };
    assert!(differing(&background).is_empty());
    // Guides alone: orange strokes on the blue-grey background (edges are
    // blended with it, highlights pale, but all are warmer than it).
    let guides = differing(&read("guides.png"));
    let orange = guides
        .iter()
        .filter(|[r, _, b]| *r > b.saturating_add(10))
        .count();
    assert!(
        guides.len() > 200 && orange * 10 > guides.len() * 8,
        "{orange} of {} orange",
        guides.len()
    );
    // Skin and hairs cover far more.
    let groom = differing(&read("groom.png"));
    assert!(
        groom.len() > 5 * guides.len(),
        "{} vs {}",
        groom.len(),
        guides.len()
    );
}

#[test]
fn the_fox_runs_furred_and_its_timeline_moves_it() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // examples/shells/fox.toml, its paths made absolute.
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../pelage/assets/fox");
    let scene = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/shells/fox.toml"),
    )
    .unwrap()
    .replace("../../crates/pelage/assets/fox", assets.to_str().unwrap());
    let stdout = view_scripted(
        dir.path(),
        &scene,
        "ui = false\n\
         [[step]]\ntime = 0.1\n\
         [[step]]\nwait = 2\n\
         [[step]]\nscreenshot = \"early.png\"\n\
         [[step]]\ntime = 0.4\n\
         [[step]]\nwait = 2\n\
         [[step]]\nscreenshot = \"late.png\"\n",
    );
    eprintln!("{stdout}");
    let read = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgb8();
    let (early, late) = (read("early.png"), read("late.png"));
    // The fox: orange-brown fur covering a good part of the picture.
    let furred = |image: &image::RgbImage| {
        image
            .pixels()
            .filter(|p| u16::from(p.0[0]) > u16::from(p.0[2]) + 40 && p.0[0] > 80)
            .count()
    };
    let total = (SIZE.0 * SIZE.1) as usize;
    let (a, b) = (furred(&early), furred(&late));
    eprintln!("fox pixels: {a} at 0.1 s, {b} at 0.4 s, of {total}");
    assert!(a > total / 20 && b > total / 20, "{a} {b}");
    // Its legs and body are elsewhere 0.3 s later.
    let (near, far) = changed_near_and_far(&early, &late, (0.0, 0.0), 0.0);
    let changed = near + far;
    assert!(changed > total / 50, "{changed} pixels changed");
}

#[test]
fn grooming_in_the_window_saves_a_groom_that_grows_as_shown() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let groom = "[mesh]\npath = \"spot\"\n\
        [roots]\ncount = 8000\nseed = 3\n\
        [guides]\npoints = 8\ngenerate = { count = 80, length = 0.1, comb = [0, -0.5, -1.0], seed = 2 }\n\
        [[ops]]\nclump = { count = 100, rate = 0.5 }\n\
        [output]\npath = \"grown.usdc\"\n";
    let groom_path = dir.path().join("fur.toml");
    std::fs::write(&groom_path, groom).unwrap();
    let (cx, cy) = (SIZE.0 as f32 / 2.0, SIZE.1 as f32 / 2.0);
    // Comb, cut and paint density away, undo the paint stroke (one step),
    // save; then export what the window shows.
    let script = format!(
        "ui = false\n\
         [[step]]\nwait = 1\n\
         [[step]]\nbrush = {{ name = \"comb\", from = [{a}, {cy}], to = [{b}, {cy}], radius = 0.2, strength = 1.0 }}\n\
         [[step]]\nbrush = {{ name = \"cut\", from = [{cx}, {c}], radius = 0.15 }}\n\
         [[step]]\nbrush = {{ name = \"paint\", from = [{a}, {c}], to = [{b}, {c}], layer = \"density\", value = 0.0, radius = 0.2 }}\n\
         [[step]]\nscreenshot = \"painted.png\"\n\
         [[step]]\nundo = 1\n\
         [[step]]\nbrush = {{ name = \"paint\", from = [{cx}, {cy}], layer = \"density\", value = 0.3, radius = 0.1 }}\n\
         [[step]]\nsave = \"fur_groomed.toml\"\n\
         [[step]]\nexport = \"shown.usdc\"\n\
         [[step]]\nscreenshot = \"saved.png\"\n",
        a = cx - 60.0,
        b = cx + 60.0,
        c = cy + 30.0,
    );
    let script_path = dir.path().join("groom.toml");
    std::fs::write(&script_path, script).unwrap();
    let out = groom_by_script(&groom_path, &script_path);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(!stderr.contains("missed the mesh"), "{stderr}");
    assert!(stdout.contains("brush dabs: median"), "{stdout}");
    for file in [
        "fur_groomed.toml",
        "fur_groomed.guides.usdc",
        "fur_groomed.layers.ply",
    ] {
        assert!(dir.path().join(file).exists(), "{file} was not saved");
    }
    // `pelage groom` grows the saved groom to the hairs the window showed.
    let grown = pelage(&[
        "groom",
        dir.path().join("fur_groomed.toml").to_str().unwrap(),
    ]);
    assert!(
        grown.status.success(),
        "{}",
        String::from_utf8_lossy(&grown.stderr)
    );
    let shown = pelage::io::read_curves(&dir.path().join("shown.usdc")).unwrap();
    let full = pelage::io::read_curves(&dir.path().join("grown.usdc")).unwrap();
    assert_eq!(shown.curve_count(), full.curve_count());
    let index: std::collections::HashMap<u64, usize> = full
        .ids()
        .unwrap()
        .iter()
        .enumerate()
        .map(|(i, id)| (*id, i))
        .collect();
    let mut worst = 0.0f32;
    for i in 0..shown.curve_count() {
        let j = index[&shown.ids().unwrap()[i]];
        for (a, b) in shown.points()[shown.range(i)]
            .iter()
            .zip(&full.points()[full.range(j)])
        {
            worst = worst.max(a.distance(*b));
        }
    }
    assert!(
        worst < 1e-4,
        "the grown groom differs from the shown one by {worst}"
    );
    // The strokes changed the groom: fewer hairs than the 8,000 asked for
    // (density painted at 0.3 under one dab) or moved ones.
    let first = image::open(dir.path().join("painted.png"))
        .unwrap()
        .to_rgba8();
    let last = image::open(dir.path().join("saved.png"))
        .unwrap()
        .to_rgba8();
    assert_ne!(first.as_raw(), last.as_raw());
}

#[test]
fn a_simulated_groom_written_with_its_skin_plays_in_the_viewer() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let fox = Path::new(env!("CARGO_MANIFEST_DIR")).join("../pelage/assets/fox/Fox.gltf");
    let groom = dir.path().join("fox.toml");
    std::fs::write(
        &groom,
        format!(
            "[mesh]\npath = {:?}\n[roots]\ncount = 600\n[guides]\ngenerate = {{ count = 60, length = 12.0 }}\n\
             [animation]\nframes = \"1-6\"\nclip = \"Run\"\nmode = \"simulate\"\n\
             [simulation]\ngravity = [0, -500, 0]\npreroll = 2\n[output]\nwith_mesh = true\n",
            fox.display()
        ),
    )
    .unwrap();
    let written = dir.path().join("fox.usdc");
    let out = pelage(&[
        "groom",
        groom.to_str().unwrap(),
        "-o",
        written.to_str().unwrap(),
        "-q",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Held at the first sample, then 5 frames (5/24 s) on.
    let script = dir.path().join("script.toml");
    std::fs::write(
        &script,
        "ui = false\n\
         [[step]]\ntime = 0\n[[step]]\nwait = 2\n[[step]]\nscreenshot = \"first.png\"\n\
         [[step]]\ntime = 0.2084\n[[step]]\nwait = 2\n[[step]]\nscreenshot = \"last.png\"\n",
    )
    .unwrap();
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let out = pelage(&[
        "view",
        written.to_str().unwrap(),
        "--script",
        script.to_str().unwrap(),
        "--size",
        &size,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("no time samples"), "{stderr}");
    let read = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgb8();
    let (first, last) = (read("first.png"), read("last.png"));
    let total = (SIZE.0 * SIZE.1) as usize;
    // The file's own skin and its fur run on: the picture changes.
    let (near, far) = changed_near_and_far(&first, &last, (0.0, 0.0), 0.0);
    assert!(near + far > total / 50, "{} pixels changed", near + far);
}

/// `pelage view GROOM --groom --script SCRIPT` at the tests' size.
fn groom_by_script(groom: &Path, script: &Path) -> Output {
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    pelage(&[
        "view",
        groom.to_str().unwrap(),
        "--groom",
        "--script",
        script.to_str().unwrap(),
        "--size",
        &size,
    ])
}

#[test]
fn a_scripted_step_that_fails_ends_the_run_with_its_error() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let groom = "[mesh]\npath = \"spot\"\n[roots]\ncount = 500\n\
        [guides]\ngenerate = { count = 20, length = 0.1 }\n";
    let groom_path = dir.path().join("fur.toml");
    std::fs::write(&groom_path, groom).unwrap();
    let (cx, cy) = (SIZE.0 as f32 / 2.0, SIZE.1 as f32 / 2.0);
    // A save into a folder, and a brush with a negative radius: each used
    // to close the window and exit 0, skipping the steps after it.
    for (step, says) in [
        ("save = \"sub\"".to_string(), "sub"),
        (
            format!("brush = {{ name = \"length\", from = [{cx}, {cy}], radius = -1.0 }}"),
            "radius -1",
        ),
    ] {
        std::fs::create_dir_all(dir.path().join("sub")).unwrap();
        let script = format!(
            "ui = false\n[[step]]\nwait = 1\n[[step]]\n{step}\n[[step]]\nscreenshot = \"after.png\"\n"
        );
        let script_path = dir.path().join("steps.toml");
        std::fs::write(&script_path, script).unwrap();
        let out = groom_by_script(&groom_path, &script_path);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{step}: {stderr}");
        assert!(stderr.contains(says), "{step}: {stderr}");
        assert!(!dir.path().join("after.png").exists(), "{step}");
    }
}

#[test]
fn the_guides_under_the_brush_are_highlighted_where_the_pointer_is() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let groom = "[mesh]\npath = \"spot\"\n[roots]\ncount = 500\n\
        [guides]\ngenerate = { count = 300, length = 0.1 }\n";
    let groom_path = dir.path().join("fur.toml");
    std::fs::write(&groom_path, groom).unwrap();
    let (cx, cy) = (SIZE.0 as f32 / 2.0, SIZE.1 as f32 / 2.0);
    let script = format!(
        "ui = false\n[[step]]\nshow = {{ hairs = false }}\n[[step]]\nwait = 1\n\
         [[step]]\nscreenshot = \"before.png\"\n[[step]]\npointer = [{cx}, {cy}]\n\
         [[step]]\nwait = 1\n[[step]]\nscreenshot = \"after.png\"\n"
    );
    let script_path = dir.path().join("steps.toml");
    std::fs::write(&script_path, script).unwrap();
    let out = groom_by_script(&groom_path, &script_path);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The highlight is green; the other guides orange, the skin white and
    // black.
    let green = |name: &str| {
        let image = image::open(dir.path().join(name)).unwrap().to_rgb8();
        image
            .pixels()
            .filter(|p| {
                i32::from(p[1]) > i32::from(p[0]) + 40 && i32::from(p[1]) > i32::from(p[2]) + 40
            })
            .count()
    };
    let (before, after) = (green("before.png"), green("after.png"));
    assert!(
        after >= before + 10,
        "{before} green pixels before, {after} after"
    );
}

#[test]
fn a_groom_plays_in_real_time_and_its_fur_runs_with_the_fox() {
    if !has_display() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let fox = Path::new(env!("CARGO_MANIFEST_DIR")).join("../pelage/assets/fox/Fox.gltf");
    let groom = dir.path().join("fox.toml");
    std::fs::write(
        &groom,
        format!(
            "[mesh]\npath = {fox:?}\n[roots]\ncount = 4000\n\
             [guides]\npoints = 8\ngenerate = {{ count = 100, length = 10 }}\n\
             [[ops]]\nclump = {{ count = 300, rate = 0.4 }}\n\
             [finish]\npoints = 8\noutside_skin = false\nwidth = {{ root = 1.2, tip = 0.4 }}\n\
             [animation]\nframes = \"1-12\"\nclip = \"Run\"\nmode = \"simulate\"\n\
             [simulation]\ngravity = [0, -1000, 0]\n"
        ),
    )
    .unwrap();
    let script = dir.path().join("script.toml");
    std::fs::write(
        &script,
        "ui = false\n\
         [[step]]\ntime = 0.1\n\
         [[step]]\nwait = 2\n\
         [[step]]\nscreenshot = \"early.png\"\n\
         [[step]]\ntime = 0.4\n\
         [[step]]\nwait = 2\n\
         [[step]]\nscreenshot = \"late.png\"\n",
    )
    .unwrap();
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let out = pelage(&[
        "view",
        groom.to_str().unwrap(),
        "--realtime",
        "--script",
        script.to_str().unwrap(),
        "--size",
        &size,
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("4000 hairs from 100 guides, in real time"),
        "{stdout}"
    );
    assert!(!stderr.contains("not on the GPU"), "{stderr}");
    let read = |name: &str| image::open(dir.path().join(name)).unwrap().to_rgb8();
    let (early, late) = (read("early.png"), read("late.png"));
    // Orange-brown fur over a good part of the picture, and elsewhere
    // 0.3 s later.
    let furred = |image: &image::RgbImage| {
        image
            .pixels()
            .filter(|p| u16::from(p.0[0]) > u16::from(p.0[2]) + 40 && p.0[0] > 80)
            .count()
    };
    let total = (SIZE.0 * SIZE.1) as usize;
    let (a, b) = (furred(&early), furred(&late));
    assert!(
        a > total / 20 && b > total / 20,
        "fox pixels {a} {b} of {total}"
    );
    let (near, far) = changed_near_and_far(&early, &late, (0.0, 0.0), 0.0);
    assert!(near + far > total / 50, "{} pixels changed", near + far);
}
