//! `pelage bench shells`: the structure of Silva et al.'s Table 1 — frame
//! time of shell fur for meshes from 5.9 k to 1.5 M triangles (spot, blub,
//! spot subdivided `×n` = n times, 4ⁿ × the triangles), 16 and 64 layers, 800×600 and 1680×1050 — for plain
//! shells, with curl, and with curl + clumps, on the adapter present. A
//! frame is the skin pass + the instanced layer draw + the MSAA resolve,
//! submitted and waited for (no read-back). The clumped runs use a wetness
//! mask with 400 droplets (about a third of the fur wet).
//!
//! The paper's figures (GeForce 8800 GTS, 2010, 256² textures, its method
//! i.e. with curl and clumps) are printed beside ours for scale; the
//! target is on the ratio measured here: curl + clump ≤ 1.15 × plain.

use crate::format::thousands;
use clap::Args;
use pelage::Mesh;
use pelage::shell::wetness::{DropletStyle, droplets_on_mesh};
use pelage::shell::{ShellScene, ShellTextureParams, ShellTextures, WetnessMask};
use pelage_gpu::{GpuContext, ShellFeatures, ShellParams, ShellRenderer, ShellTarget, ShellView};

/// Arguments of `pelage bench shells`.
#[derive(Debug, Args)]
pub struct ShellsBenchArgs {
    /// A reduced run: spot and spot ×2 (subdivided twice, 94 k triangles),
    /// 16 layers, 800×600.
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Frames per median.
    #[arg(long, default_value_t = 5)]
    pub frames: usize,
    /// Only the rows for game characters (indexed layers, culling and
    /// level of detail; skinned; a crowd; fins), not Table 1's matrix.
    #[arg(long)]
    pub game: bool,
}

impl ShellsBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }

    /// Frames per median: one in a smoke run.
    fn frames(&self) -> usize {
        self.scale().pick(self.frames, self.frames, 1).max(1)
    }
}

/// Silva Table 1: (model, triangles, fps at 16 layers 800×600, 1680×1050,
/// 64 layers 800×600, 1680×1050).
const PAPER: &[(&str, u32, f64, f64, f64, f64)] = &[
    ("Torus", 9_360, 267.0, 117.0, 90.0, 35.0),
    ("Pear", 20_845, 256.0, 117.0, 84.0, 34.0),
    ("Hippo", 44_452, 154.0, 80.0, 51.0, 24.0),
    ("Cow", 92_689, 78.0, 63.0, 28.0, 21.0),
    ("Horse", 95_533, 66.0, 52.0, 23.0, 17.0),
    ("Bunny", 142_307, 24.0, 22.0, 8.0, 8.0),
    ("Elephant", 154_789, 25.0, 21.0, 7.0, 7.0),
    ("Lion", 365_118, 3.0, 3.0, 1.0, 1.0),
];

struct Row {
    model: String,
    triangles: usize,
    layers: u32,
    size: (u32, u32),
    ms: [f64; 3],
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &ShellsBenchArgs) -> anyhow::Result<()> {
    let ctx = GpuContext::headless()?;
    let frames = args.frames();
    let reduced = args.scale().reduced();
    if args.game {
        let game = super::shells_game::measure(&ctx, reduced, frames)?;
        if args.json {
            let mut report = game_json(&game);
            report["adapter"] = ctx.adapter_name().into();
            report["software_adapter"] = ctx.is_software().into();
            println!("{report}");
        } else {
            println!(
                "pelage bench shells --game — median of {} frames, on {}\n",
                frames,
                ctx.adapter_name()
            );
            print_game(&game);
        }
        return Ok(());
    }
    let rows = measure(&ctx, args, frames)?;
    let game = super::shells_game::measure(&ctx, reduced, frames)?;
    if args.json {
        print_json(&ctx, &rows, &game);
    } else {
        print_table(&ctx, args, &rows, &game);
    }
    Ok(())
}

