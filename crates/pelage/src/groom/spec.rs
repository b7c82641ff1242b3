//! The groom as plain Rust values: a mesh, guides, where roots grow, how
//! hairs take the guides' shape, the operator chain and the finish
//! (Sik §4's generator inputs). [`GroomSpec::generator`] prepares a
//! [`Generator`] from them; a groom file ([`super::Groom`]) is one front end
//! that produces a `GroomSpec`, a program (or a binding) is another.
//!
//! Everything here is owned or shared (`Arc`), so a spec and the generator
//! built from it borrow nothing and can be held for as long as a caller
//! likes.
//!
//! ```
//! use pelage::groom::{GroomOp, GroomSpec, NoiseParams, RootsSpec};
//! use pelage::guides::{GuideGrowth, Guides};
//! use pelage::map::Map;
//! use std::sync::Arc;
//!
//! let mesh = Arc::new(pelage::assets::spot());
//! let growth = GuideGrowth { count: 50, length: Map::Constant(0.05), ..Default::default() };
//! let guides = Guides::grow(&mesh, &growth).unwrap();
//! let spec = GroomSpec::new(mesh, guides, RootsSpec::new(2_000))
//!     .with_op(GroomOp::Noise(NoiseParams::new(Map::Constant(0.002))));
//! let generator = spec.generator().unwrap();
//! let curves = generator.part(0).unwrap();
//! assert_eq!(curves.curve_count(), 2_000);
//! ```

use super::error::{GroomError, GroomErrorKind};
use super::generator::Generator;
use super::ops::{Color, Cut, RootToTip};
use crate::guides::Guides;
use crate::interp::InterpolationMethod;
use crate::map::Map;
use crate::mesh::Mesh;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use super::ramp::Ramp;
pub use super::regions::{RegionSource, RegionsSpec};

/// A whole groom, as values. Build one with [`GroomSpec::new`] and the
/// `with_*` methods (or set the public fields), then call
/// [`GroomSpec::generator`].
#[derive(Debug, Clone)]
pub struct GroomSpec {
    /// The name errors start with: a groom file's path, or `<groom>`.
    pub name: PathBuf,
    /// The surface hairs grow on.
    pub mesh: Arc<Mesh>,
    /// The guides, bound to `mesh`.
    pub guides: Arc<Guides>,
    /// How many hairs, where, and their seed.
    pub roots: RootsSpec,
    /// How hairs take their shape from the guides.
    pub interpolation: InterpolationMethod,
    /// The operators, applied in order to every hair.
    pub ops: Vec<GroomOp>,
    /// Points, widths, colours, opacities and normals.
    pub finish: FinishSpec,
    /// Regions that share no guides and no clumps (`None`: one region).
    pub regions: Option<RegionsSpec>,
    /// Where the settings were written, for a groom read from a file.
    pub(crate) origin: Option<Arc<SpecOrigin>>,
}

impl GroomSpec {
    /// A groom of `roots` on `mesh` shaped by `guides`, with Shepard
    /// interpolation (k = 4, power 2), no operators and the default finish
    /// (16 points, widths 0.002 to 0.0002, normals): the defaults of a
    /// groom file.
    pub fn new(
        mesh: impl Into<Arc<Mesh>>,
        guides: impl Into<Arc<Guides>>,
        roots: RootsSpec,
    ) -> Self {
        Self {
            name: PathBuf::from("<groom>"),
            mesh: mesh.into(),
            guides: guides.into(),
            roots,
            interpolation: InterpolationMethod::Shepard {
                k: 4,
                power: 2.0,
                radius: None,
            },
            ops: Vec::new(),
            finish: FinishSpec::default(),
            regions: None,
            origin: None,
        }
    }

    /// Splits the skin into regions.
    pub fn with_regions(mut self, regions: RegionsSpec) -> Self {
        self.regions = Some(regions);
        self
    }

    /// Sets the interpolation method.
    pub fn with_interpolation(mut self, method: InterpolationMethod) -> Self {
        self.interpolation = method;
        self
    }

    /// Appends an operator to the chain.
    pub fn with_op(mut self, op: GroomOp) -> Self {
        self.ops.push(op);
        self
    }

    /// Sets the finish.
    pub fn with_finish(mut self, finish: FinishSpec) -> Self {
        self.finish = finish;
        self
    }

