//! The gallery of shell fur for game characters, `docs/gallery/`:
//!
//! - `shells-fins.png`: the Fox mid-run without and with fins (Lengyel et
//!   al. 2001): with fins its outline reads as hair, not as stacked layers;
//! - `shells-lod-crowd.png`: 100 spots in ten rows from 8 to 35 units
//!   away, with every layer,
//!   with the level of detail, and the difference between the two ×4 —
//!   the screen-space error the level of detail makes — with the layers
//!   each row gets;
//! - `shells-fox-run.gif`: the Fox running with moving fur (the scene
//!   `examples/shells/fox.toml`, smaller).
//!
//! ```sh
//! cargo run --release -p pelage-gpu --example games_gallery
//! ```

use glam::Vec3;
use image::{GenericImage, Rgba, RgbaImage};
use pelage::settings::SettingsSource;
use pelage::shell::ShellScene;
use pelage_gpu::{
    Camera, FinParams, GpuContext, ShellLod, ShellParams, ShellScenePlayer, ShellView,
};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = GpuContext::headless()?;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let gallery = root.join("docs/gallery");
    let fox_file = root.join("examples/shells/fox.toml");
    let fox_text = std::fs::read_to_string(&fox_file)?;

    // The Fox without and with fins, held at 0.3 s of its run.
    let still = SettingsSource {
        path: fox_file.clone(),
        text: fox_text.replace("frames = 48", "frames = 1"),
    };
    let scene = ShellScene::from_source(&still)?;
    let (w, h) = (560, 400);
    let mut player = ShellScenePlayer::new(&ctx, &scene, w, h)?;
    // Closer on the back and the tail, where the outline is long.
    let view = ShellView::new(
        Some(Camera {
            eye: Vec3::new(150.0, 70.0, -20.0),
            target: Vec3::new(0.0, 45.0, -20.0),
            fov_y_degrees: 30.0,
        }),
        scene.mesh.bounds(),
        scene.fur.length,
        w as f32 / h as f32,
        scene.light,
    );
    player.view = view;
    player.params.fins = None;
    let without = player.render_at(&ctx, 0.3)?;
    player.params.fins = Some(FinParams::default());
    let with = player.render_at(&ctx, 0.3)?;
    let mut pair = RgbaImage::new(2 * w, h);
    pair.copy_from(&without, 0, 0)?;
    pair.copy_from(&with, w, 0)?;
    pair.save(gallery.join("shells-fins.png"))?;
    println!("wrote shells-fins.png");

    crowd(&ctx, &gallery)?;

    // The run, small, 48 frames at 24 fps.
    let run = SettingsSource {
        path: fox_file,
        text: fox_text,
    };
    let scene = ShellScene::from_source(&run)?;
    let mut player = ShellScenePlayer::new(&ctx, &scene, 400, 300)?;
    let frames: Vec<RgbaImage> = (0..scene.frames)
        .map(|f| player.render_at(&ctx, f as f32 / scene.fps))
        .collect::<Result<_, _>>()?;
    write_gif(&gallery.join("shells-fox-run.gif"), &frames, scene.fps)?;
    println!("wrote shells-fox-run.gif");
    Ok(())
}

/// 100 spots in ten rows of ten: every layer, the level of detail, and
/// their difference ×4.
fn crowd(ctx: &GpuContext, gallery: &Path) -> Result<(), Box<dyn std::error::Error>> {
    use pelage_gpu::{ShellFeatures, ShellRenderer, ShellTarget};
    let scene = ShellScene::spot();
    let (w, h) = (480, 360);
    let renderer = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let textures = pelage::shell::ShellTextures::generate(&pelage::shell::ShellTextureParams {
        layers: 32,
        ..scene.texture
    });
    let model = renderer.upload(ctx, &scene.mesh, &scene.color, &textures, 64)?;
    let target = ShellTarget::new(ctx, &renderer, w, h)?;
    // The layout of `pelage bench shells`' crowd.
    let eye = Vec3::new(0.0, 4.0, 6.0);
    let view = ShellView {
        clip_from_world: Camera {
            eye,
            target: Vec3::new(0.0, 0.0, -20.0),
            fov_y_degrees: 40.0,
        }
        .clip_from_world(w as f32 / h as f32, 80.0),
        eye,
        light: Vec3::new(0.4, 0.9, 0.5).normalize(),
    };
    let offsets: Vec<Vec3> = (0..100)
        .map(|i| {
            let (row, column) = ((i / 10) as f32, (i % 10) as f32);
            Vec3::new((column - 4.5) * 1.8, 0.0, -2.0 - 3.0 * row)
        })
        .collect();
    let base = ShellParams {
        layers: 32,
        ..ShellParams::from_scene(&scene)
    };
    let draw = |lod: Option<ShellLod>| -> Result<RgbaImage, Box<dyn std::error::Error>> {
        let objects: Vec<_> = offsets
            .iter()
            .map(|&offset| {
                (
                    &model,
                    ShellParams {
                        offset,
                        lod,
                        ..base
                    },
                )
            })
            .collect();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let resolve = target.resolve_view();
        renderer.encode_all(ctx, &mut encoder, &objects, &view, &target, &resolve)?;
        Ok(pelage_gpu::read_texture(ctx, encoder, target.resolved())?)
    };
    let all = draw(None)?;
    let lod = draw(Some(ShellLod::default()))?;
    let diff = RgbaImage::from_fn(w, h, |x, y| {
        let (a, b) = (all.get_pixel(x, y), lod.get_pixel(x, y));
        let d = (0..3).map(|c| a.0[c].abs_diff(b.0[c])).max().unwrap_or(0);
        let v = 255u8.saturating_sub(d.saturating_mul(4));
        Rgba([v, v, v, 255])
    });
    let mut strip = RgbaImage::new(3 * w, h);
    strip.copy_from(&all, 0, 0)?;
    strip.copy_from(&lod, w, 0)?;
    strip.copy_from(&diff, 2 * w, 0)?;
    strip.save(gallery.join("shells-lod-crowd.png"))?;
    let levels: Vec<String> = (0..10)
        .map(|row| {
            let p = ShellParams {
                offset: offsets[row * 10 + 5],
                lod: Some(ShellLod::default()),
                ..base
            };
            format!("{:.1}", renderer.level(&model, &p, &view, h as f32).layers)
        })
        .collect();
    println!(
        "wrote shells-lod-crowd.png; layers by row, near to far: {}",
        levels.join(", ")
    );
    Ok(())
}

fn write_gif(
    path: &Path,
    frames: &[RgbaImage],
    fps: f32,
) -> Result<(), Box<dyn std::error::Error>> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let delay = image::Delay::from_numer_denom_ms(1000, fps.round() as u32);
    let mut encoder = GifEncoder::new_with_speed(std::fs::File::create(path)?, 20);
    encoder.set_repeat(Repeat::Infinite)?;
    for frame in frames {
        encoder.encode_frame(image::Frame::from_parts(frame.clone(), 0, 0, delay))?;
    }
    Ok(())
}
