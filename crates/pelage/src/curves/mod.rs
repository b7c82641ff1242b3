//! Hair curves as structure of arrays with one offsets array, like
//! Blender's `CurvesGeometry` and USD's `BasisCurves`: curve `i` is
//! `points[offsets[i]..offsets[i + 1]]`, and every per-point attribute is
//! sliced the same way.
//!
//! Besides positions and widths, curves carry the optional attributes
//! renderers read (docs/design.md, "Data model"): per point a normal (ribbon
//! orientation), a colour and an opacity; per curve its root on the mesh
//! ([`SurfacePoint`]), the root's UV, a stable id, and what a hair shader
//! reads ([`HairShading`]).
//!
//! [`frames`] holds Catmull-Rom tangents and rotation-minimizing frames
//! (Wang et al. 2008) for the per-point normals.
//!
//! One file, past 600 lines: `Curves` and its validating builders (about 200
//! of its lines are tests).

pub mod frames;
mod shading;

pub use shading::HairShading;

/// Width given to curves read from a file that has no widths.
pub const DEFAULT_WIDTH: f32 = 0.01;

use crate::SurfacePoint;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Curves: points, per-point widths, and an offsets array one longer than
/// the number of curves, plus optional per-point and per-curve attributes.
///
/// ```
/// use glam::Vec3;
/// use pelage::Curves;
///
/// // Two hairs: 3 points and 2 points; curve i is points[offsets[i]..offsets[i + 1]].
/// let points = vec![Vec3::ZERO, Vec3::Y * 0.5, Vec3::Y, Vec3::X, Vec3::X + Vec3::Y];
/// let widths = vec![0.01, 0.005, 0.001, 0.01, 0.001];
/// let curves = Curves::new(points, widths, vec![0, 3, 5])?
///     .with_ids(vec![7, 8])?;
/// assert_eq!(curves.curve_count(), 2);
/// assert_eq!(curves.offsets(), &[0, 3, 5]);
/// // Offsets that do not match the points are refused.
/// assert!(Curves::new(vec![Vec3::ZERO], vec![0.01], vec![0, 2]).is_err());
/// # Ok::<(), pelage::curves::CurvesError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Curves {
    points: Vec<Vec3>,
    widths: Vec<f32>,
    offsets: Vec<u32>,
    normals: Option<Vec<Vec3>>,
    colors: Option<Vec<Vec3>>,
    opacities: Option<Vec<f32>>,
    roots: Option<Vec<SurfacePoint>>,
    root_uvs: Option<Vec<Vec2>>,
    ids: Option<Vec<u64>>,
    /// Per-point velocities (units a second) of an animated frame.
    velocities: Option<Vec<Vec3>>,
    /// Per-curve values for a hair shader.
    shading: Option<HairShading>,
    /// The skin region each curve grew in (a groom with `[regions]`).
    regions: Option<Vec<u32>>,
}

/// What the skin binding moves (points, normals) beside what it reads
/// (offsets, roots), borrowed together.
pub(crate) type CarryView<'a> = (
    &'a mut [Vec3],
    Option<&'a mut [Vec3]>,
    &'a [u32],
    Option<&'a [SurfacePoint]>,
);

/// Every array of a [`Curves`], taken back by [`Curves::into_arrays`] to
/// reuse their memory (an attribute the curves lacked is empty).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CurveArrays {
    /// Positions.
    pub points: Vec<Vec3>,
    /// Per-point widths.
    pub widths: Vec<f32>,
    /// Curve offsets.
    pub offsets: Vec<u32>,
    /// Per-point normals.
    pub normals: Vec<Vec3>,
    /// Per-point colours.
    pub colors: Vec<Vec3>,
    /// Per-point opacities.
    pub opacities: Vec<f32>,
    /// Per-curve roots.
    pub roots: Vec<SurfacePoint>,
    /// Per-curve root UVs.
    pub root_uvs: Vec<Vec2>,
    /// Per-curve ids.
    pub ids: Vec<u64>,
}

