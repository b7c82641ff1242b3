//! Shell textures: a tileable volume of hair sliced horizontally into N
//! RGBA layers (Banisch & Wüthrich, "Shell Texture Generation").
//!
//! [`TextureStyle::Blades`] is Banisch's method: each hair is a curve whose
//! horizontal offset grows exponentially with height,
//! `s(z) = lean · (e^(b z/ℓ) − 1) / (e^b − 1)` for `z ∈ [0, ℓ]`, with a
//! stochastic length `ℓ`, inclination direction `θ` and bending `b` per
//! hair, tapering from root to tip; under it a dense coat of short, thin
//! hair (the "undercoat", after Kajiya & Kay). [`TextureStyle::RandomStrands`]
//! is Lengyel et al.'s simpler texture for comparison: straight vertical
//! strands of random length, one texel wide.
//!
//! Channels of each texel: A = coverage (how much hair is there, 0–255,
//! antialiased at the hair's edge); R, G = the hair's direction projected on
//! the texture plane (`0.5 + 0.5 t`), which the shader adds to the strand
//! tangent so each hair catches its own highlight; B = how far along its
//! hair the texel is (0 root, 255 tip), shown by the `structure` shading.
//! Layer `n`, drawn at `h = (n + 1) / N`, holds the slice through the
//! middle of its step, `z = (n + ½) / N`: what the layer stands for between
//! the layer below and itself (a slice at `h` itself would leave the top
//! layer empty, since only hairs of full length reach `h = 1`).

use crate::sample::SampleRng;
use rayon::prelude::*;
use std::f32::consts::TAU;

/// Which hair fills the volume (`blades` or `random-strands` in scene
/// files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TextureStyle {
    /// Banisch: exponential blades with length, direction and bending
    /// variation, plus an undercoat.
    Blades,
    /// Lengyel: straight random strands.
    RandomStrands,
}

/// What a shell texture is made of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellTextureParams {
    /// Texels per side (the paper: 256).
    pub resolution: u32,
    /// Number of layers N.
    pub layers: u32,
    /// Guard hairs per texel (0.025 at 256² is ~1,600 hairs).
    pub density: f32,
    /// Guard hair radius at the root, in texels.
    pub thickness: f32,
    /// Length variation: lengths are uniform in `[1 − v, 1]` of the shell.
    pub length_variance: f32,
    /// Largest horizontal travel of a hair from root to tip, in texture
    /// widths.
    pub lean: f32,
    /// Exponential bending `b` (0 would be straight; larger bends late).
    pub bend: f32,
    /// Undercoat hairs per guard hair.
    pub undercoat_ratio: f32,
    /// Undercoat length, as a fraction of the shell.
    pub undercoat_length: f32,
    /// The method.
    pub style: TextureStyle,
    /// Random seed.
    pub seed: u64,
}

impl Default for ShellTextureParams {
    fn default() -> Self {
        Self {
            resolution: 256,
            layers: 16,
            density: 0.025,
            thickness: 1.3,
            length_variance: 0.35,
            lean: 0.02,
            bend: 3.0,
            undercoat_ratio: 4.0,
            undercoat_length: 0.35,
            style: TextureStyle::Blades,
            seed: 1,
        }
    }
}

/// N square RGBA8 layers, layer-major then row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellTextures {
    resolution: u32,
    layers: u32,
    texels: Vec<[u8; 4]>,
}

/// One hair of the volume.
#[derive(Debug, Clone, Copy)]
struct Hair {
    root: [f32; 2],
    length: f32,
    direction: [f32; 2],
    lean: f32,
    bend: f32,
    thickness: f32,
}

impl Hair {
    /// Horizontal offset (texture widths) and its slope at height `z`.
    fn offset(&self, z: f32) -> (f32, f32) {
        let t = (z / self.length).clamp(0.0, 1.0);
        if self.bend.abs() < 1e-4 {
            return (self.lean * t, self.lean / self.length);
        }
        let denom = self.bend.exp() - 1.0;
        let s = self.lean * ((self.bend * t).exp() - 1.0) / denom;
        let slope = self.lean * self.bend * (self.bend * t).exp() / (denom * self.length);
        (s, slope)
    }
}

