//! `[look]`: every hair's values for a physically based hair shader
//! (Chiang et al. 2016, as Cycles' Principled Hair BSDF and MaterialX's
//! `chiang_hair_bsdf` implement it): melanin, melanin redness, tint,
//! longitudinal and radial roughness, each a map read at the hair's root,
//! with per-hair jitter, and a per-hair random number. Written as uniform
//! primvars (`hair_melanin`, …) with a material that reads them
//! (docs/curves-io.md, "Hair shading").
//!
//! Values are found after a part is grown, from each hair's root and id
//! alone, so a hair has the same values in every part, thread, preview
//! fraction and animated frame.
//!
//! A groom with colours and no `[look]` is shaded by its colours
//! ([`HairLook::fitted_to_colors`]): each hair's melanin and redness are
//! the pigments whose absorption gives its root colour, by Chiang et al.
//! 2016's colour-to-absorption mapping (§4.2, eq. 9) inverted over
//! Cycles' eumelanin and pheomelanin absorptions.

use crate::curves::HairShading;
use crate::map::{Map, MapSite};
use crate::mesh::{Mesh, SurfacePoint};
use crate::sample::SampleRng;
use crate::sample::salts;
use glam::Vec3;
use rayon::prelude::*;

/// Hairs shaded by one task: enough to pay for the task, few enough that
/// a part's hairs spread over every thread.
const CHUNK: usize = 4096;

/// `[look]`: the maps of a hair shader's parameters.
#[derive(Debug, Clone)]
pub struct HairLook {
    /// Melanin, 0 (white) to 1 (black), on Cycles' scale.
    pub melanin: Map,
    /// The share of red pheomelanin in the melanin, 0 to 1.
    pub melanin_redness: Map,
    /// Dye colour, linear RGB, each channel a map (white: none).
    pub tint: [Map; 3],
    /// Longitudinal roughness, 0 to 1.
    pub roughness: Map,
    /// Azimuthal roughness, 0 to 1.
    pub radial_roughness: Map,
    /// Per-hair variation, a fraction: melanin, redness and both
    /// roughnesses of each hair are multiplied by `1 ± jitter` (each its
    /// own random draw), then kept within 0 to 1.
    pub jitter: Map,
    /// Seed of the variation and of `hair_random`.
    pub seed: u64,
    /// Write a material that reads the values (USD: a MaterialX
    /// `chiang_hair_bsdf` network bound to the curves). Off for scenes
    /// that bind their own hair shader to the primvars.
    pub material: bool,
}

impl Default for HairLook {
    /// Cycles' Principled Hair defaults (melanin 0.8, redness 1, white
    /// tint, roughness 0.3, radial roughness 0.3), no jitter, seed 0, a
    /// material.
    fn default() -> Self {
        Self {
            melanin: Map::Constant(0.8),
            melanin_redness: Map::Constant(1.0),
            tint: [Map::Constant(1.0), Map::Constant(1.0), Map::Constant(1.0)],
            roughness: Map::Constant(0.3),
            radial_roughness: Map::Constant(0.3),
            jitter: Map::Constant(0.0),
            seed: 0,
            material: true,
        }
    }
}

impl HairLook {
    /// Its maps with their keys (`melanin`, `tint`, …).
    pub(crate) fn maps_mut(&mut self) -> Vec<(&'static str, &mut Map)> {
        let [r, g, b] = &mut self.tint;
        vec![
            ("melanin", &mut self.melanin),
            ("melanin_redness", &mut self.melanin_redness),
            ("tint", r),
            ("tint", g),
            ("tint", b),
            ("roughness", &mut self.roughness),
            ("radial_roughness", &mut self.radial_roughness),
            ("jitter", &mut self.jitter),
        ]
    }

    /// The values of the hairs rooted at `roots` with ids `ids` (the maps
    /// bound to `mesh`).
    pub fn shade(&self, mesh: &Mesh, roots: &[SurfacePoint], ids: &[u64]) -> HairShading {
        debug_assert_eq!(roots.len(), ids.len());
        let chunks: Vec<HairShading> = roots
            .par_chunks(CHUNK)
            .zip(ids.par_chunks(CHUNK))
            .map(|(roots, ids)| {
                let mut out = HairShading::with_capacity(roots.len());
                for (root, &id) in roots.iter().zip(ids) {
                    self.shade_one(mesh, *root, id, &mut out);
                }
                out
            })
            .collect();
        let mut all = HairShading::with_capacity(roots.len());
        for chunk in &chunks {
            all.extend_from(chunk);
        }
        all
    }

