//! `pelage view`: the interactive fur viewer — a window (winit + wgpu +
//! egui) with an orbit camera over shell fur: sliders for every parameter,
//! click to drop water (Silva Alg. 1), drag to push the fur (Banisch's
//! user force), shake the object, rain and drying. `--script` drives the
//! same window from a file, for tests and demos.
//!
//! The window needs the `viewer` feature (`cargo install --path
//! crates/pelage-cli --features viewer`); without it the command says so.

#[cfg(feature = "viewer")]
mod app;
#[cfg(feature = "viewer")]
pub mod script;
#[cfg(feature = "viewer")]
mod shells;

use super::render::parse_size;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `pelage view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// A shell scene (TOML, docs/shells-format.md) or a mesh with UVs
    /// (.obj .ply .gltf .glb) to cover in fur. Without it: the embedded Spot.
    pub input: Option<PathBuf>,
    /// Run the steps of this file (docs/viewer.md), then close.
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// Write what the window shows to this PNG and close: after the
    /// script, or after a few frames without one.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Window size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x800", value_parser = parse_size)]
    pub size: (u32, u32),
}

/// Runs `pelage view`.
#[cfg(not(feature = "viewer"))]
pub fn run(_: &ViewArgs) -> anyhow::Result<()> {
    anyhow::bail!(
        "this pelage was built without its viewer; build it with the `viewer` feature: \
         `cargo run --release --features viewer -- view` or \
         `cargo install --path crates/pelage-cli --features viewer`"
    )
}

/// Runs `pelage view`.
#[cfg(feature = "viewer")]
pub fn run(args: &ViewArgs) -> anyhow::Result<()> {
    use pelage::groom::GroomSource;
    use pelage::shell::ShellScene;

    let (scene, title) = match &args.input {
        None => (ShellScene::spot(), "embedded spot".to_string()),
        Some(path) => {
            let is_toml = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
            let scene = if is_toml {
                ShellScene::load(path)?
            } else {
                // A mesh: the default scene on it.
                let text = format!(
                    "[mesh]\npath = {}\n",
                    toml_string(
                        &path
                            .canonicalize()
                            .unwrap_or(path.clone())
                            .to_string_lossy()
                    )
                );
                ShellScene::from_source(&GroomSource {
                    path: path.clone(),
                    text,
                })?
            };
            (scene, path.display().to_string())
        }
    };
    let mut script = match &args.script {
        Some(path) => Some(script::Script::load(path)?),
        None => None,
    };
    if let Some(shot) = &args.screenshot {
        match &mut script {
            Some(s) => s.steps.push(script::Step::Screenshot(shot.clone())),
            None => script = Some(script::Script::screenshot_after(3, shot.clone())),
        }
    }
    println!(
        "{title}: {} layers over {} ({} triangles)",
        scene.fur.layers,
        scene.mesh.name(),
        scene.mesh.triangle_count()
    );
    let timings = app::run(
        scene,
        app::WindowOptions {
            size: args.size,
            title: format!("pelage view — {title}"),
            script,
        },
    )?;
    let median = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    println!(
        "{} frames on {}: frame time median {:.1} ms ({:.1} fps), simulation median {:.2} ms",
        timings.frame_ms.len() + 1,
        timings.adapter,
        median(&timings.frame_ms),
        1e3 / median(&timings.frame_ms),
        median(&timings.simulation_ms),
    );
    Ok(())
}

/// A TOML basic string (quotes and backslashes escaped).
#[cfg(feature = "viewer")]
fn toml_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}
