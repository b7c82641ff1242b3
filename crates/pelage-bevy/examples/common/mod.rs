//! What both examples share: their command line (`--frames N
//! --screenshot PNG --no-fur --size WxH --headless --timing`), the app
//! (Bevy's default plugins on pelage's asset folder, with the Fox, and
//! [`PelagePlugin`]), a window or, headless, an image to draw into, and
//! the screenshot taken after N frames, then exit.

use bevy::app::ScheduleRunnerPlugin;
use bevy::camera::RenderTarget;
use bevy::prelude::*;
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy::render::renderer::RenderDevice;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::render::{Render, RenderApp, RenderSystems};
use bevy::time::TimeUpdateStrategy;
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;
use pelage_bevy::PelagePlugin;
use std::path::PathBuf;
use std::time::Duration;

/// The examples' command line.
#[derive(Resource, Debug, Clone)]
pub struct Args {
    /// Stop after this many frames (with `--screenshot`, after saving it).
    pub frames: Option<u32>,
    /// Save the last frame here.
    pub screenshot: Option<PathBuf>,
    /// Leave the fur off (the same app and scene, for comparison).
    pub no_fur: bool,
    /// Window size.
    pub size: (u32, u32),
    /// Print the median frame time at the end (the benchmark reads it);
    /// each frame then waits for the GPU to finish it.
    pub timing: bool,
    /// No window: draw into an image (servers, the benchmark).
    pub headless: bool,
    /// Fur from a groom file (`GroomFur`: strands near, its shell
    /// stand-in far) rather than a shells file.
    pub groom: bool,
    /// The camera's distance from the character (`None`: the example's).
    pub distance: Option<f32>,
}

impl Args {
    /// Reads `std::env::args`, exiting with a message on a bad one.
    pub fn parse(default_size: (u32, u32)) -> Self {
        let mut args = Args {
            frames: None,
            screenshot: None,
            no_fur: false,
            size: default_size,
            timing: false,
            headless: false,
            groom: false,
            distance: None,
        };
        let mut it = std::env::args().skip(1);
        while let Some(a) = it.next() {
            let mut value = |name: &str| {
                it.next().unwrap_or_else(|| {
                    eprintln!("{name} needs a value");
                    std::process::exit(2)
                })
            };
            match a.as_str() {
                "--frames" => {
                    args.frames = Some(value("--frames").parse().unwrap_or_else(|_| {
                        eprintln!("--frames takes a whole number");
                        std::process::exit(2)
                    }))
                }
                "--screenshot" => args.screenshot = Some(value("--screenshot").into()),
                "--no-fur" => args.no_fur = true,
                "--timing" => args.timing = true,
                "--headless" => args.headless = true,
                "--groom" => args.groom = true,
                "--distance" => {
                    args.distance = Some(value("--distance").parse().unwrap_or_else(|_| {
                        eprintln!("--distance takes a number (scene units)");
                        std::process::exit(2)
                    }))
                }
                "--size" => {
                    let v = value("--size");
                    let parsed = v
                        .split_once('x')
                        .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
                    args.size = parsed.unwrap_or_else(|| {
                        eprintln!("--size takes WIDTHxHEIGHT, e.g. 1280x720");
                        std::process::exit(2)
                    });
                }
                "-h" | "--help" => {
                    println!(
                        "options: --frames N  --screenshot PNG  --no-fur  --groom  --distance D  --size WxH  --headless  --timing"
                    );
                    std::process::exit(0)
                }
                other => {
                    eprintln!("unknown option {other} (try --help)");
                    std::process::exit(2)
                }
            }
        }
        args
    }
}

/// The Fox's fur as the command line asks: its shells file, or its
/// groom file's stand-in (`--groom`); none with `--no-fur`.
pub fn fox_fur(args: &Args, assets: &AssetServer, entity: &mut EntityCommands) {
    if args.no_fur {
        return;
    }
    if args.groom {
        entity.insert(pelage_bevy::GroomFur(assets.load("fox/fox.groom.toml")));
    } else {
        entity.insert(pelage_bevy::ShellFur(assets.load("fox/fox.shells.toml")));
    }
}

/// The Khronos Fox in pelage's asset folder.
const FOX: &str = "fox/Fox.gltf";