/// Curves could not be built from their arrays.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum CurvesError {
    /// The offsets do not start at 0, decrease, or do not end at the point count.
    #[error(
        "curve offsets must start at 0, never decrease and end at the point count ({points}); offset {index} is {value}"
    )]
    BadOffsets {
        /// The offending offset's index.
        index: usize,
        /// Its value.
        value: u32,
        /// The number of points.
        points: usize,
    },
    /// Per-point attributes of the wrong length.
    #[error("{what}: {got} values for {points} points")]
    Length {
        /// The attribute.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The number of points.
        points: usize,
    },
    /// Per-curve attributes of the wrong length.
    #[error("{what}: {got} values for {curves} curves")]
    CurveLength {
        /// The attribute.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The number of curves.
        curves: usize,
    },
    /// A NaN or infinite value.
    #[error("{what} of point {index} is not finite")]
    NonFinite {
        /// The attribute.
        what: &'static str,
        /// The point.
        index: usize,
    },
}

/// Whether every value is finite: a bit test rather than
/// [`f32::is_finite`] and a branch a value, so that a hair's worth compiles
/// to SIMD (the groom generator checks every hair it grows).
pub(crate) fn floats_finite(values: &[f32]) -> bool {
    values.iter().fold(0, |bad, &v| bad | not_finite_bit(v)) == 0
}

/// [`floats_finite`] for vectors.
pub(crate) fn vectors_finite(values: &[Vec3]) -> bool {
    values.iter().fold(0, |bad, v| {
        bad | not_finite_bit(v.x) | not_finite_bit(v.y) | not_finite_bit(v.z)
    }) == 0
}

/// The sign bit set for infinities and NaNs, zero for finite values: an
/// exponent of all ones is the only one that carries into bit 31 when
/// one is added to it.
#[inline(always)]
fn not_finite_bit(v: f32) -> u32 {
    ((v.to_bits() & 0x7f80_0000) + 0x0080_0000) & 0x8000_0000
}

/// The first index whose value is not finite: the same answer as a serial
/// scan, but a groom part's millions of points are scanned in blocks on
/// all threads — the check runs once a part on the thread assembling it,
/// and serial it is time every other core waits for.
fn first_non_finite<T: Sync>(values: &[T], finite: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    const BLOCK: usize = 1 << 16;
    if values.len() <= BLOCK {
        return values.iter().position(|v| !finite(v));
    }
    values
        .par_chunks(BLOCK)
        .enumerate()
        .filter_map(|(b, block)| block.iter().position(|v| !finite(v)).map(|i| b * BLOCK + i))
        .min()
}

/// Whether a builder of [`Curves`] scans the values for NaNs and
/// infinities: always for curves from outside; not for the groom
/// generator's, which checks each chunk of hairs while it is still in
/// cache (and names the operator at fault). A second pass over a part's
/// arrays cost about 4 % of a groom's time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Values {
    /// Scan them.
    Scan,
    /// The caller found them finite (checked again in debug builds).
    Checked,
}

impl Values {
    /// `first_non_finite()`, unless the values are known to be finite.
    fn first_non_finite(self, first_non_finite: impl FnOnce() -> Option<usize>) -> Option<usize> {
        match self {
            Values::Scan => first_non_finite(),
            Values::Checked => {
                debug_assert_eq!(first_non_finite(), None, "values checked finite are");
                None
            }
        }
    }
}

impl Curves {
    /// Builds curves, checking offsets, lengths and finiteness.
    pub fn new(
        points: Vec<Vec3>,
        widths: Vec<f32>,
        offsets: Vec<u32>,
    ) -> Result<Self, CurvesError> {
        Self::build(points, widths, offsets, Values::Scan)
    }

    /// [`Self::new`], scanning the values only when asked.
    pub(crate) fn build(
        points: Vec<Vec3>,
        widths: Vec<f32>,
        offsets: Vec<u32>,
        values: Values,
    ) -> Result<Self, CurvesError> {
        let n = points.len();
        if widths.len() != n {
            return Err(CurvesError::Length {
                what: "widths",
                got: widths.len(),
                points: n,
            });
        }
        let bad = |index: usize| CurvesError::BadOffsets {
            index,
            value: offsets.get(index).copied().unwrap_or(0),
            points: n,
        };
        if offsets.first() != Some(&0) {
            return Err(bad(0));
        }
        if let Some(i) = offsets.windows(2).position(|w| w[1] < w[0]) {
            return Err(bad(i + 1));
        }
        if *offsets.last().expect("checked non-empty") as usize != n {
            return Err(bad(offsets.len() - 1));
        }
        if let Some(index) =
            values.first_non_finite(|| first_non_finite(&points, |p| p.is_finite()))
        {
            return Err(CurvesError::NonFinite {
                what: "position",
                index,
            });
        }
        if let Some(index) =
            values.first_non_finite(|| first_non_finite(&widths, |w| w.is_finite()))
        {
            return Err(CurvesError::NonFinite {
                what: "width",
                index,
            });
        }
        Ok(Self {
            points,
            widths,
            offsets,
            ..Self::default()
        })
    }

