//! Regenerates `docs/gallery/sik-fig11-12-spot.png`: Sik's Figs. 11–12 on
//! Spot — 8,000 uniform samples (left) and 8,000 samples of a density that
//! increases from left to right (right).
//!
//! ```sh
//! cargo run --release -p pelage --example gallery_sampler
//! ```
//!
//! A small CPU rasterizer (z-buffer, Lambert shading, points as depth-tested
//! discs, 2× supersampling) stands in until the GPU preview renderer lands;
//! it draws exactly what the sampler returns, nothing more.

use glam::{Vec2, Vec3};
use pelage::Mesh;
use pelage::map::{Filter, ImageMap, Map, Wrap};
use pelage::mesh::{SurfacePoint, Uvs};
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};

const WIDTH: usize = 640;
const HEIGHT: usize = 560;
const SUPERSAMPLE: usize = 2;
const SAMPLES: u64 = 8_000;

/// An orthographic camera looking along −x (Spot's side), y up.
struct Camera {
    center: Vec3,
    scale: f32,
}

impl Camera {
    fn fit(mesh: &Mesh, w: usize, h: usize) -> Self {
        let (lo, hi) = mesh.bounds();
        let center = 0.5 * (lo + hi);
        let extent = hi - lo;
        let scale = 0.9 * (w as f32 / extent.z).min(h as f32 / extent.y);
        Self { center, scale }
    }

    /// Screen position (pixels, y down) and depth (larger = nearer).
    fn project(&self, p: Vec3, w: usize, h: usize) -> (Vec2, f32) {
        let d = p - self.center;
        // Looking along −x: screen right is −z, screen up is +y.
        let x = w as f32 * 0.5 - d.z * self.scale;
        let y = h as f32 * 0.5 - d.y * self.scale;
        (Vec2::new(x, y), d.x)
    }
}

struct Frame {
    w: usize,
    h: usize,
    color: Vec<Vec3>,
    depth: Vec<f32>,
}

impl Frame {
    fn new(w: usize, h: usize) -> Self {
        Self {
            w,
            h,
            color: vec![Vec3::splat(1.0); w * h],
            depth: vec![f32::NEG_INFINITY; w * h],
        }
    }

    fn draw_mesh(&mut self, mesh: &Mesh, camera: &Camera) {
        let light = Vec3::new(0.6, 0.7, -0.4).normalize();
        let skin = Vec3::new(0.86, 0.80, 0.72);
        for t in 0..mesh.triangle_count() {
            let tri = mesh.triangles()[t];
            let corners = mesh
                .triangle_positions(t)
                .map(|p| camera.project(p, self.w, self.h));
            let normals = tri.map(|v| mesh.normals()[v as usize]);
            let [(a, za), (b, zb), (c, zc)] = corners;
            let area = (b - a).perp_dot(c - a);
            if area.abs() < 1e-12 {
                continue;
            }
            let lo = a.min(b).min(c).max(Vec2::ZERO);
            let hi = a
                .max(b)
                .max(c)
                .min(Vec2::new(self.w as f32 - 1.0, self.h as f32 - 1.0));
            for y in lo.y as usize..=hi.y as usize {
                for x in lo.x as usize..=hi.x as usize {
                    let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let w0 = (b - p).perp_dot(c - p) / area;
                    let w1 = (c - p).perp_dot(a - p) / area;
                    let w2 = 1.0 - w0 - w1;
                    if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                        continue;
                    }
                    let z = w0 * za + w1 * zb + w2 * zc;
                    let i = y * self.w + x;
                    if z > self.depth[i] {
                        self.depth[i] = z;
                        let n = (w0 * normals[0] + w1 * normals[1] + w2 * normals[2])
                            .normalize_or_zero();
                        // Two-sided Lambert plus ambient.
                        let lambert = n.dot(light).abs();
                        self.color[i] = skin * (0.35 + 0.65 * lambert);
                    }
                }
            }
        }
    }

    fn draw_points(&mut self, mesh: &Mesh, points: &[SurfacePoint], camera: &Camera, radius: f32) {
        let ink = Vec3::new(0.55, 0.08, 0.05);
        for p in points {
            let (s, z) = camera.project(p.position(mesh), self.w, self.h);
            let r = radius.ceil() as i64;
            for dy in -r..=r {
                for dx in -r..=r {
                    let (x, y) = (s.x as i64 + dx, s.y as i64 + dy);
                    if x < 0 || y < 0 || x >= self.w as i64 || y >= self.h as i64 {
                        continue;
                    }
                    let d = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - s;
                    let i = y as usize * self.w + x as usize;
                    // Depth test with a little slack: a point on the surface
                    // is visible where that surface is the nearest.
                    if d.length() <= radius && z >= self.depth[i] - 0.02 {
                        self.color[i] = ink;
                    }
                }
            }
        }
    }

    /// Box-filters the supersampled frame down.
    fn downsample(&self, k: usize) -> Vec<Vec3> {
        let (w, h) = (self.w / k, self.h / k);
        let mut out = vec![Vec3::ZERO; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut sum = Vec3::ZERO;
                for sy in 0..k {
                    for sx in 0..k {
                        sum += self.color[(y * k + sy) * self.w + x * k + sx];
                    }
                }
                out[y * w + x] = sum / (k * k) as f32;
            }
        }
        out
    }
}

