//! A hundred furred foxes running in a field: one shells file, one fur
//! mesh a level of detail shared by all, each fox's fur skinned by its own
//! joints and its layers chosen per camera by distance (fewer layers far
//! away). Prints frames per second every two seconds.
//!
//! ```text
//! cargo run --release -p pelage-bevy --example bevy_crowd
//! cargo run --release -p pelage-bevy --example bevy_crowd -- --frames 90 --screenshot crowd.png
//! ```

mod common;

use bevy::prelude::*;
use common::{Args, Running};

/// Foxes a side of the square.
const SIDE: i32 = 10;
/// Between neighbours (the fox is about 100 units long).
const SPACING: f32 = 200.0;

fn main() {
    let args = Args::parse((1280, 720));
    common::app(&args, "pelage in Bevy: a crowd of foxes")
        .insert_resource(common::Characters((SIDE * SIDE) as usize))
        .add_systems(Startup, setup)
        .add_systems(Update, (fly_over, report_fps))
        .run();
}

fn setup(
    mut commands: Commands,
    args: Res<Args>,
    target: Res<common::Target>,
    assets: Res<AssetServer>,
    mut graphs: ResMut<Assets<AnimationGraph>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let (scene, graph, index) = common::fox_scene_and_run(&assets, &mut graphs);
    for i in 0..SIDE * SIDE {
        let (x, z) = ((i % SIDE) as f32, (i / SIDE) as f32);
        let offset = (SIDE as f32 - 1.0) / 2.0;
        let mut fox = commands.spawn((
            WorldAssetRoot(scene.clone()),
            Transform::from_xyz((x - offset) * SPACING, 0.0, (z - offset) * SPACING)
                .with_rotation(Quat::from_rotation_y(0.3 * (i as f32 * 1.7).sin())),
            Running {
                graph: graph.clone(),
                index,
                phase: 0.7 * ((i as f32 * 0.37) % 1.0),
            },
        ));
        common::fox_fur(&args, &assets, &mut fox);
        fox.observe(common::start_running);
    }
    common::ground_and_sun(&mut commands, &mut meshes, &mut materials, 4000.0, false);
    target.spawn_camera(&mut commands);
}

/// The camera circles the field, near foxes close, far ones small.
fn fly_over(time: Res<Time>, mut cameras: Query<&mut Transform, With<Camera3d>>) {
    let a = 0.1 * time.elapsed_secs() + 0.5;
    for mut t in &mut cameras {
        let eye = Vec3::new(1500.0 * a.sin(), 520.0, 1500.0 * a.cos());
        *t = Transform::from_translation(eye).looking_at(Vec3::new(0.0, 0.0, 0.0), Vec3::Y);
    }
}

fn report_fps(time: Res<Time<Real>>, mut since: Local<f32>, mut frames: Local<u32>) {
    *frames += 1;
    *since += time.delta_secs();
    if *since >= 2.0 {
        println!("{:.1} frames/s", *frames as f32 / *since);
        *since = 0.0;
        *frames = 0;
    }
}
