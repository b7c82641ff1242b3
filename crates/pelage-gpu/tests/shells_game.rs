//! Shell fur for games: the GPU's skinning against the CPU's
//! (`pelage::anim::SkinRig`), fins only at the silhouette, and a level of
//! detail that drops layers far away without popping. Needs an adapter
//! (lavapipe serves); `PELAGE_REQUIRE_GPU=1` (CI) makes a missing one a
//! failure.

use glam::{Vec2, Vec3};
use pelage::Mesh;
use pelage::mesh::Uvs;
use pelage::shell::math::{ClumpParams, Coupling, CurlParams, KajiyaKay, ShadingMode};
use pelage::shell::{ShellAnimation, ShellTextureParams, ShellTextures};
use pelage_gpu::{
    FinParams, ShellFeatures, ShellLod, ShellParams, ShellRenderer, ShellTarget, ShellUpload,
    ShellView,
};
mod common;

use common::gpu;

fn fox() -> ShellAnimation {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../pelage/assets/fox/Fox.gltf");
    ShellAnimation::load(&path, "Run", 1).expect("the embedded Fox loads")
}

#[test]
fn gpu_skinning_matches_the_cpu_reference() {
    let Some(ctx) = gpu() else { return };
    let fox = fox();
    let rest = fox.rest_mesh();
    let renderer = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let model = renderer
        .upload_with(
            ctx,
            rest,
            &image::RgbaImage::from_pixel(1, 1, image::Rgba([200; 4])),
            &ShellTextures::generate(&ShellTextureParams {
                resolution: 16,
                layers: 4,
                ..Default::default()
            }),
            8,
            ShellUpload {
                rig: Some(fox.rig()),
                per_corner: false,
            },
        )
        .unwrap();
    let tangents = pelage_gpu::vertex_tangents(rest);
    let (lo, hi) = rest.bounds();
    let size = (hi - lo).length();
    let mut worst = (0.0f32, 0.0f32);
    for seconds in [0.0, 0.23, 0.51] {
        let palette = fox.palette_at(seconds);
        renderer.pose_now(ctx, &model, &palette).unwrap();
        let gpu = model.read_pose(ctx).unwrap();
        let cpu = fox.rig().pose_frames(&palette, rest.normals(), &tangents);
        for (i, &v) in model.mesh_vertices().iter().enumerate() {
            let v = v as usize;
            worst.0 = worst
                .0
                .max(gpu.positions[i].distance(cpu.positions[v]) / size);
            worst.1 = worst.1.max(gpu.normals[i].distance(cpu.normals[v]));
        }
        // The pose is not the rest pose: the test would notice a pass that
        // did nothing.
        let moved = cpu
            .positions
            .iter()
            .zip(rest.positions())
            .map(|(p, q)| p.distance(*q))
            .fold(0.0f32, f32::max);
        assert!(moved > 0.05 * size, "the Fox moved {moved}");
    }
    eprintln!(
        "GPU vs CPU skinning: positions within {:.2e} of the model's size, normals within {:.2e}",
        worst.0, worst.1
    );
    assert!(
        worst.0 <= 1e-5,
        "positions off by {:e} of the size",
        worst.0
    );
    assert!(worst.1 <= 1e-4, "normals off by {:e}", worst.1);
}

/// A UV sphere of radius 1 at the origin, UVs per vertex (a seam column
/// doubled), normals outwards.
fn sphere(rings: u32, segments: u32) -> Mesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            positions.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ));
            uvs.push(Vec2::new(
                s as f32 / segments as f32,
                1.0 - r as f32 / rings as f32,
            ));
        }
    }
    let row = segments + 1;
    let mut triangles = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, r * row + s + 1);
            let (c, d) = (a + row, b + row);
            if r != 0 {
                triangles.push([a, b, c]);
            }
            if r != rings - 1 {
                triangles.push([b, d, c]);
            }
        }
    }
    let normals = positions.clone();
    Mesh::new(
        "sphere",
        positions,
        triangles,
        Some(normals),
        Some(Uvs::PerVertex(uvs)),
    )
    .unwrap()
}

const SIZE: u32 = 160;

fn params(layers: u32) -> ShellParams {
    ShellParams {
        layers,
        length: 0.15,
        tiles: 4.0,
        curl: CurlParams {
            radius: 0.0,
            frequency: 0.0,
        },
        coupling: Coupling::Bezier,
        offset: Vec3::ZERO,
        clump: ClumpParams {
            w: 0.0,
            strength: 0.0,
        },
        mode: ShadingMode::Color,
        kajiya_kay: KajiyaKay {
            specular: Vec3::ZERO,
            exponent: 1.0,
            k_shadow: 1.0,
        },
        background: [0.0, 0.0, 1.0],
        fins: None,
        lod: None,
        opacity: 1.0,
    }
}

/// Seen along −z from `distance`, a perspective camera.
fn view(distance: f32) -> ShellView {
    let eye = Vec3::new(0.0, 0.0, distance);
    let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
    let projection = glam::camera::rh::proj::directx::perspective(0.5, 1.0, 0.1, distance + 10.0);
    ShellView {
        clip_from_world: projection * view,
        eye,
        light: Vec3::new(0.3, 0.8, 0.5).normalize(),
    }
}

