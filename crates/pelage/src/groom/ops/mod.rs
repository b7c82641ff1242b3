//! Groom operators: the ordered chain every hair passes through after
//! interpolation (Sik §4.2.2's noise, colour, width, strands and cut;
//! Furtility's idea of a chain of groom operators; clump and curl as
//! XGen, Houdini and Silva Eq. 4 shape them).
//!
//! An operator works on a [`HairBatch`]: the hairs grown from one root —
//! one hair, or several once [`Strands`] has split it. Every random number
//! comes from a stream keyed by the operator's seed and the hair's id
//! ([`SampleRng`]), so a hair is the same whichever thread, part or run
//! makes it (docs/design.md, "Deterministic by hair id"). Parameters are
//! [`Map`]s read at the root's UV.
//!
//! Points are indexed root to tip; `t = j / (n − 1)` is point `j`'s curve
//! parameter, the `t` of every root-to-tip [`Ramp`].

mod centres;
mod clump;
mod color;
mod curl;
mod cut;
mod flyaways;
mod frizz;
mod kind;
mod length;
mod mask;
mod noise;
mod opacity;
mod root_to_tip;
pub(crate) mod settings;
mod strands;
mod twist;
mod width;

pub use centres::{CentreGuides, ClumpCentres};
pub use clump::{Clump, ClumpParams};
pub use color::Color;
pub use curl::{Curl, CurlParams};
pub use cut::Cut;
pub use flyaways::{Flyaways, FlyawaysParams};
pub use frizz::{Frizz, FrizzParams};
pub use length::{Length, LengthParams};
pub use mask::{Masked, UNMASKED_COLOR, UNMASKED_OPACITY};
pub use noise::{Noise, NoiseParams, NoiseScratch};
pub use opacity::Opacity;
pub use strands::{Strands, StrandsParams};
pub use twist::{Twist, TwistParams};
pub use width::Width;

pub use color::ColorSpec;
pub use kind::OperatorSchema;
pub(crate) use kind::{ChainSoFar, OpKey, Preparation, schema_of};
pub use root_to_tip::{RootToTip, RootToTipSpec};
pub(crate) use settings::{OperatorSettings, SpecReader, map_on_mesh};
pub use settings::{SettingSchema, Start};

use crate::groom::error::GroomError;
use crate::groom::values::MapValue;
use crate::settings::Rule;
use kind::{OperatorKind, operators};

// The registry: every operator, one a line. The enums `OpSpec`, `GroomOp`
// and `Operator` and their dispatch are derived from it (`kind.rs`).
operators! {
    /// Perlin displacement ([`Noise`]).
    Noise(Noise, NoiseParams),
    /// Per-hair random high-frequency displacement ([`Frizz`]).
    Frizz(Frizz, FrizzParams),
    /// Pull hairs toward clump centre hairs ([`Clump`]).
    Clump(Clump, ClumpParams),
    /// Helix around the hair's path ([`Curl`]).
    Curl(Curl, CurlParams),
    /// Cut at a curve parameter ([`Cut`]).
    Cut(Cut, Cut),
    /// Scale the length ([`Length`]).
    Length(Length, LengthParams),
    /// Each hair becomes a strand of hairs ([`Strands`]).
    Strands(Strands, StrandsParams),
    /// Widths root to tip ([`Width`]).
    Width(Width, RootToTip),
    /// Colours root to tip ([`Color`]).
    Color(Color, Color),
    /// Opacities root to tip ([`Opacity`]).
    Opacity(Opacity, RootToTip),
    /// Hairs turned about their root–tip axis ([`Twist`]).
    Twist(Twist, TwistParams),
    /// A fraction of the hairs lengthened and pushed off their clump
    /// ([`Flyaways`]).
    Flyaways(Flyaways, FlyawaysParams),
}

use crate::curves::frames::{catmull_rom_tangents, rotation_minimizing_normals};
use crate::curves::{floats_finite, vectors_finite};
use crate::groom::ramp::Ramp;
use crate::interp::QueryRegion;
use crate::map::{Map, MapSite};
use crate::mesh::SurfacePoint;
use crate::sample::SampleRng;
use glam::Vec3;

/// One hair while operators shape it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Hair {
    /// Stable id (a strand's hairs get `id · count + k`).
    pub id: u64,
    /// Points, root first.
    pub points: Vec<Vec3>,
    /// Per-point widths.
    pub widths: Vec<f32>,
    /// Per-point colours (empty: none).
    pub colors: Vec<Vec3>,
    /// Per-point opacities (empty: none).
    pub opacities: Vec<f32>,
}

