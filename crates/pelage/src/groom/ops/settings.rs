//! An operator's settings, each declared once: [`operator_settings!`]
//! takes one line a setting (its doc, kind, default, starting value and
//! range rule) and writes from it the `[[ops]]` table as a groom file
//! writes it (the serde spec), the parameters programs build (with `new`
//! taking the required ones), reading the spec's maps on the mesh
//! ([`SpecReader`]), every map by name, the range rules, and the schema
//! front ends build their panels from ([`SettingSchema`]).
//!
//! Kinds of setting, as a groom file writes them and as programs hold
//! them:
//!
//! | kind | file | program |
//! | --- | --- | --- |
//! | `map` | a number or a map spec | [`Map`] |
//! | `rgb` | three of those | `[Map; 3]` |
//! | `maybe_map` | a map, or nothing (no default) | `Option<Map>` |
//! | `count(T)` | a whole number, its line noted for later errors | `T` |
//! | `value(T)` | `T` as serde reads it (a [`crate::groom::ramp::Ramp`], a seed) | `T` |
//!
//! A required setting has no default and the groom file must write it;
//! an optional one's default is what `new` and a file that leaves it out
//! both use. Every operator also takes `mask`.

use crate::groom::error::GroomError;
use crate::groom::values::{MapValue, default_map};
use crate::map::Map;
use crate::mesh::Mesh;
use crate::settings::SettingsSource;
use std::collections::HashMap;

/// Where a front end starts a setting of a new operator (the Blender
/// panel's new entry): a value that shows the operator's effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Start {
    /// A plain number.
    Number(f64),
    /// A length in world units for a mesh about 1 unit across: front
    /// ends scale it by the mesh's size.
    Length(f64),
    /// A colour, linear RGB.
    Rgb([f64; 3]),
}

/// One setting of an operator, as declared: what front ends offer.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingSchema {
    /// The key a groom file writes (`amplitude`).
    pub name: &'static str,
    /// What it is, its doc comment's lines.
    pub doc: &'static [&'static str],
    /// Whether a groom file must write it.
    pub required: bool,
    /// Where a front end starts it, if anywhere.
    pub start: Option<Start>,
}

/// What [`operator_settings!`] writes for a parameters type: the spec it
/// reads from, its settings and rules, and its maps.
pub(crate) trait OperatorSettings: Sized + std::fmt::Debug + Clone {
    /// The table as a groom file writes it.
    type Spec: serde::de::DeserializeOwned + std::fmt::Debug + Clone;
    /// Every setting but `mask`, in declaration order.
    const SETTINGS: &'static [SettingSchema];
    /// The documented ranges of the numeric settings, keyed by setting.
    const RULES: &'static [crate::settings::Rule];

    /// The spec's `mask`, if it has one.
    fn mask(spec: &Self::Spec) -> Option<&MapValue>;