fn textures(layers: u32) -> ShellTextures {
    ShellTextures::generate(&ShellTextureParams {
        resolution: 64,
        layers,
        density: 0.05,
        thickness: 1.5,
        ..Default::default()
    })
}

fn white() -> image::RgbaImage {
    image::RgbaImage::from_pixel(1, 1, image::Rgba([240, 200, 150, 255]))
}

#[test]
fn fins_appear_only_at_the_silhouette() {
    let Some(ctx) = gpu() else { return };
    let renderer = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let model = renderer
        .upload(ctx, &sphere(24, 48), &white(), &textures(16), 8)
        .unwrap();
    let target = ShellTarget::new(ctx, &renderer, SIZE, SIZE).unwrap();
    let distance = 6.0;
    let view = view(distance);
    let without = renderer
        .render(ctx, &model, &params(16), &view, &target)
        .unwrap();
    let with_fins = ShellParams {
        fins: Some(FinParams::default()),
        ..params(16)
    };
    let with = renderer
        .render(ctx, &model, &with_fins, &view, &target)
        .unwrap();
    // The sphere's outline on screen: the tangent cone from the eye.
    let centre = 0.5 * SIZE as f32;
    let silhouette_px = {
        let sin = 1.0 / distance;
        let angle = sin.asin();
        angle.tan() / (0.25f32).tan() * centre
    };
    let mut inside = 0;
    let mut near_outline = [0u32; 4];
    for (x, y, a) in with.enumerate_pixels() {
        let b = without.get_pixel(x, y);
        if (0..3).all(|c| a.0[c].abs_diff(b.0[c]) <= 8) {
            continue;
        }
        let d = Vec2::new(x as f32 + 0.5 - centre, y as f32 + 0.5 - centre);
        let r = d.length() / silhouette_px;
        if r < 0.8 {
            inside += 1;
        } else {
            let quadrant = usize::from(d.x > 0.0) + 2 * usize::from(d.y > 0.0);
            near_outline[quadrant] += 1;
        }
    }
    let _ = with.save(std::env::temp_dir().join("fins-sphere-with.png"));
    let _ = without.save(std::env::temp_dir().join("fins-sphere-without.png"));
    eprintln!("fins changed {near_outline:?} pixels near the outline, {inside} inside");
    assert_eq!(inside, 0, "fins drew inside the outline");
    assert!(
        near_outline.iter().all(|&n| n >= 20),
        "fins missing from part of the outline: {near_outline:?}"
    );
}

#[test]
fn far_objects_get_fewer_layers_and_neighbouring_levels_look_alike() {
    let Some(ctx) = gpu() else { return };
    let renderer = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let model = renderer
        .upload(ctx, &sphere(24, 48), &white(), &textures(32), 8)
        .unwrap();
    let lod = ShellParams {
        lod: Some(ShellLod::default()),
        ..params(32)
    };
    let near = renderer.level(&model, &lod, &view(4.0), SIZE as f32);
    let far = renderer.level(&model, &lod, &view(40.0), SIZE as f32);
    eprintln!("near: {near:?}\nfar: {far:?}");
    assert!(far.drawn() < near.drawn(), "{far:?} vs {near:?}");
    assert!(far.drawn() >= ShellLod::default().min_layers);

    // Neighbouring levels at one distance: 12 layers of 32, just past 12
    // (a 13th layer appears, faded in), and 12.5.
    let target = ShellTarget::new(ctx, &renderer, SIZE, SIZE).unwrap();
    let fur_px = view(4.0).projected_length(Vec3::ZERO, 0.15, SIZE as f32);
    let at = |layers: f32| {
        let p = ShellParams {
            lod: Some(ShellLod {
                max_gap_px: fur_px / layers,
                min_layers: 1,
            }),
            ..params(32)
        };
        let level = renderer.level(&model, &p, &view(4.0), SIZE as f32);
        assert!((level.layers - layers).abs() < 1e-3, "{level:?}");
        renderer
            .render(ctx, &model, &p, &view(4.0), &target)
            .unwrap()
    };
    let mean_diff = |x: &image::RgbaImage, y: &image::RgbaImage| {
        let total: u64 = x
            .pixels()
            .zip(y.pixels())
            .map(|(p, q)| {
                (0..3)
                    .map(|k| u64::from(p.0[k].abs_diff(q.0[k])))
                    .sum::<u64>()
            })
            .sum();
        total as f64 / (3.0 * f64::from(SIZE * SIZE))
    };
    let (twelve, past, half) = (at(12.0), at(12.01), at(12.5));
    let full = renderer
        .render(ctx, &model, &params(32), &view(4.0), &target)
        .unwrap();
    let (appear, step, whole) = (
        mean_diff(&twelve, &past),
        mean_diff(&twelve, &half),
        mean_diff(&twelve, &full),
    );
    eprintln!(
        "mean |Δ| per channel, of 255: 12 → 12.01 layers {appear:.3}, 12 → 12.5 {step:.3}, 12 → all 32 {whole:.3}"
    );
    // No pop: a layer appearing changes next to nothing; half a layer and
    // even the whole way to 32 layers stay within a level or two of 255
    // on average (the coverage of 32 layers is kept by fewer).
    assert!(appear < 0.1, "{appear}");
    assert!(step < 1.5, "{step}");
    assert!(whole < 3.0, "{whole}");
}