/// Plain, curl and curl + clump frames on each mesh, layer count and size.
fn measure(ctx: &GpuContext, args: &ShellsBenchArgs, frames: usize) -> anyhow::Result<Vec<Row>> {
    let renderers = [
        ShellFeatures::PLAIN,
        ShellFeatures {
            curl: true,
            ..ShellFeatures::PLAIN
        },
        ShellFeatures::ALL,
    ]
    .map(|f| ShellRenderer::new(ctx, f));
    let scene = ShellScene::spot();
    let spot = pelage::assets::spot();
    let mut meshes: Vec<(String, Mesh)> = vec![
        ("spot".into(), spot.subdivided(0)),
        ("spot ×2".into(), spot.subdivided(2)),
    ];
    let (layer_counts, sizes): (&[u32], &[(u32, u32)]) = if args.scale().reduced() {
        (&[16], &[(800, 600)])
    } else {
        let blub = super::test_meshes().join("blub_triangulated.obj");
        if let Ok(mesh) = Mesh::load(&blub) {
            meshes.insert(1, ("blub".into(), mesh));
        }
        meshes.insert(2, ("spot ×1".into(), spot.subdivided(1)));
        meshes.push(("spot ×3".into(), spot.subdivided(3)));
        meshes.push(("spot ×4".into(), spot.subdivided(4)));
        (&[16, 64], &[(800, 600), (1680, 1050)])
    };
    let max_layers = *layer_counts.iter().max().expect("layer counts");
    let textures = ShellTextures::generate(&ShellTextureParams {
        layers: max_layers,
        ..scene.texture
    });
    let mut rows = Vec::new();
    for (name, mesh) in &meshes {
        let mut mask = WetnessMask::dry_mask(256, 256);
        let style = DropletStyle {
            radius_min: 0.02,
            radius_max: 0.04,
            wetness: 0.9,
        };
        for d in droplets_on_mesh(mesh, 400, style, 11)? {
            mask.add_droplet(d);
        }
        let models = renderers
            .iter()
            .map(|r| {
                let model = r.upload(ctx, mesh, &scene.color, &textures, 256)?;
                r.set_wetness(ctx, &model, &mask)?;
                Ok(model)
            })
            .collect::<Result<Vec<_>, pelage_gpu::GpuError>>()?;
        for &size in sizes {
            let targets = renderers
                .iter()
                .map(|r| ShellTarget::new(ctx, r, size.0, size.1))
                .collect::<Result<Vec<_>, _>>()?;
            let length = 0.025 * (mesh.bounds().1 - mesh.bounds().0).length();
            let view = ShellView::new(
                None,
                mesh.bounds(),
                length,
                size.0 as f32 / size.1 as f32,
                None,
            );
            for &layers in layer_counts {
                let params = ShellParams {
                    layers,
                    length,
                    curl: pelage::shell::CurlParams {
                        radius: 0.4 * length,
                        frequency: 4.0 * std::f32::consts::PI,
                    },
                    clump: pelage::shell::ClumpParams {
                        w: 0.6,
                        strength: 4.0,
                    },
                    ..ShellParams::from_scene(&scene)
                };
                // Interleaved: each feature set's frames alternate with the
                // others', so drift on a noisy machine hits all three alike.
                let draw = |k: usize| -> anyhow::Result<()> {
                    Ok(renderers[k].draw(ctx, &models[k], &params, &view, &targets[k])?)
                };
                let medians = super::interleaved(
                    frames,
                    &mut [&mut || draw(0), &mut || draw(1), &mut || draw(2)],
                )?;
                let ms = [medians[0], medians[1], medians[2]];
                rows.push(Row {
                    model: name.clone(),
                    triangles: mesh.triangle_count(),
                    layers,
                    size,
                    ms,
                });
            }
        }
    }
    Ok(rows)
}

/// The row the target is judged on: spot ×2, 16 layers, 800×600.
fn headline(rows: &[Row]) -> &Row {
    rows.iter()
        .find(|r| r.model == "spot ×2" && r.layers == 16 && r.size == (800, 600))
        .expect("spot ×2 at 16 layers, 800×600 is always measured")
}

/// The figures as one JSON object (`--json`).
fn print_json(ctx: &GpuContext, rows: &[Row], game: &super::shells_game::GameFigures) {
    let headline = headline(rows);
    let list: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            serde_json::json!({
                "model": r.model,
                "triangles": r.triangles,
                "layers": r.layers,
                "width": r.size.0,
                "height": r.size.1,
                "plain_ms": r.ms[0],
                "curl_ms": r.ms[1],
                "curl_clump_ms": r.ms[2],
            })
        })
        .collect();
    let mut report = game_json(game);
    for (key, value) in [
        ("adapter", ctx.adapter_name().into()),
        ("software_adapter", ctx.is_software().into()),
        ("plain_ms", headline.ms[0].into()),
        ("curl_ms", headline.ms[1].into()),
        ("curl_clump_ms", headline.ms[2].into()),
        ("overhead_ratio", (headline.ms[2] / headline.ms[0]).into()),
        ("target_overhead_ratio", 1.15.into()),
        ("rows", list.into()),
    ] {
        report[key] = value;
    }
    println!("{report}");
}

