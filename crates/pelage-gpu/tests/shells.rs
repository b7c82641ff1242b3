//! The shell shaders against the Rust reference (`pelage::shell::math`):
//! a flat square seen straight down through an orthographic camera, one
//! pixel per texel of the shell texture and of the wetness mask, so every
//! pixel's colour can be computed on the CPU — skin, then each layer's
//! Alg. 2 decision, texture lookups, Eq. 6 and alpha blending, in order —
//! and compared with what the GPU drew. Needs an adapter (lavapipe serves);
//! `PELAGE_REQUIRE_GPU=1` (CI) makes a missing one a failure.

use glam::{Vec2, Vec3};
use pelage::Mesh;
use pelage::mesh::Uvs;
use pelage::shell::math::{
    ClumpDecision, ClumpParams, Coupling, CurlParams, KajiyaKay, ShadingMode, Strand,
    clump_fragment, coupled_layer_offset, coupled_strand_tangent, layer_height, shade,
};
use pelage::shell::{Droplet, ShellTextureParams, ShellTextures, WetnessMask};
use pelage_gpu::{GpuContext, ShellFeatures, ShellParams, ShellRenderer, ShellTarget, ShellView};
mod common;

use common::gpu;

/// Pixels, texels and mask texels per side.
const SIZE: u32 = 64;

/// The unit square in the y = 0 plane, normal +y, UV (x, 1 − z): mask
/// coordinates are then (x, z), and with the camera's up along −z image
/// pixel (i, j) lies over mask texel (i, j).
fn square() -> Mesh {
    let positions = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let uvs = positions
        .iter()
        .map(|p| Vec2::new(p.x, 1.0 - p.z))
        .collect();
    Mesh::new(
        "square",
        positions,
        vec![[0, 2, 1], [0, 3, 2]],
        Some(vec![Vec3::Y; 4]),
        Some(Uvs::PerVertex(uvs)),
    )
    .unwrap()
}

const EYE: Vec3 = Vec3::new(0.5, 10.0, 0.5);

fn view(light: Vec3) -> ShellView {
    let view = glam::camera::rh::view::look_at_mat4(EYE, Vec3::new(0.5, 0.0, 0.5), -Vec3::Z);
    let projection = glam::camera::rh::proj::directx::orthographic(-0.5, 0.5, -0.5, 0.5, 1.0, 20.0);
    ShellView {
        clip_from_world: projection * view,
        eye: EYE,
        light,
    }
}

