//! The GPU's explicit mass-spring step — and its implicit one, where no
//! springs join the tips — against the CPU's
//! (`pelage::dynamics`): every topology on spot, in gusting turbulent wind
//! with gravity and a brush, some tips started inside the skin or
//! overstretched so the constraints act; after 80 substeps (more than one
//! submission's worth) the two states must agree. Needs an adapter
//! (lavapipe serves); `PELAGE_REQUIRE_GPU=1` (CI) makes a missing one a
//! failure.

use glam::Vec3;
use pelage::dynamics::{DynamicsParams, MassSpringSystem, PushBrush, Solver, Topology, Wind};
use pelage_gpu::GpuMassSpring;
mod common;

use common::gpu;

/// Gusting turbulent wind, gravity and a brush over `mesh`.
fn windy_brushed(mesh: &pelage::Mesh) -> DynamicsParams {
    let (lo, hi) = mesh.bounds();
    DynamicsParams {
        wind: Some(Wind::new(Vec3::new(3.0, 0.0, 1.0), 0.8, 1.5, 4.0, 3.0, 7)),
        brush: Some(PushBrush {
            centre: mesh.positions()[0],
            radius: 0.3 * (hi - lo).length(),
            force: Vec3::new(0.0, 0.0, 0.02),
        }),
        ..Default::default()
    }
}

/// Every seventh tip starts inside the skin, every eleventh stretched to
/// twice its length: the constraints must bring them back alike.
fn displace_some_tips(cpu: &mut MassSpringSystem, length: f32) {
    for i in 0..cpu.mass_count() {
        let (root, n) = (cpu.roots()[i], cpu.normals()[i]);
        if i % 7 == 0 {
            cpu.set_tip(i, root - 0.5 * length * n, Vec3::ZERO);
        } else if i % 11 == 0 {
            cpu.set_tip(i, root + 2.0 * length * n, -n);
        }
    }
}

/// The GPU's state read back against the CPU's, both stepped from
/// `start`: the fur must have moved, and the two agree to 1e-3 L0 (tips)
/// and 1e-2 (velocities, relative).
fn assert_gpu_matches_cpu(
    label: &str,
    gpu_state: (Vec<Vec3>, Vec<Vec3>),
    cpu: &MassSpringSystem,
    start: &[Vec3],
    length: f32,
) {
    let (tips, velocities) = gpu_state;
    let moved = start
        .iter()
        .zip(cpu.tips())
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    assert!(
        moved > 0.2 * length,
        "{label}: the fur hardly moved ({moved}), the comparison would prove little"
    );
    let worst = tips
        .iter()
        .zip(cpu.tips())
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    let worst_velocity = velocities
        .iter()
        .zip(cpu.velocities())
        .map(|(a, b)| a.distance(*b) / (1.0 + b.length()))
        .fold(0.0f32, f32::max);
    eprintln!(
        "{label}: {} masses, moved up to {:.3} L0, GPU − CPU up to {:.2e} L0, velocity {:.2e}",
        cpu.mass_count(),
        moved / length,
        worst / length,
        worst_velocity
    );
    assert!(
        worst <= 1e-3 * length,
        "{label}: GPU and CPU tips differ by {worst} (L0 = {length})"
    );
    assert!(
        worst_velocity <= 1e-2,
        "{label}: GPU and CPU velocities differ by {worst_velocity}"
    );
}

#[test]
fn the_gpu_explicit_step_matches_the_cpu_one() {
    let Some(ctx) = gpu() else { return };
    let mesh = pelage::assets::spot();
    let (lo, hi) = mesh.bounds();
    let length = 0.03 * (hi - lo).length();
    let params = windy_brushed(&mesh);
    let (dt, substeps, steps) = (1.0 / 60.0, 2, 40);
    for topology in Topology::ALL {
        let mut cpu = MassSpringSystem::new(&mesh, topology, length);
        displace_some_tips(&mut cpu, length);
        let start = cpu.tips().to_vec();
        let mut gpu_system = GpuMassSpring::new(ctx, &cpu).expect("upload");
        gpu_system.step_explicit(ctx, dt, &params, substeps, 0.0, steps);
        for k in 0..steps {
            cpu.step(dt, &params, Solver::Explicit { substeps }, k as f32 * dt);
        }
        let state = gpu_system.read_state(ctx).expect("read back");
        assert_gpu_matches_cpu(&format!("{topology:?}"), state, &cpu, &start, length);
    }
}

