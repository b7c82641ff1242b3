//! Guide curves: the few hundred to few thousand curves an artist grooms,
//! from which every generated hair takes its shape (Sik §4.2.2; Furtility).
//!
//! [`Guides`] are curves bound to the mesh they grow from — each root is a
//! [`SurfacePoint`] — and resampled to one point count, so a hair can
//! interpolate them point by point. Guides come from a file
//! ([`Guides::bind`], with a report of the ones left out) or are grown on
//! the mesh ([`Guides::grow`]).

use crate::map::{Map, MapError};
use crate::mesh::{Mesh, SurfacePoint, TriangleBvh};
use crate::sample::{DensitySampler, DensitySamplerOptions, SampleError, sample_range};
use crate::{Curves, curves::CurvesError};
use glam::Vec3;

/// Guide curves bound to a mesh, all with the same number of points.
#[derive(Debug, Clone)]
pub struct Guides {
    /// The guides, their roots attached (`Curves::roots` is always set).
    curves: Curves,
    points_per_guide: usize,
}

/// Why a guide was left out.
#[derive(Debug, Clone, PartialEq)]
pub enum DropReason {
    /// Its root is farther from the surface than the tolerance.
    FarFromSurface {
        /// Distance from the root to the closest point of the mesh.
        distance: f32,
    },
    /// It has fewer than two points (no direction, no length).
    TooFewPoints(usize),
}

/// A guide left out by [`Guides::bind`].
#[derive(Debug, Clone, PartialEq)]
pub struct DroppedGuide {
    /// Its index in the file.
    pub index: usize,
    /// Why.
    pub reason: DropReason,
}

impl std::fmt::Display for DroppedGuide {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.reason {
            DropReason::FarFromSurface { distance } => write!(
                f,
                "guide {} left out: its root is {distance:.6} from the surface",
                self.index
            ),
            DropReason::TooFewPoints(n) => {
                write!(f, "guide {} left out: it has {n} point(s)", self.index)
            }
        }
    }
}

/// What [`Guides::bind`] did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BindReport {
    /// Guides kept.
    pub kept: usize,
    /// Guides left out, in file order.
    pub dropped: Vec<DroppedGuide>,
    /// The largest root-to-surface distance among the kept guides.
    pub max_distance: f32,
}

/// How [`Guides::grow`] grows guides.
#[derive(Debug, Clone)]
pub struct GuideGrowth {
    /// Number of guides.
    pub count: usize,
    /// Root density (the sampler's map).
    pub density: Map,
    /// Length at the root's UV.
    pub length: Map,
    /// Comb direction (world space); its part along the surface bends the
    /// guide, its length is the strength (0: straight along the normal).
    pub comb: Vec3,
    /// A comb direction per UV instead of `comb` (a flow map); `None`: use
    /// `comb`.
    pub comb_map: Option<CombMap>,
    /// Gravity's pull, world −Y, relative to the normal (0: none).
    pub gravity: f32,
    /// Points per guide (at least 2).
    pub points: usize,
    /// Root width of the guides (they taper to a fifth at the tip).
    pub width: f32,
    /// Seed of the roots.
    pub seed: u64,
}

impl Default for GuideGrowth {
    fn default() -> Self {
        Self {
            count: 500,
            density: Map::Constant(1.0),
            length: Map::Constant(0.1),
            comb: Vec3::ZERO,
            comb_map: None,
            gravity: 0.0,
            points: 8,
            width: 0.004,
            seed: 1,
        }
    }
}

/// A comb direction painted over the surface, as flow maps are (Houdini,
/// Unreal, Blender's hair tools): two maps read at the root's UV give the
/// direction in the surface's UV tangent frame, `(2u − 1) T + (2v − 1) B`
/// (mid-grey: no comb; red 1 combs along +U), times `strength`. `T` is the
/// direction of increasing U on the surface, `B = N × T`.
#[derive(Debug, Clone)]
pub struct CombMap {
    /// The component along +U (an image's red channel, say).
    pub u: Map,
    /// The component along `N × T` (an image's green channel).
    pub v: Map,
    /// Multiplies the direction (1: a full-red texel bends like `comb` of
    /// length 1).
    pub strength: f32,
}

impl CombMap {
    /// The comb at `root` (in world space, tangent to the surface).
    pub fn at(&self, mesh: &Mesh, root: SurfacePoint) -> Vec3 {
        let site = crate::map::MapSite::on(mesh, root);
        let frame = root.tangent_frame(mesh);
        let (a, b) = (2.0 * self.u.at(&site) - 1.0, 2.0 * self.v.at(&site) - 1.0);
        self.strength * (a * frame.tangent + b * frame.bitangent)
    }
}

