//! What one operator module provides ([`OperatorKind`]), and the registry
//! macro that derives the operator chain's three enums from the list of
//! modules: [`super::OpSpec`] (the `[[ops]]` table as a groom file writes
//! it), [`super::GroomOp`] (the operator as plain values, what programs
//! build) and [`super::Operator`] (prepared, what the generator runs).
//!
//! An operator lives in one file, `groom/ops/<name>.rs`: its serde spec
//! with defaults, its parameters, its prepared form, its name, its map
//! fields, its range rules and its salts. Adding one is that file, one
//! line of the registry in `ops/mod.rs`, its tests and its docs
//! (docs/adding-an-operator.md).

use super::centres::ClumpCentres;
use super::settings::{OperatorSettings, SettingSchema, Start};
use super::{Hair, HairBatch, RootContext, Scratch};
use crate::groom::error::{GroomError, GroomErrorKind};
use crate::mesh::{Mesh, SurfacePoint};
use crate::settings::Rule;

/// One operator: implemented by its prepared form (the value the
/// generator runs), which names the operator's other two forms.
pub(crate) trait OperatorKind: Sized {
    /// The name groom files, errors and bindings use (`noise`, `clump`).
    const NAME: &'static str;
    /// One line saying what it does, for `--help`-like listings and the
    /// Python builders' docstrings.
    const SUMMARY: &'static str;
    /// The operator as plain values (maps read, not yet prepared): its
    /// settings, declared once with `operator_settings!`, which also
    /// writes the `[[ops]]` table as a groom file writes it.
    type Params: OperatorSettings;

    /// The documented ranges of the operator's numeric settings, keyed by
    /// field name (`count`), checked when a groom file is read: its
    /// settings' (an operator whose settings another shares, as `width`
    /// and `opacity` share theirs, says its own).
    const RULES: &'static [Rule] = <Self::Params as OperatorSettings>::RULES;
    /// Where front ends start its settings, by setting, over the
    /// declaration's starts (an operator whose settings another shares
    /// says its own).
    const STARTS: &'static [(&'static str, Start)] = &[];
    /// The salts of the operator's random streams (kept apart from every
    /// other stream's: a test compares them all).
    const SALTS: &'static [(&'static str, u64)] = &[];
    /// Whether every root still grows exactly one hair after it (`false`
    /// for operators that split or remove hairs).
    const KEEPS_ONE_HAIR: bool = true;
    /// Whether it gives hairs colours.
    const ADDS_COLORS: bool = false;
    /// Whether it gives hairs opacities.
    const ADDS_OPACITIES: bool = false;
    /// Whether it searches for hairs near the root (roots then carry the
    /// ball around their skin triangle).
    const SEARCHES_NEIGHBOURS: bool = false;

    /// Counts with a ceiling (field, value, most, what is counted),
    /// checked before anything is prepared.
    fn counts(_params: &Self::Params) -> Vec<(&'static str, u64, u64, &'static str)> {
        Vec::new()
    }

    /// The operator prepared: seeds mixed, anything it precomputes built.
    fn prepare(params: Self::Params, cx: &Preparation<'_>) -> Result<Self, GroomError>;

    /// Shapes one hair (operators that keep one hair a root).
    fn apply_to_hair(&self, _hair: &mut Hair, _root: &RootContext, _scratch: &mut Scratch) {
        unreachable!("{} works on the whole batch", Self::NAME)
    }

    /// Shapes every hair grown from one root.
    fn apply(&self, batch: &mut HairBatch, root: &RootContext, scratch: &mut Scratch) {
        for hair in batch.hairs_mut() {
            self.apply_to_hair(hair, root, scratch);
        }
    }

    /// Shapes hairs grown one a root (`hairs[i]` from `roots[i]`); an
    /// operator that can share work across hairs overrides it.
    fn apply_each(&self, hairs: &mut [Hair], roots: &[RootContext], scratch: &mut Scratch) {
        for (hair, root) in hairs.iter_mut().zip(roots) {
            self.apply_to_hair(hair, root, scratch);
        }
    }

    /// Applies the operator at strength `m` (0 to 1) its own way, instead
    /// of the mask's blend of before and after; `false` when it has none.
    fn apply_faded(
        &self,
        _batch: &mut HairBatch,
        _root: &RootContext,
        _m: f32,
        _scratch: &mut Scratch,
    ) -> bool {
        false
    }

    /// Where a mask of 0 leaves the hairs as they were: nothing, unless
    /// their ids must change with the operator's (a strand's hairs).
    fn masked_out(&self, _batch: &mut HairBatch) {}
}