/// The figures as tables beside the target and Silva et al.'s Table 1.
fn print_table(
    ctx: &GpuContext,
    args: &ShellsBenchArgs,
    rows: &[Row],
    game: &super::shells_game::GameFigures,
) {
    let headline = headline(rows);
    println!(
        "pelage bench shells{} — median of {} frames, on {}",
        args.scale().flag(),
        args.frames(),
        ctx.adapter_name()
    );
    println!(
        "frame = skin + instanced layers + MSAA resolve, waited for; 256² textures; 400 droplets\n"
    );
    println!(
        "{:>9}  {:>10}  {:>6}  {:>10}  {:>10}  {:>10}  {:>12}  {:>9}",
        "model", "triangles", "layers", "size", "plain", "+ curl", "+ curl+clump", "÷ plain"
    );
    for r in rows {
        println!(
            "{:>9}  {:>10}  {:>6}  {:>10}  {:>7.1} ms  {:>7.1} ms  {:>9.1} ms  {:>8.2}×",
            r.model,
            thousands(r.triangles as u64),
            r.layers,
            format!("{}×{}", r.size.0, r.size.1),
            r.ms[0],
            r.ms[1],
            r.ms[2],
            r.ms[2] / r.ms[0]
        );
    }
    let ratio = headline.ms[2] / headline.ms[0];
    println!(
        "\ntarget (spot ×2, 16 layers, 800×600): curl + clump ≤ 1.15 × plain — measured {ratio:.2}× ({})",
        if ratio <= 1.15 { "met" } else { "missed" }
    );
    println!();
    print_game(game);
    println!(
        "\nSilva et al. Table 1 (GeForce 8800 GTS, with curl and clumps), ms per frame (fps):"
    );
    println!(
        "{:>9}  {:>10}  {:>16}  {:>16}  {:>16}  {:>16}",
        "model", "triangles", "16 · 800×600", "16 · 1680×1050", "64 · 800×600", "64 · 1680×1050"
    );
    for (model, triangles, a, b, c, d) in PAPER {
        let cell = |fps: f64| format!("{:.1} ({fps})", 1e3 / fps);
        println!(
            "{:>9}  {:>10}  {:>16}  {:>16}  {:>16}  {:>16}",
            model,
            thousands(u64::from(*triangles)),
            cell(*a),
            cell(*b),
            cell(*c),
            cell(*d)
        );
    }
}

/// The game rows as JSON: each row's configurations in ms, and the ratios
/// the targets are on.
fn game_json(game: &super::shells_game::GameFigures) -> serde_json::Value {
    let rows = [
        ("geometry", &game.geometry),
        ("skinned", &game.skinned),
        ("crowd", &game.crowd),
        ("fins", &game.fins),
    ]
    .map(|(key, row)| {
        let timed: serde_json::Map<String, serde_json::Value> = row
            .timed
            .iter()
            .map(|t| (t.name.to_string(), t.ms.into()))
            .collect();
        (key, serde_json::json!({ "what": row.what, "ms": timed }))
    });
    let last = game.geometry.timed.len() - 1;
    serde_json::json!({
        "game_rows": serde_json::Map::from_iter(rows.map(|(k, v)| (k.to_string(), v))),
        "indexed_speedup": game.geometry.speedup(1),
        "geometry_speedup": game.geometry.speedup(last),
        "target_geometry_speedup": 4.0,
        "skinned_ratio": game.skinned.ratio(1),
        "target_skinned_ratio": 1.2,
        "lod_speedup": game.crowd.speedup(1),
        "target_lod_speedup": 3.0,
        "fins_overhead_ratio": game.fins.ratio(1),
        "target_fins_overhead_ratio": 1.1,
    })
}

/// The game rows as a table, each configuration beside its peer (the
/// row's first), with the targets.
fn print_game(game: &super::shells_game::GameFigures) {
    println!(
        "shells for games (each row's first configuration is its peer, measured in the same run):"
    );
    for (row, target) in [
        (&game.geometry, "the last ≥ 4× faster than the first"),
        (&game.skinned, "running ≤ 1.2× standing"),
        (&game.crowd, "level of detail ≥ 3× faster"),
        (&game.fins, "fins ≤ 1.1× shells alone"),
    ] {
        println!("\n  {}", row.what);
        for (k, t) in row.timed.iter().enumerate() {
            println!(
                "    {:<22} {:>9.1} ms  {:>6.2}× the time",
                t.name,
                t.ms,
                row.ratio(k)
            );
        }
        println!("    target: {target}");
    }
}
