//! The wetness mask (Silva §3.1): a float RGBA texture over the mesh's UV
//! layout storing, per texel, the clump centre (R, G), the clump radius (B)
//! and the wetness ρ (A). Droplets are blended in by Alg. 1; a mask can be
//! filled with random droplets over the surface, or painted from an image
//! (Fig. 12c's word written in water). [`WetnessMask::dry`] lets ρ decay
//! over time, so curls come back and clumps open — the effect the paper is
//! about and only implies.
//!
//! Coordinates are image coordinates: `(0, 0)` is the top-left corner of the
//! mask, `(1, 1)` the bottom-right, so a mesh UV `(u, v)` is at `(u, 1 − v)`
//! ([`mask_coordinates`]); radii are in the same unit.

use super::math::WetTexel;
use crate::Mesh;
use crate::map::Map;
use crate::sample::{
    DensitySampler, DensitySamplerOptions, SampleError, SampleRng, salts, sample_range,
};
use glam::Vec2;
use std::ops::Range;

/// One drop of water: where it hits (mask coordinates), how wide the clump
/// it makes is, and how wet (ρ_drop in [0, 1]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Droplet {
    /// `c_drop`.
    pub centre: Vec2,
    /// `r_drop`.
    pub radius: f32,
    /// `ρ_drop`.
    pub wetness: f32,
}

/// A mesh UV in mask (image) coordinates: `(u, 1 − v)`.
pub fn mask_coordinates(uv: Vec2) -> Vec2 {
    Vec2::new(uv.x, 1.0 - uv.y)
}

/// Alg. 1 for one texel the droplet covers: a texel already wet with a
/// clump whose centre is within the droplet's radius merges with the drop
/// (centre and radius move towards the drop's by `α = ρ_drop / ρ_total`,
/// wetness adds up to 1); any other texel takes the droplet as it is.
///
/// One departure from the printed algorithm, whose first test is on the
/// centre alone: there a *dry* texel whose stored centre happens to lie
/// within the radius (a clump that has dried, or the all-zero initial
/// centre near the corner) is left untouched, so a drop falling where fur
/// has dried would write nothing. Here a dry texel always takes the drop
/// ([`blend_droplet_as_printed`] keeps the printed form; a test shows the
/// difference).
pub fn blend_droplet(mask: WetTexel, drop: Droplet) -> WetTexel {
    if mask.wetness != 0.0 && mask.centre.distance(drop.centre) <= drop.radius {
        merge(mask, drop)
    } else {
        take(drop)
    }
}

/// Alg. 1 exactly as printed (see [`blend_droplet`]).
pub fn blend_droplet_as_printed(mask: WetTexel, drop: Droplet) -> WetTexel {
    if mask.centre.distance(drop.centre) <= drop.radius {
        if mask.wetness != 0.0 {
            merge(mask, drop)
        } else {
            mask
        }
    } else {
        take(drop)
    }
}

fn merge(mut mask: WetTexel, drop: Droplet) -> WetTexel {
    let total = (mask.wetness + drop.wetness).clamp(0.0, 1.0);
    if total != 0.0 {
        let alpha = drop.wetness / total;
        mask.centre = (1.0 - alpha) * mask.centre + alpha * drop.centre;
        mask.radius = (1.0 - alpha) * mask.radius + alpha * drop.radius;
    }
    mask.wetness = total;
    mask
}

fn take(drop: Droplet) -> WetTexel {
    WetTexel {
        centre: drop.centre,
        radius: drop.radius,
        wetness: drop.wetness,
    }
}

/// Below this wetness a drying texel is dry (0): Alg. 2 tests ρ = 0 exactly,
/// and the 8-bit colour of a 1/256 wet clump is that of a dry one.
pub const DRY_BELOW: f32 = 1.0 / 256.0;

/// The wetness mask texture.
#[derive(Debug, Clone, PartialEq)]
pub struct WetnessMask {
    width: u32,
    height: u32,
    texels: Vec<WetTexel>,
}