impl Hair {
    /// The first of its attributes holding a value that is not finite
    /// (`"positions"`, `"widths"`, `"colours"`, `"opacities"`), if any.
    pub fn non_finite(&self) -> Option<&'static str> {
        if !vectors_finite(&self.points) {
            Some("positions")
        } else if !floats_finite(&self.widths) {
            Some("widths")
        } else if !vectors_finite(&self.colors) {
            Some("colours")
        } else if !floats_finite(&self.opacities) {
            Some("opacities")
        } else {
            None
        }
    }

    /// Copies `other` into `self`, reusing `self`'s buffers.
    pub fn copy_from(&mut self, other: &Hair) {
        self.id = other.id;
        for (dst, src) in [
            (&mut self.points, &other.points),
            (&mut self.colors, &other.colors),
        ] {
            dst.clear();
            dst.extend_from_slice(src);
        }
        for (dst, src) in [
            (&mut self.widths, &other.widths),
            (&mut self.opacities, &other.opacities),
        ] {
            dst.clear();
            dst.extend_from_slice(src);
        }
    }
}

/// The hairs grown from one root. Slots beyond `len` keep their buffers
/// for reuse, so the chain allocates nothing per hair once warm.
#[derive(Debug, Clone, Default)]
pub struct HairBatch {
    hairs: Vec<Hair>,
    len: usize,
}

impl HairBatch {
    /// The live hairs.
    pub fn hairs(&self) -> &[Hair] {
        &self.hairs[..self.len]
    }

    /// The live hairs, to change.
    pub fn hairs_mut(&mut self) -> &mut [Hair] {
        &mut self.hairs[..self.len]
    }

    /// Empties the batch (keeping buffers) and returns a fresh first hair.
    pub fn reset(&mut self) -> &mut Hair {
        self.len = 0;
        self.push()
    }

    /// Appends a hair (a reused slot: the caller overwrites every field).
    pub fn push(&mut self) -> &mut Hair {
        if self.len == self.hairs.len() {
            self.hairs.push(Hair::default());
        }
        self.len += 1;
        &mut self.hairs[self.len - 1]
    }

    /// Keeps the hairs for which `keep` is true, in order.
    pub fn retain(&mut self, mut keep: impl FnMut(&Hair) -> bool) {
        let mut kept = 0;
        for i in 0..self.len {
            if keep(&self.hairs[i]) {
                self.hairs.swap(kept, i);
                kept += 1;
            }
        }
        self.len = kept;
    }

    /// Number of live hairs.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no hair is left.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// Where a batch grows: the root on the skin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RootContext {
    /// The root on the mesh.
    pub point: SurfacePoint,
    /// Its position.
    pub position: Vec3,
    /// The skin normal there.
    pub normal: Vec3,
    /// Where the operators' maps are read (UV, rest position, corners).
    pub site: MapSite,
    /// The root's region (0 when the skin is not split).
    pub region: u32,
    /// A ball around the root's skin triangle, when an operator searches
    /// for nearest points (`clump`): one candidate list serves all the
    /// roots in it.
    pub skin_triangle: Option<QueryRegion>,
}

/// Buffers operators share, reused hair after hair.
#[derive(Debug, Default)]
pub struct Scratch {
    pub(crate) tangents: Vec<Vec3>,
    pub(crate) frame: Vec<Vec3>,
    pub(crate) points: Vec<Vec3>,
    pub(crate) floats: Vec<f32>,
    pub(crate) bases: HairBatch,
    /// Clump centres near the last roots.
    pub(crate) near: crate::interp::NeighbourCache,
    pub(crate) noise: NoiseScratch,
    /// Root-to-tip profiles at the hairs' point counts.
    pub(crate) ramps: RampTables,
    /// The hairs before a masked operator.
    pub(crate) masked: HairBatch,
}

/// `ramp(t_j)` for the points `j` of an `n`-point hair, kept per (ramp,
/// `n`): a groom's hairs mostly share one point count, so `noise`,
/// `clump`, `width`, `color` and `opacity` read their profile from a table
/// instead of evaluating it (and dividing for `t_j`) at every point of
/// every hair.
#[derive(Debug, Default)]
pub struct RampTables {
    tables: Vec<(Ramp, usize, Vec<f32>)>,
}

