//! pelage-bevy in a real Bevy app, rendered headless into an image on
//! whatever adapter wgpu finds (Mesa's lavapipe in CI). One test binary,
//! so Bevy is linked once. The Khronos Fox comes from Bevy's own glTF
//! loader; the fur from `fox/fox.shells.toml`.

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::log::LogPlugin;
use bevy::mesh::VertexAttributeValues;
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::pbr::ExtendedMaterial;
use bevy::prelude::*;
use bevy::render::gpu_readback::{Readback, ReadbackComplete};
use bevy::render::render_resource::TextureFormat;
use bevy::render::storage::ShaderBuffer;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;
use pelage_bevy::{
    ATTRIBUTE_SHELL_LAYER, FurForces, FurLayers, FurPositionProbe, FurPositionProbePlugin,
    GroomFur, GroomStrands, PelagePlugin, ProbedShellFurMaterial, ShellFur, ShellFurAsset,
    ShellFurMaterial, StrandsLod,
};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;
/// How far fur may reach past the skin on screen, in pixels: it is 2.5 %
/// of the fox's 150-unit diagonal, 3.8 units, at up to 2 pixels a unit
/// (the fox's face, 150 units from the camera; 45° over 240 pixels), with
/// gravity's sag and a pixel for rasterisation.
const FUR_PX: i32 = 10;
/// The clear colour: anything else in a picture is the scene.
const BACKGROUND: [u8; 3] = [0, 0, 0];

/// Bevy apps are heavy; on a two-core machine they take turns.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Whether an adapter exists (else the test says why and passes, unless
/// PELAGE_REQUIRE_GPU is set, as in CI).
fn gpu_available() -> bool {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        bevy::tasks::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()));
    match adapter {
        Ok(_) => true,
        Err(e) if std::env::var_os("PELAGE_REQUIRE_GPU").is_some() => {
            panic!("PELAGE_REQUIRE_GPU is set but no adapter: {e}")
        }
        Err(e) => {
            eprintln!("skipped: {e}");
            false
        }
    }
}

/// A headless app on `folder`, with this test's turn at the GPU; `None`
/// (the test passes, having said why) without an adapter.
fn headless(folder: &Path) -> Option<(MutexGuard<'static, ()>, Headless)> {
    if !gpu_available() {
        return None;
    }
    let turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    Some((turn, Headless::new(folder)))
}

fn pelage_assets() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../pelage/assets"))
}

/// A headless Bevy app drawing into an image, stepped frame by frame.
struct Headless {
    app: App,
    target: Handle<Image>,
}

