//! Guide interpolation: each hair's shape as a weighted sum of guide shapes.
//!
//! Two ways of choosing the guides and their weights, behind one small
//! interface ([`GuideWeights`]) so the groom generator picks one by name
//! ([`InterpolationMethod`]):
//!
//! - [`Shepard`]: the k nearest guide roots in space from a kd-tree,
//!   inverse-distance weights (Sik §4.2.2, Stubble; Shepard 1968).
//! - [`StyleMesh`]: the Furtility talk's style mesh, built from the surface
//!   by geodesic colouring; a hair takes the barycentric weights of its
//!   closest point on it. It exists because Shepard fails on thin parts: a
//!   hair on one side of an ear must not follow a guide on the other side.
//!
//! Shapes are combined in the hair's own frame: each guide's offsets from
//! its root are turned by the smallest rotation that takes the guide's root
//! normal to the hair's root normal, then weighted. So hairs follow the
//! surface's curvature, and a hair at a guide's root is that guide exactly.
//! (Frames built from UV tangents would flip across UV seams; the minimal
//! rotation between two normals has no seams.)

mod regional;
mod shepard;
mod style_mesh;

pub use crate::nearest::{NearestPoints, Neighbour, NeighbourCache, QueryRegion};
pub use regional::RegionWeights;
pub(crate) use regional::indices_by_region;
pub use shepard::Shepard;
pub use style_mesh::{LostGuide, StyleMesh, StyleMeshOptions};

use crate::guides::Guides;
use crate::mesh::{Mesh, SurfacePoint};
use glam::{Mat3, Quat, Vec3, Vec3A};
use std::sync::Arc;

/// One guide's share of a hair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuideWeight {
    /// The guide's index.
    pub guide: u32,
    /// Its weight (non-negative; a hair's weights sum to 1).
    pub weight: f32,
}

/// Where a hair grows: its root in world space and, when it is on the
/// skin, the skin triangle it lies on (the style mesh uses it to look only
/// at the hair's own cells).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HairRoot {
    /// The root position.
    pub position: Vec3,
    /// The skin triangle under the root, if known.
    pub triangle: Option<u32>,
    /// The root's region (0 when the skin is not split;
    /// [`RegionWeights`] reads it).
    pub region: u32,
}

impl HairRoot {
    /// A root on the skin.
    pub fn on(mesh: &Mesh, point: SurfacePoint) -> Self {
        Self {
            position: point.position(mesh),
            triangle: Some(point.tri),
            region: 0,
        }
    }

    /// A root known only by its position.
    pub fn at(position: Vec3) -> Self {
        Self {
            position,
            triangle: None,
            region: 0,
        }
    }
}

/// Chooses guides and weights for a hair root.
pub trait GuideWeights: Send + Sync {
    /// Replaces `out` with the guides and weights of a hair rooted at
    /// `root`. Weights are non-negative and sum to 1.
    fn weights(&self, root: HairRoot, out: &mut Vec<GuideWeight>);

    /// [`Self::weights`] for one of a run of nearby roots (a part's hairs,
    /// sorted by triangle): `near` keeps what earlier roots found, which
    /// Shepard uses to skip most kd-tree searches. The same result as
    /// [`Self::weights`] whatever `near` holds.
    fn weights_near(&self, root: HairRoot, near: &mut NeighbourCache, out: &mut Vec<GuideWeight>) {
        let _ = near;
        self.weights(root, out);
    }

    /// Guides this weighting never uses, and why (the style mesh's guides
    /// that share a vertex with a nearer one). Empty by default.
    fn lost_guides(&self) -> Vec<LostGuide> {
        Vec::new()
    }
}

/// What shaping a run of hairs reuses from one hair to the next.
#[derive(Debug, Default)]
pub struct HairScratch {
    /// The last hair's guide weights.
    pub weights: Vec<GuideWeight>,
    /// Guides near the last roots.
    pub near: NeighbourCache,
}