/// The Fox's scene, and a graph playing its Run clip (the glTF's third).
pub fn fox_scene_and_run(
    assets: &AssetServer,
    graphs: &mut Assets<AnimationGraph>,
) -> (
    Handle<WorldAsset>,
    Handle<AnimationGraph>,
    AnimationNodeIndex,
) {
    let (graph, index) =
        AnimationGraph::from_clip(assets.load(GltfAssetLabel::Animation(2).from_asset(FOX)));
    (
        assets.load(GltfAssetLabel::Scene(0).from_asset(FOX)),
        graphs.add(graph),
        index,
    )
}

/// A grass-green ground `size` units across and the sun (with shadow
/// maps if `shadows`), as both examples light their foxes.
pub fn ground_and_sun(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<StandardMaterial>,
    size: f32,
    shadows: bool,
) {
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(size, size))),
        MeshMaterial3d(materials.add(Color::srgb(0.32, 0.42, 0.28))),
    ));
    commands.spawn((
        DirectionalLight {
            illuminance: 8000.0,
            shadow_maps_enabled: shadows,
            ..default()
        },
        Transform::from_xyz(1.0, 2.0, 1.5).looking_at(Vec3::ZERO, Vec3::Y),
    ));
}

/// A fox's clip, to play once its scene has spawned, from `phase`
/// seconds in.
#[derive(Component)]
pub struct Running {
    /// The graph holding the clip.
    pub graph: Handle<AnimationGraph>,
    /// The clip's node.
    pub index: AnimationNodeIndex,
    /// Where in the clip to start (s).
    pub phase: f32,
}

/// Observer of a fox's scene: plays its [`Running`] clip on the scene's
/// animation player.
pub fn start_running(
    ready: On<bevy::world_serialization::WorldInstanceReady>,
    mut commands: Commands,
    children: Query<&Children>,
    running: Query<&Running>,
    mut players: Query<&mut AnimationPlayer>,
) {
    let Ok(run) = running.get(ready.entity) else {
        return;
    };
    for child in children.iter_descendants(ready.entity) {
        if let Ok(mut player) = players.get_mut(child) {
            player.play(run.index).repeat().seek_to(run.phase);
            commands
                .entity(child)
                .insert(AnimationGraphHandle(run.graph.clone()));
        }
    }
}

/// pelage's asset folder, where the Fox and its shells file are.
pub fn asset_folder() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../pelage/assets"))
}

/// Where a headless app draws (none: the window).
#[derive(Resource, Clone, Default)]
pub struct Target(pub Option<Handle<Image>>);

impl Target {
    /// Spawns the examples' camera, drawing into the window or the image.
    pub fn spawn_camera<'a>(&self, commands: &'a mut Commands) -> EntityCommands<'a> {
        let mut camera = commands.spawn((
            Camera3d::default(),
            // Bevy's default (TonyMcMapface) needs its LUT feature, which
            // these examples leave out to build faster.
            bevy::core_pipeline::tonemapping::Tonemapping::AcesFitted,
            Transform::default(),
        ));
        if let Some(h) = &self.0 {
            camera.insert(RenderTarget::Image(h.clone().into()));
        }
        camera
    }
}

/// The app both examples run: Bevy's default plugins on pelage's assets,
/// a window (or an image, `--headless`), pelage's plugin, and the frame
/// counter.
pub fn app(args: &Args, title: &str) -> App {
    let folder = asset_folder();
    let mut app = App::new();
    let assets = AssetPlugin {
        file_path: folder.display().to_string(),
        ..default()
    };
    if args.headless {
        app.add_plugins(
            DefaultPlugins
                .set(assets)
                .set(WindowPlugin {
                    primary_window: None,
                    exit_condition: ExitCondition::DontExit,
                    ..default()
                })
                .disable::<WinitPlugin>(),
        )
        .add_plugins(ScheduleRunnerPlugin::run_loop(Duration::ZERO));
    } else {
        app.add_plugins(DefaultPlugins.set(assets).set(WindowPlugin {
            primary_window: Some(Window {
                title: title.into(),
                resolution: args.size.into(),
                ..default()
            }),
            ..default()
        }));
    }
    app.insert_resource(args.clone())
        .insert_resource(GlobalAmbientLight {
            color: Color::WHITE,
            brightness: 600.0,
            ..default()
        })
        .add_plugins(PelagePlugin {
            asset_folder: Some(folder),
        })
        .add_plugins(RunFor);
    let target = args.headless.then(|| {
        let (w, h) = args.size;
        let mut image = Image::new_target_texture(w, h, TextureFormat::Rgba8UnormSrgb, None);
        image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
        app.world_mut().resource_mut::<Assets<Image>>().add(image)
    });
    app.insert_resource(Target(target));
    if args.timing
        && let Some(render) = app.get_sub_app_mut(RenderApp)
    {
        render.add_systems(Render, wait_for_gpu.after(RenderSystems::Render));
    }
    app
}

