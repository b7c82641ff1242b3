//! Headless renders, checked for properties of the image a person would
//! see, not just that a file exists. They need a GPU adapter: lavapipe
//! (Mesa's software Vulkan) serves without a GPU. With
//! `PELAGE_REQUIRE_GPU=1` (CI) a missing adapter fails the tests; without
//! it they are skipped with a message.

use glam::Vec3;
use pelage_gpu::{Camera, GpuContext, PreviewScene, PreviewStyle, Renderer};
use std::sync::OnceLock;

mod common;

fn gpu() -> Option<&'static (GpuContext, Renderer)> {
    static GPU: OnceLock<Option<(GpuContext, Renderer)>> = OnceLock::new();
    GPU.get_or_init(|| {
        common::open_headless().map(|ctx| {
            let renderer = Renderer::new(&ctx);
            eprintln!("rendering on {}", ctx.adapter_name());
            (ctx, renderer)
        })
    })
    .as_ref()
}

const WHITE: [u8; 4] = [255, 255, 255, 255];

fn is(pixel: &image::Rgba<u8>, rgb: [u8; 3], tolerance: u8) -> bool {
    pixel.0[..3]
        .iter()
        .zip(rgb)
        .all(|(a, b)| a.abs_diff(b) <= tolerance)
}

#[test]
fn spot_fills_the_middle_and_leaves_the_corners_background() {
    let Some((ctx, renderer)) = gpu() else { return };
    let spot = pelage::assets::spot();
    let scene = PreviewScene {
        mesh: Some(&spot),
        points: &[],
        curves: None,
        skin_texture: None,
    };
    let image = renderer
        .render(ctx, &scene, &PreviewStyle::default(), None, 320, 240)
        .unwrap();
    for (x, y) in [(0, 0), (319, 0), (0, 239), (319, 239)] {
        assert_eq!(image.get_pixel(x, y).0, WHITE, "corner ({x}, {y})");
    }
    let skin = image.pixels().filter(|p| p.0 != WHITE).count() as f64;
    let fraction = skin / (320.0 * 240.0);
    // Auto-framing: the mesh is big in the picture but not cut off.
    assert!(
        (0.10..0.7).contains(&fraction),
        "skin covers {fraction:.3} of the image"
    );
    // Shaded, not flat: the skin shows a range of brightness.
    let brightness: Vec<u32> = image
        .pixels()
        .filter(|p| p.0 != WHITE)
        .map(|p| p.0[..3].iter().map(|&c| u32::from(c)).sum())
        .collect();
    let (lo, hi) = (
        brightness.iter().min().unwrap(),
        brightness.iter().max().unwrap(),
    );
    assert!(hi - lo > 90, "skin brightness spans only {lo}..{hi}");
}

#[test]
fn a_point_covers_about_a_disc_of_its_radius() {
    let Some((ctx, renderer)) = gpu() else { return };
    // A grid of points far apart, seen head-on.
    let points: Vec<Vec3> = (0..5)
        .flat_map(|i| (0..5).map(move |j| Vec3::new(i as f32 - 2.0, j as f32 - 2.0, 0.0)))
        .collect();
    let style = PreviewStyle {
        point: [0.0, 0.0, 1.0],
        point_radius: 4.0,
        ..Default::default()
    };
    let camera = Camera {
        eye: Vec3::new(0.0, 0.0, 20.0),
        target: Vec3::ZERO,
        fov_y_degrees: 30.0,
    };
    let scene = PreviewScene {
        mesh: None,
        points: &points,
        curves: None,
        skin_texture: None,
    };
    let image = renderer
        .render(ctx, &scene, &style, Some(camera), 256, 256)
        .unwrap();
    let blue = image.pixels().filter(|p| is(p, [0, 0, 255], 40)).count() as f64;
    let expected = 25.0 * std::f64::consts::PI * 16.0;
    assert!(
        (blue - expected).abs() < 0.3 * expected,
        "{blue} point pixels, expected about {expected:.0}"
    );
    // The centre point lands in the middle of the image.
    assert!(is(image.get_pixel(128, 128), [0, 0, 255], 40));
}

