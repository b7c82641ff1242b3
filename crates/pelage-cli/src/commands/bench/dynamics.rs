//! `pelage bench dynamics`: time per step of every mass-spring topology ×
//! solver (Banisch & Wüthrich's four, Silva's strands; explicit symplectic
//! Euler with one substep, implicit backward Euler: 10 CG iterations where
//! springs join the tips, a direct 3×3 solve per tip where none do)
//! on spot, blub and spot ×4 (1.5 M triangles), under gravity and gusting
//! turbulent wind, on all threads. Targets (2 cores): 1 M masses —
//! implicit ≤ 10 ms a step, explicit ≤ 3 ms. Banisch's baseline: 1,247 to
//! 6,888 masses at 22–27 fps including rendering (P4 1.7 GHz, 2006).

use super::median_seconds;
use crate::format::thousands;
use clap::Args;
use glam::Vec3;
use pelage::Mesh;
use pelage::dynamics::{DynamicsParams, MassSpringSystem, Solver, Topology, Wind};
use std::path::Path;

/// Arguments of `pelage bench dynamics`.
#[derive(Debug, Args)]
pub struct DynamicsBenchArgs {
    /// A reduced run: spot only.
    #[arg(long)]
    pub quick: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Steps per median.
    #[arg(long, default_value_t = 5)]
    pub steps: usize,
}

struct Row {
    model: String,
    topology: Topology,
    masses: usize,
    springs: usize,
    ms: [f64; 2],
}

const SOLVERS: [Solver; 2] = [
    Solver::Explicit { substeps: 1 },
    Solver::Implicit { iterations: 10 },
];

pub fn run(args: &DynamicsBenchArgs) -> anyhow::Result<()> {
    let spot = pelage::assets::spot();
    let mut meshes: Vec<(String, Mesh)> = vec![("spot".into(), spot.subdivided(0))];
    if !args.quick {
        let blub = Path::new("../shared/data/meshes/blub_triangulated.obj");
        if let Ok(mesh) = Mesh::load(blub) {
            meshes.push(("blub".into(), mesh));
        }
        meshes.push(("spot ×4".into(), spot.subdivided(4)));
    }
    let params = DynamicsParams {
        wind: Some(Wind::new(Vec3::new(3.0, 0.0, 1.0), 0.6, 0.7, 2.0, 4.0, 1)),
        ..Default::default()
    };
    let dt = 1.0 / 60.0;
    let mut rows = Vec::new();
    for (name, mesh) in &meshes {
        let length = 0.025 * (mesh.bounds().1 - mesh.bounds().0).length();
        for topology in Topology::ALL {
            let mut ms = [0.0; 2];
            let mut counts = (0, 0);
            for (k, solver) in SOLVERS.into_iter().enumerate() {
                let mut system = MassSpringSystem::new(mesh, topology, length);
                counts = (system.mass_count(), system.spring_count());
                let mut step = 0;
                let (seconds, ()) = median_seconds(args.steps.max(1), true, || {
                    system.step(dt, &params, solver, step as f32 * dt);
                    step += 1;
                });
                ms[k] = seconds * 1e3;
            }
            rows.push(Row {
                model: name.clone(),
                topology,
                masses: counts.0,
                springs: counts.1,
                ms,
            });
        }
    }
    let threads = rayon::current_num_threads();
    let headline = rows
        .iter()
        .rev()
        .find(|r| r.topology == Topology::SpringSticks)
        .expect("spring-sticks always run");
    if args.json {
        let list: Vec<String> = rows
            .iter()
            .map(|r| {
                format!(
                    "{{\"model\":{:?},\"topology\":{:?},\"masses\":{},\"springs\":{},\"explicit_ms\":{:.4},\"implicit_ms\":{:.4}}}",
                    r.model,
                    r.topology.name(),
                    r.masses,
                    r.springs,
                    r.ms[0],
                    r.ms[1]
                )
            })
            .collect();
        println!(
            "{{\"model\":{:?},\"masses\":{},\"explicit_ms\":{:.4},\"implicit_ms\":{:.4},\"explicit_ms_per_million\":{:.4},\"implicit_ms_per_million\":{:.4},\"threads\":{threads},\"rows\":[{}]}}",
            headline.model,
            headline.masses,
            headline.ms[0],
            headline.ms[1],
            headline.ms[0] * 1e6 / headline.masses as f64,
            headline.ms[1] * 1e6 / headline.masses as f64,
            list.join(",")
        );
        return Ok(());
    }
    println!(
        "pelage bench dynamics — ms per step (median of {}), {threads} threads; gravity + gusting turbulent wind",
        args.steps.max(1)
    );
    println!(
        "explicit: symplectic Euler, 1 substep; implicit: backward Euler, 10 CG iterations (prisms) or a direct 3×3 solve per tip (no tip-tip springs)\n"
    );
    println!(
        "{:>8}  {:>24}  {:>10}  {:>10}  {:>11}  {:>11}  {:>14}",
        "model", "topology", "masses", "springs", "explicit", "implicit", "M masses/s (impl.)"
    );
    for r in &rows {
        println!(
            "{:>8}  {:>24}  {:>10}  {:>10}  {:>8.2} ms  {:>8.2} ms  {:>14.2}",
            r.model,
            r.topology.name(),
            thousands(r.masses as u64),
            thousands(r.springs as u64),
            r.ms[0],
            r.ms[1],
            r.masses as f64 / r.ms[1] / 1e3
        );
    }
    let per_million = |ms: f64| ms * 1e6 / headline.masses as f64;
    println!(
        "\ntargets (spring-sticks on {}, scaled to 1 M masses): explicit ≤ 3 ms — {:.1} ms ({}); implicit ≤ 10 ms — {:.1} ms ({})",
        headline.model,
        per_million(headline.ms[0]),
        if per_million(headline.ms[0]) <= 3.0 {
            "met"
        } else {
            "missed"
        },
        per_million(headline.ms[1]),
        if per_million(headline.ms[1]) <= 10.0 {
            "met"
        } else {
            "missed"
        },
    );
    println!(
        "Banisch & Wüthrich (P4 1.7 GHz, 2006): 1,247–6,888 masses at 22–27 fps including rendering"
    );
    Ok(())
}
