//! `pelage bench dynamics`: time per step of every mass-spring topology ×
//! solver (Banisch & Wüthrich's four, Silva's strands; explicit symplectic
//! Euler with as many substeps as stability needs — one, except for the
//! prisms — implicit backward Euler: 10 CG iterations where
//! springs join the tips, a direct 3×3 solve per tip where none do)
//! on spot, blub and spot ×4 (1.5 M triangles), under gravity and gusting
//! turbulent wind, on all threads. Targets (2 cores): 1 M masses —
//! implicit ≤ 10 ms a step, explicit ≤ 3 ms. Banisch's baseline: 1,247 to
//! 6,888 masses at 22–27 fps including rendering (P4 1.7 GHz, 2006).
//!
//! Beside the CPU, the same steps on the GPU adapter present
//! (`pelage_gpu::GpuMassSpring`; lavapipe without a GPU) — explicit for
//! every topology, implicit where no springs join the tips (the prisms'
//! implicit step is the CPU's): steps queued in one submission, as a
//! real-time loop would, and waited for.

use super::median_seconds;
use crate::format::thousands;
use clap::Args;
use glam::Vec3;
use pelage::Mesh;
use pelage::dynamics::{DynamicsParams, MassSpringSystem, Solver, Topology, Wind};
use pelage_gpu::GpuContext;

/// Arguments of `pelage bench dynamics`.
#[derive(Debug, Args)]
pub struct DynamicsBenchArgs {
    /// A reduced run: spot only.
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Steps per median.
    #[arg(long, default_value_t = 5)]
    pub steps: usize,
    /// Leave out the GPU column.
    #[arg(long)]
    pub no_gpu: bool,
    /// Guide strands on the running Fox instead (Dynamic
    /// Follow-The-Leader with body collisions): frames per second.
    #[arg(long)]
    pub strands: bool,
    /// With `--strands`: guides (default 10,000; 2,000 with `--quick`).
    #[arg(long, requires = "strands")]
    pub guides: Option<usize>,
    /// With `--strands`: points a guide (default 16).
    #[arg(long, requires = "strands", default_value_t = 16)]
    pub points: usize,
    /// With `--strands`, also measure a peer in the same run: `blender`
    /// simulates as many guides on the Fox running with its own hair
    /// dynamics (particle hair, the cloth solver, a Collision modifier;
    /// bpy from PyPI in a cached venv, tools/bpy-python).
    #[arg(long, value_enum, requires = "strands")]
    pub peer: Option<super::groom::Peer>,
}

impl DynamicsBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

struct Row {
    model: String,
    topology: Topology,
    masses: usize,
    springs: usize,
    ms: [f64; 2],
    /// Substeps of the explicit step (the stability bound's).
    substeps: u32,
    /// The explicit and implicit steps on the GPU, where measured.
    gpu_ms: [Option<f64>; 2],
}

/// Milliseconds a GPU step with `solver` (explicit substeps resolved as
/// the CPU resolves them): the median over three batches of `steps` steps,
/// each batch queued in one go and waited for.
fn gpu_step_ms(
    ctx: &pelage_gpu::GpuContext,
    system: &MassSpringSystem,
    params: &DynamicsParams,
    dt: f32,
    solver: Solver,
    steps: usize,
) -> anyhow::Result<f64> {
    let mut gpu = pelage_gpu::GpuMassSpring::new(ctx, system)?;
    let mut queue = |time: f32, steps: u32| -> anyhow::Result<()> {
        match solver {
            Solver::Explicit { substeps } => {
                let substeps = system.explicit_substeps(dt, params, substeps);
                gpu.step_explicit(ctx, dt, params, substeps, time, steps);
            }
            Solver::Implicit { .. } => gpu.step_implicit(ctx, dt, params, time, steps)?,
        }
        gpu.wait(ctx)?;
        Ok(())
    };
    queue(0.0, 1)?;
    let steps = steps.max(1) as u32;
    let mut batches = Vec::new();
    for b in 0..3 {
        let start = std::time::Instant::now();
        queue((1 + b * steps) as f32 * dt, steps)?;
        batches.push(start.elapsed().as_secs_f64() * 1e3 / f64::from(steps));
    }
    batches.sort_by(f64::total_cmp);
    Ok(batches[1])
}