#[test]
fn points_behind_the_mesh_are_hidden_and_points_in_front_are_seen() {
    let Some((ctx, renderer)) = gpu() else { return };
    let spot = pelage::assets::spot();
    let (lo, hi) = spot.bounds();
    let center = 0.5 * (lo + hi);
    let camera = Camera {
        eye: center + Vec3::new(6.0, 0.0, 0.0),
        target: center,
        fov_y_degrees: 30.0,
    };
    let style = PreviewStyle {
        point: [0.0, 0.0, 1.0],
        point_radius: 6.0,
        ..Default::default()
    };
    let render = |p: Vec3| {
        let points = [p];
        let scene = PreviewScene {
            mesh: Some(&spot),
            points: &points,
            curves: None,
            skin_texture: None,
        };
        renderer
            .render(ctx, &scene, &style, Some(camera), 200, 200)
            .unwrap()
    };
    let count =
        |image: &image::RgbaImage| image.pixels().filter(|p| is(p, [0, 0, 255], 40)).count();
    // Centre of the body, on the far side (−x) and on the near side (+x).
    let behind = render(Vec3::new(lo.x - 0.05, center.y, center.z));
    let in_front = render(Vec3::new(hi.x + 0.05, center.y, center.z));
    assert_eq!(count(&behind), 0, "a point behind the mesh shows through");
    assert!(
        count(&in_front) > 50,
        "a point in front of the mesh is not drawn"
    );
}

#[test]
fn impossible_sizes_are_errors() {
    let Some((ctx, renderer)) = gpu() else { return };
    let scene = PreviewScene::default();
    let err = renderer
        .render(ctx, &scene, &PreviewStyle::default(), None, 0, 10)
        .unwrap_err();
    assert!(err.to_string().contains("cannot be rendered"), "{err}");
}

/// A straight curve along x from −1 to 1 (9 points) of constant `width`.
fn straight_curve(width: f32) -> pelage::Curves {
    let points: Vec<Vec3> = (0..9)
        .map(|i| Vec3::new(-1.0 + i as f32 * 0.25, 0.0, 0.0))
        .collect();
    pelage::Curves::new(points, vec![width; 9], vec![0, 9]).unwrap()
}