/// With `--timing`, each frame ends when the GPU has drawn it, so the
/// frame time counts the GPU's work, not only its submission.
fn wait_for_gpu(device: Res<RenderDevice>) {
    let _ = device.poll(bevy::render::render_resource::PollType::wait_indefinitely());
}

/// Counts frames from when the scene is ready and warm; with `--frames`, steps time by exactly 1/30 s a frame
/// (the same pictures on any machine), saves the screenshot and exits.
pub struct RunFor;

/// How many characters the scene has: frames count once every one of
/// them is running (and furred, unless `--no-fur`).
#[derive(Resource, Clone, Copy)]
pub struct Characters(pub usize);

/// Seconds since every character was running (and furred): what the
/// examples animate their props by, so a `--frames` picture shows the
/// same moment however long loading took.
#[derive(Resource, Default)]
pub struct SceneClock(pub f32);

/// Frames a ready scene is given before any counts: Bevy compiles
/// pipelines in the background and draws nothing with one not ready.
const WARM_UP: u32 = 30;

/// Frames drawn since the scene was ready and warm, and each one's wall
/// time.
#[derive(Resource, Default)]
struct FrameLog {
    ready: bool,
    warming: u32,
    frames: u32,
    last: Option<std::time::Instant>,
    times: Vec<f64>,
    asked: bool,
}

impl Plugin for RunFor {
    fn build(&self, app: &mut App) {
        let args = app.world().resource::<Args>().clone();
        if args.frames.is_some() {
            app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
                1.0 / 30.0,
            )));
        }
        app.init_resource::<FrameLog>()
            .init_resource::<SceneClock>()
            .add_systems(Last, count_frames);
    }
}

#[allow(clippy::too_many_arguments)]
fn count_frames(
    mut commands: Commands,
    args: Res<Args>,
    target: Res<Target>,
    characters: Res<Characters>,
    players: Query<&AnimationPlayer>,
    fur: Query<&pelage_bevy::FurLayers>,
    time: Res<Time>,
    mut clock: ResMut<SceneClock>,
    mut log: ResMut<FrameLog>,
    mut exit: MessageWriter<AppExit>,
) {
    if !log.ready {
        let furred: std::collections::HashSet<Entity> = fur.iter().map(|f| f.owner).collect();
        log.ready =
            players.iter().count() >= characters.0 && (args.no_fur || furred.len() >= characters.0);
        if !log.ready {
            return;
        }
    }
    clock.0 += time.delta_secs();
    if log.warming < WARM_UP {
        log.warming += 1;
        return;
    }
    let now = std::time::Instant::now();
    if let Some(last) = log.last {
        log.times.push((now - last).as_secs_f64() * 1e3);
    }
    log.last = Some(now);
    log.frames += 1;
    let Some(frames) = args.frames else {
        return;
    };
    if log.frames < frames || log.asked {
        return;
    }
    log.asked = true;
    if args.timing {
        let mut t = log.times.clone();
        t.sort_by(f64::total_cmp);
        let median = t.get(t.len() / 2).copied().unwrap_or(f64::NAN);
        println!("frame_ms {median:.3} frames {}", t.len());
    }
    match args.screenshot.clone() {
        Some(path) => {
            let shot = match &target.0 {
                Some(image) => Screenshot::image(image.clone()),
                None => Screenshot::primary_window(),
            };
            commands.spawn(shot).observe(
                move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
                    let saved = captured
                        .image
                        .clone()
                        .try_into_dynamic()
                        .map_err(|e| e.to_string())
                        .and_then(|i| i.to_rgb8().save(&path).map_err(|e| e.to_string()));
                    match saved {
                        Ok(()) => {
                            println!("wrote {}", path.display());
                            exit.write(AppExit::Success);
                        }
                        Err(e) => {
                            eprintln!("could not save {}: {e}", path.display());
                            exit.write(AppExit::error());
                        }
                    }
                },
            );
        }
        None => {
            exit.write(AppExit::Success);
        }
    }
}