/// Tables kept at most: one for each of a few operators and point counts;
/// past that the oldest makes room.
const RAMP_TABLES: usize = 8;

impl RampTables {
    /// `ramp.at(param(j, n))` for `j` in `0..n`.
    pub fn along(&mut self, ramp: &Ramp, n: usize) -> &[f32] {
        let found = self
            .tables
            .iter()
            .position(|(r, m, _)| *m == n && r == ramp);
        let i = match found {
            Some(i) => i,
            None => {
                if self.tables.len() == RAMP_TABLES {
                    self.tables.remove(0);
                }
                let values = (0..n).map(|j| ramp.at(param(j, n))).collect();
                self.tables.push((ramp.clone(), n, values));
                self.tables.len() - 1
            }
        };
        &self.tables[i].2
    }
}

impl Scratch {
    /// Fills `tangents` and `frame` with the Catmull-Rom tangents and the
    /// rotation-minimizing normals along `points`, started from any vector
    /// perpendicular to the skin normal (operators that wrap shapes around
    /// a hair need a frame that does not twist, not a particular start).
    pub(crate) fn frame_along(&mut self, points: &[Vec3], skin_normal: Vec3) {
        let n = points.len();
        self.tangents.resize(n, Vec3::ZERO);
        self.frame.resize(n, Vec3::ZERO);
        catmull_rom_tangents(points, &mut self.tangents);
        rotation_minimizing_normals(
            points,
            &self.tangents,
            skin_normal.any_orthonormal_vector(),
            &mut self.frame,
        );
    }
}

/// Curve parameter of point `j` of `n`.
#[inline]
pub(crate) fn param(j: usize, n: usize) -> f32 {
    if n > 1 {
        j as f32 / (n - 1) as f32
    } else {
        0.0
    }
}

/// `to` points evenly spaced in the parameter of a polyline of `from`
/// points (linear interpolation between its points): for each output
/// point, the segment it falls in and how far along, worked out once and
/// reused for every hair of those point counts.
#[derive(Debug, Clone)]
pub(crate) struct Resampling {
    from: usize,
    to: usize,
    /// Point `k`: `shape[j].lerp(shape[j + 1], f)`, as `(j, f)`.
    between: Vec<(u32, f32)>,
}

impl Resampling {
    pub(crate) fn new(from: usize, to: usize) -> Self {
        let between = if from >= 2 && from != to {
            (0..to)
                .map(|k| {
                    let x = k as f32 / (to - 1) as f32 * (from - 1) as f32;
                    let j = (x as usize).min(from - 2);
                    (j as u32, x - j as f32)
                })
                .collect()
        } else {
            Vec::new()
        };
        Self { from, to, between }
    }

    /// For each output point (when `from ≥ 2` and `from ≠ to`): the
    /// segment it falls in and how far along, `(j, f)`.
    pub(crate) fn between(&self) -> &[(u32, f32)] {
        &self.between
    }

    /// Appends `shape` (of `from` points) resampled to `to` points.
    pub(crate) fn apply(&self, shape: &[Vec3], out: &mut Vec<Vec3>) {
        debug_assert_eq!(shape.len(), self.from);
        if self.from == self.to {
            out.extend_from_slice(shape);
        } else if self.from < 2 {
            out.extend(std::iter::repeat_n(
                shape.first().copied().unwrap_or_default(),
                self.to,
            ));
        } else {
            out.extend(
                self.between
                    .iter()
                    .map(|&(j, f)| shape[j as usize].lerp(shape[j as usize + 1], f)),
            );
        }
    }
}

/// `1 + jitter · (2ξ − 1)`: a per-hair factor varying by ±`jitter`.
#[inline]
pub(crate) fn jittered(jitter: f32, rng: &mut SampleRng) -> f32 {
    if jitter == 0.0 {
        1.0
    } else {
        1.0 + jitter * (2.0 * rng.uniform_f32() - 1.0)
    }
}

#[cfg(test)]
pub(crate) mod test_hairs {
    use super::*;

    /// A straight hair of `n` points from the origin up +Z to height `len`.
    pub fn straight(id: u64, n: usize, len: f32) -> Hair {
        Hair {
            id,
            points: (0..n).map(|j| Vec3::Z * len * param(j, n)).collect(),
            widths: vec![0.01; n],
            colors: Vec::new(),
            opacities: Vec::new(),
        }
    }