/// Where an operator sits in a groom: its place in the chain and its
/// name. Setting keys in errors are built from it (`ops[2].clump.count`),
/// never spelled by hand.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct OpKey {
    /// Place in the chain.
    pub index: usize,
    /// The operator's name.
    pub name: &'static str,
}

impl OpKey {
    /// The key of one of its settings.
    pub fn field(&self, field: &str) -> String {
        format!("{self}.{field}")
    }
}

impl std::fmt::Display for OpKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ops[{}].{}", self.index, self.name)
    }
}

/// What preparing an operator can ask of the chain before it: the
/// generator being built implements this (`groom/build.rs`), so the
/// operators never name the generator that runs them.
pub(crate) trait ChainSoFar: Sync {
    /// The groom's seed.
    fn seed(&self) -> u64;
    /// An error about the setting `key`, at its line when the groom came
    /// from a file.
    fn error(&self, key: &str, kind: GroomErrorKind) -> GroomError;
    /// The mesh hairs grow on.
    fn mesh(&self) -> &Mesh;
    /// The centre roots of the clump at chain position `k` in the groom
    /// being reshaped, when nothing but guide shapes changed.
    fn unchanged_centre_roots(&self, k: usize) -> Option<Vec<SurfacePoint>>;
    /// Hairs grown from `roots` through the operators before position
    /// `k`: the centre hairs of a clump level.
    fn clump_centres(&self, k: usize, roots: &[SurfacePoint]) -> ClumpCentres;
}

/// What preparing operator `k` of a chain can use: the chain built so far
/// (the operators before it are prepared), the operator's own random
/// streams and its errors.
pub(crate) struct Preparation<'a> {
    pub(crate) chain: &'a dyn ChainSoFar,
    pub(crate) key: OpKey,
}

impl Preparation<'_> {
    /// The operator's own random stream for its seed `s`: the groom's seed
    /// mixed with the operator's place in the chain and `s`, so two
    /// operators with the same seed still differ.
    pub fn seed(&self, s: u64) -> u64 {
        use crate::sample::mix64;
        mix64(self.chain.seed() ^ mix64((self.key.index as u64 + 1) << 32 ^ s))
    }

    /// An error about one of the operator's settings, at its line.
    pub fn error(&self, field: &str, kind: GroomErrorKind) -> GroomError {
        self.chain.error(&self.key.field(field), kind)
    }

    /// The mesh hairs grow on.
    pub fn mesh(&self) -> &Mesh {
        self.chain.mesh()
    }

    /// The centre roots of this clump operator in the generator being
    /// reshaped, when nothing but guide shapes changed (the same density,
    /// count and seed sample the same roots).
    pub fn unchanged_centre_roots(&self) -> Option<Vec<SurfacePoint>> {
        self.chain.unchanged_centre_roots(self.key.index)
    }

    /// Hairs grown from `roots` through the operators before this one: the
    /// centre hairs of a clump level.
    pub fn centres(&self, roots: &[SurfacePoint]) -> ClumpCentres {
        self.chain.clump_centres(self.key.index, roots)
    }
}

