//! The Khronos Fox, loaded by Bevy's glTF loader and running round a
//! circle, wearing pelage's shell fur (`fox/fox.shells.toml`): Bevy skins
//! the fur with the fox's own joints, the coat sways as the fox turns and
//! hangs with gravity, a ball passes in front and hides it, the sun lights
//! both. Drag with the left mouse button to orbit, scroll to zoom; hold W
//! for wind (pelage's `FurForces`).
//!
//! ```text
//! cargo run --release -p pelage-bevy --example bevy_fox
//! cargo run --release -p pelage-bevy --example bevy_fox -- --frames 60 --screenshot fox.png
//! ```
//!
//! `--no-fur` draws the same scene without fur (the benchmark's baseline);
//! `--groom` furs it from `fox/fox.groom.toml` (`GroomFur`) instead.

mod common;

use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::prelude::*;
use common::{Args, Running};

fn main() {
    let args = Args::parse((1280, 720));
    common::app(&args, "pelage in Bevy: the Fox")
        .insert_resource(common::Characters(1))
        .add_systems(Startup, setup)
        .add_systems(Update, (run_round, orbit, pass_the_ball, blow))
        .run();
}

/// The camera's orbit about the fox.
#[derive(Component)]
struct Orbit {
    yaw: f32,
    pitch: f32,
    distance: f32,
}

/// The ball that passes between the camera and the fox.
#[derive(Component)]
struct Ball;

/// The fox, running round the field's centre.
#[derive(Component)]
struct Fox;

/// Radius of the fox's circle, and its speed (the Run clip's pace).
const CIRCLE: f32 = 60.0;
const SPEED: f32 = 110.0;

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
    let mut fox = commands.spawn((
        Fox,
        WorldAssetRoot(scene),
        Running {
            graph,
            index,
            phase: 0.0,
        },
    ));
    common::fox_fur(&args, &assets, &mut fox);
    fox.observe(common::start_running);

    common::ground_and_sun(&mut commands, &mut meshes, &mut materials, 600.0, true);
    commands.spawn((
        Ball,
        Mesh3d(meshes.add(Sphere::new(14.0).mesh().uv(48, 24))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.75, 0.2, 0.15),
            perceptual_roughness: 0.35,
            ..default()
        })),
        Transform::from_xyz(0.0, 30.0, 90.0),
    ));
    target.spawn_camera(&mut commands).insert(Orbit {
        yaw: 0.6,
        pitch: 0.3,
        distance: args.distance.unwrap_or(190.0),
    });
}

/// The fox runs round the circle (its clip runs in place): the entity
/// moves and turns, and its coat's spring feels it.
fn run_round(clock: Res<common::SceneClock>, mut foxes: Query<&mut Transform, With<Fox>>) {
    let angle = SPEED / CIRCLE * clock.0;
    for mut t in &mut foxes {
        t.translation = CIRCLE * Vec3::new(angle.cos(), 0.0, -angle.sin());
        // The glTF fox faces +z; it runs along the circle's tangent.
        let heading = Vec3::new(-angle.sin(), 0.0, -angle.cos());
        t.rotation = Quat::from_rotation_arc(Vec3::Z, heading);
    }
}

/// Hold W: wind across the field, pulling every coat (a resource).
fn blow(keys: Res<ButtonInput<KeyCode>>, mut forces: ResMut<pelage_bevy::FurForces>) {
    forces.wind = if keys.pressed(KeyCode::KeyW) {
        Vec3::new(400.0, 0.0, 0.0)
    } else {
        Vec3::ZERO
    };
}

/// The camera orbits the running fox: drag to turn, scroll to zoom; left
/// alone, it circles slowly.
fn orbit(
    time: Res<Time>,
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    foxes: Query<&Transform, (With<Fox>, Without<Orbit>)>,
    mut cameras: Query<(&mut Orbit, &mut Transform)>,
) {
    let fox = foxes.iter().next().map_or(Vec3::ZERO, |t| t.translation);
    for (mut orbit, mut transform) in &mut cameras {
        if buttons.pressed(MouseButton::Left) {
            orbit.yaw -= motion.delta.x * 0.005;
            orbit.pitch = (orbit.pitch + motion.delta.y * 0.005).clamp(-0.2, 1.4);
        } else {
            orbit.yaw += 0.15 * time.delta_secs();
        }
        orbit.distance = (orbit.distance * (1.0 - 0.1 * scroll.delta.y)).clamp(40.0, 3000.0);
        let target = fox + Vec3::new(0.0, 35.0, 0.0);
        let eye = target
            + orbit.distance
                * Vec3::new(
                    orbit.yaw.sin() * orbit.pitch.cos(),
                    orbit.pitch.sin(),
                    orbit.yaw.cos() * orbit.pitch.cos(),
                );
        *transform = Transform::from_translation(eye).looking_at(target, Vec3::Y);
    }
}

/// The camera's transform, apart from the fox's and the ball's.
type OnlyTheCamera = (With<Camera3d>, Without<Ball>, Without<Fox>);

/// The ball swings across the line between the camera and the fox.
fn pass_the_ball(
    clock: Res<common::SceneClock>,
    cameras: Query<&Transform, OnlyTheCamera>,
    foxes: Query<&Transform, (With<Fox>, Without<Ball>)>,
    mut balls: Query<&mut Transform, With<Ball>>,
) {
    let (Ok(camera), Ok(fox)) = (cameras.single(), foxes.single()) else {
        return;
    };
    let target = fox.translation + Vec3::new(0.0, 30.0, 0.0);
    let towards = (camera.translation - target).normalize_or_zero();
    let across = towards.cross(Vec3::Y).normalize_or_zero();
    // Before the fox's face a second and a quarter after the scene is
    // ready (the sixth frame a `--frames` run counts), then to either side.
    let swing = (0.8 * (clock.0 - 1.2)).sin() * 70.0;
    for mut ball in &mut balls {
        ball.translation = target + 70.0 * towards + swing * across;
    }
}