    /// The root context of [`straight`]: at the origin, normal +Z.
    pub fn root() -> RootContext {
        RootContext {
            point: SurfacePoint::new(0, [0.3, 0.3]),
            position: Vec3::ZERO,
            normal: Vec3::Z,
            site: MapSite::at_uv(glam::Vec2::new(0.5, 0.5)),
            region: 0,
            skin_triangle: None,
        }
    }

    /// A batch holding one hair.
    pub fn batch(hair: Hair) -> HairBatch {
        let mut b = HairBatch::default();
        *b.reset() = hair;
        b
    }
}

#[cfg(test)]
mod registry_tests {
    use super::*;

    /// Panics unless a groom file whose one operator is `name` with
    /// `keys` (`"count = 3"`, …) reads.
    fn reads_as_the_only_operator(name: &str, keys: &[String]) {
        let text = format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 10\n[[ops]]\n{name} = {{ {} }}\n",
            keys.join(", ")
        );
        let source = crate::settings::SettingsSource {
            path: "ops.toml".into(),
            text,
        };
        source
            .check_groom()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
    }

    #[test]
    fn every_range_rule_names_a_field_of_its_operator() {
        // A misspelt rule key would check nothing: no number is ever
        // written under it.
        let schema = operator_schema();
        let rules = operator_rules();
        assert!(rules.len() >= 10, "{} rules", rules.len());
        for rule in rules {
            let parts: Vec<&str> = rule.key.split('.').collect();
            let [_, name, field] = parts[..] else {
                panic!("{}: not ops.NAME.FIELD", rule.key);
            };
            let fields = &schema.iter().find(|s| s.name == name).unwrap().fields;
            assert!(
                fields.contains(&field),
                "{}: {name} has no field {field:?} (its fields: {fields:?})",
                rule.key
            );
        }
    }

    #[test]
    fn every_required_setting_starts_where_a_groom_file_reads_it() {
        // Front ends start a new operator from the schema (the Blender
        // panel): a required setting without a start, or one a groom file
        // refuses (`count = 200.0`), would leave the entry unusable.
        for op in operator_schema() {
            let mut keys = Vec::new();
            for setting in &op.settings {
                let start = match setting.start {
                    Some(Start::Number(x) | Start::Length(x)) => format!("{x:?}"),
                    Some(Start::Rgb([r, g, b])) => format!("[{r:?}, {g:?}, {b:?}]"),
                    None if setting.required => {
                        panic!("{}.{} is required and has no start", op.name, setting.name)
                    }
                    None => continue,
                };
                // As the Python binding hands it over: whole numbers whole.
                let start = start.strip_suffix(".0").unwrap_or(&start).to_string();
                keys.push(format!("{} = {start}", setting.name));
            }
            reads_as_the_only_operator(op.name, &keys);
        }
        let width = operator_schema().into_iter().find(|s| s.name == "width");
        let root = &width.unwrap().settings[0];
        assert_eq!(
            (root.name, root.start),
            ("root", Some(Start::Length(0.002)))
        );
    }

    #[test]
    fn the_schema_is_read_off_each_operators_spec() {
        let schema = operator_schema();
        let names: Vec<&str> = schema.iter().map(|s| s.name).collect();
        assert_eq!(names, OPERATOR_NAMES);
        let clump = schema.iter().find(|s| s.name == "clump").unwrap();
        assert_eq!(
            clump.fields,
            ["count", "density", "rate", "ramp", "size", "seed", "mask"]
        );
        assert_eq!(clump.required, ["count"]);
        let color = schema.iter().find(|s| s.name == "color").unwrap();
        assert_eq!(color.required, ["root", "tip"]);
        let twist = schema.iter().find(|s| s.name == "twist").unwrap();
        assert_eq!(twist.required, ["angle"]);
        assert!(schema.iter().all(|s| s.fields.contains(&"mask")));
    }

    #[test]
    fn every_operator_reads_under_its_name_with_its_required_keys() {
        for op in operator_schema() {
            let keys: Vec<String> = op
                .required
                .iter()
                .map(|k| match (op.name, *k) {
                    ("color", _) => format!("{k} = [0.5, 0.5, 0.5]"),
                    _ => format!("{k} = 1"),
                })
                .collect();
            reads_as_the_only_operator(op.name, &keys);
        }
    }
}
