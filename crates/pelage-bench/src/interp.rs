//! `pelage bench interp`: guide interpolation on a production-sized case —
//! 5,000 guides on spot ×4 (1.5 M triangles), the guide count the Furtility
//! talk quotes for a furry character. Style-mesh build time (cold: the
//! mesh's edge list and edge graph are built too; warm: they are cached on
//! the mesh, as when guides change and the groom is regenerated), and the time to weigh one hair: style mesh
//! (closest point among the style triangles of the hair's own cells, hairs
//! in skin-triangle order as a generator meets them, and in the sampler's
//! random order; and, by position alone, on the whole style mesh through a
//! BVH) and Shepard
//! with k = 4 and 8 (kd-tree query). The build runs on the default thread
//! pool (one search per guide, in parallel), the weights on one thread;
//! hair roots from the density sampler.

use super::{median_seconds, on_threads};
use crate::format::thousands;
use clap::Args;
use glam::Vec3;
use pelage::Map;
use pelage::guides::{GuideGrowth, Guides};
use pelage::interp::{GuideWeight, GuideWeights, HairRoot, Shepard, StyleMesh, StyleMeshOptions};
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};

/// Arguments of `pelage bench interp`.
#[derive(Debug, Args)]
pub struct InterpBenchArgs {
    /// A reduced run (spot ×2, 1,000 guides, 100,000 hairs).
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

impl InterpBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

fn ns_per_hair(method: &dyn GuideWeights, roots: &[HairRoot], runs: usize) -> f64 {
    let mut w: Vec<GuideWeight> = Vec::with_capacity(16);
    let (seconds, checksum) = median_seconds(runs, true, || {
        let mut checksum = 0u64;
        for &r in roots {
            method.weights(r, &mut w);
            checksum = checksum.wrapping_add(w[0].guide as u64);
        }
        checksum
    });
    std::hint::black_box(checksum);
    seconds * 1e9 / roots.len() as f64
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &InterpBenchArgs) -> anyhow::Result<()> {
    let (levels, guide_count, hair_count, runs) = args.scale().pick(
        (4, 5_000, 1_000_000u64, 5),
        (2, 1_000, 100_000, 3),
        (0, 100, 2_000, 1),
    );
    let mesh = pelage::assets::spot().subdivided(levels);
    let guides = Guides::grow(
        &mesh,
        &GuideGrowth {
            count: guide_count,
            comb: Vec3::new(0.0, 0.0, 1.0),
            ..GuideGrowth::default()
        },
    )?;
    let sampler =
        DensitySampler::new(&mesh, &Map::Constant(1.0), DensitySamplerOptions::default())?;
    let roots: Vec<HairRoot> = sample_range(&sampler, 77, 0..hair_count)
        .iter()
        .map(|r| HairRoot::on(&mesh, *r))
        .collect();
    let positions: Vec<HairRoot> = roots.iter().map(|r| HairRoot::at(r.position)).collect();
    // The same hairs in skin-triangle order, as a generator walking the
    // mesh meets them (the sampler's order is random by design).
    let mut sorted = roots.clone();
    sorted.sort_by_key(|r| r.triangle);
    let options = StyleMeshOptions::default();
    // The build on the default pool (its searches run in parallel), the
    // per-hair weights on one thread.
    // Cold on a fresh copy of the mesh (a clone carries no cached
    // topology), so the edge list and edge graph are built inside.
    let fresh = mesh.clone();
    let (cold_s, _) = median_seconds(1, false, || StyleMesh::build(&fresh, &guides, &options));
    drop(fresh);
    let (warm_s, style) =
        median_seconds(runs, false, || StyleMesh::build(&mesh, &guides, &options));
    let (style_sorted_ns, style_ns, style_bvh_ns, shepard4, shepard8) = on_threads(1, || {
        (
            ns_per_hair(&style, &sorted, runs),
            ns_per_hair(&style, &roots, runs),
            ns_per_hair(&style, &positions, runs),
            ns_per_hair(&Shepard::new(&mesh, &guides, 4, 2.0, None), &roots, runs),
            ns_per_hair(&Shepard::new(&mesh, &guides, 8, 2.0, None), &roots, runs),
        )
    })?;
    let (triangles, lost) = (style.triangles().len(), style.lost().len());
    let threads = rayon::current_num_threads();
    if args.json {
        let report = serde_json::json!({
            "triangles": mesh.triangle_count(),
            "guides": guide_count,
            "hairs": hair_count,
            "threads": threads,
            "style_mesh_build_s": warm_s,
            "style_mesh_build_cold_s": cold_s,
            "style_mesh_triangles": triangles,
            "style_mesh_lost_guides": lost,
            "style_mesh_ns_per_hair": style_sorted_ns,
            "style_mesh_random_order_ns_per_hair": style_ns,
            "style_mesh_bvh_ns_per_hair": style_bvh_ns,
            "shepard_k4_ns_per_hair": shepard4,
            "shepard_k8_ns_per_hair": shepard8,
        });
        println!("{report}");
        return Ok(());
    }
    println!(
        "pelage bench interp — {} guides on spot ×{levels} ({} triangles), {} hairs; build on {threads} threads, weights on 1; median of {runs}\n",
        thousands(guide_count as u64),
        thousands(mesh.triangle_count() as u64),
        thousands(hair_count)
    );
    println!("{:<34} {:>12} {:>12}", "", "pelage", "target");
    println!(
        "{:<34} {:>9.1} ms {:>9} ms",
        "style mesh build (graph cached)",
        warm_s * 1e3,
        "≤ 150"
    );
    println!(
        "{:<34} {:>9.1} ms {:>12}",
        "  cold (+ edges, edge graph)",
        cold_s * 1e3,
        "—"
    );
    println!(
        "{:<34} {:>9.1} ns {:>9} ns",
        "style mesh weights, per hair", style_sorted_ns, "≤ 100"
    );
    println!(
        "{:<34} {:>9.1} ns {:>12}",
        "  hairs in random order", style_ns, "—"
    );
    println!(
        "{:<34} {:>9.1} ns {:>12}",
        "  by position only (BVH)", style_bvh_ns, "—"
    );
    println!(
        "{:<34} {:>9.1} ns {:>12}",
        "Shepard k = 4, per hair", shepard4, "—"
    );
    println!(
        "{:<34} {:>9.1} ns {:>12}",
        "Shepard k = 8, per hair", shepard8, "—"
    );
    println!(
        "\nstyle mesh: {} triangles over {} guides; {lost} guides lost (sharing a vertex with a nearer guide)",
        thousands(triangles as u64),
        thousands(guide_count as u64)
    );
    Ok(())
}
