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

/// `v` kept within 0 to 1 (NaN reads 0).
fn unit(v: f32) -> f32 {
    if v > 0.0 { v.min(1.0) } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

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