/// Covered area in pixels of black hair on white: each pixel's darkness,
/// in linear light, is its coverage.
fn covered_pixels(image: &image::RgbaImage) -> f64 {
    let linear = |c: u8| {
        let c = f64::from(c) / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    image.pixels().map(|p| 1.0 - linear(p.0[0])).sum()
}

fn render_curve(curves: &pelage::Curves, style: &PreviewStyle) -> Option<image::RgbaImage> {
    render_curve_from(Vec3::new(0.0, 0.0, 10.0), curves, style)
}

/// `curves` seen from `eye`, looking at the origin.
fn render_curve_from(
    eye: Vec3,
    curves: &pelage::Curves,
    style: &PreviewStyle,
) -> Option<image::RgbaImage> {
    let (ctx, renderer) = gpu()?;
    let camera = Camera {
        eye,
        target: Vec3::ZERO,
        fov_y_degrees: 30.0,
    };
    let scene = PreviewScene {
        mesh: None,
        points: &[],
        curves: Some(curves),
        skin_texture: None,
    };
    Some(
        renderer
            .render(ctx, &scene, style, Some(camera), 400, 400)
            .unwrap(),
    )
}

/// Pixels per world unit at distance 10 with a 30° field of view on 400 px.
fn pixels_per_unit() -> f64 {
    200.0 / (15f64.to_radians().tan()) / 10.0
}

#[test]
fn a_ribbon_covers_its_width_times_its_length() {
    let black = PreviewStyle {
        hair: [0.0, 0.0, 0.0],
        hair_specular: 0.0,
        ..Default::default()
    };
    let Some(image) = render_curve(&straight_curve(0.05), &black) else {
        return;
    };
    let expected = 2.0 * pixels_per_unit() * 0.05 * pixels_per_unit();
    let covered = covered_pixels(&image);
    assert!(
        (covered - expected).abs() < 0.15 * expected,
        "covered {covered:.0} px², expected {expected:.0}"
    );
}

#[test]
fn a_ribbon_seen_from_straight_above_is_as_wide_as_from_the_side() {
    // Looking straight down, world +y is the view direction: the hairs'
    // width in pixels must not be read off it (they vanished).
    let black = PreviewStyle {
        hair: [0.0, 0.0, 0.0],
        hair_specular: 0.0,
        ..Default::default()
    };
    let curve = straight_curve(0.05);
    let Some(above) = render_curve_from(Vec3::new(0.0, 10.0, 0.0), &curve, &black) else {
        return;
    };
    let expected = 2.0 * pixels_per_unit() * 0.05 * pixels_per_unit();
    let covered = covered_pixels(&above);
    assert!(
        (covered - expected).abs() < 0.15 * expected,
        "covered {covered:.0} px² from above, expected {expected:.0}"
    );
}

#[test]
fn a_hair_thinner_than_a_pixel_thins_instead_of_vanishing() {
    let black = PreviewStyle {
        hair: [0.0, 0.0, 0.0],
        hair_specular: 0.0,
        ..Default::default()
    };
    // 0.37 pixels wide: drawn one pixel wide at 0.37 coverage.
    let Some(image) = render_curve(&straight_curve(0.005), &black) else {
        return;
    };
    let expected = 2.0 * pixels_per_unit() * 0.005 * pixels_per_unit();
    let covered = covered_pixels(&image);
    assert!(
        covered > 0.5 * expected && covered < 1.6 * expected,
        "covered {covered:.0} px², expected {expected:.0}"
    );
}

#[test]
fn hair_is_drawn_in_its_colour() {
    let red = PreviewStyle {
        hair: [0.8, 0.05, 0.05],
        hair_specular: 0.0,
        ..Default::default()
    };
    let Some(image) = render_curve(&straight_curve(0.2), &red) else {
        return;
    };
    let center = image.get_pixel(200, 200).0;
    assert!(
        center[0] > 120 && center[1] < 90 && center[2] < 90,
        "centre pixel {center:?}"
    );
    assert_eq!(
        image.get_pixel(200, 20).0,
        WHITE,
        "background above the hair"
    );
}

#[test]
fn a_skin_texture_colours_the_mesh_at_its_uvs() {
    let Some((ctx, renderer)) = gpu() else { return };
    let spot = pelage::assets::spot();
    let texture = image::load_from_memory(pelage::assets::SPOT_TEXTURE_PNG)
        .unwrap()
        .to_rgba8();
    let white_skin = PreviewStyle {
        skin: [1.0, 1.0, 1.0],
        ..Default::default()
    };
    let render = |skin_texture| {
        let scene = PreviewScene {
            mesh: Some(&spot),
            points: &[],
            curves: None,
            skin_texture,
        };
        renderer
            .render(ctx, &scene, &white_skin, None, 320, 240)
            .unwrap()
    };
    // Spot's texture has dark patches; a lit white skin never falls below
    // its ambient (about 137 in sRGB), so dark pixels come from the texture.
    let dark = |image: &image::RgbaImage| {
        image
            .pixels()
            .filter(|p| p.0[..3].iter().all(|&c| c < 90))
            .count()
    };
    let (plain, textured) = (render(None), render(Some(&texture)));
    assert_eq!(
        dark(&plain),
        0,
        "an untextured white skin has no dark pixels"
    );
    assert!(
        dark(&textured) > 400,
        "only {} dark pixels with the texture",
        dark(&textured)
    );
}

#[test]
fn a_surface_format_renderer_draws_the_same_picture_through_encode() {
    // Window surfaces are Bgra8UnormSrgb on most platforms; the renderer
    // built for that format must draw what the offscreen one draws.
    let Some((ctx, rgba)) = gpu() else { return };
    let bgra = Renderer::for_format(ctx, wgpu::TextureFormat::Bgra8UnormSrgb);
    assert_eq!(bgra.format(), wgpu::TextureFormat::Bgra8UnormSrgb);
    let spot = pelage::assets::spot();
    let roots: Vec<pelage::SurfacePoint> = (0..300)
        .map(|i| pelage::SurfacePoint::new(i * 17, [0.3, 0.3]))
        .collect();
    let curves = pelage::Curves::along_normals(&spot, &roots, 0.1, 4, 0.01, 0.002);
    let scene = PreviewScene {
        mesh: Some(&spot),
        points: &[],
        curves: Some(&curves),
        skin_texture: None,
    };
    let style = PreviewStyle::default();
    let a = rgba.render(ctx, &scene, &style, None, 200, 150).unwrap();
    let b = bgra.render(ctx, &scene, &style, None, 200, 150).unwrap();
    let differing = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 1))
        .count();
    assert_eq!(differing, 0, "BGRA and RGBA renders differ");
    assert!(
        a.pixels().any(|p| p.0 != a.get_pixel(0, 0).0),
        "nothing was drawn"
    );
    let err = Renderer::for_format(ctx, wgpu::TextureFormat::Rgba16Float)
        .render(ctx, &scene, &style, None, 8, 8)
        .unwrap_err();
    assert!(err.to_string().contains("Rgba16Float"), "{err}");
}