/// One operator's settings as a groom file spells them.
#[derive(Debug, Clone, PartialEq)]
pub struct OperatorSchema {
    /// The operator's name (`clump`).
    pub name: &'static str,
    /// One line saying what it does.
    pub summary: &'static str,
    /// Every key its table takes, `mask` last, in declaration order.
    pub fields: Vec<&'static str>,
    /// The keys it cannot do without.
    pub required: Vec<&'static str>,
    /// Every setting but `mask`, as declared (docs, starting values).
    pub settings: Vec<SettingSchema>,
}

/// The schema of operator `K`, from its settings' declaration.
pub(crate) fn schema_of<K: OperatorKind>() -> OperatorSchema {
    let settings = <K::Params as OperatorSettings>::SETTINGS;
    OperatorSchema {
        name: K::NAME,
        summary: K::SUMMARY,
        fields: settings.iter().map(|s| s.name).chain(["mask"]).collect(),
        required: settings
            .iter()
            .filter(|s| s.required)
            .map(|s| s.name)
            .collect(),
        settings: settings
            .iter()
            .map(|s| SettingSchema {
                start: K::STARTS
                    .iter()
                    .find(|(name, _)| *name == s.name)
                    .map(|(_, start)| *start)
                    .or(s.start),
                ..s.clone()
            })
            .collect(),
    }
}