    /// Appends one hair's values.
    fn shade_one(&self, mesh: &Mesh, root: SurfacePoint, id: u64, out: &mut HairShading) {
        let site = MapSite::on(mesh, root);
        let jitter = self.jitter.at(&site);
        let varied = |map: &Map, salt: u64| {
            let mut factor = 1.0;
            if jitter != 0.0 {
                let xi = SampleRng::new(self.seed ^ salt, id).uniform_f32();
                factor += jitter * (2.0 * xi - 1.0);
            }
            unit(map.at(&site) * factor)
        };
        out.melanin.push(varied(&self.melanin, salts::LOOK_MELANIN));
        out.melanin_redness
            .push(varied(&self.melanin_redness, salts::LOOK_REDNESS));
        out.roughness
            .push(varied(&self.roughness, salts::LOOK_ROUGHNESS));
        out.radial_roughness
            .push(varied(&self.radial_roughness, salts::LOOK_RADIAL_ROUGHNESS));
        let tint = Vec3::from(self.tint.each_ref().map(|m| m.at(&site)));
        out.tint.push(tint.max(Vec3::ZERO));
        out.random
            .push(SampleRng::new(self.seed ^ salts::LOOK_RANDOM, id).uniform_f32());
    }
}

/// Cycles' absorption coefficients of a unit concentration of eumelanin
/// and of pheomelanin (as the hair material's network uses them).
const EUMELANIN_SIGMA: Vec3 = Vec3::new(0.506, 0.841, 1.653);
const PHEOMELANIN_SIGMA: Vec3 = Vec3::new(0.343, 0.733, 1.924);

/// Chiang et al. 2016, eq. 9's denominator: how the absorption that
/// gives a colour scales with the azimuthal roughness `beta`
/// (`σ_a = (ln c / D(β))²`).
fn color_scale(beta: f32) -> f32 {
    5.969 - 0.215 * beta + 2.532 * beta.powi(2) - 10.73 * beta.powi(3)
        + 5.574 * beta.powi(4)
        + 0.245 * beta.powi(5)
}

/// The colour (linear RGB) a hair of `melanin` and `redness` (Cycles'
/// 0–1 scales) reads as at azimuthal roughness `beta`: the inverse of
/// [`melanin_of_color`].
pub fn color_of_melanin(melanin: f32, redness: f32, beta: f32) -> Vec3 {
    let concentration = -(1.0 - melanin).max(1e-4).ln();
    let sigma = concentration * ((1.0 - redness) * EUMELANIN_SIGMA + redness * PHEOMELANIN_SIGMA);
    let scale = color_scale(beta);
    Vec3::from(sigma.to_array().map(|s| (-s.max(0.0).sqrt() * scale).exp()))
}

/// The melanin and redness (Cycles' 0–1 scales) whose colour at
/// azimuthal roughness `beta` is nearest the linear colour `color`, in
/// log colour (`ln c`, each channel within 10⁻⁶ to 1): a mix of the two
/// pigments gives `ln c = −√(concentration · σ(redness)) · D(β)`, linear in
/// `√concentration`, so for each redness the best concentration is a
/// least-squares line fit; the redness is searched on a grid of 100
/// steps, then of 0.001 around the best. Exact where a mix gives the
/// colour; a colour none gives (a blue, an orange more saturated than
/// pheomelanin) gets the nearest.
pub fn melanin_of_color(color: Vec3, beta: f32) -> (f32, f32) {
    let scale = color_scale(beta);
    let logs = color.to_array().map(|c| c.clamp(1e-6, 1.0).ln());
    // For redness r: the best √concentration and its squared error.
    let fit = |r: f32| {
        let sigma = (1.0 - r) * EUMELANIN_SIGMA + r * PHEOMELANIN_SIGMA;
        let a = sigma.to_array().map(|s| s.sqrt() * scale);
        let aa: f32 = a.iter().map(|x| x * x).sum();
        let la: f32 = logs.iter().zip(&a).map(|(l, x)| l * x).sum();
        let t = (-la / aa).max(0.0);
        let error: f32 = logs.iter().zip(&a).map(|(l, x)| (l + t * x).powi(2)).sum();
        (error, t)
    };
    let best = |steps: std::ops::RangeInclusive<i32>, step: f32, from: f32| {
        steps
            .map(|k| (from + k as f32 * step).clamp(0.0, 1.0))
            .map(|r| (fit(r), r))
            .min_by(|((x, _), _), ((y, _), _)| x.total_cmp(y))
            .expect("a step")
    };
    let (_, coarse) = best(0..=100, 0.01, 0.0);
    let ((_, t), redness) = best(-10..=10, 0.001, coarse);
    let concentration = t * t;
    if concentration <= 0.0 {
        return (0.0, 0.0);
    }
    (unit(1.0 - (-concentration).exp()), unit(redness))
}