const SOLVERS: [Solver; 2] = [
    // As many substeps as stability needs: timing a diverging step says
    // nothing.
    Solver::Explicit { substeps: 0 },
    Solver::Implicit { iterations: 10 },
];

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &DynamicsBenchArgs) -> anyhow::Result<()> {
    let gpu = if args.no_gpu {
        None
    } else {
        match pelage_gpu::GpuContext::headless() {
            Ok(ctx) => Some(ctx),
            Err(e) => {
                eprintln!("no GPU column: {:#}", anyhow::Error::from(e));
                None
            }
        }
    };
    let rows = measure(args, gpu.as_ref())?;
    if args.json {
        print_json(&rows, gpu.as_ref());
    } else {
        print_table(args, &rows, gpu.as_ref());
    }
    Ok(())
}

/// Every topology × solver on each mesh, on the CPU and (where `gpu` is
/// given) the GPU.
fn measure(args: &DynamicsBenchArgs, gpu: Option<&GpuContext>) -> anyhow::Result<Vec<Row>> {
    let spot = pelage::assets::spot();
    let mut meshes: Vec<(String, Mesh)> = vec![("spot".into(), spot.subdivided(0))];
    let steps = if args.smoke { 1 } else { args.steps };
    if !args.scale().reduced() {
        let blub = super::test_meshes().join("blub_triangulated.obj");
        if let Ok(mesh) = Mesh::load(&blub) {
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
            // Built once; every measurement starts from a copy at rest.
            let at_rest = MassSpringSystem::new(mesh, topology, length);
            let substeps = at_rest.stable_substeps(dt, &params);
            let mut gpu_ms = [None; 2];
            if let Some(ctx) = gpu {
                for (k, solver) in SOLVERS.into_iter().enumerate() {
                    // The prisms' implicit step has no GPU path.
                    if matches!(solver, Solver::Implicit { .. }) && at_rest.joins_tips() {
                        continue;
                    }
                    gpu_ms[k] = Some(gpu_step_ms(ctx, &at_rest, &params, dt, solver, steps)?);
                }
            }
            let mut ms = [0.0; 2];
            for (k, solver) in SOLVERS.into_iter().enumerate() {
                let mut system = at_rest.clone();
                let mut step = 0;
                let (seconds, ()) = median_seconds(steps.max(1), true, || {
                    system.step(dt, &params, solver, step as f32 * dt);
                    step += 1;
                });
                ms[k] = seconds * 1e3;
            }
            rows.push(Row {
                model: name.clone(),
                topology,
                masses: at_rest.mass_count(),
                springs: at_rest.spring_count(),
                ms,
                substeps,
                gpu_ms,
            });
        }
    }
    Ok(rows)
}

/// The row the targets are judged on: spring-sticks on the largest mesh.
fn headline(rows: &[Row]) -> &Row {
    rows.iter()
        .rev()
        .find(|r| r.topology == Topology::SpringSticks)
        .expect("spring-sticks always run")
}