impl Headless {
    fn new(folder: &Path) -> Self {
        let mut app = App::new();
        app.add_plugins(
            DefaultPlugins
                .set(AssetPlugin {
                    file_path: folder.display().to_string(),
                    watch_for_changes_override: Some(true),
                    ..default()
                })
                .set(WindowPlugin {
                    primary_window: None,
                    exit_condition: ExitCondition::DontExit,
                    ..default()
                })
                .disable::<WinitPlugin>()
                .disable::<LogPlugin>()
                // The render world stays in the app between frames, so a
                // test can ask its pipeline cache what is still compiling.
                .disable::<bevy::render::pipelined_rendering::PipelinedRenderingPlugin>(),
        )
        .add_plugins((
            PelagePlugin {
                asset_folder: Some(folder.to_path_buf()),
            },
            FurPositionProbePlugin,
        ))
        // No gravity: the coat's spring stays at rest, so pictures settle.
        .insert_resource(FurForces {
            gravity: Some(Vec3::ZERO),
            wind: Vec3::ZERO,
        })
        .insert_resource(ClearColor(Color::srgb_u8(
            BACKGROUND[0],
            BACKGROUND[1],
            BACKGROUND[2],
        )));
        app.finish();
        app.cleanup();
        let mut image =
            Image::new_target_texture(WIDTH, HEIGHT, TextureFormat::Rgba8UnormSrgb, None);
        image.texture_descriptor.usage |= bevy::render::render_resource::TextureUsages::COPY_SRC;
        let target = app.world_mut().resource_mut::<Assets<Image>>().add(image);
        let world = app.world_mut();
        world.spawn((
            Camera3d::default(),
            RenderTarget::Image(target.clone().into()),
            Tonemapping::None,
            Msaa::Off,
            Transform::from_xyz(0.0, 45.0, 190.0).looking_at(Vec3::new(0.0, 35.0, 0.0), Vec3::Y),
        ));
        world.spawn((
            DirectionalLight {
                illuminance: 6000.0,
                ..default()
            },
            Transform::from_xyz(0.5, 1.0, 1.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        Self { app, target }
    }

    fn frames(&mut self, n: u32) {
        for _ in 0..n {
            self.app.update();
        }
    }

    /// Steps until `ready` holds (assets loaded, a scene spawned), at most
    /// `limit` frames.
    fn until(&mut self, limit: u32, mut ready: impl FnMut(&mut World) -> bool) {
        for _ in 0..limit {
            self.app.update();
            if ready(self.app.world_mut()) {
                return;
            }
        }
        panic!("not ready after {limit} frames");
    }

    /// Steps until some fur is grown (its asset loaded, a fur entity
    /// spawned).
    fn until_furred(&mut self) {
        self.until(900, |world| {
            let mut q = world.query::<&FurLayers>();
            q.iter(world).next().is_some()
        });
    }

    /// The next frame's picture, RGB.
    fn picture(&mut self) -> image::RgbImage {
        let shot: Arc<Mutex<Option<Image>>> = Arc::default();
        let into = shot.clone();
        self.app
            .world_mut()
            .spawn(Screenshot::image(self.target.clone()))
            .observe(move |captured: On<ScreenshotCaptured>| {
                *into.lock().unwrap() = Some(captured.image.clone());
            });
        // Bevy takes it when the target has been drawn (pipelines being
        // compiled can hold a first frame back for a while).
        for frame in 0..400 {
            self.app.update();
            if let Some(image) = shot.lock().unwrap().take() {
                if frame > 20 {
                    eprintln!("screenshot after {frame} frames");
                }
                return image.try_into_dynamic().expect("an RGBA image").to_rgb8();
            }
        }
        panic!("no screenshot after 400 frames");
    }

    /// Whether Bevy is still compiling a pipeline.
    fn compiling(&self) -> bool {
        let render = self.app.sub_app(bevy::render::RenderApp);
        render
            .world()
            .resource::<bevy::render::render_resource::PipelineCache>()
            .waiting_pipelines()
            .next()
            .is_some()
    }

    /// A few frames for pipelines to compile (Bevy compiles them in the
    /// background and draws nothing with a pipeline not ready), then a
    /// picture with something in it that no longer changes.
    fn settled_picture(&mut self) -> image::RgbImage {
        let mut last = self.picture();
        for _ in 0..60 {
            self.frames(3);
            let next = self.picture();
            if next == last && count(&mask(&next)) > 0 && !self.compiling() {
                return next;
            }
            last = next;
        }
        panic!("the picture never settled");
    }
}

/// The Fox's scene root, once its meshes are spawned.
fn spawn_fox(h: &mut Headless, folder_fur: Option<&str>) -> Entity {
    let world = h.app.world_mut();
    let assets = world.resource::<AssetServer>().clone();
    let mut fox = world.spawn(WorldAssetRoot(
        assets.load(GltfAssetLabel::Scene(0).from_asset("fox/Fox.gltf")),
    ));
    if let Some(path) = folder_fur {
        fox.insert(ShellFur(assets.load(path.to_string())));
    }
    let fox = fox.id();
    h.until(600, |world| {
        let mut q = world.query::<&Mesh3d>();
        q.iter(world).next().is_some()
    });
    fox
}

fn with_fur(h: &mut Headless, fox: Entity, on: bool) {
    let world = h.app.world_mut();
    if on {
        let fur = world.resource::<AssetServer>().load("fox/fox.shells.toml");
        world.entity_mut(fox).insert(ShellFur(fur));
        h.until_furred();
    } else {
        world.entity_mut(fox).remove::<ShellFur>();
        h.frames(2);
    }
}

/// Pixels that are not the background.
fn mask(picture: &image::RgbImage) -> Vec<bool> {
    picture.pixels().map(|p| p.0 != BACKGROUND).collect()
}

/// Pixels that differ between two pictures.
fn differ(a: &image::RgbImage, b: &image::RgbImage) -> Vec<bool> {
    a.pixels().zip(b.pixels()).map(|(p, q)| p != q).collect()
}

/// `m` grown by `r` pixels.
fn dilate(m: &[bool], r: i32) -> Vec<bool> {
    let (w, h) = (WIDTH as i32, HEIGHT as i32);
    let mut out = vec![false; m.len()];
    for y in 0..h {
        for x in 0..w {
            if !m[(y * w + x) as usize] {
                continue;
            }
            for dy in -r..=r {
                for dx in -r..=r {
                    let (u, v) = (x + dx, y + dy);
                    if u >= 0 && v >= 0 && u < w && v < h {
                        out[(v * w + u) as usize] = true;
                    }
                }
            }
        }
    }
    out
}

fn count(m: &[bool]) -> usize {
    m.iter().filter(|&&b| b).count()
}

/// Turns the fox's head and tail (its joints, as an animation would), so
/// Bevy skins it into a new pose.
fn pose(h: &mut Headless, angle: f32) {
    let world = h.app.world_mut();
    let mut q = world.query::<(&Name, &mut Transform)>();
    for (name, mut t) in q.iter_mut(world) {
        if ["b_Neck_04", "b_Tail01_012", "b_Spine02_03"].contains(&name.as_str()) {
            t.rotate_local_z(angle);
        }
    }
    h.frames(2);
}

fn save_for_inspection(name: &str, picture: &image::RgbImage) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bevy");
    std::fs::create_dir_all(&dir).unwrap();
    picture.save(dir.join(name)).unwrap();
}

/// Fur shows on the fox and nowhere else; a cube in front hides it; and
/// after a pose change it is where the posed skin is, not where it was.
#[test]
fn fur_sits_on_the_fox_is_hidden_by_what_is_in_front_and_follows_its_pose() {
    let Some((_turn, mut h)) = headless(&pelage_assets()) else {
        return;
    };
    let fox = spawn_fox(&mut h, None);

    let bare = h.settled_picture();
    with_fur(&mut h, fox, true);
    let furred = h.settled_picture();
    save_for_inspection("bare.png", &bare);
    save_for_inspection("furred.png", &furred);
    let skin = mask(&bare);
    let fur = differ(&bare, &furred);
    assert!(count(&skin) > 2000, "the fox fills {} pixels", count(&skin));
    // The fur changes most of the fox's pixels...
    let on_skin = fur.iter().zip(&skin).filter(|(f, s)| **f && **s).count();
    assert!(
        on_skin as f64 > 0.5 * count(&skin) as f64,
        "fur on {on_skin} of {} fox pixels",
        count(&skin)
    );
    // ...and nothing farther from it than the fur is long on screen.
    let near = dilate(&skin, FUR_PX);
    let astray = fur.iter().zip(&near).filter(|(f, n)| **f && !**n).count();
    if astray > 0 {
        let mut debug = furred.clone();
        for (i, p) in debug.pixels_mut().enumerate() {
            if fur[i] && !near[i] {
                *p = image::Rgb([255, 0, 0]);
            }
        }
        save_for_inspection("astray.png", &debug);
    }
    assert_eq!(astray, 0, "{astray} fur pixels away from the fox");
    // It stands out past the bare silhouette.
    let outside = fur.iter().zip(&skin).filter(|(f, s)| **f && !**s).count();
    assert!(outside > 50, "fur beyond the silhouette: {outside} pixels");

    // A cube between the camera and the fox's front half.
    let cube = {
        let world = h.app.world_mut();
        let mesh = world
            .resource_mut::<Assets<Mesh>>()
            .add(Cuboid::new(24.0, 24.0, 2.0));
        let material = world
            .resource_mut::<Assets<StandardMaterial>>()
            .add(Color::srgb(0.2, 0.4, 0.9));
        world
            .spawn((
                Mesh3d(mesh),
                MeshMaterial3d(material),
                Transform::from_xyz(-12.0, 40.0, 70.0),
            ))
            .id()
    };
    let cube_furred = h.settled_picture();
    with_fur(&mut h, fox, false);
    let cube_bare = h.settled_picture();
    save_for_inspection("cube-furred.png", &cube_furred);
    let cube_pixels = differ(&bare, &cube_bare);
    let hidden_fur = differ(&cube_bare, &cube_furred);
    let inside = dilate(&cube_pixels.iter().map(|&c| !c).collect::<Vec<_>>(), 1);
    let through = hidden_fur
        .iter()
        .zip(&cube_pixels)
        .zip(&inside)
        .filter(|((f, c), edge)| **f && **c && !**edge)
        .count();
    assert!(
        count(&cube_pixels) > 1000,
        "the cube covers {}",
        count(&cube_pixels)
    );
    assert_eq!(through, 0, "{through} fur pixels drawn over the cube");
    assert!(count(&hidden_fur) > 500, "fur still shows beside the cube");
    h.app.world_mut().entity_mut(cube).despawn();

    // A new pose, skinned by Bevy: the fur goes with it.
    pose(&mut h, 0.5);
    let posed_bare = h.settled_picture();
    with_fur(&mut h, fox, true);
    let posed_furred = h.settled_picture();
    save_for_inspection("posed-furred.png", &posed_furred);
    let posed_skin = mask(&posed_bare);
    let posed_fur = differ(&posed_bare, &posed_furred);
    let moved = differ(&bare, &posed_bare);
    assert!(
        count(&moved) > 300,
        "the pose moved {} pixels",
        count(&moved)
    );
    let near = dilate(&posed_skin, FUR_PX);
    let astray = posed_fur
        .iter()
        .zip(&near)
        .filter(|(f, n)| **f && !**n)
        .count();
    assert_eq!(
        astray, 0,
        "{astray} posed fur pixels away from the posed fox"
    );
    // Where the skin left, no fur stayed behind.
    let left = skin
        .iter()
        .zip(&dilate(&posed_skin, FUR_PX))
        .map(|(was, is)| *was && !*is)
        .collect::<Vec<_>>();
    let stayed = posed_fur
        .iter()
        .zip(&left)
        .filter(|(f, l)| **f && **l)
        .count();
    assert!(
        count(&left) > 50,
        "the pose uncovered {} pixels",
        count(&left)
    );
    assert_eq!(stayed, 0, "{stayed} fur pixels where the skin was");

    // Levels of detail by the camera's distance: the file asks for layers
    // at most 0.75 pixels apart, so 24 layers near, 12 from about 120
    // units (3.8-unit fur, 240 pixels over 45°), 6 from about 245, 3 from
    // about 490, and none from about 1,470, where all the fur is shorter
    // than 0.75 pixels.
    for (distance, level) in [
        (80.0, Some(0)),
        (190.0, Some(1)),
        (350.0, Some(2)),
        (900.0, Some(3)),
        (2000.0, None),
    ] {
        let world = h.app.world_mut();
        let mut cameras = world.query_filtered::<&mut Transform, With<Camera3d>>();
        for mut t in cameras.iter_mut(world) {
            *t = Transform::from_xyz(0.0, 35.0, distance)
                .looking_at(Vec3::new(0.0, 35.0, 0.0), Vec3::Y);
        }
        h.frames(3);
        let world = h.app.world_mut();
        let mut fur = world.query::<(&FurLayers, &ViewVisibility)>();
        let mut drawn: Vec<usize> = fur
            .iter(world)
            .filter(|(_, v)| v.get())
            .map(|(f, _)| f.level)
            .collect();
        drawn.sort();
        drawn.dedup();
        assert_eq!(drawn, Vec::from_iter(level), "at {distance} units");
    }
}

/// Steps frames (in real time: the file watcher runs on its own thread)
/// until the fox's shells asset satisfies `edited`, at most 10 s.
fn wait_for_reload(h: &mut Headless, fox: Entity, edited: impl Fn(&ShellFurAsset) -> bool) {
    let done = |world: &mut World| {
        let handle = world.get::<ShellFur>(fox).unwrap().0.clone();
        world
            .resource::<Assets<ShellFurAsset>>()
            .get(&handle)
            .is_some_and(&edited)
    };
    for _ in 0..200 {
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.frames(1);
        if done(h.app.world_mut()) {
            return;
        }
    }
    panic!("the edit was not reloaded in 10 s");
}

/// Editing the shells file while the app runs regrows the fur: longer
/// fur covers more of the picture.
#[test]
fn a_changed_shells_file_changes_the_picture() {
    let dir = tempfile::tempdir().unwrap();
    let fox_dir = dir.path().join("fox");
    std::fs::create_dir_all(&fox_dir).unwrap();
    for f in ["Fox.gltf", "fox.png", "fox.shells.toml"] {
        std::fs::copy(pelage_assets().join("fox").join(f), fox_dir.join(f)).unwrap();
    }
    let shells = fox_dir.join("fox.shells.toml");
    let text = std::fs::read_to_string(&shells).unwrap();
    std::fs::write(&shells, text.replace("[fur]\n", "[fur]\nlength = 2.0\n")).unwrap();

    let Some((_turn, mut h)) = headless(dir.path()) else {
        return;
    };
    let fox = spawn_fox(&mut h, Some("fox/fox.shells.toml"));
    h.until_furred();
    let short = h.settled_picture();

    std::fs::write(&shells, text.replace("[fur]\n", "[fur]\nlength = 9.0\n")).unwrap();
    // The file watcher reports the change and the asset is read again.
    wait_for_reload(&mut h, fox, |a| a.length == 9.0);
    let long = h.settled_picture();
    save_for_inspection("reload-short.png", &short);
    save_for_inspection("reload-long.png", &long);
    assert!(long != short, "the picture did not change after the edit");
    assert!(
        count(&mask(&long)) > count(&mask(&short)) + 200,
        "longer fur covers {} pixels, shorter {}",
        count(&mask(&long)),
        count(&mask(&short))
    );

    // Curl, and droplets that wet the fur into clumps: the same fur,
    // curled and clumped, draws differently.
    let wet = text.replace("[fur]\n", "[fur]\nlength = 9.0\n")
        + "\n[curl]\nradius = 0.5\nturns = 1.5\n\n[[droplets]]\ncount = 300\nradius = [0.03, 0.06]\nseed = 3\n";
    std::fs::write(&shells, wet).unwrap();
    wait_for_reload(&mut h, fox, |a| a.curl.radius > 0.0 && a.wetness.is_some());
    let wet_picture = h.settled_picture();
    save_for_inspection("reload-curled.png", &wet_picture);
    let changed = count(&differ(&long, &wet_picture));
    assert!(changed > 500, "curl and clumps changed {changed} pixels");
}

/// A groom file on the Fox is drawn as the shell fur that stands in for
/// it, on the fox and only near it; taking the groom away takes the fur.
#[test]
fn a_groom_wears_its_shell_stand_in() {
    let Some((_turn, mut h)) = headless(&pelage_assets()) else {
        return;
    };
    let fox = spawn_fox(&mut h, None);
    let bare = h.settled_picture();
    let world = h.app.world_mut();
    let groom = world.resource::<AssetServer>().load("fox/fox.groom.toml");
    world.entity_mut(fox).insert(GroomFur(groom));
    h.until_furred();
    let furred = h.settled_picture();
    save_for_inspection("groom-furred.png", &furred);
    let skin = mask(&bare);
    let fur = differ(&bare, &furred);
    let on_skin = fur.iter().zip(&skin).filter(|(f, s)| **f && **s).count();
    assert!(
        on_skin as f64 > 0.5 * count(&skin) as f64,
        "the stand-in on {on_skin} of {} fox pixels",
        count(&skin)
    );
    // The guides are 6 units long: up to 12 pixels here, and the sag.
    let near = dilate(&skin, 15);
    let astray = fur.iter().zip(&near).filter(|(f, n)| **f && !**n).count();
    assert_eq!(astray, 0, "{astray} stand-in pixels away from the fox");

    h.app.world_mut().entity_mut(fox).remove::<GroomFur>();
    h.frames(3);
    let world = h.app.world_mut();
    let mut q = world.query::<&FurLayers>();
    assert_eq!(q.iter(world).count(), 0, "the fur went with the groom");
}

/// A mesh Bevy made itself, not skinned (a UV sphere), wears fur too:
/// the layers follow its transform, and the fur stands past its outline.
#[test]
fn a_still_bevy_mesh_wears_fur_too() {
    let Some((_turn, mut h)) = headless(&pelage_assets()) else {
        return;
    };
    let world = h.app.world_mut();
    let mesh = world
        .resource_mut::<Assets<Mesh>>()
        .add(Sphere::new(30.0).mesh().uv(48, 24));
    let material = world
        .resource_mut::<Assets<StandardMaterial>>()
        .add(Color::srgb(0.5, 0.4, 0.3));
    let ball = world
        .spawn((
            Mesh3d(mesh),
            MeshMaterial3d(material),
            Transform::from_xyz(0.0, 35.0, 0.0),
        ))
        .id();
    let bare = h.settled_picture();
    let fur = h
        .app
        .world_mut()
        .resource::<AssetServer>()
        .load("fox/fox.shells.toml");
    h.app.world_mut().entity_mut(ball).insert(ShellFur(fur));
    h.until_furred();
    let furred = h.settled_picture();
    save_for_inspection("sphere-furred.png", &furred);
    let skin = mask(&bare);
    let changed = differ(&bare, &furred);
    let outside = changed
        .iter()
        .zip(&skin)
        .filter(|(c, s)| **c && !**s)
        .count();
    let near = dilate(&skin, FUR_PX);
    let astray = changed
        .iter()
        .zip(&near)
        .filter(|(c, n)| **c && !**n)
        .count();
    assert!(
        count(&changed) > count(&skin) / 2,
        "fur on {} of {}",
        count(&changed),
        count(&skin)
    );
    assert!(outside > 100, "fur past the outline: {outside} pixels");
    assert_eq!(astray, 0, "{astray} fur pixels away from the sphere");
}

/// A fur entity's shell material swapped for the probed one, and what it
/// reads back.
struct Probe {
    fur: Entity,
    /// The fur's mesh as the plugin made it (its own copy went to the
    /// GPU): the skin's vertices once a layer.
    mesh: Mesh,
    material: ShellFurMaterial,
    buffer: Handle<ShaderBuffer>,
}

impl Probe {
    /// Probes the fur level the camera shows.
    fn on_visible_level(h: &mut Headless) -> Self {
        let world = h.app.world_mut();
        let mut q = world.query::<(
            Entity,
            &FurLayers,
            &ViewVisibility,
            &MeshMaterial3d<ShellFurMaterial>,
        )>();
        let (fur, level, _, material) = q
            .iter(world)
            .find(|(_, _, seen, ..)| seen.get())
            .expect("a fur level in view");
        eprintln!("probing level {} ({} layers)", level.level, level.layers);
        let (skin, layers, material) = (level.skin, level.layers, material.0.clone());
        let skin = world.get::<Mesh3d>(skin).unwrap().0.clone();
        let skin = world.resource::<Assets<Mesh>>().get(&skin).unwrap();
        let mesh = pelage_bevy::fur_mesh(skin, layers).unwrap();
        let vertices = mesh.count_vertices();
        let material = world
            .resource::<Assets<ShellFurMaterial>>()
            .get(&material)
            .unwrap()
            .clone();
        let buffer = world
            .resource_mut::<Assets<ShaderBuffer>>()
            .add(FurPositionProbe::buffer(vertices));
        let probed = world
            .resource_mut::<Assets<ProbedShellFurMaterial>>()
            .add(ExtendedMaterial {
                base: material.clone(),
                extension: FurPositionProbe {
                    positions: buffer.clone(),
                },
            });
        world
            .entity_mut(fur)
            .remove::<MeshMaterial3d<ShellFurMaterial>>()
            .insert(MeshMaterial3d(probed));
        Self {
            fur,
            mesh,
            material,
            buffer,
        }
    }

    /// The positions a frame drawn from now on stored (`None`: a vertex
    /// never drawn).
    fn read(&self, h: &mut Headless) -> Vec<Option<Vec3>> {
        FurPositionProbe::positions(&read_buffer(h, self.buffer.clone()))
    }

    /// Where the fur's vertices belong by Bevy's skinning of the fox now
    /// and pelage's strand model: each vertex's joint matrices (the
    /// joints' world transforms times their inverse bind poses, as Bevy
    /// skins with), weighted, carry its root and rest tip, and the layer
    /// lies along pelage's coupled strand between them.
    fn expected(&self, h: &mut Headless) -> Vec<Vec3> {
        let world = h.app.world_mut();
        let skin = world.get::<SkinnedMesh>(self.fur).unwrap().clone();
        let joints: Vec<Mat4> = {
            let bindposes = world.resource::<Assets<SkinnedMeshInverseBindposes>>();
            let bindposes = bindposes.get(&skin.inverse_bindposes).unwrap();
            skin.joints
                .iter()
                .zip(bindposes.iter())
                .map(|(&j, ibp)| world.get::<GlobalTransform>(j).unwrap().affine() * *ibp)
                .collect()
        };
        let mesh = &self.mesh;
        let vec3s = |a| match mesh.attribute(a) {
            Some(VertexAttributeValues::Float32x3(v)) => v.clone(),
            other => panic!("{other:?}"),
        };
        let (positions, normals) = (
            vec3s(Mesh::ATTRIBUTE_POSITION),
            vec3s(Mesh::ATTRIBUTE_NORMAL),
        );
        let Some(VertexAttributeValues::Uint16x4(indices)) =
            mesh.attribute(Mesh::ATTRIBUTE_JOINT_INDEX)
        else {
            panic!("joint indices");
        };
        let Some(VertexAttributeValues::Float32x4(weights)) =
            mesh.attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT)
        else {
            panic!("joint weights");
        };
        let Some(VertexAttributeValues::Uint32(layers)) = mesh.attribute(ATTRIBUTE_SHELL_LAYER)
        else {
            panic!("layers");
        };
        let u = &self.material.fur;
        let coupling = match u.coupling {
            0 => pelage::shell::Coupling::Bezier,
            1 => pelage::shell::Coupling::Linear,
            _ => pelage::shell::Coupling::Bent {
                exponent: u.coupling_exponent,
            },
        };
        let pelage_vec = |v: Vec3| glam::Vec3::from_array(v.to_array());
        (0..positions.len())
            .map(|i| {
                let m: Mat4 = (0..4)
                    .map(|k| joints[indices[i][k] as usize] * weights[i][k])
                    .fold(Mat4::ZERO, |a, b| a + b);
                let p = Vec3::from(positions[i]);
                let n = Vec3::from(normals[i]).normalize();
                let root = m.transform_point3(p);
                let rest_tip = m.transform_point3(p + u.length * n);
                let strand = pelage::shell::Strand {
                    root: pelage_vec(root),
                    rest_tip: pelage_vec(rest_tip),
                    tip: pelage_vec(rest_tip + u.tip_offset),
                };
                let h = pelage::shell::math::layer_height(layers[i], u.layers);
                root + Vec3::from_array(strand.coupled_offset(coupling, h).to_array())
            })
            .collect()
    }
}

/// The largest distance between drawn and expected positions, over the
/// fox's size; panics if a vertex was never drawn.
fn worst(drawn: &[Option<Vec3>], expected: &[Vec3]) -> f32 {
    assert_eq!(drawn.len(), expected.len());
    let missing = drawn.iter().filter(|p| p.is_none()).count();
    assert_eq!(
        missing,
        0,
        "{missing} of {} fur vertices never drawn",
        drawn.len()
    );
    let (lo, hi) = expected
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let size = (hi - lo).length();
    drawn
        .iter()
        .zip(expected)
        .map(|(d, e)| d.unwrap().distance(*e) / size)
        .fold(0.0, f32::max)
}

/// Every fur vertex Bevy draws, read back from the GPU, lies within 1e-5
/// of the fox's size of where Bevy's skinning and pelage's strand put it:
/// at rest and after a pose change that moved the fur by far more.
#[test]
fn fur_vertices_are_where_bevy_skins_the_fox() {
    let Some((_turn, mut h)) = headless(&pelage_assets()) else {
        return;
    };
    // Back far enough that the posed fox's head stays in view.
    let world = h.app.world_mut();
    let mut cameras = world.query_filtered::<&mut Transform, With<Camera3d>>();
    *cameras.single_mut(world).unwrap() =
        Transform::from_xyz(0.0, 45.0, 300.0).looking_at(Vec3::new(0.0, 45.0, 0.0), Vec3::Y);
    spawn_fox(&mut h, Some("fox/fox.shells.toml"));
    h.until_furred();
    h.frames(3);
    let probe = Probe::on_visible_level(&mut h);
    let still = probe.read(&mut h);
    let still_expected = probe.expected(&mut h);
    let still_error = worst(&still, &still_expected);
    pose(&mut h, 0.5);
    let posed = probe.read(&mut h);
    let posed_expected = probe.expected(&mut h);
    let posed_error = worst(&posed, &posed_expected);
    let moved = worst(&posed, &still_expected);
    eprintln!(
        "{} fur vertices: drawn within {still_error:.1e} (still) and {posed_error:.1e} (posed) \
         of the fox's size of Bevy's skinning; the pose moved them up to {moved:.3}",
        still.len()
    );
    assert!(still_error < 1e-5, "still: {still_error:e}");
    assert!(posed_error < 1e-5, "posed: {posed_error:e}");
    assert!(moved > 0.05, "the pose moved the fur by only {moved}");
}

/// The latest readback of `buffer` taken after `h` has drawn a few more
/// frames, with its pipelines compiled (readbacks already under way land
/// first).
fn read_buffer(h: &mut Headless, buffer: Handle<ShaderBuffer>) -> Vec<u8> {
    let latest: Arc<Mutex<Option<Vec<u8>>>> = Arc::default();
    let into = latest.clone();
    let reader = h
        .app
        .world_mut()
        .spawn(Readback::buffer(buffer))
        .observe(move |read: On<ReadbackComplete>| {
            *into.lock().unwrap() = Some(read.data.clone());
        })
        .id();
    h.frames(5);
    while h.compiling() {
        h.frames(1);
    }
    h.frames(3);
    latest.lock().unwrap().take();
    for _ in 0..100 {
        h.frames(1);
        if let Some(bytes) = latest.lock().unwrap().take() {
            h.app.world_mut().entity_mut(reader).despawn();
            return bytes;
        }
    }
    panic!("no readback after 100 frames");
}

/// The groom `path` as pelage grows it on the CPU, carried to `posed`
/// (pelage's skin vertices): hair id → its points; the render hairs' ids
/// in the GPU's order; the skin's size.
fn cpu_groom_on(path: &Path, posed: &[Vec3]) -> (HashMap<u64, Vec<glam::Vec3>>, Vec<u64>, f32) {
    let groom = pelage::groom::Groom::load(path).unwrap();
    let generator = groom.generator(None).unwrap();
    let (roots, ids) = pelage::groom::roots_by_arrival(&generator);
    let recipe = pelage::groom::GroomRecipe::new(&generator, &roots, &ids).unwrap();
    let render = recipe.render_hairs();
    let render_ids = recipe.ids[render.start as usize..render.end as usize].to_vec();
    let mesh = generator.mesh();
    let triangles = mesh.triangles().to_vec();
    let rest = pelage::anim::SkinPose::new(mesh.positions().to_vec(), &triangles);
    let binding = pelage::anim::SkinBinding::new(triangles, rest);
    let pose = binding.pose(
        posed
            .iter()
            .map(|p| glam::Vec3::from_array(p.to_array()))
            .collect(),
    );
    let mut hairs = HashMap::new();
    for p in 0..generator.parts().len() {
        let mut part = generator.part(p).unwrap();
        assert!(binding.carry_in_place(&mut part, &pose));
        for (c, &id) in part.ids().unwrap().iter().enumerate() {
            hairs.insert(id, part.points()[part.range(c)].to_vec());
        }
    }
    let (lo, hi) = mesh.bounds();
    (hairs, render_ids, (hi - lo).max_element())
}

/// A groom's hairs grown on the GPU through Bevy's renderer, read back,
/// are pelage's CPU groom carried to the skin as Bevy posed it: every
/// point of every hair, matched by id, within 1e-4 of the fox's size.
/// Drawn near, the strands cover the fox; far, its shell stand-in is
/// drawn instead and the strands are not. (The Fox's groom with a fifth
/// of its roots, to keep the debug build's CPU groom quick;
/// pelage-gpu's tests grow the whole of it.)
#[test]
fn a_groom_grows_as_strands_on_the_gpu_near_and_gives_way_to_its_stand_in_far() {
    let dir = tempfile::tempdir().unwrap();
    let fox_dir = dir.path().join("fox");
    std::fs::create_dir_all(&fox_dir).unwrap();
    for f in ["Fox.gltf", "fox.png"] {
        std::fs::copy(pelage_assets().join("fox").join(f), fox_dir.join(f)).unwrap();
    }
    let groom_path = fox_dir.join("fox.groom.toml");
    let text = std::fs::read_to_string(pelage_assets().join("fox/fox.groom.toml")).unwrap();
    assert!(text.contains("count = 40000"));
    std::fs::write(&groom_path, text.replace("count = 40000", "count = 8000")).unwrap();
    let Some((_turn, mut h)) = headless(dir.path()) else {
        return;
    };
    // Every strand at any size on screen, for the comparison.
    h.app.insert_resource(StrandsLod(pelage_bevy::FurLod {
        full_px: 1.0,
        ..default()
    }));
    let fox = spawn_fox(&mut h, None);
    let bare = h.settled_picture();
    let world = h.app.world_mut();
    let groom = world.resource::<AssetServer>().load("fox/fox.groom.toml");
    world.entity_mut(fox).insert(GroomFur(groom));
    h.until(900, |world| {
        let mut q = world.query::<&GroomStrands>();
        q.iter(world).any(|s| s.drawn > 0)
    });
    pose(&mut h, 0.4);
    let world = h.app.world_mut();
    let mut q = world.query::<&GroomStrands>();
    let strands = q.single(world).unwrap().clone();
    let bytes = read_buffer(&mut h, strands.points().clone());
    let world = h.app.world_mut();
    let mut q = world.query::<&GroomStrands>();
    let posed = q.single(world).unwrap().posed_skin();
    let (cpu, render_ids, size) = cpu_groom_on(&groom_path, &posed);
    let (hairs, n, render) = strands.layout();
    let gpu: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
    assert_eq!(gpu.len(), (hairs * n) as usize);
    let mut far = 0f32;
    for (r, h_index) in render.clone().enumerate() {
        let cpu_points = cpu.get(&render_ids[r]).expect("a CPU hair of that id");
        assert_eq!(cpu_points.len(), n as usize);
        for (j, p) in cpu_points.iter().enumerate() {
            let g = gpu[j * hairs as usize + h_index as usize];
            far = far.max(p.distance(glam::Vec3::new(g[0], g[1], g[2])));
        }
    }
    eprintln!(
        "{} hairs of {n} points grown on the GPU in Bevy: within {:.1e} of the fox's size of the CPU's",
        render.len(),
        far / size
    );
    assert_eq!(render.len(), cpu.len(), "as many hairs on both");
    assert!(
        far <= 1e-4 * size,
        "a point {far} from the CPU's (size {size})"
    );
    let near = h.settled_picture();
    save_for_inspection("strands-near.png", &near);
    let changed = count(&differ(&bare, &near));
    let fox_px = count(&mask(&bare));
    eprintln!("strands change {changed} of the fox's {fox_px} pixels");
    assert!(
        changed * 2 > fox_px,
        "strands change only {changed} of {fox_px} pixels"
    );
    // Looking away: Bevy culls the strands by the bounds the plugin gives
    // them each frame, and the render world grows none.
    let world = h.app.world_mut();
    let mut cameras = world.query_filtered::<&mut Transform, With<Camera3d>>();
    let mut camera = cameras.single_mut(world).unwrap();
    let facing = *camera;
    camera.look_at(facing.translation + facing.back().as_vec3(), Vec3::Y);
    h.frames(3);
    let world = h.app.world_mut();
    let mut q = world.query_filtered::<&ViewVisibility, With<GroomStrands>>();
    assert!(!q.single(world).unwrap().get(), "culled behind the camera");
    let mut cameras = world.query_filtered::<&mut Transform, With<Camera3d>>();
    *cameras.single_mut(world).unwrap() = facing;
    h.frames(3);
    let world = h.app.world_mut();
    let mut q = world.query_filtered::<&ViewVisibility, With<GroomStrands>>();
    assert!(q.single(world).unwrap().get(), "seen again in front of it");
    // Far, with the default level of detail: the stand-in only.
    h.app.insert_resource(StrandsLod::default());
    let world = h.app.world_mut();
    let mut cameras = world.query_filtered::<&mut Transform, With<Camera3d>>();
    *cameras.single_mut(world).unwrap() =
        Transform::from_xyz(0.0, 45.0, 900.0).looking_at(Vec3::new(0.0, 35.0, 0.0), Vec3::Y);
    h.frames(3);
    let world = h.app.world_mut();
    let mut q = world.query::<(&GroomStrands, &Visibility)>();
    let (far_strands, shown) = q.single(world).unwrap();
    assert_eq!(far_strands.drawn, 0);
    assert_eq!(*shown, Visibility::Hidden);
    let mut shells = world.query::<(&FurLayers, &Visibility)>();
    assert!(
        shells.iter(world).any(|(_, v)| *v != Visibility::Hidden),
        "the stand-in is shown far away"
    );
}