    /// The arrays, to reuse their memory for the next curves (the groom
    /// generator recycles a written part's arrays into the next part: fresh
    /// memory costs a page fault every 4 KB).
    pub fn into_arrays(self) -> CurveArrays {
        CurveArrays {
            points: self.points,
            widths: self.widths,
            offsets: self.offsets,
            normals: self.normals.unwrap_or_default(),
            colors: self.colors.unwrap_or_default(),
            opacities: self.opacities.unwrap_or_default(),
            roots: self.roots.unwrap_or_default(),
            root_uvs: self.root_uvs.unwrap_or_default(),
            ids: self.ids.unwrap_or_default(),
        }
    }

    /// Every `step`-th curve (0, step, 2·step, …) with its points, widths,
    /// colours, shading values and regions: a lighter set for previews.
    pub fn every_nth(&self, step: usize) -> Curves {
        let step = step.max(1);
        let (mut points, mut widths, mut colors) = (Vec::new(), Vec::new(), Vec::new());
        let mut shading = HairShading::default();
        let mut regions = Vec::new();
        let mut offsets = vec![0u32];
        for i in (0..self.curve_count()).step_by(step) {
            let range = self.range(i);
            points.extend_from_slice(&self.points[range.clone()]);
            widths.extend_from_slice(&self.widths[range.clone()]);
            if let Some(c) = &self.colors {
                colors.extend_from_slice(&c[range]);
            }
            if let Some(s) = &self.shading {
                shading.push_from(s, i);
            }
            if let Some(r) = &self.regions {
                regions.push(r[i]);
            }
            offsets.push(points.len() as u32);
        }
        Curves {
            points,
            widths,
            offsets,
            colors: self.colors.is_some().then_some(colors),
            shading: self.shading.is_some().then_some(shading),
            regions: self.regions.is_some().then_some(regions),
            ..Curves::default()
        }
    }

    /// Curves from arrays a grower filled and checked as it went (every
    /// value finite): the per-point attributes asked for, ids and roots,
    /// and root UVs when there are any. A failure here is a bug.
    pub(crate) fn assembled(a: CurveArrays, normals: bool, colors: bool, opacities: bool) -> Self {
        let checked = Values::Checked;
        let mut curves =
            Curves::build(a.points, a.widths, a.offsets, checked).expect("consistent arrays");
        if normals {
            curves = curves
                .with_normals_as(a.normals, checked)
                .expect("one normal a point");
        }
        if colors {
            curves = curves
                .with_colors_as(a.colors, checked)
                .expect("one colour a point");
        }
        if opacities {
            curves = curves
                .with_opacities_as(a.opacities, checked)
                .expect("one opacity a point");
        }
        let mut curves = curves
            .with_ids(a.ids)
            .and_then(|c| c.with_roots(a.roots))
            .expect("one id and root a curve");
        if !a.root_uvs.is_empty() {
            curves = curves.with_root_uvs(a.root_uvs).expect("one UV a curve");
        }
        curves
    }

