//! Per-vertex maps: a scalar painted on the mesh's vertices (a PLY
//! property, an OBJ vertex colour channel), read at a surface point by
//! barycentric interpolation of its triangle's three corners. They need no
//! UVs, so meshes without texture coordinates can still carry painted
//! densities, lengths and masks.

use std::sync::Arc;

/// A per-vertex scalar of the mesh, by name. Written `vertex:NAME` in
/// groom files (`vertex:red`, `vertex:density`); the values are looked up
/// on the mesh when the groom is prepared ([`super::Map::bind`]).
#[derive(Debug, Clone, PartialEq)]
pub struct VertexMap {
    /// The vertex attribute's name.
    pub name: String,
    /// Its values, one a vertex, once bound to a mesh.
    pub(super) values: Option<Arc<[f32]>>,
}

impl VertexMap {
    /// The attribute `name`, not yet bound to a mesh.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            values: None,
        }
    }

    /// The values, once bound.
    pub fn values(&self) -> Option<&[f32]> {
        self.values.as_deref()
    }

    /// Linear interpolation of the corners' values (zero before binding).
    #[inline]
    pub(super) fn eval(&self, corners: [u32; 3], weights: [f32; 3]) -> f32 {
        let Some(values) = &self.values else {
            return 0.0;
        };
        let at = |k: usize| values.get(corners[k] as usize).copied().unwrap_or(0.0);
        weights[0] * at(0) + weights[1] * at(1) + weights[2] * at(2)
    }

    /// The largest value (zero before binding).
    pub(super) fn max_value(&self) -> f32 {
        self.values
            .as_deref()
            .map_or(0.0, |v| v.iter().copied().fold(f32::NEG_INFINITY, f32::max))
    }
}