    /// The parameters the spec says, maps read on the mesh.
    fn read(spec: &Self::Spec, reader: &mut SpecReader<'_>) -> Result<Self, GroomError>;

    /// Every map, with its setting's name.
    fn maps(&self) -> Vec<(&'static str, &Map)>;

    /// Every map, to change (binding them to a mesh).
    fn maps_mut(&mut self) -> Vec<(&'static str, &mut Map)>;
}

/// Reads a spec's values from a groom file: maps resolved against the
/// file's folder and bound to the mesh, and where each setting was written
/// noted for errors the generator finds later.
pub(crate) struct SpecReader<'a> {
    source: &'a SettingsSource,
    mesh: &'a Mesh,
    lines: &'a mut HashMap<String, (usize, usize)>,
    /// The setting's key: `ops[2].clump` or `finish.width`.
    prefix: String,
}

impl<'a> SpecReader<'a> {
    pub(crate) fn new(
        source: &'a SettingsSource,
        mesh: &'a Mesh,
        lines: &'a mut HashMap<String, (usize, usize)>,
        prefix: String,
    ) -> Self {
        Self {
            source,
            mesh,
            lines,
            prefix,
        }
    }

    /// Notes where `field` was written.
    pub fn mark(&mut self, field: &str, span: std::ops::Range<usize>) {
        if let Some(line) = self.source.line_of(span) {
            self.lines.insert(format!("{}.{field}", self.prefix), line);
        }
    }

    /// A spanned number, its line noted.
    pub fn value<T: Copy>(&mut self, field: &str, value: &toml::Spanned<T>) -> T {
        self.mark(field, value.span());
        *value.get_ref()
    }

    /// A map, read and bound to the mesh, both errors at its line.
    pub fn map(&mut self, field: &str, value: &MapValue) -> Result<Map, GroomError> {
        self.mark(field, value.span());
        map_on_mesh(self.source, self.mesh, value)
    }

    /// A map the file may leave out: `default` (a constant) then.
    pub fn map_or(
        &mut self,
        field: &str,
        value: Option<&MapValue>,
        default: f32,
    ) -> Result<Map, GroomError> {
        match value {
            Some(value) => self.map(field, value),
            None => self.map(field, &default_map(default)),
        }
    }

    /// Three maps (a colour's channels).
    pub fn rgb(&mut self, field: &str, value: &[MapValue; 3]) -> Result<[Map; 3], GroomError> {
        Ok([
            self.map(field, &value[0])?,
            self.map(field, &value[1])?,
            self.map(field, &value[2])?,
        ])
    }
}

/// Resolves a map value and binds it to `mesh` (UVs, vertex
/// attributes), both errors at the value's line.
pub(crate) fn map_on_mesh(
    source: &SettingsSource,
    mesh: &Mesh,
    value: &MapValue,
) -> Result<Map, GroomError> {
    let mut map = source.map(value)?;
    map.bind(mesh)
        .map_err(|e| source.error_at(value.span(), crate::groom::error::GroomErrorKind::Map(e)))?;
    Ok(map)
}

/// The spec's type of a setting of a kind.
macro_rules! spec_type {
    (map) => { $crate::groom::values::MapValue };
    (maybe_map) => { $crate::groom::values::MapValue };
    (rgb) => { [$crate::groom::values::MapValue; 3] };
    (count $t:ty) => { toml::Spanned<$t> };
    (value $t:ty) => { $t };
}

/// The parameters' type of a setting of a kind.
macro_rules! params_type {
    (map) => { $crate::map::Map };
    (maybe_map) => { Option<$crate::map::Map> };
    (rgb) => { [$crate::map::Map; 3] };
    (count $t:ty) => { $t };
    (value $t:ty) => { $t };
}

/// An optional setting's default in the parameters.
macro_rules! default_value {
    (map, $d:expr) => {
        $crate::map::Map::Constant($d)
    };
    (maybe_map, $d:expr) => {
        $d
    };
    (value, $d:expr) => {
        $d
    };
}

/// Reads a required setting `$v` of the spec.
macro_rules! read_required {
    (map, $r:ident, $name:expr, $v:expr) => {
        $r.map($name, $v)?
    };
    (rgb, $r:ident, $name:expr, $v:expr) => {
        $r.rgb($name, $v)?
    };
    (count, $r:ident, $name:expr, $v:expr) => {
        $r.value($name, $v)
    };
    (value, $r:ident, $name:expr, $v:expr) => {
        ::std::clone::Clone::clone($v)
    };
}

/// Reads an optional setting `$v` (an `Option`) of the spec.
macro_rules! read_optional {
    (map, $r:ident, $name:expr, $v:expr, $d:expr) => {
        $r.map_or($name, $v.as_ref(), $d)?
    };
    (maybe_map, $r:ident, $name:expr, $v:expr, $d:expr) => {
        $v.as_ref().map(|m| $r.map($name, m)).transpose()?
    };
    (value, $r:ident, $name:expr, $v:expr, $d:expr) => {
        $v.clone().unwrap_or_else(|| $d)
    };
}

/// Adds a setting's maps (`&` or `&mut`, by `$iter`) to `$maps`.
macro_rules! push_maps {
    (map, $maps:ident, $name:expr, $v:expr, $iter:ident) => {
        $maps.push(($name, $v))
    };
    (maybe_map, $maps:ident, $name:expr, $v:expr, $iter:ident) => {
        if let Some(m) = $v {
            $maps.push(($name, m));
        }
    };
    (rgb, $maps:ident, $name:expr, $v:expr, $iter:ident) => {
        $maps.extend($v.$iter().map(|m| ($name, m)))
    };
    (count, $maps:ident, $name:expr, $v:expr, $iter:ident) => {};
    (value, $maps:ident, $name:expr, $v:expr, $iter:ident) => {};
}

/// `None`, or `Some` of a start.
macro_rules! start_of {
    () => {
        None
    };
    ($start:expr) => {
        Some($start)
    };
}

/// Declares an operator's settings once: its spec (`$Spec`, the table a
/// groom file writes), its parameters (`$Params`, with `new` taking the
/// required settings) and their [`OperatorSettings`]. See the module docs
/// for the kinds; docs/adding-an-operator.md for an example.
macro_rules! operator_settings {
    (
        $(#[doc = $spec_doc:literal])*
        $vis:vis spec $Spec:ident;
        $(#[doc = $params_doc:literal])*
        params $Params:ident {
            required {
                $(
                    $(#[doc = $rdoc:literal])+
                    $rf:ident : $rkind:ident $(($rty:ty))?
                    $(, start $rstart:expr)?
                    $(, rule $rbound:expr, $rwhy:literal)? ;
                )*
            }
            optional {
                $(
                    $(#[doc = $odoc:literal])+
                    $of:ident : $okind:ident $(($oty:ty))? = $odef:expr
                    $(, start $ostart:expr)?
                    $(, rule $obound:expr, $owhy:literal)? ;
                )*
            }
        }
    ) => {
        $(#[doc = $spec_doc])*
        #[derive(Debug, Clone, serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        $vis struct $Spec {
            $(
                $(#[doc = $rdoc])+
                pub $rf: $crate::groom::ops::settings::spec_type!($rkind $($rty)?),
            )*
            $(
                $(#[doc = $odoc])+
                pub $of: Option<$crate::groom::ops::settings::spec_type!($okind $($oty)?)>,
            )*
            /// Where the operator acts: its effect is faded by this map (0:
            /// none, 1: full).
            pub mask: Option<$crate::groom::values::MapValue>,
        }

        $(#[doc = $params_doc])*
        #[derive(Debug, Clone)]
        pub struct $Params {
            $(
                $(#[doc = $rdoc])+
                pub $rf: $crate::groom::ops::settings::params_type!($rkind $($rty)?),
            )*
            $(
                $(#[doc = $odoc])+
                pub $of: $crate::groom::ops::settings::params_type!($okind $($oty)?),
            )*
        }

        impl $Params {
            /// The settings a groom file must write; the others at the
            /// defaults a groom file that leaves them out gets.
            #[allow(clippy::new_without_default, reason = "declared settings")]
            pub fn new(
                $( $rf: $crate::groom::ops::settings::params_type!($rkind $($rty)?), )*
            ) -> Self {
                Self {
                    $( $rf, )*
                    $( $of: $crate::groom::ops::settings::default_value!($okind, $odef), )*
                }
            }
        }

        impl $crate::groom::ops::settings::OperatorSettings for $Params {
            type Spec = $Spec;
            const SETTINGS: &'static [$crate::groom::ops::settings::SettingSchema] = &[
                $(
                    $crate::groom::ops::settings::SettingSchema {
                        name: stringify!($rf),
                        doc: &[$($rdoc),+],
                        required: true,
                        start: $crate::groom::ops::settings::start_of!($($rstart)?),
                    },
                )*
                $(
                    $crate::groom::ops::settings::SettingSchema {
                        name: stringify!($of),
                        doc: &[$($odoc),+],
                        required: false,
                        start: $crate::groom::ops::settings::start_of!($($ostart)?),
                    },
                )*
            ];
            const RULES: &'static [$crate::settings::Rule] = &[
                $($( $crate::settings::Rule::new(stringify!($rf), $rbound, $rwhy), )?)*
                $($( $crate::settings::Rule::new(stringify!($of), $obound, $owhy), )?)*
            ];

            fn mask(spec: &$Spec) -> Option<&$crate::groom::values::MapValue> {
                spec.mask.as_ref()
            }

            fn read(
                s: &$Spec,
                r: &mut $crate::groom::ops::settings::SpecReader<'_>,
            ) -> Result<Self, $crate::groom::error::GroomError> {
                Ok(Self {
                    $( $rf: $crate::groom::ops::settings::read_required!(
                        $rkind, r, stringify!($rf), &s.$rf
                    ), )*
                    $( $of: $crate::groom::ops::settings::read_optional!(
                        $okind, r, stringify!($of), &s.$of, $odef
                    ), )*
                })
            }

            #[allow(clippy::vec_init_then_push, reason = "one push a declared setting")]
            fn maps(&self) -> Vec<(&'static str, &$crate::map::Map)> {
                let mut maps = Vec::new();
                $( $crate::groom::ops::settings::push_maps!(
                    $rkind, maps, stringify!($rf), &self.$rf, iter
                ); )*
                $( $crate::groom::ops::settings::push_maps!(
                    $okind, maps, stringify!($of), &self.$of, iter
                ); )*
                maps
            }

            #[allow(clippy::vec_init_then_push, reason = "one push a declared setting")]
            fn maps_mut(&mut self) -> Vec<(&'static str, &mut $crate::map::Map)> {
                let mut maps = Vec::new();
                $( $crate::groom::ops::settings::push_maps!(
                    $rkind, maps, stringify!($rf), &mut self.$rf, iter_mut
                ); )*
                $( $crate::groom::ops::settings::push_maps!(
                    $okind, maps, stringify!($of), &mut self.$of, iter_mut
                ); )*
                maps
            }
        }
    };
}

pub(crate) use {
    default_value, operator_settings, params_type, push_maps, read_optional, read_required,
    spec_type, start_of,
};