/// An interpolation method by name, as groom files spell it.
#[derive(Debug, Clone, PartialEq)]
pub enum InterpolationMethod {
    /// `shepard`: k nearest guides, weights `1 / d^power`, guides beyond
    /// `radius` (if any) ignored.
    Shepard {
        /// Guides per hair.
        k: usize,
        /// Distance exponent.
        power: f32,
        /// Largest distance at which a guide counts.
        radius: Option<f32>,
    },
    /// `style-mesh`: Furtility's style mesh.
    StyleMesh(StyleMeshOptions),
}

impl InterpolationMethod {
    /// The method called `name` with its default parameters: `shepard`
    /// (k = 4, power = 2) or `style-mesh`.
    pub fn by_name(name: &str) -> Option<Self> {
        match name {
            "shepard" => Some(Self::Shepard {
                k: 4,
                power: 2.0,
                radius: None,
            }),
            "style-mesh" | "style_mesh" => Some(Self::StyleMesh(StyleMeshOptions::default())),
            _ => None,
        }
    }
}

/// Guides ready to shape hairs with one method.
pub struct Interpolator {
    /// Shared, so that an interpolator (and a generator holding one) owns
    /// what it reads and borrows nothing.
    guides: Arc<Guides>,
    /// Each guide's offsets from its root.
    offsets: Vec<Vec3>,
    /// Each guide's skin normal at its root, padded to 16 bytes: read as one load
    /// (a 12-byte `Vec3` went through the stack in two pieces and stalled
    /// the load that reassembled it).
    normals: Vec<Vec3A>,
    weights: Arc<dyn GuideWeights>,
}

impl Interpolator {
    /// Prepares `guides` (bound to `mesh`) for interpolation by `method`.
    pub fn new(mesh: &Mesh, guides: impl Into<Arc<Guides>>, method: &InterpolationMethod) -> Self {
        let guides = guides.into();
        let weights: Box<dyn GuideWeights> = match method {
            InterpolationMethod::Shepard { k, power, radius } => {
                Box::new(Shepard::new(mesh, &guides, *k, *power, *radius))
            }
            InterpolationMethod::StyleMesh(options) => {
                Box::new(StyleMesh::build(mesh, &guides, options))
            }
        };
        Self::with_weights(mesh, guides, weights)
    }

    /// Prepares `guides` for interpolation by `method` within regions:
    /// guide `i` is in region `guide_regions[i]`, and a hair takes its
    /// shape only from the guides of its own region
    /// ([`HairRoot::region`]); see [`RegionWeights`].
    pub fn with_regions(
        mesh: &Mesh,
        guides: impl Into<Arc<Guides>>,
        method: &InterpolationMethod,
        guide_regions: &[u32],
    ) -> Self {
        let guides = guides.into();
        let weights = RegionWeights::new(mesh, &guides, method, guide_regions);
        Self::with_weights(mesh, guides, Box::new(weights))
    }

    /// Prepares `guides` with a weighting of your own.
    pub fn with_weights(
        mesh: &Mesh,
        guides: impl Into<Arc<Guides>>,
        weights: Box<dyn GuideWeights>,
    ) -> Self {
        Self::with_shared_weights(mesh, guides.into(), Arc::from(weights))
    }

    fn with_shared_weights(
        mesh: &Mesh,
        guides: Arc<Guides>,
        weights: Arc<dyn GuideWeights>,
    ) -> Self {
        let mut offsets = Vec::with_capacity(guides.curves().points().len());
        for i in 0..guides.len() {
            let g = guides.guide(i);
            offsets.extend(g.iter().map(|p| *p - g[0]));
        }
        let normals = guides
            .roots()
            .iter()
            .map(|r| Vec3A::from(r.normal(mesh)))
            .collect();
        Self {
            guides,
            offsets,
            normals,
            weights,
        }
    }

    /// The same weighting over `guides`: guides with the same roots as
    /// this interpolator's, in other shapes (a frame of animated guides).
    pub fn reshaped(&self, mesh: &Mesh, guides: impl Into<Arc<Guides>>) -> Self {
        Self::with_shared_weights(mesh, guides.into(), self.weights.clone())
    }

