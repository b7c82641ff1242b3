//! The generator: a [`GroomSpec`] prepared for growing (the root sampler
//! and part layout, the interpolator, the operator chain with its clump
//! centres), what it holds and answers, and each part's roots before any
//! thinning. Its layers above: `blue_noise.rs` thins the roots of all parts,
//! `grow.rs` grows a part's hairs (and traces a hair that overflows to its
//! operator), `build.rs` builds a generator from a spec. See the module
//! docs of [`crate::groom`] for the path of one hair.

use super::error::{GroomError, GroomErrorKind};
use super::hair_look::HairLook;
use super::ops::{Operator, Resampling};
use super::outside_skin::OutsideSkin;
use super::parts::{Part, PartLayout};
use super::parts::{sort_cell_roots, sorted_by_triangle};
use super::regions::RegionLookup;
use super::spec::{RootDistribution, SpecOrigin, setting_error};
use crate::curves::{CurveArrays, Curves};
use crate::guides::Guides;
use crate::interp::Interpolator;
use crate::mesh::{Mesh, SurfacePoint};
use crate::sample::{DensitySampler, RootCells, mix64, salts, sample_range};
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicUsize;
use std::sync::{Arc, Mutex, OnceLock};

/// What a generated part holds, for progress and summaries.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroomSummary {
    /// Hairs (curves) written.
    pub hairs: u64,
    /// Points written.
    pub points: u64,
}

/// A groom prepared for generation. Shared by every thread; [`Self::part`]
/// may be called in any order, any number of times.
pub struct Generator {
    pub(super) mesh: Arc<Mesh>,
    pub(super) guides: Arc<Guides>,
    /// The groom's name and where its settings were written, for errors.
    pub(super) name: PathBuf,
    pub(super) origin: Option<Arc<SpecOrigin>>,
    pub(super) sampler: Arc<DensitySampler>,
    /// With stable ids: the root cells parts are made of.
    pub(super) cells: Option<Arc<RootCells>>,
    pub(super) distribution: RootDistribution,
    pub(super) layout: Arc<PartLayout>,
    pub(super) interpolator: Interpolator,
    /// The skin's regions, when it is split.
    pub(super) regions: Option<Arc<RegionLookup>>,
    pub(super) ops: Vec<Operator>,
    /// The finish's width, colour and opacity, before the operators.
    pub(super) base: Vec<Operator>,
    pub(super) points: usize,
    /// From the guides' points to the hairs'.
    pub(super) resampling: Resampling,
    pub(super) colors: bool,
    pub(super) opacities: bool,
    /// Whether a `clump` searches for centres: only then do roots carry
    /// the ball around their triangle.
    pub(super) clumps: bool,
    /// Whether clump centres record the guides they depend on.
    pub(super) records_centre_guides: bool,
    /// [`crate::groom::GroomSpec::most_hairs_per_root`] of the spec it was built from.
    pub(super) hairs_per_root: u64,
    /// Every width's factor: `√(count / grown)`, one over the square root
    /// of the share of the hairs actually grown, so a preview covers the
    /// skin as the whole groom does.
    pub(super) width_scale: f32,
    pub(super) normals: bool,
    /// The skin hairs are kept out of, after the operators.
    pub(super) outside_skin: Option<Arc<OutsideSkin>>,
    /// Each hair's values for a hair shader.
    pub(super) look: Option<HairLook>,
    pub(super) seed: u64,
    /// Arrays of parts handed back by [`Self::recycle`], for the next parts.
    pub(super) spare: Arc<Mutex<Vec<CurveArrays>>>,
    /// The part asked for last (`usize::MAX`: none yet), and the roots of
    /// the one after it, sampled ahead.
    pub(super) last_part: AtomicUsize,
    pub(super) prefetched: Mutex<Option<(usize, PartRoots)>>,
    /// Blue-noise roots: every part's, thinned together when the first
    /// part asks.
    pub(super) blue_noise_roots: OnceLock<Vec<PartRoots>>,
}

/// What [`Generator::rebuilt`] takes from an earlier generator instead of
/// building again.
#[derive(Clone, Copy, Default)]
pub(crate) struct Reuse<'a> {
    /// The earlier generator (`None`: build everything).
    pub(crate) from: Option<&'a Generator>,
    /// The root sampler, root cells and part layout (same mesh geometry,
    /// density, count and seed).
    pub(crate) roots: bool,
    /// The region lookup (same regions map or face sets).
    pub(crate) regions: bool,
    /// The guide weighting (same guide roots and regions, same method);
    /// only with `regions`.
    pub(crate) weights: bool,
    /// With `weights`: the only guides whose shape changed (`None`: any
    /// may have). Clump centres of other guides keep their shapes.
    pub(crate) moved_guides: Option<&'a [u32]>,
    /// Record the guides each clump centre depends on (an editable groom
    /// reads them; a groom grown once does not pay for them).
    pub(crate) centre_guides: bool,
}

/// A part's roots, in the order they grow, and their hairs' ids.
pub(super) type PartRoots = (Vec<SurfacePoint>, Vec<u64>);