/// Derives the chain's enums and their dispatch from the list of
/// operators: `Variant(Prepared, Params)`, one a line, in the
/// registry (`ops/mod.rs`). The variant's name, in kebab case, is the
/// operator's name in groom files.
macro_rules! operators {
    ($( $(#[$doc:meta])* $Variant:ident($Op:ty, $Params:ty) ),* $(,)?) => {
        /// One operator as a groom file writes it: `[[ops]]` followed by
        /// `NAME = { … }` or `[ops.NAME]`.
        #[derive(Debug, Clone, serde::Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub(crate) enum OpSpec {
            $( $(#[$doc])* $Variant(<$Params as OperatorSettings>::Spec), )*
        }

        /// One operator of the chain, with its settings, as plain values.
        /// Seeds are the operator's own; the generator mixes them with the
        /// groom's seed and the operator's place in the chain, so two
        /// operators with the same seed still differ.
        #[derive(Debug, Clone)]
        #[allow(
            clippy::large_enum_variant,
            reason = "a groom holds a handful, built once; boxing would only add noise to building them"
        )]
        pub enum GroomOp {
            $( $(#[$doc])* $Variant($Params), )*
            /// An operator whose effect is faded by a map ([`Masked`]):
            /// build one with [`GroomOp::masked`].
            Masked(Box<GroomOp>, Map),
        }

        /// One operator of the chain, prepared.
        #[derive(Debug)]
        pub enum Operator {
            $( $(#[$doc])* $Variant($Op), )*
            /// An operator faded by a mask.
            Masked(Masked),
        }

        /// Every operator's name, in the registry's order.
        pub const OPERATOR_NAMES: &[&str] = &[$( <$Op as OperatorKind>::NAME ),*];

        /// Every operator's settings as a groom file spells them, from
        /// their declarations: what front ends (the Python builders, the
        /// Blender panel) must offer.
        pub fn operator_schema() -> Vec<OperatorSchema> {
            vec![$( schema_of::<$Op>() ),*]
        }

        /// Every operator's range rules, keyed as the groom file's
        /// settings are (`ops.clump.count`).
        pub(crate) fn operator_rules() -> Vec<Rule> {
            let mut rules = Vec::new();
            $(
                for rule in <$Op as OperatorKind>::RULES {
                    rules.push(Rule::owned(
                        format!("ops.{}.{}", <$Op as OperatorKind>::NAME, rule.key),
                        rule.bound,
                        rule.why,
                    ));
                }
            )*
            rules
        }

        /// Every operator's salts, named `name.SALT`: the streams they
        /// key must stay apart from each other and from every other
        /// stream's (`crate::sample::salts`).
        pub fn operator_salts() -> Vec<(String, u64)> {
            let mut salts = Vec::new();
            $(
                for (name, salt) in <$Op as OperatorKind>::SALTS {
                    salts.push((format!("{}.{name}", <$Op as OperatorKind>::NAME), *salt));
                }
            )*
            salts
        }

        impl OpSpec {
            /// The operator's name.
            pub(crate) fn name(&self) -> &'static str {
                match self {
                    $( OpSpec::$Variant(_) => <$Op as OperatorKind>::NAME, )*
                }
            }

            /// The operator's `mask`, if it has one.
            pub(crate) fn mask(&self) -> Option<&MapValue> {
                match self {
                    $( OpSpec::$Variant(s) => <$Params as OperatorSettings>::mask(s), )*
                }
            }

            /// The operator as values, its mask included, maps read on the
            /// mesh; `reader` notes where each setting was written.
            pub(crate) fn read(
                &self,
                reader: &mut SpecReader<'_>,
            ) -> Result<GroomOp, GroomError> {
                let op = match self {
                    $( OpSpec::$Variant(s) => GroomOp::$Variant(<$Params as OperatorSettings>::read(s, reader)?), )*
                };
                Ok(match self.mask() {
                    Some(mask) => op.masked(reader.map("mask", mask)?),
                    None => op,
                })
            }
        }

        impl GroomOp {
            /// The operator with its effect faded by `mask` (0: none, 1:
            /// full), read at each hair's root.
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
                    $( GroomOp::$Variant(_) => <$Op as OperatorKind>::NAME, )*
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
                    $( GroomOp::$Variant(p) => <$Params as OperatorSettings>::maps(p), )*
                }
            }

            /// Every map the operator reads, to change (binding them to a
            /// mesh).
            pub fn maps_mut(&mut self) -> Vec<(&'static str, &mut Map)> {
                match self {
                    GroomOp::Masked(op, mask) => {
                        let mut maps = op.maps_mut();
                        maps.push(("mask", mask));
                        maps
                    }
                    $( GroomOp::$Variant(p) => <$Params as OperatorSettings>::maps_mut(p), )*
                }
            }

            /// The first of the operator's numbers that breaks its range
            /// rule (`RULES`, the same the groom file is checked with): the
            /// field and the file check's message. Maps given as constants
            /// and counts are checked; a map read from an image or noise is
            /// not a number to check.
            pub(crate) fn out_of_range(&self) -> Option<(&'static str, String)> {
                let rules: &[Rule] = match self {
                    // The mask is a map without a range: the operator's own.
                    GroomOp::Masked(op, _) => return op.out_of_range(),
                    $( GroomOp::$Variant(_) => <$Op as OperatorKind>::RULES, )*
                };
                let constants = self.maps().into_iter().filter_map(|(field, map)| match map {
                    Map::Constant(v) => Some((field, f64::from(*v), v.to_string())),
                    _ => None,
                });
                let counts = self
                    .counts()
                    .into_iter()
                    .map(|(field, value, _, _)| (field, value as f64, value.to_string()));
                constants.chain(counts).find_map(|(field, value, shown)| {
                    rules
                        .iter()
                        .filter(|rule| rule.key == field)
                        .find_map(|rule| rule.refusal(value, &shown))
                        .map(|message| (field, message))
                })
            }

            /// Counts with a ceiling: (field, value, most, what).
            pub(crate) fn counts(&self) -> Vec<(&'static str, u64, u64, &'static str)> {
                match self {
                    GroomOp::Masked(op, _) => op.counts(),
                    $( GroomOp::$Variant(p) => <$Op as OperatorKind>::counts(p), )*
                }
            }

            /// The operator prepared for the generator.
            pub(crate) fn prepare(self, cx: &Preparation<'_>) -> Result<Operator, GroomError> {
                Ok(match self {
                    GroomOp::Masked(op, mask) => {
                        Operator::Masked(Masked::new(op.prepare(cx)?, mask))
                    }
                    $( GroomOp::$Variant(p) => Operator::$Variant(<$Op as OperatorKind>::prepare(p, cx)?), )*
                })
            }
        }

        impl Operator {
            /// Applies the operator to every hair of `batch`.
            pub fn apply(&self, batch: &mut HairBatch, root: &RootContext, scratch: &mut Scratch) {
                match self {
                    Operator::Masked(op) => op.apply(batch, root, scratch),
                    $( Operator::$Variant(op) => op.apply(batch, root, scratch), )*
                }
            }

            /// Applies the operator to hairs grown one a root (`hairs[i]`
            /// from `roots[i]`): the same result as [`Self::apply`] root by
            /// root, with the work of some operators (noise) shared across
            /// the hairs.
            ///
            /// # Panics
            /// For operators that change the number of hairs
            /// ([`Self::keeps_one_hair_a_root`]).
            pub fn apply_each(&self, hairs: &mut [Hair], roots: &[RootContext], scratch: &mut Scratch) {
                assert_eq!(hairs.len(), roots.len(), "one root a hair");
                assert!(
                    self.keeps_one_hair_a_root(),
                    "{} changes the number of hairs a root grows",
                    self.name()
                );
                match self {
                    Operator::Masked(op) => op.apply_each(hairs, roots, scratch),
                    $( Operator::$Variant(op) => op.apply_each(hairs, roots, scratch), )*
                }
            }

            /// Applies the operator at strength `m` its own way (`false`:
            /// it has none; a mask blends before and after instead).
            pub(crate) fn apply_faded(
                &self,
                batch: &mut HairBatch,
                root: &RootContext,
                m: f32,
                scratch: &mut Scratch,
            ) -> bool {
                match self {
                    Operator::Masked(_) => false,
                    $( Operator::$Variant(op) => op.apply_faded(batch, root, m, scratch), )*
                }
            }

            /// Where a mask of 0 leaves the hairs as they were
            /// ([`OperatorKind::masked_out`]).
            pub(crate) fn masked_out(&self, batch: &mut HairBatch) {
                match self {
                    Operator::Masked(masked) => masked.operator().masked_out(batch),
                    $( Operator::$Variant(op) => op.masked_out(batch), )*
                }
            }

            /// Whether every root still grows exactly one hair after this
            /// operator.
            pub fn keeps_one_hair_a_root(&self) -> bool {
                match self {
                    Operator::Masked(op) => op.operator().keeps_one_hair_a_root(),
                    $( Operator::$Variant(_) => <$Op as OperatorKind>::KEEPS_ONE_HAIR, )*
                }
            }

            /// Whether it gives hairs colours.
            pub fn adds_colors(&self) -> bool {
                match self {
                    Operator::Masked(op) => op.operator().adds_colors(),
                    $( Operator::$Variant(_) => <$Op as OperatorKind>::ADDS_COLORS, )*
                }
            }

            /// Whether it gives hairs opacities.
            pub fn adds_opacities(&self) -> bool {
                match self {
                    Operator::Masked(op) => op.operator().adds_opacities(),
                    $( Operator::$Variant(_) => <$Op as OperatorKind>::ADDS_OPACITIES, )*
                }
            }

            /// Whether it searches for hairs near the root.
            pub fn searches_neighbours(&self) -> bool {
                match self {
                    Operator::Masked(op) => op.operator().searches_neighbours(),
                    $( Operator::$Variant(_) => <$Op as OperatorKind>::SEARCHES_NEIGHBOURS, )*
                }
            }

            /// The operator under any mask.
            pub fn unmasked(&self) -> &Operator {
                match self {
                    Operator::Masked(op) => op.operator().unmasked(),
                    op => op,
                }
            }

            /// The operator's name as groom files spell it.
            pub fn name(&self) -> &'static str {
                match self {
                    Operator::Masked(op) => op.operator().name(),
                    $( Operator::$Variant(_) => <$Op as OperatorKind>::NAME, )*
                }
            }
        }
    };
}

pub(crate) use operators;