impl WetnessMask {
    /// A dry mask of `width × height` texels (the paper uses 256 × 256).
    pub fn dry_mask(width: u32, height: u32) -> Self {
        let (width, height) = (width.max(1), height.max(1));
        Self {
            width,
            height,
            texels: vec![WetTexel::default(); (width * height) as usize],
        }
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texels, row by row from the top.
    pub fn texels(&self) -> &[WetTexel] {
        &self.texels
    }

    /// The texel at column `x`, row `y`.
    pub fn texel(&self, x: u32, y: u32) -> WetTexel {
        self.texels[(y * self.width + x) as usize]
    }

    /// The texel under mask point `p`, nearest texel, clamped at the edges —
    /// exactly what the shader's `textureLoad` reads.
    pub fn at(&self, p: Vec2) -> WetTexel {
        let (x, y) = self.texel_index(p);
        self.texel(x, y)
    }

    /// The texel `(column, row)` under mask point `p`, clamped.
    pub fn texel_index(&self, p: Vec2) -> (u32, u32) {
        let x = (p.x * self.width as f32).floor();
        let y = (p.y * self.height as f32).floor();
        (
            x.clamp(0.0, (self.width - 1) as f32) as u32,
            y.clamp(0.0, (self.height - 1) as f32) as u32,
        )
    }

    /// The centre of texel `(x, y)` in mask coordinates.
    pub fn texel_centre(&self, x: u32, y: u32) -> Vec2 {
        Vec2::new(
            (x as f32 + 0.5) / self.width as f32,
            (y as f32 + 0.5) / self.height as f32,
        )
    }

    /// The columns and rows of the texels a disc of `radius` around mask
    /// point `centre` can cover (its bounding box, clamped to the mask).
    fn texels_around(&self, centre: Vec2, radius: f32) -> (Range<u32>, Range<u32>) {
        let (w, h) = (self.width as f32, self.height as f32);
        let x0 = ((centre.x - radius) * w).floor().max(0.0) as u32;
        let x1 = ((centre.x + radius) * w).ceil().min(w) as u32;
        let y0 = ((centre.y - radius) * h).floor().max(0.0) as u32;
        let y1 = ((centre.y + radius) * h).ceil().min(h) as u32;
        (x0..x1, y0..y1)
    }

    /// A mask of clumps standing side by side (a groom's clumps seen as
    /// shells): each texel belongs to the nearest of the `clumps` whose
    /// radius reaches it (by centre, ties to the first) and is wet with
    /// it; texels no clump reaches are dry. Unlike droplets falling one
    /// after another (Alg. 1), neighbouring clumps never merge: the texels
    /// between two centres split between them, as the hairs do. A texel
    /// stores its clump's reach over its own texels (the farthest texel's
    /// corner) rather than the radius given, so Alg. 2, which discards a
    /// pixel beyond its clump's radius, never cuts a clump short.
    pub fn of_clumps(width: u32, height: u32, clumps: &[Droplet]) -> Self {
        let mut mask = Self::dry_mask(width, height);
        let (w, h) = (mask.width as f32, mask.height as f32);
        // Each texel's clump so far and its distance, clump by clump over
        // the texels its disc covers.
        let mut owner = vec![(u32::MAX, f32::INFINITY); mask.texels.len()];
        for (c, clump) in clumps.iter().enumerate() {
            if !(clump.centre.is_finite() && clump.radius > 0.0 && clump.wetness >= DRY_BELOW) {
                continue;
            }
            let (centre, r) = (clump.centre, clump.radius.min(2.0));
            let (xs, ys) = mask.texels_around(centre, r);
            for y in ys {
                for x in xs.clone() {
                    let d = mask.texel_centre(x, y).distance(centre);
                    let slot = &mut owner[(y * mask.width + x) as usize];
                    if d <= r && d < slot.1 {
                        *slot = (c as u32, d);
                    }
                }
            }
        }
        let corner = 0.5 * Vec2::new(1.0 / w, 1.0 / h).length();
        let mut reach = vec![0.0f32; clumps.len()];
        for &(c, d) in &owner {
            if let Some(r) = reach.get_mut(c as usize) {
                *r = r.max(d + corner);
            }
        }
        for (texel, &(c, _)) in mask.texels.iter_mut().zip(&owner) {
            if let Some(clump) = clumps.get(c as usize) {
                *texel = take(Droplet {
                    radius: reach[c as usize],
                    wetness: clump.wetness.clamp(0.0, 1.0),
                    ..*clump
                });
            }
        }
        mask
    }

    /// Blends a droplet into every texel whose centre it covers (Alg. 1 per
    /// texel, [`blend_droplet`]).
    pub fn add_droplet(&mut self, drop: Droplet) {
        if drop.radius.is_nan() || drop.radius <= 0.0 || !drop.centre.is_finite() {
            return;
        }
        let drop = Droplet {
            wetness: drop.wetness.clamp(0.0, 1.0),
            ..drop
        };
        let (xs, ys) = self.texels_around(drop.centre, drop.radius);
        for y in ys {
            for x in xs.clone() {
                if self.texel_centre(x, y).distance(drop.centre) <= drop.radius {
                    let i = (y * self.width + x) as usize;
                    self.texels[i] = blend_droplet(self.texels[i], drop);
                }
            }
        }
    }

    /// Lets the mask dry for `seconds` at `rate` (per second): every
    /// wetness decays as `ρ ← ρ e^(−rate · seconds)`, and a texel below
    /// [`DRY_BELOW`] is dry again (all channels 0). Half-life: ln 2 / rate.
    pub fn dry(&mut self, seconds: f32, rate: f32) {
        let factor = (-rate.max(0.0) * seconds.max(0.0)).exp();
        for t in &mut self.texels {
            t.wetness *= factor;
            if t.wetness < DRY_BELOW {
                *t = WetTexel::default();
            }
        }
    }

    /// The fraction of texels that are wet.
    pub fn wet_fraction(&self) -> f64 {
        let wet = self.texels.iter().filter(|t| t.wetness != 0.0).count();
        wet as f64 / self.texels.len() as f64
    }

    /// The texels as float RGBA, for upload (`Rgba32Float`).
    pub fn to_rgba(&self) -> Vec<[f32; 4]> {
        self.texels.iter().map(|t| t.to_rgba()).collect()
    }

    /// A picture of the mask as in Silva Fig. 11's insets: black where dry,
    /// blue as deep as the wetness where wet, clump centres lighter.
    pub fn preview(&self) -> image::RgbaImage {
        image::RgbaImage::from_fn(self.width, self.height, |x, y| {
            let t = self.texel(x, y);
            if t.wetness == 0.0 {
                return image::Rgba([0, 0, 0, 255]);
            }
            let p = self.texel_centre(x, y);
            let near_centre = 1.0 - (p.distance(t.centre) / t.radius.max(1e-6)).min(1.0);
            let blue = 90.0 + 165.0 * t.wetness;
            let light = 120.0 * near_centre * t.wetness;
            image::Rgba([light as u8, (40.0 + light) as u8, blue as u8, 255])
        })
    }
}

/// Droplet sizes and wetness for [`droplets_on_mesh`] and
/// [`droplets_from_image`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DropletStyle {
    /// Smallest radius (mask units).
    pub radius_min: f32,
    /// Largest radius (mask units).
    pub radius_max: f32,
    /// ρ_drop.
    pub wetness: f32,
}