/// Guides could not be grown.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GuideError {
    /// Sampling the roots failed.
    #[error(transparent)]
    Sample(#[from] SampleError),
    /// A map cannot be used on the mesh.
    #[error(transparent)]
    Map(#[from] MapError),
    /// The curves could not be built.
    #[error(transparent)]
    Curves(#[from] CurvesError),
}

impl Guides {
    /// Binds `curves` to `mesh`: each root to its closest point on the
    /// surface, each guide resampled to `points` points by arc length.
    /// Guides whose root is farther than `tolerance` from the surface, or
    /// that have fewer than two points, are left out and listed in the
    /// report — never silently.
    pub fn bind(mesh: &Mesh, curves: &Curves, points: usize, tolerance: f32) -> (Self, BindReport) {
        let points = points.max(2);
        let bvh = TriangleBvh::new(mesh.positions(), mesh.triangles());
        let mut report = BindReport::default();
        let (mut pts, mut widths, mut roots) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..curves.curve_count() {
            let range = curves.range(i);
            if range.len() < 2 {
                report.dropped.push(DroppedGuide {
                    index: i,
                    reason: DropReason::TooFewPoints(range.len()),
                });
                continue;
            }
            let guide = &curves.points()[range.clone()];
            let Some(hit) = bvh.closest(guide[0]) else {
                continue;
            };
            let distance = hit.distance_squared.sqrt();
            if distance > tolerance {
                report.dropped.push(DroppedGuide {
                    index: i,
                    reason: DropReason::FarFromSurface { distance },
                });
                continue;
            }
            report.max_distance = report.max_distance.max(distance);
            let root = SurfacePoint::new(hit.triangle, [hit.weights[1], hit.weights[2]]);
            // The guide starts exactly on the surface.
            let shift = root.position(mesh) - guide[0];
            let moved: Vec<Vec3> = guide.iter().map(|p| *p + shift).collect();
            pts.extend(resample_by_arc_length(&moved, points));
            let w = &curves.widths()[range];
            widths.extend((0..points).map(|k| {
                let t = k as f32 / (points - 1) as f32 * (w.len() - 1) as f32;
                let (j, f) = (t.floor() as usize, t.fract());
                w[j] * (1.0 - f) + w[(j + 1).min(w.len() - 1)] * f
            }));
            roots.push(root);
        }
        report.kept = roots.len();
        let offsets = (0..=roots.len() as u32)
            .map(|i| i * points as u32)
            .collect();
        let curves = Curves::new(pts, widths, offsets).expect("resampled finite guides");
        let curves = curves.with_roots(roots).expect("one root a guide");
        (
            Self {
                curves,
                points_per_guide: points,
            },
            report,
        )
    }

    /// Grows guides on `mesh`: roots from the density sampler; each guide
    /// leaves the surface along the normal and turns, along its length,
    /// toward the comb direction (its part tangent to the surface) and
    /// down by gravity: the direction at arc fraction `s` is
    /// `normalize(n + s · (comb_t + gravity · (−Y)))`.
    pub fn grow(mesh: &Mesh, growth: &GuideGrowth) -> Result<Self, GuideError> {
        let sampler = DensitySampler::new(mesh, &growth.density, DensitySamplerOptions::default())?;
        let roots = sample_range(&sampler, growth.seed, 0..growth.count as u64);
        let length = growth.length.on_mesh(mesh)?;
        // Refuse maps the mesh cannot serve here, and take per-vertex
        // maps' values.
        let comb_map = match &growth.comb_map {
            Some(map) => Some(CombMap {
                u: map.u.bound(mesh)?.into_owned(),
                v: map.v.bound(mesh)?.into_owned(),
                strength: map.strength,
            }),
            None => None,
        };
        let n = growth.points.max(2);
        let (mut points, mut widths) = (Vec::new(), Vec::new());
        for root in &roots {
            let (p0, normal) = (root.position(mesh), root.normal(mesh));
            let comb = match &comb_map {
                Some(map) => map.at(mesh, *root),
                None => growth.comb,
            };
            let comb = comb - normal * normal.dot(comb);
            let pull = comb + Vec3::NEG_Y * growth.gravity;
            let step = length.eval(*root).max(0.0) / (n - 1) as f32;
            let mut p = p0;
            points.push(p);
            for k in 1..n {
                // Direction at the middle of the step.
                let s = (k as f32 - 0.5) / (n - 1) as f32;
                let dir = (normal + s * pull).normalize_or(normal);
                p += dir * step;
                points.push(p);
            }
            widths.extend((0..n).map(|k| growth.width * (1.0 - 0.8 * k as f32 / (n - 1) as f32)));
        }
        let offsets = (0..=roots.len() as u32).map(|i| i * n as u32).collect();
        let curves = Curves::new(points, widths, offsets)?.with_roots(roots)?;
        Ok(Self {
            curves,
            points_per_guide: n,
        })
    }

    /// Guide `i`'s length along its points.
    pub fn length(&self, i: usize) -> f32 {
        self.guide(i)
            .windows(2)
            .map(|w| (w[1] - w[0]).length())
            .sum()
    }

    /// The same guides (roots, widths) in other shapes: `points` holds
    /// every guide's points, `points_per_guide` each, in order.
    pub fn with_points(&self, points: Vec<Vec3>) -> Result<Self, CurvesError> {
        let curves = Curves::new(
            points,
            self.curves.widths().to_vec(),
            self.curves.offsets().to_vec(),
        )?
        .with_roots(self.roots().to_vec())?;
        Ok(Self {
            curves,
            points_per_guide: self.points_per_guide,
        })
    }

    /// Guides from arrays already at one point count (`points_per_guide`
    /// points and widths a root), roots bound.
    pub(crate) fn from_resampled(
        points: Vec<Vec3>,
        widths: Vec<f32>,
        roots: Vec<SurfacePoint>,
        points_per_guide: usize,
    ) -> Result<Self, CurvesError> {
        let offsets = (0..=roots.len() as u32)
            .map(|i| i * points_per_guide as u32)
            .collect();
        let curves = Curves::new(points, widths, offsets)?.with_roots(roots)?;
        Ok(Self {
            curves,
            points_per_guide,
        })
    }

    /// The guides at `indices` (in that order), as guides of their own.
    pub fn subset(&self, indices: &[u32]) -> Self {
        let n = self.points_per_guide;
        let mut points = Vec::with_capacity(indices.len() * n);
        let mut widths = Vec::with_capacity(indices.len() * n);
        let mut roots = Vec::with_capacity(indices.len());
        for &i in indices {
            points.extend_from_slice(self.guide(i as usize));
            widths.extend_from_slice(self.widths(i as usize));
            roots.push(self.roots()[i as usize]);
        }
        let offsets = (0..=indices.len() as u32).map(|i| i * n as u32).collect();
        let curves = Curves::new(points, widths, offsets)
            .and_then(|c| c.with_roots(roots))
            .expect("a subset of valid guides is valid");
        Self {
            curves,
            points_per_guide: n,
        }
    }

    /// The guides as curves (with their roots).
    pub fn curves(&self) -> &Curves {
        &self.curves
    }

    /// Each guide's root on the mesh.
    pub fn roots(&self) -> &[SurfacePoint] {
        self.curves
            .roots()
            .expect("guides always carry their roots")
    }

    /// Number of guides.
    pub fn len(&self) -> usize {
        self.curves.curve_count()
    }

    /// Whether there are no guides.
    pub fn is_empty(&self) -> bool {
        self.curves.curve_count() == 0
    }

    /// Points of every guide.
    pub fn points_per_guide(&self) -> usize {
        self.points_per_guide
    }

    /// The points of guide `i`.
    pub fn guide(&self, i: usize) -> &[Vec3] {
        &self.curves.points()[self.curves.range(i)]
    }

    /// The widths of guide `i`.
    pub fn widths(&self, i: usize) -> &[f32] {
        &self.curves.widths()[self.curves.range(i)]
    }
}

/// `n` points (at least 2) evenly spaced by arc length along the polyline
/// `points`, first and last kept exactly.
pub fn resample_by_arc_length(points: &[Vec3], n: usize) -> Vec<Vec3> {
    let n = n.max(2);
    if points.len() < 2 {
        return vec![points.first().copied().unwrap_or(Vec3::ZERO); n];
    }
    let mut cumulative = Vec::with_capacity(points.len());
    let mut total = 0.0f32;
    cumulative.push(0.0);
    for w in points.windows(2) {
        total += (w[1] - w[0]).length();
        cumulative.push(total);
    }
    if total <= 0.0 {
        return vec![points[0]; n];
    }
    let mut out = Vec::with_capacity(n);
    let mut segment = 0;
    for k in 0..n {
        let target = total * k as f32 / (n - 1) as f32;
        while segment + 2 < points.len() && cumulative[segment + 1] < target {
            segment += 1;
        }
        let (a, b) = (cumulative[segment], cumulative[segment + 1]);
        let t = if b > a {
            ((target - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(points[segment].lerp(points[segment + 1], t));
    }
    out[0] = points[0];
    out[n - 1] = *points.last().unwrap();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comb_map_bends_each_guide_its_own_way() {
        use crate::map::{ImageMap, Wrap};
        // Left half of the square combed toward −U, right half toward +U
        // (red 0 and 1, clamped, nearest); green mid-grey: no V part.
        let square = crate::mesh::tests::unit_square();
        let red = ImageMap::from_texels(2, 1, vec![0.0, 1.0], Wrap::Clamp)
            .unwrap()
            .with_filter(crate::map::Filter::Nearest);
        let growth = GuideGrowth {
            count: 200,
            length: Map::Constant(0.2),
            comb_map: Some(CombMap {
                u: Map::Image(red),
                v: Map::Constant(0.5),
                strength: 2.0,
            }),
            ..GuideGrowth::default()
        };
        let guides = Guides::grow(&square, &growth).unwrap();
        let (mut left, mut right) = (0, 0);
        for i in 0..guides.len() {
            let g = guides.guide(i);
            let lean = g[g.len() - 1] - g[0];
            assert!(lean.y.abs() < 1e-5, "no V component");
            if g[0].x < 0.5 {
                assert!(lean.x < -0.05, "guide {i} at {} leans {lean}", g[0]);
                left += 1;
            } else {
                assert!(lean.x > 0.05, "guide {i} at {} leans {lean}", g[0]);
                right += 1;
            }
        }
        assert!(left > 50 && right > 50);
        // A comb map on a mesh without UVs is refused.
        let growth = GuideGrowth {
            comb_map: Some(CombMap {
                u: Map::Image(ImageMap::from_texels(1, 1, vec![1.0], Wrap::Clamp).unwrap()),
                v: Map::Constant(0.5),
                strength: 1.0,
            }),
            ..GuideGrowth::default()
        };
        assert!(Guides::grow(&crate::mesh::tests::tetrahedron(), &growth).is_err());
    }

    #[test]
    fn resampling_spaces_points_evenly_and_keeps_the_ends() {
        let bent = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 3.0, 0.0)];
        let r = resample_by_arc_length(&bent, 5);
        assert_eq!((r[0], r[4]), (bent[0], bent[2]));
        for w in r.windows(2) {
            assert!(((w[1] - w[0]).length() - 1.0).abs() < 1e-5, "{r:?}");
        }
    }

    #[test]
    fn far_and_short_guides_are_reported_by_index_and_distance() {
        let spot = crate::assets::spot();
        let on = SurfacePoint::new(10, [0.2, 0.3]);
        let (p, n) = (on.position(&spot), on.normal(&spot));
        let points = vec![p, p + 0.1 * n, p + 5.0 * n, p + 6.0 * n, p];
        let curves = Curves::new(points, vec![0.01; 5], vec![0, 2, 4, 5]).unwrap();
        let (guides, report) = Guides::bind(&spot, &curves, 6, 1e-3);
        assert_eq!((guides.len(), report.kept), (1, 1));
        assert_eq!(report.dropped.len(), 2);
        assert_eq!(report.dropped[0].index, 1);
        let DropReason::FarFromSurface { distance } = report.dropped[0].reason else {
            panic!("{:?}", report.dropped[0]);
        };
        assert!(distance > 4.0, "{distance}");
        assert_eq!(report.dropped[1].reason, DropReason::TooFewPoints(1));
        assert!(
            report.dropped[0]
                .to_string()
                .starts_with("guide 1 left out: its root is")
        );
        // The kept guide is bound where it was and resampled to 6 points.
        assert!((guides.roots()[0].position(&spot) - p).length() < 1e-5);
        assert_eq!(guides.guide(0).len(), 6);
    }

    #[test]
    fn grown_guides_start_on_the_surface_and_lean_toward_the_comb() {
        let spot = crate::assets::spot();
        let growth = GuideGrowth {
            count: 50,
            comb: Vec3::new(0.0, 0.0, 2.0),
            ..GuideGrowth::default()
        };
        let guides = Guides::grow(&spot, &growth).unwrap();
        assert_eq!(guides.len(), 50);
        for (i, root) in guides.roots().iter().enumerate() {
            let g = guides.guide(i);
            assert_eq!(g[0], root.position(&spot));
            let length: f32 = g.windows(2).map(|w| (w[1] - w[0]).length()).sum();
            assert!((length - 0.1).abs() < 1e-4, "{length}");
            let n = root.normal(&spot);
            let comb_t = growth.comb - n * n.dot(growth.comb);
            if comb_t.length() > 0.5 {
                assert!(
                    (g[7] - g[0]).dot(comb_t) > 0.0,
                    "guide {i} does not lean toward the comb"
                );
            }
        }
    }
}
