//! Interpolation within regions: a hair takes its shape only from guides
//! of its own region, so a parting stays parted and a mane does not pull
//! the neck's hair up. Each region gets its own weighting (Shepard's
//! kd-tree or a style mesh) over its own guides; a region without guides
//! borrows from all of them (reported by the groom, never silent).

use super::{
    GuideWeight, GuideWeights, HairRoot, InterpolationMethod, NeighbourCache, Shepard, StyleMesh,
};
use crate::guides::Guides;
use crate::mesh::Mesh;

/// A region's weighting over its own guides, and their indices among all.
type RegionGuides = (Box<dyn GuideWeights>, Vec<u32>);

/// One weighting a region, over the region's guides.
pub struct RegionWeights {
    /// Indexed by region id (`None`: no guide in the region).
    regions: Vec<Option<RegionGuides>>,
    /// Over every guide, for hairs in a region without guides.
    all: Box<dyn GuideWeights>,
}

impl RegionWeights {
    /// Weightings by `method` for each region that has guides; guide `i`
    /// is in region `guide_regions[i]`.
    pub fn new(
        mesh: &Mesh,
        guides: &Guides,
        method: &InterpolationMethod,
        guide_regions: &[u32],
    ) -> Self {
        assert_eq!(guide_regions.len(), guides.len(), "one region a guide");
        let build = |guides: &Guides| -> Box<dyn GuideWeights> {
            match method {
                InterpolationMethod::Shepard { k, power, radius } => {
                    Box::new(Shepard::new(mesh, guides, *k, *power, *radius))
                }
                InterpolationMethod::StyleMesh(options) => {
                    Box::new(StyleMesh::build(mesh, guides, options))
                }
            }
        };
        let regions = indices_by_region(guide_regions)
            .into_iter()
            .map(|indices| {
                (!indices.is_empty()).then(|| (build(&guides.subset(&indices)), indices))
            })
            .collect();
        Self {
            regions,
            all: build(guides),
        }
    }

    /// The region's weighting and guide indices, if it has guides.
    fn region(&self, region: u32) -> Option<&RegionGuides> {
        self.regions.get(region as usize).and_then(Option::as_ref)
    }
}

impl GuideWeights for RegionWeights {
    fn weights(&self, root: HairRoot, out: &mut Vec<GuideWeight>) {
        match self.region(root.region) {
            Some((weights, indices)) => {
                weights.weights(root, out);
                to_all(out, indices);
            }
            None => self.all.weights(root, out),
        }
    }

    fn weights_near(&self, root: HairRoot, near: &mut NeighbourCache, out: &mut Vec<GuideWeight>) {
        // The cache keeps each kd-tree's candidates apart, so one cache
        // serves every region.
        match self.region(root.region) {
            Some((weights, indices)) => {
                weights.weights_near(root, near, out);
                to_all(out, indices);
            }
            None => self.all.weights_near(root, near, out),
        }
    }

    /// Each region's lost guides, numbered among all guides.
    fn lost_guides(&self) -> Vec<super::LostGuide> {
        let mut lost = Vec::new();
        for (weights, indices) in self.regions.iter().flatten() {
            lost.extend(weights.lost_guides().into_iter().map(|l| super::LostGuide {
                guide: indices[l.guide as usize],
                kept_by: indices[l.kept_by as usize],
                ..l
            }));
        }
        lost.sort_by_key(|l| l.guide);
        lost
    }
}

/// For each region id up to the largest in `regions`, the indices of the
/// items in it, ascending (empty for an id no item has).
pub(crate) fn indices_by_region(regions: &[u32]) -> Vec<Vec<u32>> {
    let top = regions.iter().copied().max().map_or(0, |m| m as usize + 1);
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); top];
    for (i, &r) in regions.iter().enumerate() {
        members[r as usize].push(i as u32);
    }
    members
}

/// Renumbers a region's guide weights to indices among all guides.
fn to_all(out: &mut [GuideWeight], indices: &[u32]) {
    for w in out {
        w.guide = indices[w.guide as usize];
    }
}