    /// Each guide's offsets from its root, guide after guide (what
    /// [`Self::shape`] turns and weights).
    pub fn guide_offsets(&self) -> &[Vec3] {
        &self.offsets
    }

    /// Each guide's skin normal at its root.
    pub fn guide_normals(&self) -> impl ExactSizeIterator<Item = Vec3> + '_ {
        self.normals.iter().map(|&n| Vec3::from(n))
    }

    /// The guides.
    pub fn guides(&self) -> &Guides {
        &self.guides
    }

    /// The weighting.
    pub fn weighting(&self) -> &dyn GuideWeights {
        self.weights.as_ref()
    }

    /// Shapes the hair rooted at `root` into `out` (`points_per_guide`
    /// points, `out[0]` the root). `scratch` is best kept for a run of
    /// nearby roots (it speeds the guide search, never changes a result).
    pub fn hair(
        &self,
        mesh: &Mesh,
        root: SurfacePoint,
        scratch: &mut HairScratch,
        out: &mut [Vec3],
    ) {
        self.hair_at(HairRoot::on(mesh, root), root.normal(mesh), scratch, out);
    }

    /// [`Self::hair`] for a root whose position (with its triangle) and
    /// skin normal the caller has at hand already.
    pub fn hair_at(
        &self,
        root: HairRoot,
        normal: Vec3,
        scratch: &mut HairScratch,
        out: &mut [Vec3],
    ) {
        self.weights
            .weights_near(root, &mut scratch.near, &mut scratch.weights);
        self.shape(&scratch.weights, root.position, normal, out);
    }

    /// Shapes a hair at `position` with surface normal `normal` from given
    /// weights.
    pub fn shape(&self, weights: &[GuideWeight], position: Vec3, normal: Vec3, out: &mut [Vec3]) {
        let n = self.guides.points_per_guide();
        out.iter_mut().for_each(|p| *p = position);
        for w in weights {
            let g = w.guide as usize;
            // The weight folded into the rotation: one matrix-vector
            // product a point.
            let turn = w.weight * rotation_between(Vec3::from(self.normals[g]), normal);
            for (o, offset) in out.iter_mut().zip(&self.offsets[g * n..(g + 1) * n]) {
                *o += turn * *offset;
            }
        }
    }
}

/// The smallest rotation taking unit vector `from` to unit vector `to`, as
/// a matrix: Rodrigues' formula without trigonometry,
/// `R = I + [v]× + [v]×² / (1 + c)` with `v = from × to`, `c = from · to`.
/// Equal vectors give the identity exactly (so a hair at a guide's root is
/// that guide to the bit); nearly opposite ones, where `1 + c` vanishes,
/// fall back to glam's half-turn about a perpendicular axis.
fn rotation_between(from: Vec3, to: Vec3) -> Mat3 {
    let v = from.cross(to);
    let c = from.dot(to);
    let one_plus_c = 1.0 + c;
    if one_plus_c < 1e-4 {
        return Mat3::from_quat(Quat::from_rotation_arc(from, to));
    }
    let h = one_plus_c.recip();
    let (hx, hy, hz) = (h * v.x, h * v.y, h * v.z);
    let (xy, xz, yz) = (hx * v.y, hx * v.z, hy * v.z);
    Mat3::from_cols(
        Vec3::new(1.0 - hy * v.y - hz * v.z, xy + v.z, xz - v.y),
        Vec3::new(xy - v.z, 1.0 - hx * v.x - hz * v.z, yz + v.x),
        Vec3::new(xz + v.y, yz - v.x, 1.0 - hx * v.x - hy * v.y),
    )
}

/// Normalises weights to sum 1 (they must be non-negative, not all zero).
fn normalise(out: &mut [GuideWeight]) {
    let total: f32 = out.iter().map(|w| w.weight).sum();
    if total > 0.0 {
        out.iter_mut().for_each(|w| w.weight /= total);
    }
}