    /// Makes these curves `other`'s in everything but the values of
    /// points and normals, which are sized to match but left to the caller
    /// to write (the skin binding's carry: copying them only to overwrite
    /// them cost a quarter of a frame).
    pub(crate) fn copy_unmoved_from(&mut self, other: &Curves) {
        fn copy<T: Copy>(to: &mut Vec<T>, from: &[T]) {
            to.clear();
            to.extend_from_slice(from);
        }
        fn copy_opt<T: Copy>(to: &mut Option<Vec<T>>, from: Option<&Vec<T>>) {
            match from {
                Some(f) => copy(to.get_or_insert_with(Vec::new), f),
                None => *to = None,
            }
        }
        fn sized<T: Copy + Default>(to: &mut Vec<T>, len: usize) {
            to.truncate(len);
            to.resize(len, T::default());
        }
        copy(&mut self.widths, &other.widths);
        copy(&mut self.offsets, &other.offsets);
        copy_opt(&mut self.colors, other.colors.as_ref());
        copy_opt(&mut self.opacities, other.opacities.as_ref());
        copy_opt(&mut self.roots, other.roots.as_ref());
        copy_opt(&mut self.root_uvs, other.root_uvs.as_ref());
        copy_opt(&mut self.ids, other.ids.as_ref());
        self.shading.clone_from(&other.shading);
        copy_opt(&mut self.regions, other.regions.as_ref());
        self.velocities = None;
        sized(&mut self.points, other.points.len());
        match &other.normals {
            Some(n) => sized(self.normals.get_or_insert_with(Vec::new), n.len()),
            None => self.normals = None,
        }
    }