/// A colour texture with something to see: a gradient, 16×16.
fn color_image() -> image::RgbaImage {
    image::RgbaImage::from_fn(16, 16, |x, y| {
        image::Rgba([(40 + 13 * x) as u8, (200 - 9 * y) as u8, 90, 255])
    })
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// The colour texture as the GPU reads an sRGB texture with a linear,
/// clamping sampler: decoded, then filtered.
fn sample_color(image: &image::RgbaImage, uv: Vec2) -> Vec3 {
    let (w, h) = (image.width() as f32, image.height() as f32);
    let (x, y) = (uv.x * w - 0.5, uv.y * h - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let texel = |dx: f32, dy: f32| {
        let px = (x0 + dx).clamp(0.0, w - 1.0) as u32;
        let py = (y0 + dy).clamp(0.0, h - 1.0) as u32;
        let p = image.get_pixel(px, py).0;
        Vec3::new(
            srgb_to_linear(f32::from(p[0]) / 255.0),
            srgb_to_linear(f32::from(p[1]) / 255.0),
            srgb_to_linear(f32::from(p[2]) / 255.0),
        )
    };
    texel(0.0, 0.0) * (1.0 - fx) * (1.0 - fy)
        + texel(1.0, 0.0) * fx * (1.0 - fy)
        + texel(0.0, 1.0) * (1.0 - fx) * fy
        + texel(1.0, 1.0) * fx * fy
}

struct Case {
    features: ShellFeatures,
    params: ShellParams,
    textures: ShellTextures,
    mask: WetnessMask,
    light: Vec3,
    /// Every corner's tip moved by this (`p − p0`).
    tip_offset: Vec3,
}

/// What the shaders should draw, pixel by pixel, from the reference
/// functions.
fn reference(case: &Case) -> image::RgbaImage {
    let p = &case.params;
    let color = color_image();
    let l = case.light.normalize();
    let n = Vec3::Y;
    let (u, v) = (Vec3::X, Vec3::Y.cross(Vec3::X));
    let curl = if case.features.curl {
        p.curl
    } else {
        CurlParams {
            radius: 0.0,
            frequency: 0.0,
        }
    };
    image::RgbaImage::from_fn(SIZE, SIZE, |i, j| {
        let pixel = Vec2::new(
            (i as f32 + 0.5) / SIZE as f32,
            (j as f32 + 0.5) / SIZE as f32,
        );
        let skin = Vec3::new(pixel.x, 0.0, pixel.y);
        let e = (EYE - skin).normalize();
        let mut out = shade(
            p.mode,
            sample_color(&color, pixel),
            0.0,
            n,
            n,
            l,
            e,
            0.0,
            p.kajiya_kay,
        );
        for layer in 0..p.layers {
            let h = layer_height(layer, p.layers);
            // Every vertex of the square has the same frame and wetness
            // (the mask is uniform at its corners in the curl case), so the
            // whole layer moves by one offset: the pixel sees the layer
            // point that was under pixel − offset.
            let wet_vertex = case.mask.at(Vec2::ZERO).wetness;
            let mut strand = Strand::at_rest(Vec3::ZERO, n, p.length);
            strand.tip += case.tip_offset;
            let offset = coupled_layer_offset(p.coupling, &strand, h, wet_vertex, curl, u, v);
            let uv = pixel - Vec2::new(offset.x, offset.z);
            if !(0.0..=1.0).contains(&uv.x) || !(0.0..=1.0).contains(&uv.y) {
                continue;
            }
            let world = skin + Vec3::new(0.0, offset.y, 0.0);
            let t_strand = coupled_strand_tangent(p.coupling, &strand, h, wet_vertex, curl, u, v);
            let (mut uv_color, mut uv_geo) = (uv, uv * p.tiles);
            if case.features.clump {
                let here = case.mask.at(uv);
                match clump_fragment(uv, here, h, p.layers, p.clump, |q| case.mask.at(q)) {
                    ClumpDecision::Dry => {}
                    ClumpDecision::Displaced(d) => {
                        uv_color += d;
                        uv_geo += d * p.tiles;
                    }
                    ClumpDecision::DifferentClump | ClumpDecision::DryTarget => continue,
                }
            }
            let fur = case.textures.sample(layer, uv_geo);
            if fur[3] == 0.0 {
                continue;
            }
            let lean = (2.0 * fur[0] - 1.0) * u - (2.0 * fur[1] - 1.0) * n.cross(u);
            let t = (t_strand + lean).normalize();
            let e = (EYE - world).normalize();
            let c = shade(
                p.mode,
                sample_color(&color, uv_color),
                fur[2],
                t,
                n,
                l,
                e,
                h,
                p.kajiya_kay,
            );
            out = c * fur[3] + out * (1.0 - fur[3]);
        }
        image::Rgba([
            (255.0 * linear_to_srgb(out.x)).round() as u8,
            (255.0 * linear_to_srgb(out.y)).round() as u8,
            (255.0 * linear_to_srgb(out.z)).round() as u8,
            255,
        ])
    })
}

fn draw(ctx: &GpuContext, case: &Case) -> image::RgbaImage {
    let renderer = ShellRenderer::new(ctx, case.features);
    let model = renderer
        .upload(ctx, &square(), &color_image(), &case.textures, SIZE)
        .unwrap();
    renderer.set_wetness(ctx, &model, &case.mask).unwrap();
    let corners = vec![case.tip_offset; 6];
    renderer.set_tip_offsets(ctx, &model, &corners).unwrap();
    let target = ShellTarget::new(ctx, &renderer, SIZE, SIZE).unwrap();
    renderer
        .render(ctx, &model, &case.params, &view(case.light), &target)
        .unwrap()
}

/// Compares the images: the share of pixels more than 2/255 apart in any
/// channel, and the largest difference.
fn compare(gpu: &image::RgbaImage, cpu: &image::RgbaImage) -> (f64, u8) {
    let mut off = 0;
    let mut worst = 0u8;
    for (a, b) in gpu.pixels().zip(cpu.pixels()) {
        let diff = (0..3).map(|c| a.0[c].abs_diff(b.0[c])).max().unwrap();
        worst = worst.max(diff);
        off += usize::from(diff > 2);
    }
    (off as f64 / f64::from(SIZE * SIZE), worst)
}

fn params(layers: u32) -> ShellParams {
    ShellParams {
        layers,
        length: 0.05,
        tiles: 1.0,
        curl: CurlParams {
            radius: 0.0,
            frequency: 0.0,
        },
        coupling: Coupling::Bezier,
        offset: Vec3::ZERO,
        clump: ClumpParams {
            w: 0.5,
            strength: 3.0,
        },
        mode: ShadingMode::KajiyaKay,
        kajiya_kay: KajiyaKay {
            specular: Vec3::splat(0.3),
            exponent: 8.0,
            k_shadow: 2.0,
        },
        background: [0.0, 0.0, 1.0],
        fins: None,
        lod: None,
        opacity: 1.0,
    }
}

fn textures(layers: u32) -> ShellTextures {
    ShellTextures::generate(&ShellTextureParams {
        resolution: SIZE,
        layers,
        density: 0.04,
        thickness: 1.6,
        ..Default::default()
    })
}

fn save_on_failure(name: &str, gpu: &image::RgbaImage, cpu: &image::RgbaImage) {
    let dir = std::env::temp_dir();
    let _ = gpu.save(dir.join(format!("{name}-gpu.png")));
    let _ = cpu.save(dir.join(format!("{name}-cpu.png")));
    // Where they differ, 4× enlarged: the GPU's image, red where off.
    let diff = image::RgbaImage::from_fn(SIZE * 4, SIZE * 4, |x, y| {
        let (a, b) = (gpu.get_pixel(x / 4, y / 4), cpu.get_pixel(x / 4, y / 4));
        if (0..3).any(|c| a.0[c].abs_diff(b.0[c]) > 2) {
            image::Rgba([255, 0, 0, 255])
        } else {
            *a
        }
    });
    let _ = diff.save(dir.join(format!("{name}-diff.png")));
    eprintln!("images in {}", dir.display());
}

#[test]
fn wet_clumps_and_kajiya_kay_match_the_reference_pixel_for_pixel() {
    let Some(ctx) = gpu() else { return };
    let layers = 6;
    let mut mask = WetnessMask::dry_mask(SIZE, SIZE);
    for (x, y, r, w) in [
        (0.3, 0.3, 0.15, 1.0),
        (0.7, 0.4, 0.12, 0.7),
        (0.45, 0.75, 0.2, 0.5),
        (0.55, 0.5, 0.1, 0.6),
    ] {
        mask.add_droplet(Droplet {
            centre: Vec2::new(x, y),
            radius: r,
            wetness: w,
        });
    }
    let case = Case {
        features: ShellFeatures::ALL,
        params: params(layers),
        textures: textures(layers),
        mask,
        light: Vec3::new(0.4, 0.8, 0.3),
        tip_offset: Vec3::ZERO,
    };
    let (gpu_image, cpu_image) = (draw(ctx, &case), reference(&case));
    let (off, worst) = compare(&gpu_image, &cpu_image);
    if off > 0.01 {
        save_on_failure("shells-clump", &gpu_image, &cpu_image);
    }
    // Rounding in the GPU's texture filtering can flip a fragment at the
    // very edge of a hair (alpha just above or at 0) or of a clump; all
    // but a handful of pixels agree to 2/255.
    eprintln!(
        "clumps: {:.2} % of pixels differ (worst {worst})",
        100.0 * off
    );
    assert!(
        off <= 0.01,
        "{:.2} % of pixels differ (worst {worst})",
        100.0 * off
    );
    // And the clumps did something: the same case dry looks different.
    let dry = Case {
        mask: WetnessMask::dry_mask(SIZE, SIZE),
        ..case
    };
    let (off_dry, _) = compare(&draw(ctx, &dry), &gpu_image);
    eprintln!("wet vs dry: {:.2} %", 100.0 * off_dry);
    assert!(
        off_dry > 0.1,
        "wet and dry differ on {:.1} % of pixels",
        100.0 * off_dry
    );
}

#[test]
fn curl_moves_the_layer_by_the_reference_offset_and_wetness_straightens_it() {
    let Some(ctx) = gpu() else { return };
    // One layer at h = 1, ω = 0: the layer moves K_α (1 − ρ) along dP/du.
    // K_α = 6 texels and ρ = 1/3 everywhere: exactly 4 texels.
    let mut mask = WetnessMask::dry_mask(SIZE, SIZE);
    mask.add_droplet(Droplet {
        centre: Vec2::splat(0.5),
        radius: 1.0,
        wetness: 1.0 / 3.0,
    });
    let mut p = params(1);
    p.curl = CurlParams {
        radius: 6.0 / SIZE as f32,
        frequency: 0.0,
    };
    p.mode = ShadingMode::Color;
    let case = Case {
        features: ShellFeatures {
            curl: true,
            ..ShellFeatures::PLAIN
        },
        params: p,
        textures: textures(1),
        mask,
        light: Vec3::Y,
        tip_offset: Vec3::ZERO,
    };
    let (gpu_image, cpu_image) = (draw(ctx, &case), reference(&case));
    let (off, worst) = compare(&gpu_image, &cpu_image);
    if off > 0.01 {
        save_on_failure("shells-curl", &gpu_image, &cpu_image);
    }
    assert!(
        off <= 0.01,
        "{:.2} % of pixels differ (worst {worst})",
        100.0 * off
    );
    // Unshifted it would not match.
    let straight = Case {
        features: ShellFeatures::PLAIN,
        ..case
    };
    let (off_straight, _) = compare(&draw(ctx, &straight), &gpu_image);
    assert!(off_straight > 0.05);
}

#[test]
fn meshes_without_uvs_are_refused_by_name() {
    let Some(ctx) = gpu() else { return };
    let mesh = Mesh::new(
        "no-uv triangle",
        vec![Vec3::ZERO, Vec3::X, Vec3::Z],
        vec![[0, 1, 2]],
        None,
        None,
    )
    .unwrap();
    let renderer = ShellRenderer::new(ctx, ShellFeatures::ALL);
    let e = renderer
        .upload(ctx, &mesh, &color_image(), &textures(2), 8)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no-uv triangle") && e.contains("no UVs"), "{e}");
}

#[test]
fn moved_tips_bend_the_layers_as_each_coupling_says() {
    let Some(ctx) = gpu() else { return };
    // Sticks L0 = 1/8 tipped 30° towards +x: the tip moves 4 texels
    // sideways, so at h = 1/2 Silva's Bézier and Banisch's bent layers
    // (k = 2) move a layer 1 texel and the linear ones 2: all on texel
    // centres, and all different.
    let length = 0.125;
    let s = Vec3::new(0.5, 0.75f32.sqrt(), 0.0);
    let tip_offset = length * s - length * Vec3::Y;
    let mut images = Vec::new();
    for coupling in [
        Coupling::Bezier,
        Coupling::Linear,
        Coupling::Bent { exponent: 2.0 },
    ] {
        let mut p = params(2);
        p.length = length;
        p.coupling = coupling;
        p.mode = ShadingMode::Color;
        let case = Case {
            features: ShellFeatures::PLAIN,
            params: p,
            textures: textures(2),
            mask: WetnessMask::dry_mask(SIZE, SIZE),
            light: Vec3::Y,
            tip_offset,
        };
        let (gpu_image, cpu_image) = (draw(ctx, &case), reference(&case));
        let (off, worst) = compare(&gpu_image, &cpu_image);
        eprintln!(
            "{coupling:?}: {:.2} % of pixels differ (worst {worst})",
            100.0 * off
        );
        if off > 0.01 {
            save_on_failure("shells-coupling", &gpu_image, &cpu_image);
        }
        assert!(off <= 0.01, "{coupling:?}: {:.2} % differ", 100.0 * off);
        images.push(gpu_image);
    }
    // Linear differs from the other two (2 texels vs 1 at h = 1/2).
    assert!(compare(&images[0], &images[1]).0 > 0.05);
}