/// Spot with planar UVs seen from the camera's side: u runs left to right
/// on screen, v bottom to top, so a horizontal ramp texture is a
/// left-to-right density.
fn with_side_uvs(mesh: &Mesh) -> Mesh {
    let (lo, hi) = mesh.bounds();
    let uvs = mesh
        .positions()
        .iter()
        .map(|p| Vec2::new((hi.z - p.z) / (hi.z - lo.z), (p.y - lo.y) / (hi.y - lo.y)))
        .collect();
    Mesh::new(
        "spot with side-projected UVs",
        mesh.positions().to_vec(),
        mesh.triangles().to_vec(),
        Some(mesh.normals().to_vec()),
        Some(Uvs::PerVertex(uvs)),
    )
    .expect("same geometry, new UVs")
}

fn render(mesh: &Mesh, points: &[SurfacePoint]) -> Vec<Vec3> {
    let (w, h) = (WIDTH * SUPERSAMPLE, HEIGHT * SUPERSAMPLE);
    let camera = Camera::fit(mesh, w, h);
    let mut frame = Frame::new(w, h);
    frame.draw_mesh(mesh, &camera);
    frame.draw_points(mesh, points, &camera, 1.6 * SUPERSAMPLE as f32);
    frame.downsample(SUPERSAMPLE)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let spot = with_side_uvs(&pelage::assets::spot());

    let uniform =
        DensitySampler::new(&spot, &Map::Constant(1.0), DensitySamplerOptions::default())?;
    let uniform_points = sample_range(&uniform, 11, 0..SAMPLES);

    // A 256-texel ramp from 0 on the left to 1 on the right.
    let ramp: Vec<f32> = (0..256).map(|x| (x as f32 + 0.5) / 256.0).collect();
    let gradient =
        Map::Image(ImageMap::from_texels(256, 1, ramp, Wrap::Clamp)?.with_filter(Filter::Bilinear));
    let gradient_sampler = DensitySampler::new(&spot, &gradient, DensitySamplerOptions::default())?;
    let gradient_points = sample_range(&gradient_sampler, 11, 0..SAMPLES);

    let left = render(&spot, &uniform_points);
    let right = render(&spot, &gradient_points);
    let gap = 16;
    let total_w = 2 * WIDTH + gap;
    let mut image =
        image::RgbImage::from_pixel(total_w as u32, HEIGHT as u32, image::Rgb([255, 255, 255]));
    for (offset, panel) in [(0, &left), (WIDTH + gap, &right)] {
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                let c = panel[y * WIDTH + x].clamp(Vec3::ZERO, Vec3::ONE) * 255.0;
                image.put_pixel(
                    (offset + x) as u32,
                    y as u32,
                    image::Rgb([c.x as u8, c.y as u8, c.z as u8]),
                );
            }
        }
    }
    let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs/gallery/sik-fig11-12-spot.png");
    std::fs::create_dir_all(out.parent().expect("has a folder"))?;
    image.save(&out)?;
    println!("wrote {}", out.display());
    Ok(())
}