    /// The points and (if present) normals, to move in place: counts and
    /// every other attribute stay as they are (the skin binding carries a
    /// part from pose to pose this way). The caller keeps them finite.
    pub(crate) fn carry_view(&mut self) -> CarryView<'_> {
        (
            &mut self.points,
            self.normals.as_deref_mut(),
            &self.offsets,
            self.roots.as_deref(),
        )
    }

    /// Adds per-point normals (the orientation of flat ribbons; USD
    /// `normals`).
    pub fn with_normals(self, normals: Vec<Vec3>) -> Result<Self, CurvesError> {
        self.with_normals_as(normals, Values::Scan)
    }

    /// [`Self::with_normals`], scanning the values only when asked.
    pub(crate) fn with_normals_as(
        mut self,
        normals: Vec<Vec3>,
        values: Values,
    ) -> Result<Self, CurvesError> {
        self.check_per_point(
            "normals",
            normals.len(),
            values.first_non_finite(|| first_non_finite(&normals, |n| n.is_finite())),
        )?;
        self.normals = Some(normals);
        Ok(self)
    }

    /// Adds per-point linear RGB colours.
    pub fn with_colors(self, colors: Vec<Vec3>) -> Result<Self, CurvesError> {
        self.with_colors_as(colors, Values::Scan)
    }

    /// [`Self::with_colors`], scanning the values only when asked.
    pub(crate) fn with_colors_as(
        mut self,
        colors: Vec<Vec3>,
        values: Values,
    ) -> Result<Self, CurvesError> {
        self.check_per_point(
            "colors",
            colors.len(),
            values.first_non_finite(|| first_non_finite(&colors, |c| c.is_finite())),
        )?;
        self.colors = Some(colors);
        Ok(self)
    }

    /// Adds per-point opacities (1 = opaque).
    pub fn with_opacities(self, opacities: Vec<f32>) -> Result<Self, CurvesError> {
        self.with_opacities_as(opacities, Values::Scan)
    }

    /// [`Self::with_opacities`], scanning the values only when asked.
    pub(crate) fn with_opacities_as(
        mut self,
        opacities: Vec<f32>,
        values: Values,
    ) -> Result<Self, CurvesError> {
        let bad = values.first_non_finite(|| first_non_finite(&opacities, |o| o.is_finite()));
        self.check_per_point("opacities", opacities.len(), bad)?;
        self.opacities = Some(opacities);
        Ok(self)
    }

    /// Adds each curve's root on the mesh it grows from.
    pub fn with_roots(mut self, roots: Vec<SurfacePoint>) -> Result<Self, CurvesError> {
        self.check_per_curve("roots", roots.len())?;
        self.roots = Some(roots);
        Ok(self)
    }

    /// Adds each curve's root UV (USD writes it as the uniform `st`).
    pub fn with_root_uvs(mut self, uvs: Vec<Vec2>) -> Result<Self, CurvesError> {
        self.check_per_curve("root UVs", uvs.len())?;
        if let Some(index) = uvs.iter().position(|uv| !uv.is_finite()) {
            return Err(CurvesError::NonFinite {
                what: "root UV",
                index,
            });
        }
        self.root_uvs = Some(uvs);
        Ok(self)
    }

    /// Adds each curve's stable id (the same hair keeps its id across
    /// parts, threads and re-runs with the same seed).
    pub fn with_ids(mut self, ids: Vec<u64>) -> Result<Self, CurvesError> {
        self.check_per_curve("ids", ids.len())?;
        self.ids = Some(ids);
        Ok(self)
    }

    /// Adds each curve's values for a hair shader. Fails unless every
    /// array holds one finite value a curve.
    pub fn with_shading(mut self, shading: HairShading) -> Result<Self, CurvesError> {
        if let Some((what, got)) = shading.mismatch(self.curve_count()) {
            return Err(CurvesError::CurveLength {
                what,
                got,
                curves: self.curve_count(),
            });
        }
        if let Some((what, index)) = shading.first_non_finite() {
            return Err(CurvesError::NonFinite { what, index });
        }
        self.shading = Some(shading);
        Ok(self)
    }

    /// Adds the skin region each curve grew in (written as USD's
    /// `hair_region` and Alembic's `groom_group_id`).
    pub fn with_regions(mut self, regions: Vec<u32>) -> Result<Self, CurvesError> {
        self.check_per_curve("regions", regions.len())?;
        self.regions = Some(regions);
        Ok(self)
    }

    /// Checks a per-point attribute's length; `first_non_finite` is the
    /// index of its first NaN or infinite value, if any.
    fn check_per_point(
        &self,
        what: &'static str,
        got: usize,
        first_non_finite: Option<usize>,
    ) -> Result<(), CurvesError> {
        if got != self.points.len() {
            return Err(CurvesError::Length {
                what,
                got,
                points: self.points.len(),
            });
        }
        if let Some(index) = first_non_finite {
            return Err(CurvesError::NonFinite { what, index });
        }
        Ok(())
    }

    fn check_per_curve(&self, what: &'static str, got: usize) -> Result<(), CurvesError> {
        if got != self.curve_count() {
            return Err(CurvesError::CurveLength {
                what,
                got,
                curves: self.curve_count(),
            });
        }
        Ok(())
    }

    /// Per-point normals, if any.
    pub fn normals(&self) -> Option<&[Vec3]> {
        self.normals.as_deref()
    }

    /// Per-point velocities in units a second (an animated frame's, for
    /// motion blur: USD `velocities`, Alembic `.velocities`), if any.
    pub fn velocities(&self) -> Option<&[Vec3]> {
        self.velocities.as_deref()
    }

    /// The velocities, taken out (a buffer to fill for the next frame).
    pub(crate) fn take_velocities(&mut self) -> Option<Vec<Vec3>> {
        self.velocities.take()
    }

    /// Sets velocities its caller found finite, one a point, without
    /// reading them again.
    pub(crate) fn set_finite_velocities(&mut self, velocities: Vec<Vec3>) {
        debug_assert_eq!(velocities.len(), self.points.len());
        debug_assert!(velocities.iter().all(|v| v.is_finite()));
        self.velocities = Some(velocities);
    }

    /// Sets (or, with `None`, removes) the per-point velocities. Fails
    /// unless there is one finite velocity a point.
    pub fn set_velocities(&mut self, velocities: Option<Vec<Vec3>>) -> Result<(), CurvesError> {
        if let Some(v) = &velocities {
            self.check_per_point(
                "velocities",
                v.len(),
                first_non_finite(v, |x| x.is_finite()),
            )?;
        }
        self.velocities = velocities;
        Ok(())
    }

    /// Per-point colours, if any.
    pub fn colors(&self) -> Option<&[Vec3]> {
        self.colors.as_deref()
    }

    /// Per-point opacities, if any.
    pub fn opacities(&self) -> Option<&[f32]> {
        self.opacities.as_deref()
    }

    /// Per-curve roots on the mesh, if any.
    pub fn roots(&self) -> Option<&[SurfacePoint]> {
        self.roots.as_deref()
    }

    /// Per-curve root UVs, if any.
    pub fn root_uvs(&self) -> Option<&[Vec2]> {
        self.root_uvs.as_deref()
    }

    /// Per-curve ids, if any.
    pub fn ids(&self) -> Option<&[u64]> {
        self.ids.as_deref()
    }

    /// Per-curve values for a hair shader, if any.
    pub fn shading(&self) -> Option<&HairShading> {
        self.shading.as_ref()
    }

    /// The skin region each curve grew in, if known.
    pub fn regions(&self) -> Option<&[u32]> {
        self.regions.as_deref()
    }

    /// The number of points of the shortest and the longest curve
    /// (`(0, 0)` without curves).
    pub fn point_count_range(&self) -> (usize, usize) {
        (0..self.curve_count())
            .map(|i| self.range(i).len())
            .fold(None, |acc: Option<(usize, usize)>, n| {
                Some(acc.map_or((n, n), |(lo, hi)| (lo.min(n), hi.max(n))))
            })
            .unwrap_or((0, 0))
    }

    /// Number of curves.
    pub fn curve_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// All points.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// All widths (one per point).
    pub fn widths(&self) -> &[f32] {
        &self.widths
    }

    /// The offsets array (`curve_count() + 1` entries).
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// The point range of curve `i`.
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// Number of segments (consecutive point pairs within curves).
    pub fn segment_count(&self) -> usize {
        (0..self.curve_count())
            .map(|i| self.range(i).len().saturating_sub(1))
            .sum()
    }

    /// Straight strands grown from `roots` along the surface normal:
    /// `points_per_curve` points (at least 2) over `length`, widths tapering
    /// linearly from `root_width` to `tip_width`. The simplest groom — what
    /// benchmarks and previews use before guides exist.
    pub fn along_normals(
        mesh: &crate::Mesh,
        roots: &[crate::SurfacePoint],
        length: f32,
        points_per_curve: usize,
        root_width: f32,
        tip_width: f32,
    ) -> Self {
        let n = points_per_curve.max(2);
        let mut points = Vec::with_capacity(roots.len() * n);
        let mut widths = Vec::with_capacity(roots.len() * n);
        for root in roots {
            let (p, normal) = (root.position(mesh), root.normal(mesh));
            for k in 0..n {
                let t = k as f32 / (n - 1) as f32;
                points.push(p + normal * (t * length));
                // Weighted form: exactly the root and tip widths at the ends.
                widths.push((1.0 - t) * root_width + t * tip_width);
            }
        }
        let offsets = (0..=roots.len() as u32).map(|i| i * n as u32).collect();
        Self::new(points, widths, offsets).expect("finite roots give valid curves")
    }

    /// Axis-aligned bounds of the points, or `None` without points.
    /// Blocks are bounded in parallel; min and max are exact, so the
    /// result does not depend on the threads.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.points.first()?;
        let bound = |(lo, hi): (Vec3, Vec3), p: &Vec3| (lo.min(*p), hi.max(*p));
        Some(
            self.points
                .par_chunks(1 << 16)
                .map(|block| block.iter().fold((first, first), bound))
                .reduce(|| (first, first), |(a, b), (c, d)| (a.min(c), b.max(d))),
        )
    }
}