    /// Sets the name errors start with.
    pub fn with_name(mut self, name: impl Into<PathBuf>) -> Self {
        self.name = name.into();
        self
    }

    /// Prepares generation: the root sampler and part layout, the
    /// interpolator (the style mesh is built here), the operator chain and
    /// its clump centres.
    ///
    /// # Errors
    /// A count of zero, fewer than 2 points a hair, a map that needs UVs on
    /// a mesh without them, a density that is zero everywhere; the error
    /// names the setting (`ops[2].clump.count`), and its line when the
    /// groom came from a file.
    pub fn generator(self) -> Result<Generator, GroomError> {
        Generator::new(self)
    }

    /// An error about the setting `key` (`roots.count`, `ops[1].noise`),
    /// at its line when the groom came from a file.
    pub(crate) fn error(&self, key: &str, kind: GroomErrorKind) -> GroomError {
        setting_error(&self.name, self.origin.as_deref(), key, kind)
    }
}

/// An error about the setting `key` of the groom `name`, at its line when
/// `origin` (the groom file) says where it was written.
pub(crate) fn setting_error(
    name: &std::path::Path,
    origin: Option<&SpecOrigin>,
    key: &str,
    kind: GroomErrorKind,
) -> GroomError {
    let line = origin.and_then(|o| o.lines.get(key).copied());
    GroomError::new(name.to_path_buf(), line, Some(key.to_string()), kind)
}

/// Where a groom file wrote the settings the generator checks: setting key
/// (`roots.count`, `ops[2].clump.density`, `ops[2].clump` for an
/// operator's `[[ops]]` header) to line and column.
#[derive(Debug, Default)]
pub(crate) struct SpecOrigin {
    pub(crate) lines: HashMap<String, (usize, usize)>,
}

/// `[roots]`: how many hairs grow where.
#[derive(Debug, Clone)]
pub struct RootsSpec {
    /// Number of hairs (before `strands` multiplies them).
    pub count: u64,
    /// Root density over the surface.
    pub density: Map,
    /// Seed of every random number in the groom.
    pub seed: u64,
    /// Number of parts (`None`: one per 100,000 hairs).
    pub parts: Option<u32>,
    /// How hairs are numbered when the count or the density changes.
    pub ids: HairIds,
    /// Independent random roots, or roots spread apart (blue noise).
    pub distribution: RootDistribution,
}

/// How hairs are numbered and placed as the count or density changes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum HairIds {
    /// Root cells ([`crate::sample::RootCells`]): raising the count keeps
    /// every hair (id, root, shape) and adds new ones, lowering it removes
    /// hairs without moving the rest, and a local density edit moves only
    /// the hairs near it. Ids are `k · cells + cell`, not contiguous.
    #[default]
    Stable,
    /// Ids `0..N` over the parts in order, each part sampled on its own:
    /// any change of the count or density moves every root.
    Sequential,
}

impl HairIds {
    /// `stable` or `sequential`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "stable" => Some(Self::Stable),
            "sequential" => Some(Self::Sequential),
            _ => None,
        }
    }
}

/// How roots are spread.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum RootDistribution {
    /// Independent random roots following the density (Sik §3).
    #[default]
    Random,
    /// Blue-noise-like roots: drawn four times over and thinned by
    /// weighted sample elimination (Yuksel 2015) with radii that follow
    /// the density, so neighbours keep their distance and the density
    /// still matches the map.
    BlueNoise,
}

impl RootDistribution {
    /// `random` or `blue-noise`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "random" => Some(Self::Random),
            "blue-noise" | "blue_noise" => Some(Self::BlueNoise),
            _ => None,
        }
    }
}

impl RootsSpec {
    /// `count` hairs, uniform density, seed 1, the default parts, stable
    /// ids, random roots.
    pub fn new(count: u64) -> Self {
        Self {
            count,
            density: Map::Constant(1.0),
            seed: 1,
            parts: None,
            ids: HairIds::default(),
            distribution: RootDistribution::default(),
        }
    }

    /// Sets how hairs are numbered.
    pub fn with_ids(mut self, ids: HairIds) -> Self {
        self.ids = ids;
        self
    }

    /// Sets how roots are spread.
    pub fn with_distribution(mut self, distribution: RootDistribution) -> Self {
        self.distribution = distribution;
        self
    }

    /// Sets the density map.
    pub fn with_density(mut self, density: Map) -> Self {
        self.density = density;
        self
    }

