//! The rejection-sampling baseline of Sik §3.4.1: choose a triangle by area
//! (a CDF searched by bisection), a uniform point in it, and accept it when
//! a uniform number is below the density there.
//!
//! The paper's densities lie in [0, 1]. For maps that exceed 1 the
//! acceptance test divides by the map's upper bound, which leaves the
//! distribution exact and equals the paper's test whenever the map ≤ 1.

use super::cdf::CdfGrid;
use super::density::{DensitySamplerOptions, SubTriangleRecords};
use super::rng::SampleRng;
use super::{SampleError, SurfaceSampler, warp};
use crate::map::{Map, MapOnMesh};
use crate::mesh::{Mesh, SurfacePoint};

/// Rejection sampling of a density map over a mesh.
#[derive(Debug, Clone)]
pub struct RejectionSampler<'m> {
    mesh: &'m Mesh,
    map: MapOnMesh<'m>,
    /// Triangles by area, bisection only (no grid), as in the paper.
    area_cdf: CdfGrid,
    /// Triangle index of each CDF entry (degenerate triangles are left out).
    triangles: Vec<u32>,
    acceptance_scale: f32,
    /// ∫ density dA, for the pdf.
    normalisation: f64,
}

impl<'m> RejectionSampler<'m> {
    /// Builds the area CDF. The density is validated (and its integral,
    /// needed by [`SurfaceSampler::pdf`], computed) with the same
    /// sub-triangle quadrature as [`DensitySampler`](super::DensitySampler), so an all-zero,
    /// negative or NaN density is an error here too, instead of a sampler
    /// that never accepts.
    pub fn new(mesh: &'m Mesh, density: &'m Map) -> Result<Self, SampleError> {
        let map = density.on_mesh(mesh)?;
        // The records alone: no selector is built.
        let quadrature =
            SubTriangleRecords::build(mesh, density, DensitySamplerOptions::default().max_level)?;
        let triangles: Vec<u32> = (0..mesh.triangle_count() as u32)
            .filter(|&t| mesh.triangle_areas()[t as usize] > 0.0)
            .collect();
        let area_cdf = CdfGrid::new(
            triangles
                .iter()
                .map(|&t| f64::from(mesh.triangle_areas()[t as usize])),
            0,
        );
        Ok(Self {
            mesh,
            map,
            area_cdf,
            triangles,
            acceptance_scale: 1.0 / density.upper_bound().max(1.0),
            normalisation: quadrature.total,
        })
    }
}

impl SurfaceSampler for RejectionSampler<'_> {
    fn sample(&self, seed: u64, index: u64) -> SurfacePoint {
        let mut rng = SampleRng::new(seed, index);
        loop {
            let t = self.triangles[self.area_cdf.select(rng.next_u64())];
            let bary = warp::sample_uniform_triangle(rng.uniform_f32_pair());
            let point = SurfacePoint { tri: t, bary };
            if rng.uniform_f32() < self.map.eval(point) * self.acceptance_scale {
                return point;
            }
        }
    }

    /// `density / ∫ density dA`, the integral by the sub-triangle quadrature
    /// (exact for maps linear over each sub-triangle).
    fn pdf(&self, point: SurfacePoint) -> f64 {
        if self.mesh.triangle_areas()[point.tri as usize] == 0.0 {
            return 0.0;
        }
        f64::from(self.map.eval(point)) / self.normalisation
    }
}