impl HairLook {
    /// The values of hairs shaded by their colours, for a groom with
    /// colours and no `[look]`: melanin and redness fitted to each root's
    /// colour ([`melanin_of_color`]), the other values the defaults'
    /// (a white tint, roughness and radial roughness 0.3), and
    /// `hair_random` from each id, as the default look's seed (0) draws it.
    pub fn fitted_to_colors(root_colors: &[Vec3], ids: &[u64]) -> HairShading {
        let beta = 0.3;
        let mut out = HairShading::with_capacity(root_colors.len());
        for (&color, &id) in root_colors.iter().zip(ids) {
            let (melanin, redness) = melanin_of_color(color, beta);
            out.melanin.push(melanin);
            out.melanin_redness.push(redness);
            out.roughness.push(0.3);
            out.radial_roughness.push(beta);
            out.tint.push(Vec3::ONE);
            out.random
                .push(SampleRng::new(salts::LOOK_RANDOM, id).uniform_f32());
        }
        out
    }
}

/// `v` kept within 0 to 1 (NaN reads 0).
fn unit(v: f32) -> f32 {
    if v > 0.0 { v.min(1.0) } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn melanin_fitted_to_a_colour_gives_that_colour_back() {
        // Every mix of the two pigments, read as a colour and fitted
        // again: the same colour (the fit is exact where a mix exists).
        for melanin in [0.05, 0.2, 0.5, 0.8, 0.95] {
            for redness in [0.0, 0.3, 0.7, 1.0] {
                let color = color_of_melanin(melanin, redness, 0.3);
                let (m, r) = melanin_of_color(color, 0.3);
                let back = color_of_melanin(m, r, 0.3);
                assert!(
                    (back - color).abs().max_element() < 2e-3,
                    "{melanin} {redness}: {color} fitted as {m} {r}, giving {back}"
                );
            }
        }
        // A red fox's orange is mostly pheomelanin, white little of
        // either, black a lot of eumelanin.
        let (m, r) = melanin_of_color(Vec3::new(0.6, 0.2, 0.05), 0.3);
        assert!(r > 0.8 && m > 0.05 && m < 0.5, "{m} {r}");
        let (m, _) = melanin_of_color(Vec3::splat(0.9), 0.3);
        assert!(m < 0.1, "{m}");
        let (m, r) = melanin_of_color(Vec3::splat(0.01), 0.3);
        assert!(m > 0.3 && r < 0.2, "{m} {r}");
    }

    #[test]
    fn constants_come_through_and_jitter_stays_within_its_band() {
        let mesh = crate::assets::spot();
        let roots: Vec<SurfacePoint> = (0..2000)
            .map(|i| SurfacePoint::new(i % mesh.triangle_count() as u32, [0.3, 0.3]))
            .collect();
        let ids: Vec<u64> = (0..2000).map(|i| i * 7 + 3).collect();
        let plain = HairLook {
            melanin: Map::Constant(0.4),
            ..HairLook::default()
        }
        .shade(&mesh, &roots, &ids);
        assert_eq!(plain.len(), 2000);
        assert!(plain.melanin.iter().all(|&m| m == 0.4));
        assert!(plain.tint.iter().all(|&t| t == Vec3::ONE));
        let jittered = HairLook {
            melanin: Map::Constant(0.4),
            jitter: Map::Constant(0.25),
            ..HairLook::default()
        }
        .shade(&mesh, &roots, &ids);
        let (lo, hi) = jittered
            .melanin
            .iter()
            .fold((1.0f32, 0.0f32), |(lo, hi), &m| (lo.min(m), hi.max(m)));
        assert!(lo >= 0.3 - 1e-6 && hi <= 0.5 + 1e-6, "{lo} {hi}");
        assert!(lo < 0.31 && hi > 0.49, "the band is used: {lo} {hi}");
        // Redness 1 times 1.25 stays 1; melanin and roughness draw apart.
        assert!(jittered.melanin_redness.iter().all(|&r| r <= 1.0));
        assert_ne!(jittered.melanin, jittered.roughness);
        // The random number is uniform and the same for the same id.
        let mean = jittered.random.iter().sum::<f32>() / 2000.0;
        assert!((mean - 0.5).abs() < 0.03, "{mean}");
        assert_eq!(jittered.random, plain.random);
    }
}