/// `count` droplets falling uniformly over the mesh surface (by area, not
/// by UV area), at the UVs they hit: the paper's "random droplets over the
/// surface" (Fig. 12b). Droplet `i` depends on `(seed, i)` alone.
pub fn droplets_on_mesh(
    mesh: &Mesh,
    count: usize,
    style: DropletStyle,
    seed: u64,
) -> Result<Vec<Droplet>, SampleError> {
    let sampler = DensitySampler::new(mesh, &Map::Constant(1.0), DensitySamplerOptions::default())?;
    let points = sample_range(&sampler, seed, 0..count as u64);
    Ok(points
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            let uv = p.uv(mesh)?;
            let mut rng = SampleRng::new(seed ^ salts::DROPLETS, i as u64);
            let radius =
                style.radius_min + (style.radius_max - style.radius_min) * rng.uniform_f32();
            Some(Droplet {
                centre: mask_coordinates(uv),
                radius,
                wetness: style.wetness,
            })
        })
        .collect())
}

/// Droplets that write an image in water (Fig. 12c): one droplet on every
/// point of a grid `spacing` apart (mask units) where the image's
/// brightness (`brightness(p)` in [0, 1] at mask point `p`) is above one
/// half, each jittered by up to a quarter of the spacing.
pub fn droplets_from_image(
    brightness: impl Fn(Vec2) -> f32,
    spacing: f32,
    style: DropletStyle,
    seed: u64,
) -> Vec<Droplet> {
    let spacing = spacing.max(1e-4);
    let n = (1.0 / spacing).ceil() as u32;
    let mut drops = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let index = u64::from(j) * u64::from(n) + u64::from(i);
            let mut rng = SampleRng::new(seed, index);
            let [jx, jy] = rng.uniform_f32_pair();
            let centre = Vec2::new(
                (i as f32 + 0.5 + 0.5 * (jx - 0.5)) * spacing,
                (j as f32 + 0.5 + 0.5 * (jy - 0.5)) * spacing,
            );
            if brightness(centre) > 0.5 {
                let t = rng.uniform_f32();
                drops.push(Droplet {
                    centre,
                    radius: style.radius_min + (style.radius_max - style.radius_min) * t,
                    wetness: style.wetness,
                });
            }
        }
    }
    drops
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clumps_side_by_side_split_the_texels_between_them_and_never_merge() {
        let clumps = [
            Droplet {
                centre: Vec2::new(0.3, 0.5),
                radius: 0.25,
                wetness: 0.8,
            },
            Droplet {
                centre: Vec2::new(0.6, 0.5),
                radius: 0.25,
                wetness: 0.4,
            },
        ];
        let mask = WetnessMask::of_clumps(64, 64, &clumps);
        for y in 0..64 {
            for x in 0..64 {
                let p = mask.texel_centre(x, y);
                let texel = mask.texel(x, y);
                let (a, b) = (p.distance(clumps[0].centre), p.distance(clumps[1].centre));
                let nearest = if a <= b { clumps[0] } else { clumps[1] };
                if p.distance(nearest.centre) <= nearest.radius {
                    assert_eq!(texel.centre, nearest.centre, "({x}, {y})");
                    // Its clump's reach: no farther than the radius given
                    // (and a texel's corner), covering this texel.
                    assert!(texel.radius <= nearest.radius + 0.5 / 64.0 * 2f32.sqrt());
                    assert!(texel.radius >= p.distance(nearest.centre));
                    assert_eq!(texel.wetness, nearest.wetness);
                } else {
                    assert_eq!(texel, WetTexel::default(), "({x}, {y}) is dry");
                }
            }
        }
        // Both clumps hold texels, and the far corner is dry.
        assert_eq!(mask.at(Vec2::new(0.25, 0.5)).wetness, 0.8);
        assert_eq!(mask.at(Vec2::new(0.65, 0.5)).wetness, 0.4);
        assert_eq!(mask.at(Vec2::new(0.01, 0.01)).wetness, 0.0);
        assert!(WetnessMask::of_clumps(8, 8, &[]).wet_fraction() == 0.0);
    }

    fn drop(x: f32, y: f32, r: f32, w: f32) -> Droplet {
        Droplet {
            centre: Vec2::new(x, y),
            radius: r,
            wetness: w,
        }
    }

    #[test]
    fn a_droplet_on_dry_fur_is_written_as_it_is_inside_its_radius_only() {
        let mut mask = WetnessMask::dry_mask(64, 64);
        mask.add_droplet(drop(0.5, 0.5, 0.1, 0.8));
        let inside = mask.at(Vec2::new(0.55, 0.5));
        assert_eq!(inside.centre, Vec2::new(0.5, 0.5));
        assert_eq!((inside.radius, inside.wetness), (0.1, 0.8));
        assert_eq!(mask.at(Vec2::new(0.62, 0.5)).wetness, 0.0);
        // Texels covered ≈ π r² of the mask.
        let expected = std::f64::consts::PI * 0.01;
        assert!((mask.wet_fraction() - expected).abs() < 0.004);
    }

    #[test]
    fn overlapping_droplets_merge_by_wetness_weights() {
        let mask = blend_droplet(
            WetTexel::default(),
            Droplet {
                centre: Vec2::new(0.5, 0.5),
                radius: 0.1,
                wetness: 0.25,
            },
        );
        // A second drop 0.05 away (its radius covers the first centre),
        // wetness 0.5: total 0.75, α = 2/3.
        let merged = blend_droplet(mask, drop(0.55, 0.5, 0.2, 0.5));
        assert!((merged.wetness - 0.75).abs() < 1e-6);
        assert!((merged.centre.x - (0.5 / 3.0 + 0.55 * 2.0 / 3.0)).abs() < 1e-6);
        assert!((merged.radius - (0.1 / 3.0 + 0.2 * 2.0 / 3.0)).abs() < 1e-6);
        // Wetness saturates at 1 and α = ρ_drop / 1.
        let full = blend_droplet(merged, drop(0.5, 0.5, 0.1, 0.5));
        assert_eq!(full.wetness, 1.0);
        // A drop whose radius does not reach the old centre makes a new clump.
        let other = blend_droplet(merged, drop(0.9, 0.9, 0.05, 0.3));
        assert_eq!(other.centre, Vec2::new(0.9, 0.9));
        assert_eq!(other.wetness, 0.3);
    }

    #[test]
    fn printed_alg1_leaves_dry_texels_near_a_stale_centre_unwritten() {
        // A clump dried out, its centre is still stored... or the initial
        // all-zero texel near the corner.
        let stale = WetTexel::default();
        let near_corner = drop(0.05, 0.05, 0.1, 0.7);
        assert_eq!(blend_droplet_as_printed(stale, near_corner), stale);
        assert_eq!(blend_droplet(stale, near_corner).wetness, 0.7);
    }

    #[test]
    fn drying_decays_exponentially_and_ends_dry() {
        let mut mask = WetnessMask::dry_mask(32, 32);
        mask.add_droplet(drop(0.5, 0.5, 0.2, 1.0));
        let half_life = 2.0f32.ln() / 0.5;
        mask.dry(half_life, 0.5);
        assert!((mask.at(Vec2::splat(0.5)).wetness - 0.5).abs() < 1e-5);
        mask.dry(100.0, 0.5);
        assert_eq!(mask.wet_fraction(), 0.0);
        assert_eq!(mask.at(Vec2::splat(0.5)), WetTexel::default());
        // Dried fur takes a new drop at the same place (see blend_droplet).
        mask.add_droplet(drop(0.5, 0.5, 0.2, 0.4));
        assert_eq!(mask.at(Vec2::splat(0.5)).wetness, 0.4);
    }

    #[test]
    fn lookups_are_nearest_texel_clamped() {
        let mut mask = WetnessMask::dry_mask(4, 4);
        mask.add_droplet(drop(0.125, 0.125, 0.01, 1.0));
        assert_eq!(mask.texel_index(Vec2::new(0.2, 0.24)), (0, 0));
        assert_eq!(mask.texel_index(Vec2::new(-3.0, 7.0)), (0, 3));
        assert_eq!(mask.at(Vec2::new(0.01, 0.2)).wetness, 1.0);
        assert_eq!(mask.at(Vec2::new(0.26, 0.2)).wetness, 0.0);
    }

    #[test]
    fn image_droplets_follow_the_bright_pixels_only() {
        let style = DropletStyle {
            radius_min: 0.01,
            radius_max: 0.02,
            wetness: 1.0,
        };
        // Bright in the left half.
        let drops = droplets_from_image(|p| if p.x < 0.5 { 1.0 } else { 0.0 }, 0.05, style, 3);
        assert!(!drops.is_empty());
        assert!(drops.iter().all(|d| d.centre.x < 0.5));
        assert!((drops.len() as i64 - 200).abs() <= 20, "{}", drops.len());
        assert_eq!(
            drops,
            droplets_from_image(|p| if p.x < 0.5 { 1.0 } else { 0.0 }, 0.05, style, 3)
        );
    }

    #[test]
    fn mesh_droplets_land_on_the_uv_layout() {
        let spot = crate::assets::spot();
        let style = DropletStyle {
            radius_min: 0.01,
            radius_max: 0.03,
            wetness: 0.9,
        };
        let drops = droplets_on_mesh(&spot, 100, style, 7).unwrap();
        assert_eq!(drops.len(), 100);
        for d in &drops {
            assert!((0.0..=1.0).contains(&d.centre.x) && (0.0..=1.0).contains(&d.centre.y));
            assert!((0.01..=0.03).contains(&d.radius));
        }
    }
}
