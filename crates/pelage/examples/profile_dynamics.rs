//! Profiling harness for the mass-spring step (`perf record` it):
//! spring-sticks on spot ×4 (749,570 masses) in gusting turbulent wind,
//! explicit then implicit, 20 steps each. `TURBULENCE=0` turns the wind's
//! noise off, to see what it costs.
use glam::Vec3;
use pelage::dynamics::{DynamicsParams, MassSpringSystem, Solver, Topology, Wind};

fn main() {
    let mesh = pelage::assets::spot().subdivided(4);
    let turbulence: f32 = std::env::var("TURBULENCE")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(2.0);
    let params = DynamicsParams {
        wind: Some(Wind::new(
            Vec3::new(3.0, 0.0, 1.0),
            0.6,
            0.7,
            turbulence,
            4.0,
            1,
        )),
        ..Default::default()
    };
    for solver in [
        Solver::Explicit { substeps: 1 },
        Solver::Implicit { iterations: 10 },
    ] {
        let mut system = MassSpringSystem::new(&mesh, Topology::SpringSticks, 0.05);
        let mut times = Vec::new();
        for k in 0..20 {
            let t = std::time::Instant::now();
            system.step(1.0 / 60.0, &params, solver, k as f32 / 60.0);
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        eprintln!("{}: median {:.2} ms a step", solver.name(), times[10]);
    }
}