/// Concatenates curves, keeping only the attributes every part has.
pub fn join<'c>(parts: impl IntoIterator<Item = &'c Curves>) -> Result<Curves, CurvesError> {
    let parts: Vec<&Curves> = parts.into_iter().collect();
    let mut points = Vec::new();
    let mut widths = Vec::new();
    let mut offsets = vec![0u32];
    for c in &parts {
        let base = points.len() as u32;
        points.extend_from_slice(c.points());
        widths.extend_from_slice(c.widths());
        offsets.extend(c.offsets()[1..].iter().map(|o| o + base));
    }
    let mut joined = Curves::new(points, widths, offsets)?;
    if let Some(colors) = concat_all(&parts, Curves::colors) {
        joined = joined.with_colors(colors)?;
    }
    if let Some(opacities) = concat_all(&parts, Curves::opacities) {
        joined = joined.with_opacities(opacities)?;
    }
    if let Some(normals) = concat_all(&parts, Curves::normals) {
        joined = joined.with_normals(normals)?;
    }
    if let Some(uvs) = concat_all(&parts, Curves::root_uvs) {
        joined = joined.with_root_uvs(uvs)?;
    }
    if let Some(ids) = concat_all(&parts, Curves::ids) {
        joined = joined.with_ids(ids)?;
    }
    if let Some(roots) = concat_all(&parts, Curves::roots) {
        joined = joined.with_roots(roots)?;
    }
    if let Some(regions) = concat_all(&parts, Curves::regions) {
        joined = joined.with_regions(regions)?;
    }
    let shading: Option<Vec<_>> = parts.iter().map(|c| c.shading()).collect();
    if let Some(shading) = shading.filter(|s| !s.is_empty()) {
        let mut all = HairShading::with_capacity(joined.curve_count());
        for part in shading {
            all.extend_from(part);
        }
        joined = joined.with_shading(all)?;
    }
    Ok(joined)
}

