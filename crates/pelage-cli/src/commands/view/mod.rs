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
mod curves;
#[cfg(feature = "viewer")]
mod grooming;
#[cfg(feature = "viewer")]
mod realtime;
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
    /// A shell scene (TOML, docs/shells-format.md), a mesh with UVs (.obj
    /// .ply .gltf .glb) to cover in fur, a groom file (TOML,
    /// docs/groom-format.md) or a curves file (.usda .usdc .usd .hair, PLY
    /// with edges). Without it: the embedded Spot in fur.
    pub input: Option<PathBuf>,
    /// The skin under a curves file: a mesh file, or `spot`.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// Run the steps of this file (docs/viewer.md), then close.
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// Write what the window shows to this PNG and close: after the
    /// script, or after a few frames without one.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Groom the groom file by hand: brushes on its guides and paint
    /// layers, undo, redo, save (docs/grooming.md).
    #[arg(long)]
    pub groom: bool,
    /// Play the groom file in real time on the GPU: the skin running, its
    /// guides simulated when the groom says so, every hair grown each
    /// frame, strands near and shells far (docs/realtime.md).
    #[arg(long, conflicts_with = "groom")]
    pub realtime: bool,
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
    use pelage::settings::SettingsSource;
    use pelage::shell::ShellScene;

    let title = args
        .input
        .as_deref()
        .map_or("embedded spot".into(), |p| p.display().to_string());
    let content = match &args.input {
        Some(path) if args.realtime => {
            if !is_groom_file(path)? {
                anyhow::bail!(
                    "{}: `--realtime` plays a groom file (TOML with [roots], [guides], …; docs/realtime.md)",
                    path.display()
                );
            }
            app::Content::Realtime(path.clone())
        }
        None if args.realtime => anyhow::bail!(
            "`--realtime` needs a groom file: `pelage view fox.toml --realtime` (`pelage demo fox --realtime` writes one)"
        ),
        Some(path) if args.groom => {
            if !is_groom_file(path)? {
                anyhow::bail!(
                    "{}: `--groom` grooms a groom file (TOML with [roots], [guides], …; docs/groom-format.md)",
                    path.display()
                );
            }
            app::Content::Groom(path.clone())
        }
        None if args.groom => anyhow::bail!(
            "`--groom` needs a groom file: `pelage view fur.toml --groom` (`pelage demo` writes one)"
        ),
        None => app::Content::Shells(Box::new(ShellScene::spot())),
        Some(path) if is_groom_file(path)? => {
            app::Content::Curves(curves::CurvesSource::Groom(path.clone()))
        }
        Some(path)
            if path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml")) =>
        {
            app::Content::Shells(Box::new(ShellScene::load(path)?))
        }
        Some(path) => match super::render::file_kind(path)? {
            super::render::FileKind::Curves => app::Content::Curves(curves::CurvesSource::File {
                path: path.clone(),
                mesh: args.mesh.clone(),
            }),
            super::render::FileKind::Points => anyhow::bail!(
                "{} is a point cloud: `pelage view` shows shell scenes, meshes, grooms and curves \
                 (draw points with `pelage render`)",
                path.display()
            ),
            super::render::FileKind::Mesh => {
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
                app::Content::Shells(Box::new(ShellScene::from_source(&SettingsSource {
                    path: path.clone(),
                    text,
                })?))
            }
        },
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
    if let app::Content::Shells(scene) = &content {
        println!(
            "{title}: {} layers over {} ({} triangles)",
            scene.fur.layers,
            scene.mesh.name(),
            scene.mesh.triangle_count()
        );
    }
    let timings = app::run(
        content,
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
    if !timings.dab_ms.is_empty() {
        println!(
            "{} brush dabs: median {:.1} ms (edit and regrowth), slowest {:.1} ms",
            timings.dab_ms.len(),
            median(&timings.dab_ms),
            timings.dab_ms.iter().copied().fold(0.0, f64::max)
        );
    }
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

/// Whether a TOML file is a groom file (it has a groom's tables) rather
/// than a shell scene.
#[cfg(feature = "viewer")]
fn is_groom_file(path: &std::path::Path) -> anyhow::Result<bool> {
    use anyhow::Context;
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
    {
        return Ok(false);
    }
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    // A file that does not parse goes to the shell-scene reader, whose
    // error names the line.
    let Ok(table) = text.parse::<toml::Table>() else {
        return Ok(false);
    };
    Ok([
        "roots",
        "ops",
        "guides",
        "interpolation",
        "finish",
        "output",
    ]
    .iter()
    .any(|key| table.contains_key(*key)))
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