    /// Sets the seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Sets the number of parts.
    pub fn with_parts(mut self, parts: u32) -> Self {
        self.parts = Some(parts);
        self
    }
}

/// `[finish]`: what every hair ends with.
#[derive(Debug, Clone)]
pub struct FinishSpec {
    /// Points per hair (at least 2).
    pub points: usize,
    /// Widths before any `width` operator.
    pub width: RootToTip,
    /// Colours (none unless given here or by a `color` operator).
    pub color: Option<Color>,
    /// Opacities (none unless given here or by an `opacity` operator).
    pub opacity: Option<RootToTip>,
    /// Per-point ribbon normals from rotation-minimizing frames.
    pub normals: bool,
}

impl Default for FinishSpec {
    /// A groom file's defaults: 16 points, widths 0.002 at the root to
    /// 0.0002 at the tip, linearly, normals on.
    fn default() -> Self {
        Self {
            points: 16,
            width: RootToTip::new(Map::Constant(0.002), Map::Constant(0.0002)),
            color: None,
            opacity: None,
            normals: true,
        }
    }
}

/// One operator of the chain, with its settings. Seeds are the operator's
/// own; the generator mixes them with the groom's seed and the operator's
/// place in the chain, so two operators with the same seed still differ.
#[derive(Debug, Clone)]
#[allow(
    clippy::large_enum_variant,
    reason = "a groom holds a handful, built once; boxing would only add noise to building them"
)]
pub enum GroomOp {
    /// Perlin displacement ([`super::ops::Noise`]).
    Noise(NoiseParams),
    /// Per-hair random high-frequency displacement ([`super::ops::Frizz`]).
    Frizz(FrizzParams),
    /// Pull hairs toward clump centre hairs ([`super::ops::Clump`]).
    Clump(ClumpParams),
    /// Helix around the hair's path ([`super::ops::Curl`]).
    Curl(CurlParams),
    /// Cut at a curve parameter.
    Cut(Cut),
    /// Scale the length ([`super::ops::Length`]).
    Length(LengthParams),
    /// Each hair becomes a strand of hairs ([`super::ops::Strands`]).
    Strands(StrandsParams),
    /// Widths root to tip (seed as given).
    Width(RootToTip),
    /// Colours root to tip (seed as given).
    Color(Color),
    /// Opacities root to tip (seed as given).
    Opacity(RootToTip),
    /// An operator whose effect is faded by a map ([`super::ops::Masked`]):
    /// build one with [`GroomOp::masked`].
    Masked(Box<GroomOp>, Map),
}

impl GroomOp {
    /// The operator with its effect faded by `mask` (0: none, 1: full),
    /// read at each hair's root.
    pub fn masked(self, mask: Map) -> GroomOp {
        GroomOp::Masked(Box::new(self), mask)
    }

    /// The operator under any mask.
    pub fn unmasked(&self) -> &GroomOp {
        match self {
            GroomOp::Masked(op, _) => op.unmasked(),
            op => op,
        }
    }

    /// The operator's name in groom files (`noise`, `clump`, …).
    pub fn name(&self) -> &'static str {
        match self {
            GroomOp::Masked(op, _) => op.name(),
            GroomOp::Noise(_) => "noise",
            GroomOp::Frizz(_) => "frizz",
            GroomOp::Clump(_) => "clump",
            GroomOp::Curl(_) => "curl",
            GroomOp::Cut(_) => "cut",
            GroomOp::Length(_) => "length",
            GroomOp::Strands(_) => "strands",
            GroomOp::Width(_) => "width",
            GroomOp::Color(_) => "color",
            GroomOp::Opacity(_) => "opacity",
        }
    }

    /// Every map the operator reads, with its setting's name.
    pub fn maps(&self) -> Vec<(&'static str, &Map)> {
        match self {
            GroomOp::Masked(op, mask) => {
                let mut maps = op.maps();
                maps.push(("mask", mask));
                maps
            }
            GroomOp::Noise(s) => vec![("amplitude", &s.amplitude), ("frequency", &s.frequency)],
            GroomOp::Frizz(s) => vec![
                ("amplitude", &s.amplitude),
                ("frequency", &s.frequency),
                ("fraction", &s.fraction),
            ],
            GroomOp::Clump(s) => {
                let mut maps = vec![("density", &s.density), ("rate", &s.rate)];
                maps.extend(s.size.as_ref().map(|m| ("size", m)));
                maps
            }
            GroomOp::Curl(s) => vec![("radius", &s.radius), ("turns", &s.turns)],
            GroomOp::Cut(s) => vec![("at", s.at())],
            GroomOp::Length(s) => vec![("scale", &s.scale), ("jitter", &s.jitter)],
            GroomOp::Strands(s) => vec![
                ("root_spread", &s.root_spread),
                ("tip_spread", &s.tip_spread),
                ("twist", &s.twist),
            ],
            GroomOp::Width(s) | GroomOp::Opacity(s) => root_to_tip_maps(s),
            GroomOp::Color(s) => color_maps(s),
        }
    }
}