impl ShellTextures {
    /// Generates the volume and slices it.
    pub fn generate(params: &ShellTextureParams) -> Self {
        let resolution = params.resolution.clamp(8, 4096);
        let layers = params.layers.clamp(1, 256);
        let size = (resolution * resolution) as usize;
        let mut texels = vec![[128u8, 128, 0, 0]; size * layers as usize];
        match params.style {
            TextureStyle::Blades => {
                let hairs = blades(params, resolution);
                texels
                    .par_chunks_mut(size)
                    .enumerate()
                    .for_each(|(n, layer)| {
                        let z = slice_height(n as u32, layers);
                        for hair in &hairs {
                            splat(layer, resolution, hair, z);
                        }
                    });
            }
            TextureStyle::RandomStrands => {
                for i in 0..size {
                    let mut rng = SampleRng::new(params.seed, i as u64);
                    if rng.uniform_f32() >= params.density.clamp(0.0, 1.0) * 10.0 {
                        continue;
                    }
                    let length = 1.0 - params.length_variance * rng.uniform_f32();
                    for n in 0..layers {
                        let z = slice_height(n, layers);
                        if z <= length {
                            texels[n as usize * size + i] =
                                [128, 128, (255.0 * z / length) as u8, 255];
                        }
                    }
                }
            }
        }
        Self {
            resolution,
            layers,
            texels,
        }
    }

    /// Texels per side.
    pub fn resolution(&self) -> u32 {
        self.resolution
    }

    /// Number of layers.
    pub fn layers(&self) -> u32 {
        self.layers
    }

    /// All texels, layer by layer, for upload (`Rgba8Unorm` 2D array).
    pub fn texels(&self) -> &[[u8; 4]] {
        &self.texels
    }

    /// Texel `(x, y)` of layer `n`.
    pub fn texel(&self, n: u32, x: u32, y: u32) -> [u8; 4] {
        let r = self.resolution;
        self.texels[((n * r + y) * r + x) as usize]
    }

    /// The mean coverage (alpha) of layer `n`, in [0, 1].
    pub fn coverage(&self, n: u32) -> f64 {
        let size = (self.resolution * self.resolution) as usize;
        let layer = &self.texels[n as usize * size..(n as usize + 1) * size];
        layer.iter().map(|t| f64::from(t[3])).sum::<f64>() / (255.0 * size as f64)
    }