/// Parts' arrays kept for reuse: a writer holds one part while the next
/// grows, so two cover the stream.
const SPARE_PARTS: usize = 2;

impl std::fmt::Debug for Generator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Generator")
            .field("parts", &self.layout.len())
            .field(
                "ops",
                &self.ops.iter().map(Operator::name).collect::<Vec<_>>(),
            )
            .finish()
    }
}

impl Generator {
    /// An error about the setting `key` (`ops[2].clump`,
    /// `finish.outside_skin`), at its line when the groom came from a file.
    pub fn error(&self, key: &str, kind: GroomErrorKind) -> GroomError {
        setting_error(&self.name, self.origin.as_deref(), key, kind)
    }

    /// The region of a point of the skin (0 when it is not split).
    pub fn region_of(&self, point: SurfacePoint) -> u32 {
        self.regions.as_ref().map_or(0, |r| r.of(&self.mesh, point))
    }

    /// The guides' curves as written beside the hairs, with the region
    /// of each guide's root when the skin is split.
    pub fn guide_curves(&self) -> Curves {
        let curves = self.guides.curves().clone();
        match self.regions_at(self.guides.roots()) {
            Some(regions) => curves.with_regions(regions).expect("one region a guide"),
            None => curves,
        }
    }

    /// The region of each of `roots` when the skin is split.
    pub(super) fn regions_at(&self, roots: &[SurfacePoint]) -> Option<Vec<u32>> {
        let lookup = self.regions.as_ref()?;
        Some(roots.iter().map(|&r| lookup.of(&self.mesh, r)).collect())
    }

    /// The skin's regions, when it is split.
    pub fn regions(&self) -> Option<&RegionLookup> {
        self.regions.as_deref()
    }

    /// Guides the interpolation never uses, and why (the style mesh's
    /// guides that share a vertex with a nearer one).
    pub fn lost_guides(&self) -> Vec<crate::interp::LostGuide> {
        self.interpolator.weighting().lost_guides()
    }

    /// The mesh hairs grow on.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The guides.
    pub fn guides(&self) -> &Guides {
        &self.guides
    }

    /// The seed every random number of the groom derives from.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The parts, in order.
    pub fn parts(&self) -> &[Part] {
        self.layout.parts()
    }

    /// The operator chain.
    pub fn operators(&self) -> &[Operator] {
        &self.ops
    }

    /// The most hairs one root grows ([`crate::groom::GroomSpec::most_hairs_per_root`]).
    pub fn most_hairs_per_root(&self) -> u64 {
        self.hairs_per_root
    }

    /// Points per hair.
    pub fn points_per_hair(&self) -> usize {
        self.points
    }

    /// [`Self::part_roots`] before any blue-noise thinning.
    pub(super) fn regular_part_roots(&self, p: usize) -> (Vec<SurfacePoint>, Vec<u64>) {
        let part = &self.layout.parts()[p];
        if part.hair_count == 0 {
            return (Vec::new(), Vec::new());
        }
        match &self.cells {
            Some(cells) => {
                let grown: Vec<(Vec<SurfacePoint>, Vec<u64>)> = part
                    .cells
                    .par_iter()
                    .with_max_len(8)
                    .map(|&(c, n)| {
                        let roots = cells.roots(&self.sampler, self.seed, c as usize, n);
                        let mut keyed: Vec<(SurfacePoint, u64)> = roots
                            .into_iter()
                            .enumerate()
                            .map(|(k, r)| (r, cells.id(c as usize, k as u64)))
                            .collect();
                        sort_cell_roots(&mut keyed);
                        keyed.into_iter().unzip::<_, _, Vec<_>, Vec<_>>()
                    })
                    .collect();
                let (mut roots, mut ids) = (Vec::new(), Vec::new());
                for (r, i) in grown {
                    roots.extend(r);
                    ids.extend(i);
                }
                (roots, ids)
            }
            None => {
                let Some(sampler) = self.sampler.restricted(&part.triangles) else {
                    return (Vec::new(), Vec::new());
                };
                let stream = mix64(self.seed ^ mix64(salts::PART_ROOTS + p as u64));
                let roots = sorted_by_triangle(sample_range(&sampler, stream, 0..part.hair_count));
                let ids = (part.first_hair..part.first_hair + roots.len() as u64).collect();
                (roots, ids)
            }
        }
    }

    /// The root cells hairs are numbered by (stable ids).
    pub fn root_cells(&self) -> Option<&RootCells> {
        self.cells.as_deref()
    }

    /// The root sampler over the whole mesh.
    pub fn sampler(&self) -> &DensitySampler {
        &self.sampler
    }

    /// Hands a grown part back once it is written, so that a later part
    /// reuses its memory instead of asking the kernel for fresh pages
    /// (whose first touch faults and zeroes them: a tenth of a groom's
    /// time). Optional; a part not handed back is simply freed.
    pub fn recycle(&self, curves: Curves) {
        let mut spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
        if spare.len() < SPARE_PARTS {
            spare.push(curves.into_arrays());
        }
    }

    pub(super) fn spare_arrays(&self) -> CurveArrays {
        let mut spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
        spare.pop().unwrap_or_default()
    }
}