impl GroomOp {
    /// Every map the operator reads, to change (binding them to a mesh).
    pub fn maps_mut(&mut self) -> Vec<(&'static str, &mut Map)> {
        match self {
            GroomOp::Masked(op, mask) => {
                let mut maps = op.maps_mut();
                maps.push(("mask", mask));
                maps
            }
            GroomOp::Noise(s) => vec![
                ("amplitude", &mut s.amplitude),
                ("frequency", &mut s.frequency),
            ],
            GroomOp::Frizz(s) => vec![
                ("amplitude", &mut s.amplitude),
                ("frequency", &mut s.frequency),
                ("fraction", &mut s.fraction),
            ],
            GroomOp::Clump(s) => {
                let mut maps = vec![("density", &mut s.density), ("rate", &mut s.rate)];
                maps.extend(s.size.as_mut().map(|m| ("size", m)));
                maps
            }
            GroomOp::Curl(s) => vec![("radius", &mut s.radius), ("turns", &mut s.turns)],
            GroomOp::Cut(s) => vec![("at", s.at_mut())],
            GroomOp::Length(s) => vec![("scale", &mut s.scale), ("jitter", &mut s.jitter)],
            GroomOp::Strands(s) => vec![
                ("root_spread", &mut s.root_spread),
                ("tip_spread", &mut s.tip_spread),
                ("twist", &mut s.twist),
            ],
            GroomOp::Width(s) | GroomOp::Opacity(s) => root_to_tip_maps_mut(s),
            GroomOp::Color(s) => color_maps_mut(s),
        }
    }
}

/// The maps of a root-to-tip setting, to change.
pub(crate) fn root_to_tip_maps_mut(s: &mut RootToTip) -> Vec<(&'static str, &mut Map)> {
    vec![
        ("root", &mut s.root),
        ("tip", &mut s.tip),
        ("jitter", &mut s.jitter),
    ]
}