/// One attribute of every part, concatenated; `None` unless every part
/// (and at least one) has it.
fn concat_all<T: Copy>(
    parts: &[&Curves],
    attribute: impl Fn(&Curves) -> Option<&[T]>,
) -> Option<Vec<T>> {
    let slices: Option<Vec<&[T]>> = parts.iter().map(|c| attribute(c)).collect();
    slices.filter(|s| !s.is_empty()).map(|s| s.concat())
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_bit_test_for_finite_values_agrees_with_is_finite() {
        use super::{floats_finite, vectors_finite};
        let specials = [
            0.0f32,
            -0.0,
            1.0,
            -1.5,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            f32::from_bits(1), // the least subnormal
            -f32::from_bits(0x007f_ffff),
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            f32::from_bits(0x7f80_0001), // a signalling NaN
        ];
        for v in specials {
            assert_eq!(floats_finite(&[1.0, v, 2.0]), v.is_finite(), "{v:e}");
            for axis in 0..3 {
                let mut p = Vec3::ONE;
                p[axis] = v;
                assert_eq!(vectors_finite(&[Vec3::ZERO, p]), v.is_finite(), "{p}");
            }
        }
        assert!(floats_finite(&[]) && vectors_finite(&[]));
    }

    #[test]
    fn every_nth_keeps_whole_curves_with_their_colours() {
        let points: Vec<Vec3> = (0..10).map(|i| Vec3::splat(i as f32)).collect();
        let curves = Curves::new(points, vec![1.0; 10], vec![0, 2, 5, 7, 10])
            .unwrap()
            .with_colors((0..10).map(|i| Vec3::X * i as f32).collect())
            .unwrap();
        let every_other = curves.every_nth(2);
        assert_eq!(every_other.offsets(), &[0, 2, 4]);
        assert_eq!(every_other.points()[2], Vec3::splat(5.0));
        assert_eq!(every_other.colors().unwrap()[3], Vec3::X * 6.0);
    }

    use super::*;

    #[test]
    fn literal_offsets_slice_points_like_blender_tests_do() {
        // Curves of 1, 2, 10, 1, 2 and 10 points (Blender's test layout).
        let offsets = vec![0, 1, 3, 13, 14, 16, 26];
        let points: Vec<Vec3> = (0..26).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let curves = Curves::new(points, vec![0.1; 26], offsets).unwrap();
        assert_eq!(curves.curve_count(), 6);
        assert_eq!(curves.range(2), 3..13);
        // Single-point curves have no segment.
        let sizes = [1, 2, 10, 1, 2, 10];
        assert_eq!(
            curves.segment_count(),
            sizes.iter().map(|n| n - 1).sum::<usize>()
        );
        assert_eq!(
            curves.bounds(),
            Some((Vec3::ZERO, Vec3::new(25.0, 0.0, 0.0)))
        );
    }

    #[test]
    fn strands_along_normals_start_at_their_roots_and_taper() {
        let spot = crate::assets::spot();
        let roots = [
            crate::SurfacePoint::new(10, [0.2, 0.3]),
            crate::SurfacePoint::new(99, [0.5, 0.1]),
        ];
        let curves = Curves::along_normals(&spot, &roots, 0.1, 5, 0.01, 0.002);
        assert_eq!((curves.curve_count(), curves.points().len()), (2, 10));
        for (i, root) in roots.iter().enumerate() {
            let r = curves.range(i);
            assert_eq!(curves.points()[r.start], root.position(&spot));
            let tip = curves.points()[r.end - 1] - root.position(&spot);
            assert!((tip.length() - 0.1).abs() < 1e-6);
            assert!(tip.normalize().dot(root.normal(&spot)) > 0.9999);
            assert_eq!(
                (curves.widths()[r.start], curves.widths()[r.end - 1]),
                (0.01, 0.002)
            );
        }
    }

    #[test]
    fn bad_arrays_are_errors() {
        let p = || vec![Vec3::ZERO; 3];
        assert!(matches!(
            Curves::new(p(), vec![0.1; 2], vec![0, 3]),
            Err(CurvesError::Length { .. })
        ));
        assert!(matches!(
            Curves::new(p(), vec![0.1; 3], vec![0, 2]),
            Err(CurvesError::BadOffsets { .. })
        ));
        assert!(matches!(
            Curves::new(p(), vec![0.1; 3], vec![0, 2, 1, 3]),
            Err(CurvesError::BadOffsets { index: 2, .. })
        ));
        assert!(matches!(
            Curves::new(p(), vec![0.1; 3], vec![1, 3]),
            Err(CurvesError::BadOffsets { index: 0, .. })
        ));
        let mut nan = p();
        nan[1].y = f32::NAN;
        assert_eq!(
            Curves::new(nan, vec![0.1; 3], vec![0, 3]),
            Err(CurvesError::NonFinite {
                what: "position",
                index: 1
            })
        );
        assert!(
            Curves::new(Vec::new(), Vec::new(), vec![0])
                .unwrap()
                .bounds()
                .is_none()
        );
    }

    /// Large arrays are checked block by block on all threads; the error
    /// must still name the first bad point, not the first one a thread
    /// happened to find.
    #[test]
    fn the_first_non_finite_point_of_a_large_groom_part_is_reported() {
        let n = 5 * (1 << 16) + 17;
        let mut points = vec![Vec3::ONE; n];
        for &i in &[4 * (1 << 16) + 3, 2 * (1 << 16) + 9, n - 1] {
            points[i].x = f32::INFINITY;
        }
        points[(1 << 16) + 5].z = f32::NAN;
        assert_eq!(
            Curves::new(points, vec![0.1; n], vec![0, n as u32]),
            Err(CurvesError::NonFinite {
                what: "position",
                index: (1 << 16) + 5
            })
        );
        let mut normals = vec![Vec3::Z; n];
        normals[n - 1] = Vec3::NAN;
        normals[3 * (1 << 16)] = Vec3::NAN;
        let curves = Curves::new(vec![Vec3::ONE; n], vec![0.1; n], vec![0, n as u32]).unwrap();
        assert_eq!(
            curves.with_normals(normals),
            Err(CurvesError::NonFinite {
                what: "normals",
                index: 3 * (1 << 16)
            })
        );
    }

    #[test]
    fn optional_attributes_are_checked_against_points_and_curves() {
        let c = || {
            Curves::new(
                vec![Vec3::ZERO, Vec3::Y, Vec3::X],
                vec![0.1; 3],
                vec![0, 2, 3],
            )
            .unwrap()
        };
        assert_eq!(c().point_count_range(), (1, 2));
        assert_eq!(
            c().with_colors(vec![Vec3::ONE; 2]),
            Err(CurvesError::Length {
                what: "colors",
                got: 2,
                points: 3
            })
        );
        assert_eq!(
            c().with_ids(vec![1, 2, 3]),
            Err(CurvesError::CurveLength {
                what: "ids",
                got: 3,
                curves: 2
            })
        );
        assert_eq!(
            c().with_opacities(vec![1.0, f32::NAN, 1.0]),
            Err(CurvesError::NonFinite {
                what: "opacities",
                index: 1
            })
        );
        let full = c()
            .with_normals(vec![Vec3::Z; 3])
            .and_then(|c| c.with_root_uvs(vec![Vec2::ZERO, Vec2::ONE]))
            .and_then(|c| c.with_ids(vec![7, 9]))
            .unwrap();
        assert_eq!(
            (full.normals().unwrap().len(), full.ids(), full.colors()),
            (3, Some(&[7u64, 9][..]), None)
        );
    }
}