    /// Bilinear lookup of layer `n` at texture coordinates `uv` (repeating),
    /// as the GPU's linear, repeating sampler reads it; channels in [0, 1].
    pub fn sample(&self, n: u32, uv: glam::Vec2) -> [f32; 4] {
        let r = self.resolution as f32;
        let (x, y) = (uv.x * r - 0.5, uv.y * r - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |v: f32| v.rem_euclid(r) as u32;
        let mut out = [0.0f32; 4];
        for (dx, dy, weight) in [
            (0.0, 0.0, (1.0 - fx) * (1.0 - fy)),
            (1.0, 0.0, fx * (1.0 - fy)),
            (0.0, 1.0, (1.0 - fx) * fy),
            (1.0, 1.0, fx * fy),
        ] {
            let t = self.texel(n, wrap(x0 + dx), wrap(y0 + dy));
            for c in 0..4 {
                out[c] += weight * f32::from(t[c]) / 255.0;
            }
        }
        out
    }

    /// Layer `n` as an image: the hair white on black, by coverage.
    pub fn layer_image(&self, n: u32) -> image::GrayImage {
        image::GrayImage::from_fn(self.resolution, self.resolution, |x, y| {
            image::Luma([self.texel(n, x, y)[3]])
        })
    }
}

/// Where layer `n` of `layers` slices the volume: the middle of its step.
fn slice_height(n: u32, layers: u32) -> f32 {
    (n as f32 + 0.5) / layers.max(1) as f32
}

/// The hairs of a [`TextureStyle::Blades`] volume: guard hairs, then the
/// undercoat. Hair `i` depends on `(seed, i)` alone.
fn blades(params: &ShellTextureParams, resolution: u32) -> Vec<Hair> {
    let area = (resolution * resolution) as f32;
    let guards = (params.density.max(0.0) * area).round() as u64;
    let under = (guards as f32 * params.undercoat_ratio.max(0.0)).round() as u64;
    let mut hairs = Vec::with_capacity((guards + under) as usize);
    for i in 0..guards + under {
        let mut rng = SampleRng::new(params.seed, i);
        let root = rng.uniform_f32_pair();
        let angle = TAU * rng.uniform_f32();
        let [u, v] = rng.uniform_f32_pair();
        let guard = i < guards;
        let (length, lean, thickness) = if guard {
            (
                1.0 - params.length_variance.clamp(0.0, 1.0) * u,
                params.lean * (0.3 + 0.7 * v),
                params.thickness,
            )
        } else {
            (
                params.undercoat_length.clamp(0.0, 1.0) * (1.0 - 0.3 * u),
                0.5 * params.lean * v,
                0.6 * params.thickness,
            )
        };
        hairs.push(Hair {
            root,
            length,
            direction: [angle.cos(), angle.sin()],
            lean,
            bend: params.bend * (0.5 + rng.uniform_f32()),
            thickness,
        });
    }
    hairs
}

/// Draws `hair`'s cross-section at height `z` into `layer`: a disc, wrapped
/// at the texture's edges, antialiased, tapering to 30 % at the tip.
fn splat(layer: &mut [[u8; 4]], resolution: u32, hair: &Hair, z: f32) {
    if z > hair.length {
        return;
    }
    let r = resolution as f32;
    let along = z / hair.length;
    let (s, slope) = hair.offset(z);
    let centre = [
        (hair.root[0] + s * hair.direction[0]) * r,
        (hair.root[1] + s * hair.direction[1]) * r,
    ];
    let radius = hair.thickness * (1.0 - 0.7 * along);
    // The hair's direction: horizontal slope (texture widths per shell
    // height, in texture units: the shell height is one texture width by
    // convention here) over a vertical 1.
    let tangent =
        glam::Vec3::new(slope * hair.direction[0], slope * hair.direction[1], 1.0).normalize();
    let encode = |t: f32| (127.5 + 127.5 * t).round() as u8;
    let reach = (radius + 1.0).ceil() as i32;
    let (cx, cy) = (centre[0].floor() as i32, centre[1].floor() as i32);
    for dy in -reach..=reach {
        for dx in -reach..=reach {
            let (x, y) = (cx + dx, cy + dy);
            let px = x as f32 + 0.5 - centre[0];
            let py = y as f32 + 0.5 - centre[1];
            let coverage = (radius - (px * px + py * py).sqrt() + 0.5).clamp(0.0, 1.0);
            if coverage <= 0.0 {
                continue;
            }
            let (wx, wy) = (
                x.rem_euclid(resolution as i32) as u32,
                y.rem_euclid(resolution as i32) as u32,
            );
            let texel = &mut layer[(wy * resolution + wx) as usize];
            let alpha = (coverage * 255.0).round() as u8;
            if alpha > texel[3] {
                *texel = [
                    encode(tangent.x),
                    encode(tangent.y),
                    (255.0 * along) as u8,
                    alpha,
                ];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small(style: TextureStyle) -> ShellTextureParams {
        ShellTextureParams {
            resolution: 64,
            layers: 8,
            style,
            ..Default::default()
        }
    }

    #[test]
    fn coverage_thins_towards_the_tips_and_the_undercoat_fills_the_bottom() {
        let t = ShellTextures::generate(&small(TextureStyle::Blades));
        let c: Vec<f64> = (0..8).map(|n| t.coverage(n)).collect();
        for w in c.windows(2) {
            assert!(w[1] <= w[0] + 1e-9, "{c:?}");
        }
        assert!(c[0] > 0.2, "dense undercoat at the bottom: {c:?}");
        assert!(
            c[7] > 0.0 && c[7] < 0.05,
            "a few long hairs reach the top: {c:?}"
        );
        let without_undercoat = ShellTextures::generate(&ShellTextureParams {
            undercoat_ratio: 0.0,
            ..small(TextureStyle::Blades)
        });
        assert!(without_undercoat.coverage(0) < 0.5 * c[0]);
    }

    #[test]
    fn hairs_lean_and_the_texels_say_which_way() {
        // One big hair, leaning: its cross-section moves along its
        // direction with height, faster near the tip (exponential).
        let hair = Hair {
            root: [0.5, 0.5],
            length: 1.0,
            direction: [1.0, 0.0],
            lean: 0.2,
            bend: 3.0,
            thickness: 2.0,
        };
        let (s_half, _) = hair.offset(0.5);
        let (s_tip, slope_tip) = hair.offset(1.0);
        assert!((s_tip - 0.2).abs() < 1e-6);
        assert!(
            s_half < 0.5 * s_tip,
            "exponential: most of the lean near the tip"
        );
        assert!(slope_tip > 0.2, "steeper than the straight lean");
        let mut layer = vec![[128u8, 128, 0, 0]; 64 * 64];
        splat(&mut layer, 64, &hair, 1.0);
        let covered: Vec<usize> = (0..64 * 64).filter(|&i| layer[i][3] > 0).collect();
        assert!(!covered.is_empty());
        for &i in &covered {
            let x = (i % 64) as f32 + 0.5;
            assert!((x - 0.7 * 64.0).abs() <= 2.0, "at 0.5 + lean");
            assert!(
                layer[i][0] > 128 && layer[i][1] == 128,
                "tangent leans along +x"
            );
        }
    }

    #[test]
    fn same_seed_same_texture_other_seed_other_texture() {
        let a = ShellTextures::generate(&small(TextureStyle::Blades));
        assert_eq!(a, ShellTextures::generate(&small(TextureStyle::Blades)));
        let b = ShellTextures::generate(&ShellTextureParams {
            seed: 2,
            ..small(TextureStyle::Blades)
        });
        assert_ne!(a, b);
    }

    #[test]
    fn random_strands_are_vertical_and_end_at_their_length() {
        let t = ShellTextures::generate(&small(TextureStyle::RandomStrands));
        let r = t.resolution();
        let mut strands = 0;
        for y in 0..r {
            for x in 0..r {
                let column: Vec<u8> = (0..8).map(|n| t.texel(n, x, y)[3]).collect();
                // Present from the bottom up to some height, then absent.
                let top = column.iter().take_while(|&&a| a == 255).count();
                assert!(column[top..].iter().all(|&a| a == 0), "{column:?}");
                strands += usize::from(top > 0);
            }
        }
        // density 0.025 × 10 = 25 % of texels are strands.
        let fraction = strands as f64 / f64::from(r * r);
        assert!((fraction - 0.25).abs() < 0.03, "{fraction}");
    }

    #[test]
    fn bilinear_lookup_at_texel_centres_is_the_texel() {
        let t = ShellTextures::generate(&small(TextureStyle::Blades));
        let r = t.resolution() as f32;
        for (x, y) in [(0u32, 0u32), (10, 20), (63, 63)] {
            let uv = glam::Vec2::new((x as f32 + 0.5) / r, (y as f32 + 0.5) / r);
            let s = t.sample(2, uv);
            let texel = t.texel(2, x, y);
            for c in 0..4 {
                assert!((s[c] - f32::from(texel[c]) / 255.0).abs() < 1e-5);
            }
        }
    }
}