/// The implicit step (backward Euler, a 3×3 solve per tip) on the GPU
/// against the CPU's, for the topologies whose tips no springs join, at a
/// stiffness and step where the explicit solver diverges; prisms are
/// refused with an error that says what to do.
#[test]
fn the_gpu_implicit_step_matches_the_cpu_one() {
    let Some(ctx) = gpu() else { return };
    let mesh = pelage::assets::spot();
    let (lo, hi) = mesh.bounds();
    let length = 0.03 * (hi - lo).length();
    let params = DynamicsParams {
        stiffness: 40.0,
        ..windy_brushed(&mesh)
    };
    let (dt, steps) = (1.0 / 30.0, 40);
    for topology in Topology::ALL {
        let mut cpu = MassSpringSystem::new(&mesh, topology, length);
        if topology.joins_tips() {
            let mut gpu_system = GpuMassSpring::new(ctx, &cpu).expect("upload");
            assert!(!gpu_system.steps_implicit());
            let error = gpu_system
                .step_implicit(ctx, dt, &params, 0.0, 1)
                .expect_err("prisms' implicit step is the CPU's");
            assert!(error.to_string().contains("explicit solver"), "{error}");
            continue;
        }
        assert!(
            cpu.stable_substeps(dt, &params) > 1,
            "{topology:?}: one explicit step of this size must be unstable, or the implicit solver proves little"
        );
        displace_some_tips(&mut cpu, length);
        let start = cpu.tips().to_vec();
        let mut gpu_system = GpuMassSpring::new(ctx, &cpu).expect("upload");
        gpu_system
            .step_implicit(ctx, dt, &params, 0.0, steps)
            .expect("no tip-tip springs");
        for k in 0..steps {
            cpu.step(
                dt,
                &params,
                Solver::Implicit { iterations: 10 },
                k as f32 * dt,
            );
        }
        let state = gpu_system.read_state(ctx).expect("read back");
        assert_gpu_matches_cpu(
            &format!("{topology:?} implicit"),
            state,
            &cpu,
            &start,
            length,
        );
    }
}

#[test]
fn the_gpu_state_downloads_into_the_system_it_came_from_only() {
    let Some(ctx) = gpu() else { return };
    let mesh = pelage::assets::spot();
    let params = DynamicsParams {
        wind: Some(Wind::new(Vec3::new(2.0, 0.0, 0.0), 0.5, 1.0, 1.0, 3.0, 1)),
        ..Default::default()
    };
    let mut system = MassSpringSystem::new(&mesh, Topology::Prisms, 0.05);
    let rest = system.tips().to_vec();
    let mut on_gpu = GpuMassSpring::new(ctx, &system).expect("upload");
    on_gpu.step_explicit(ctx, 1.0 / 60.0, &params, 1, 0.0, 10);
    on_gpu.download_into(ctx, &mut system).expect("read back");
    let (tips, _) = on_gpu.read_state(ctx).expect("read back");
    assert_eq!(system.tips(), &tips[..]);
    assert_ne!(system.tips(), &rest[..], "ten windy steps moved the fur");
    let mut other = MassSpringSystem::new(&mesh, Topology::SeparablePrisms, 0.05);
    let error = on_gpu
        .download_into(ctx, &mut other)
        .expect_err("a system of another size is refused");
    assert!(error.to_string().contains("masses"), "{error}");
}

/// A windy shaken scene, animated with the CPU's explicit solver and with
/// `gpu = true`: the frames must match (the renderer reads the GPU's tips
/// in place), and the fur must have moved.
#[test]
fn a_scene_stepped_on_the_gpu_renders_as_on_the_cpu() {
    let Some(ctx) = gpu() else { return };
    let base = "[fur]\nlayers = 8\nlength = 0.08\n[texture]\nresolution = 64\n[animation]\nfps = 8\n\
        [dynamics]\ntopology = \"prisms\"\nsolver = \"explicit\"\nsubsteps = 8\n\
        [dynamics.wind]\nvelocity = [6, 0, 2]\nturbulence = 3\n\
        [dynamics.shake]\namplitude = [0.05, 0, 0]\nfrequency = 4\n";
    let frames = |gpu: bool| {
        let text = base.replace("substeps = 8\n", &format!("substeps = 8\ngpu = {gpu}\n"));
        let scene = pelage::shell::ShellScene::from_source(&pelage::settings::SettingsSource {
            path: "windy.toml".into(),
            text,
        })
        .expect("scene");
        assert_eq!(scene.dynamics.as_ref().unwrap().gpu, gpu);
        let mut player = pelage_gpu::ShellScenePlayer::new(ctx, &scene, 160, 120).expect("player");
        [0.0, 0.5].map(|t| player.render_at(ctx, t).expect("frame"))
    };
    let differing = |a: &image::RgbaImage, b: &image::RgbaImage| {
        a.pixels()
            .zip(b.pixels())
            .filter(|(p, q)| (0..3).any(|c| p.0[c].abs_diff(q.0[c]) > 8))
            .count()
    };
    let [cpu_start, cpu_later] = frames(false);
    let [gpu_start, gpu_later] = frames(true);
    let moved = differing(&cpu_start, &cpu_later);
    let apart = differing(&cpu_later, &gpu_later);
    eprintln!("fur moved in {moved} pixels; GPU and CPU frames differ in {apart}");
    assert!(
        moved > 160 * 120 / 100,
        "the fur hardly moved: {moved} pixels"
    );
    assert_eq!(differing(&cpu_start, &gpu_start), 0);
    assert!(
        apart <= 160 * 120 / 500,
        "{apart} pixels differ between GPU and CPU stepping"
    );
}