/// The figures as one JSON object (`--json`).
fn print_json(rows: &[Row], gpu: Option<&GpuContext>) {
    let threads = rayon::current_num_threads();
    let headline = headline(rows);
    let gpu_name = gpu.map(|ctx| ctx.adapter_name());
    let list: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            serde_json::json!({
                "model": r.model,
                "topology": r.topology.name(),
                "masses": r.masses,
                "springs": r.springs,
                "explicit_ms": r.ms[0],
                "explicit_substeps": r.substeps,
                "implicit_ms": r.ms[1],
                "gpu_explicit_ms": r.gpu_ms[0],
                "gpu_implicit_ms": r.gpu_ms[1],
            })
        })
        .collect();
    let per_million = |ms: f64| ms * 1e6 / headline.masses as f64;
    let report = serde_json::json!({
        "model": headline.model,
        "masses": headline.masses,
        "explicit_ms": headline.ms[0],
        "implicit_ms": headline.ms[1],
        "explicit_ms_per_million": per_million(headline.ms[0]),
        "implicit_ms_per_million": per_million(headline.ms[1]),
        "threads": threads,
        "gpu_adapter": gpu_name,
        "gpu_software": gpu.map(|ctx| ctx.is_software()),
        "gpu_explicit_ms": headline.gpu_ms[0],
        "gpu_explicit_ms_per_million": headline.gpu_ms[0].map(per_million),
        "gpu_implicit_ms": headline.gpu_ms[1],
        "gpu_implicit_ms_per_million": headline.gpu_ms[1].map(per_million),
        "rows": list,
    });
    println!("{report}");
}

/// The figures as a table beside the targets and the paper's.
fn print_table(args: &DynamicsBenchArgs, rows: &[Row], gpu: Option<&GpuContext>) {
    let threads = rayon::current_num_threads();
    let headline = headline(rows);
    let gpu_name = gpu.map(|ctx| ctx.adapter_name());
    println!(
        "pelage bench dynamics — ms per step (median of {}), {threads} threads; gravity + gusting turbulent wind",
        args.steps.max(1)
    );
    println!(
        "explicit: symplectic Euler, substeps (sub.) as stability needs; implicit: backward Euler, 10 CG iterations (prisms) or a direct 3×3 solve per tip (no tip-tip springs)"
    );
    match &gpu_name {
        Some(name) => println!(
            "GPU: the same steps as compute shaders on {name} (implicit: where no springs join the tips), steps queued {} at a time\n",
            args.steps.max(1)
        ),
        None => println!(),
    }
    println!(
        "{:>8}  {:>24}  {:>10}  {:>10}  {:>4}  {:>11}  {:>11}  {:>14}  {:>12}  {:>12}",
        "model",
        "topology",
        "masses",
        "springs",
        "sub.",
        "explicit",
        "implicit",
        "M masses/s (impl.)",
        "GPU explicit",
        "GPU implicit"
    );
    for r in rows {
        println!(
            "{:>8}  {:>24}  {:>10}  {:>10}  {:>4}  {:>8.2} ms  {:>8.2} ms  {:>18.2}  {:>12}  {:>12}",
            r.model,
            r.topology.name(),
            thousands(r.masses as u64),
            thousands(r.springs as u64),
            r.substeps,
            r.ms[0],
            r.ms[1],
            r.masses as f64 / r.ms[1] / 1e3,
            r.gpu_ms[0].map_or("—".to_string(), |ms| format!("{ms:.2} ms")),
            r.gpu_ms[1].map_or("—".to_string(), |ms| format!("{ms:.2} ms"))
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
    if let Some(name) = &gpu_name {
        let software = gpu.is_some_and(|ctx| ctx.is_software());
        let verdict = |ms: Option<f64>, target: f64| match ms {
            Some(ms) => format!(
                "{:.2} ms ({})",
                per_million(ms),
                if per_million(ms) <= target {
                    "met"
                } else {
                    "missed"
                }
            ),
            None => "not measured".to_string(),
        };
        println!(
            "on the GPU ({name}{}), per 1 M masses: explicit ≤ 3 ms — {}; implicit ≤ 10 ms — {}",
            if software {
                ", a software rasteriser on this CPU"
            } else {
                ""
            },
            verdict(headline.gpu_ms[0], 3.0),
            verdict(headline.gpu_ms[1], 10.0),
        );
    }
    println!(
        "Banisch & Wüthrich (P4 1.7 GHz, 2006): 1,247–6,888 masses at 22–27 fps including rendering"
    );
}