/// The maps of a colour setting, to change.
pub(crate) fn color_maps_mut(s: &mut Color) -> Vec<(&'static str, &mut Map)> {
    let Color {
        root, tip, jitter, ..
    } = s;
    let mut maps: Vec<(&'static str, &mut Map)> = root.iter_mut().map(|m| ("root", m)).collect();
    maps.extend(tip.iter_mut().map(|m| ("tip", m)));
    maps.push(("jitter", jitter));
    maps
}

/// The maps of a root-to-tip setting, by name.
pub(crate) fn root_to_tip_maps(s: &RootToTip) -> Vec<(&'static str, &Map)> {
    vec![("root", &s.root), ("tip", &s.tip), ("jitter", &s.jitter)]
}

/// The maps of a colour setting, by name.
pub(crate) fn color_maps(s: &Color) -> Vec<(&'static str, &Map)> {
    let root = s.root.iter().map(|m| ("root", m));
    let tip = s.tip.iter().map(|m| ("tip", m));
    root.chain(tip).chain([("jitter", &s.jitter)]).collect()
}

/// `noise`: see [`super::ops::Noise`].
#[derive(Debug, Clone)]
pub struct NoiseParams {
    /// Largest displacement (world units).
    pub amplitude: Map,
    /// Noise cycles per world unit.
    pub frequency: Map,
    /// Root-to-tip profile of the amplitude.
    pub ramp: Ramp,
    /// Noise vectors sampled along each hair, interpolated between (0: one
    /// at every point).
    pub vectors: usize,
    /// Seed of the noise field.
    pub seed: u64,
}

impl NoiseParams {
    /// Noise of `amplitude`; a groom file's defaults for the rest
    /// (frequency 10, linear ramp, 5 vectors, seed 0).
    pub fn new(amplitude: Map) -> Self {
        Self {
            amplitude,
            frequency: Map::Constant(10.0),
            ramp: Ramp::default(),
            vectors: 5,
            seed: 0,
        }
    }
}

/// `frizz`: see [`super::ops::Frizz`].
#[derive(Debug, Clone)]
pub struct FrizzParams {
    /// Largest displacement (world units).
    pub amplitude: Map,
    /// Wiggles along one hair.
    pub frequency: Map,
    /// Share of hairs that frizz (0 to 1).
    pub fraction: Map,
    /// Root-to-tip profile.
    pub ramp: Ramp,
    /// Seed.
    pub seed: u64,
}

impl FrizzParams {
    /// Frizz of `amplitude` on every hair; frequency 6, linear ramp, seed 0.
    pub fn new(amplitude: Map) -> Self {
        Self {
            amplitude,
            frequency: Map::Constant(6.0),
            fraction: Map::Constant(1.0),
            ramp: Ramp::default(),
            seed: 0,
        }
    }
}

/// `clump`: see [`super::ops::Clump`].
#[derive(Debug, Clone)]
pub struct ClumpParams {
    /// Number of clumps over the whole mesh.
    pub count: u64,
    /// Density of clump centres.
    pub density: Map,
    /// How far hairs move to their centre hair (0 to 1).
    pub rate: Map,
    /// Root-to-tip profile of the rate.
    pub ramp: Ramp,
    /// Clump radius (`None`: no limit).
    pub size: Option<Map>,
    /// Seed of the clump centres.
    pub seed: u64,
}

impl ClumpParams {
    /// `count` clumps, uniform centres, rate 0.8, linear ramp, no size
    /// limit, seed 0.
    pub fn new(count: u64) -> Self {
        Self {
            count,
            density: Map::Constant(1.0),
            rate: Map::Constant(0.8),
            ramp: Ramp::default(),
            size: None,
            seed: 0,
        }
    }
}

/// `curl`: see [`super::ops::Curl`].
#[derive(Debug, Clone)]
pub struct CurlParams {
    /// Helix radius at the tip (world units): Silva's K_α.
    pub radius: Map,
    /// Turns along the hair: Silva's ω / 2π.
    pub turns: Map,
    /// Root-to-tip profile of the radius.
    pub ramp: Ramp,
    /// Seed of each hair's phase.
    pub seed: u64,
}

impl CurlParams {
    /// A curl of `radius` and `turns`, linear ramp, seed 0.
    pub fn new(radius: Map, turns: Map) -> Self {
        Self {
            radius,
            turns,
            ramp: Ramp::default(),
            seed: 0,
        }
    }
}

/// `length`: see [`super::ops::Length`].
#[derive(Debug, Clone)]
pub struct LengthParams {
    /// Length factor.
    pub scale: Map,
    /// Per-hair random variation, a fraction (0.2 = ±20 %).
    pub jitter: Map,
    /// Seed of the variation.
    pub seed: u64,
}

impl LengthParams {
    /// Lengths times `scale`, no jitter, seed 0.
    pub fn new(scale: Map) -> Self {
        Self {
            scale,
            jitter: Map::Constant(0.0),
            seed: 0,
        }
    }
}

/// `strands`: see [`super::ops::Strands`].
#[derive(Debug, Clone)]
pub struct StrandsParams {
    /// Hairs per strand (at least 1).
    pub count: u32,
    /// Spread around the base hair at the root (world units).
    pub root_spread: Map,
    /// Spread at the tip.
    pub tip_spread: Map,
    /// Turns of the strand's hairs around the base hair, root to tip.
    pub twist: Map,
    /// Seed.
    pub seed: u64,
}

impl StrandsParams {
    /// Strands of `count` hairs spreading to `tip_spread`; no root spread,
    /// no twist, seed 0.
    pub fn new(count: u32, tip_spread: Map) -> Self {
        Self {
            count,
            root_spread: Map::Constant(0.0),
            tip_spread,
            twist: Map::Constant(0.0),
            seed: 0,
        }
    }
}

impl RootToTip {
    /// From `root` to `tip`, linearly, no jitter, seed 0.
    pub fn new(root: Map, tip: Map) -> Self {
        Self {
            root,
            tip,
            ramp: Ramp::default(),
            jitter: Map::Constant(0.0),
            seed: 0,
        }
    }
}
