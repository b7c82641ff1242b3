//! Root sampling: points on a mesh distributed by a density [`Map`]
//! (Sik §3), the roots every hair grows from.
//!
//! - [`DensitySampler`]: the paper's method: sub-triangle subdivision to
//!   one texel, sibling merging, 12-byte records, and selection by CDF +
//!   uniform grid or by an alias table.
//! - [`RejectionSampler`]: the paper's baseline (§3.4.1).
//! - [`blue_noise_samples`]: samples of a [`DensitySampler`] thinned to
//!   blue noise (dart throwing over candidates, in parallel).
//!
//! Both implement [`SurfaceSampler`]: sample `i` is a pure function of
//! `(seed, i)` ([`PairDraws`], [`SampleRng`]), and each sampler gives its probability
//! density per unit area, pbrt style, so tests compare histograms with it.
//! [`sample_range`] generates any index range in parallel.
//!
//! [`Map`]: crate::Map

mod alias;
pub mod blue_noise;
mod cdf;
mod cells;
mod density;
mod rejection;
mod rng;
pub mod salts;
pub mod subtriangle;
pub mod warp;

pub use alias::{AliasBin, AliasBins, AliasTable, build_alias_bins};
pub use blue_noise::{BlueNoiseTimes, blue_noise_samples};
pub use cdf::CdfGrid;
pub use cells::RootCells;
pub use density::{
    CellSampler, DensitySampler, DensitySamplerOptions, Selector, SubTriangleRecord,
};
pub use rejection::RejectionSampler;
pub use rng::{PairDraws, SampleRng, mix64, open_unit_pair};

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

    /// Fills `out` with samples `first..first + out.len()`. The same
    /// points as calling [`SurfaceSampler::sample`] for each index; a
    /// sampler may override it to overlap the memory reads of many samples.
    fn sample_block(&self, seed: u64, first: u64, out: &mut [SurfacePoint]) {
        for (k, slot) in out.iter_mut().enumerate() {
            *slot = self.sample(seed, first + k as u64);
        }
    }
}

/// Asks the CPU to start loading the cache line holding `value`; a hint
/// with no effect on results.
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching is only a hint; it never faults, even for
    // addresses that are not mapped, and `value` is a valid reference.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>((value as *const T).cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
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
    const BLOCK: usize = 64;
    out.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, chunk)| {
            let start = first + (c * CHUNK) as u64;
            for (b, block) in chunk.chunks_mut(BLOCK).enumerate() {
                sampler.sample_block(seed, start + (b * BLOCK) as u64, block);
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
