//! The groom as plain Rust values: a mesh, guides, where roots grow, how
//! hairs take the guides' shape, the operator chain and the finish
//! (Sik §4's generator inputs). [`GroomSpec::generator`] prepares a
//! [`Generator`](super::Generator) from them; a groom file ([`super::Groom`]) is one front end
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
use super::hair_look::HairLook;
pub use super::ops::GroomOp;
use super::ops::{Color, RootToTip};
use crate::guides::Guides;
use crate::interp::InterpolationMethod;
use crate::map::Map;
use crate::mesh::Mesh;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

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
    /// Each hair's values for a hair shader (`None`: none written).
    pub look: Option<HairLook>,
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
            look: None,
            origin: None,
        }
    }

    /// Gives every hair values for a hair shader.
    pub fn with_look(mut self, look: HairLook) -> Self {
        self.look = Some(look);
        self
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

    /// The most hairs one root grows: each `strands` operator multiplies
    /// them by its count (`cut` may remove some). What memory estimates
    /// multiply the root count by.
    pub fn most_hairs_per_root(&self) -> u64 {
        self.ops
            .iter()
            .map(|op| match op.unmasked() {
                super::ops::GroomOp::Strands(s) => u64::from(s.count.max(1)),
                _ => 1,
            })
            .fold(1, u64::saturating_mul)
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
    /// A map the density is multiplied by (the constant 1: none). A
    /// grooming session paints its density here, on a layer that starts
    /// at 1, so the first dab changes the roots under it alone.
    pub density_scale: Map,
    /// Seed of every random number in the groom.
    pub seed: u64,
    /// Number of parts (`None`: one per 100,000 hairs).
    pub parts: Option<u32>,
    /// How hairs are numbered when the count or the density changes.
    pub ids: HairIds,
    /// Independent random roots, or roots spread apart (blue noise).
    pub distribution: RootDistribution,
    /// The share of the hairs grown (0 to 1; 1: all): a preview that stays
    /// true to the groom. The first arrivals of the root cells (stable
    /// ids), so a fraction's hairs are hairs of every larger fraction, bit
    /// for bit, with widths times `1/√fraction` so the fur covers the skin
    /// as the whole groom does.
    pub fraction: f64,
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

impl std::str::FromStr for HairIds {
    type Err = String;

    /// `stable` or `sequential`.
    fn from_str(s: &str) -> Result<Self, String> {
        Self::parse(s).ok_or_else(|| format!("ids {s:?}: use \"stable\" or \"sequential\""))
    }
}

impl std::fmt::Display for HairIds {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            HairIds::Stable => "stable",
            HairIds::Sequential => "sequential",
        })
    }
}

/// How roots are spread.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum RootDistribution {
    /// Independent random roots following the density (Sik §3).
    #[default]
    Random,
    /// Blue-noise roots: drawn twice over and thinned by dart throwing
    /// with spacings that follow the density, all parts together, so
    /// neighbours keep their distance (no seams at part borders) and the
    /// density still matches the map.
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
    /// ids, random roots, all of them grown.
    pub fn new(count: u64) -> Self {
        Self {
            count,
            density: Map::Constant(1.0),
            density_scale: Map::Constant(1.0),
            seed: 1,
            parts: None,
            ids: HairIds::default(),
            distribution: RootDistribution::default(),
            fraction: 1.0,
        }
    }

    /// Sets the share of the hairs grown (a preview).
    pub fn with_fraction(mut self, fraction: f64) -> Self {
        self.fraction = fraction;
        self
    }

    /// The hairs grown: `count` times the fraction, rounded, at least 1.
    pub fn grown_count(&self) -> u64 {
        if self.fraction >= 1.0 {
            return self.count;
        }
        ((self.count as f64 * self.fraction).round() as u64).max(1)
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

    /// The density the roots are drawn from: `density` times
    /// `density_scale`.
    pub fn sampled_density(&self) -> std::borrow::Cow<'_, Map> {
        match &self.density_scale {
            Map::Constant(c) if *c == 1.0 => std::borrow::Cow::Borrowed(&self.density),
            scale => std::borrow::Cow::Owned(Map::product(self.density.clone(), scale.clone())),
        }
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
    /// Keep hair points this far above the skin after the operators,
    /// segment lengths kept (`None`: off); see
    /// [`OutsideSkin`](crate::groom::OutsideSkin).
    pub outside_skin: Option<f32>,
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
            outside_skin: None,
        }
    }
}
