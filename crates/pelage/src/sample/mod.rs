//! Root sampling: points on a mesh distributed by a density [`Map`]
//! (Sik §3), the roots every hair grows from.
//!
//! - [`DensitySampler`]: the paper's method: sub-triangle subdivision to
//!   one texel, sibling merging, 12-byte records, and selection by CDF +
//!   uniform grid or by an alias table.
//! - [`RejectionSampler`]: the paper's baseline (§3.4.1).
//!
//! Both implement [`SurfaceSampler`]: sample `i` is a pure function of
//! `(seed, i)` ([`SampleRng`]), and each sampler gives its probability
//! density per unit area, pbrt style, so tests compare histograms with it.
//! [`sample_range`] generates any index range in parallel.
//!
//! [`Map`]: crate::Map

mod alias;
mod cdf;
mod density;
mod rejection;
mod rng;
pub mod subtriangle;
pub mod warp;

pub use alias::{AliasBin, AliasTable};
pub use cdf::CdfGrid;
pub use density::{DensitySampler, DensitySamplerOptions, Selector, SubTriangleRecord};
pub use rejection::RejectionSampler;
pub use rng::{SampleRng, mix64};

use crate::mesh::SurfacePoint;
use rayon::prelude::*;
use std::ops::Range;

/// A way of drawing points on a mesh.
pub trait SurfaceSampler: Sync {
    /// Sample `index` of the stream `seed`: a pure function of both.
    fn sample(&self, seed: u64, index: u64) -> SurfacePoint;

    /// Probability density per unit area at `point`, normalised over the
    /// mesh (0 where the sampler never goes).
    fn pdf(&self, point: SurfacePoint) -> f64;
}

/// Samples `range` of stream `seed` in parallel (rayon's current pool).
/// The result is identical for any number of threads, and generating
/// sub-ranges separately gives exactly the corresponding slices.
pub fn sample_range<S: SurfaceSampler + ?Sized>(
    sampler: &S,
    seed: u64,
    range: Range<u64>,
) -> Vec<SurfacePoint> {
    let mut out = vec![SurfacePoint::default(); (range.end - range.start) as usize];
    sample_into(sampler, seed, range.start, &mut out);
    out
}

/// Fills `out` with samples `first..first + out.len()` of stream `seed`,
/// in parallel.
pub fn sample_into<S: SurfaceSampler + ?Sized>(
    sampler: &S,
    seed: u64,
    first: u64,
    out: &mut [SurfacePoint],
) {
    const CHUNK: usize = 16 * 1024;
    out.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, chunk)| {
            let start = first + (c * CHUNK) as u64;
            for (k, slot) in chunk.iter_mut().enumerate() {
                *slot = sampler.sample(seed, start + k as u64);
            }
        });
}

/// Sampling could not be set up. Each error names the mesh.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SampleError {
    /// The density map cannot be evaluated on this mesh (e.g. no UVs).
    #[error(transparent)]
    Map(#[from] crate::map::MapError),
    /// The density is zero (or the mesh has no area) everywhere.
    #[error(
        "{mesh}: the density is zero everywhere on the mesh (or every triangle is degenerate); there is nowhere to place a sample"
    )]
    ZeroDensity {
        /// The mesh's name.
        mesh: String,
    },
    /// A density value is negative, NaN or infinite.
    #[error("{mesh}: triangle {triangle}{}: the density is {value}; densities must be finite and not negative", uv.map(|[u, v]| format!(" at UV ({u:.4}, {v:.4})")).unwrap_or_default())]
    BadDensity {
        /// The mesh's name.
        mesh: String,
        /// The triangle where it was found.
        triangle: u32,
        /// The UV where it was evaluated, if the mesh has UVs.
        uv: Option<[f32; 2]>,
        /// The value.
        value: f32,
    },
}
