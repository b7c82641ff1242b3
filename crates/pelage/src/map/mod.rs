//! [`Map`]: a scalar field over UV that any parameter can read: a constant,
//! an image (PNG 8/16-bit, EXR float; bilinear; wrap or clamp; one
//! channel), or procedural Perlin/fBm noise.
//!
//! Every groom parameter is a map, as in Stubble (Sik, section 4: "every
//! user parameter … is also specified by a texture"). A map is evaluated at
//! a UV; [`Map::on_mesh`] binds it to a mesh once, checking that the mesh has
//! the UVs the map needs, so per-point evaluation cannot fail.
//!
//! Texture orientation follows OBJ/USD/Blender: UV (0, 0) is the image's
//! bottom-left corner. Image values are used as stored (no sRGB decoding):
//! a density painted at 50 % grey reads 0.5.

mod image;
mod noise;
mod spec;

pub use self::image::{Channel, Filter, ImageMap, Wrap, open_image};
pub use self::noise::NoiseMap;

use crate::mesh::{Mesh, SurfacePoint};
use glam::Vec2;

/// A scalar field over UV.
#[derive(Debug, Clone, PartialEq)]
pub enum Map {
    /// The same value everywhere.
    Constant(f32),
    /// One channel of an image, bilinearly filtered.
    Image(ImageMap),
    /// Perlin fBm noise.
    Noise(NoiseMap),
}

/// A map could not be read, parsed or used. Displays as `SOURCE: what is
/// wrong`, where SOURCE is the image file, the spec string or the mesh.
/// Its `source` is the error underneath its kind, if any.
#[derive(Debug)]
pub struct MapError {
    /// The image path, the map spec as written, or the mesh name.
    pub source_name: String,
    /// What is wrong.
    pub kind: MapErrorKind,
}

impl std::fmt::Display for MapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.source_name, self.kind)
    }
}

impl std::error::Error for MapError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        std::error::Error::source(&self.kind)
    }
}

/// What is wrong with a map.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MapErrorKind {
    /// The image file could not be opened or read.
    #[error("cannot read the file: {0}")]
    Io(#[source] std::io::Error),
    /// The file is not an image pelage can decode.
    #[error("not a readable PNG or EXR image: {0}")]
    Decode(String),
    /// The image has no pixels.
    #[error("the image is empty ({width}×{height})")]
    EmptyImage {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
    },
    /// A texel is NaN or infinite (possible in EXR files).
    #[error("texel ({x}, {y}) is not a finite number")]
    NonFiniteTexel {
        /// Column.
        x: u32,
        /// Row from the top.
        y: u32,
    },
    /// The map description could not be parsed.
    #[error("{0}")]
    Spec(String),
    /// The map reads UVs and the mesh has none.
    #[error(
        "this map is evaluated at UVs, and the mesh has no UVs (texture coordinates); add UVs to the mesh or use a constant"
    )]
    MeshHasNoUvs,
}

impl MapError {
    pub(crate) fn new(source_name: impl Into<String>, kind: MapErrorKind) -> Self {
        Self {
            source_name: source_name.into(),
            kind,
        }
    }
}

impl Map {
    /// The map's value at `uv`.
    pub fn eval(&self, uv: Vec2) -> f32 {
        match self {
            Map::Constant(c) => *c,
            Map::Image(image) => image.eval(uv),
            Map::Noise(noise) => noise.eval(uv),
        }
    }

    /// A value no evaluation exceeds: the constant, the largest texel, or
    /// `offset + |scale|` for noise (fBm is normalised to [−1, 1]).
    pub fn upper_bound(&self) -> f32 {
        match self {
            Map::Constant(c) => *c,
            Map::Image(image) => image.max_texel(),
            Map::Noise(noise) => noise.offset + noise.scale.abs(),
        }
    }

    /// How finely the map varies, as a texel grid `(width, height)` over
    /// the unit UV square: the image size, or for noise four samples per
    /// cell of its finest octave; `None` for a constant. Samplers subdivide
    /// triangles until each covers at most one such texel (Sik §3.1).
    pub fn resolution(&self) -> Option<(u32, u32)> {
        match self {
            Map::Constant(_) => None,
            Map::Image(image) => Some((image.width(), image.height())),
            Map::Noise(noise) => {
                let finest = noise.frequency.abs() * 2f32.powi(noise.octaves as i32 - 1);
                let n = (4.0 * finest).ceil().clamp(1.0, 65_536.0) as u32;
                Some((n, n))
            }
        }
    }

    /// Whether evaluating the map needs texture coordinates.
    pub fn needs_uvs(&self) -> bool {
        !matches!(self, Map::Constant(_))
    }

    /// Binds the map to a mesh for evaluation at surface points. Fails,
    /// naming the mesh, if the map needs UVs and the mesh has none.
    pub fn on_mesh<'a>(&'a self, mesh: &'a Mesh) -> Result<MapOnMesh<'a>, MapError> {
        if self.needs_uvs() && !mesh.has_uvs() {
            return Err(MapError::new(mesh.name(), MapErrorKind::MeshHasNoUvs));
        }
        Ok(MapOnMesh { map: self, mesh })
    }
}

/// A map bound to a mesh it can be evaluated on (see [`Map::on_mesh`]).
#[derive(Debug, Clone, Copy)]
pub struct MapOnMesh<'a> {
    map: &'a Map,
    mesh: &'a Mesh,
}

impl MapOnMesh<'_> {
    /// The map's value at a point of the mesh.
    pub fn eval(&self, point: SurfacePoint) -> f32 {
        match self.map {
            Map::Constant(c) => *c,
            // on_mesh checked that the mesh has UVs.
            map => map.eval(point.uv(self.mesh).unwrap_or(Vec2::ZERO)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tests::{tetrahedron, unit_square};

    #[test]
    fn image_map_on_mesh_without_uvs_names_the_mesh() {
        let map = Map::Image(ImageMap::from_texels(1, 1, vec![1.0], Wrap::Repeat).unwrap());
        let mesh = tetrahedron();
        let err = map.on_mesh(&mesh).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("tetrahedron: this map is evaluated at UVs")
        );
        // A constant needs no UVs.
        assert!(Map::Constant(2.0).on_mesh(&mesh).is_ok());
    }

    #[test]
    fn bound_map_reads_the_uv_of_the_point() {
        // 2×1 image: left texel 0, right texel 1, clamped: u = 0.25 → 0, 0.75 → 1.
        let map = Map::Image(ImageMap::from_texels(2, 1, vec![0.0, 1.0], Wrap::Clamp).unwrap());
        let mesh = unit_square();
        let bound = map.on_mesh(&mesh).unwrap();
        // Triangle 0 is (0,0),(1,0),(1,1): bary [0.75, 0.0] is uv (0.75, 0).
        assert_eq!(bound.eval(SurfacePoint::new(0, [0.75, 0.0])), 1.0);
        assert_eq!(bound.eval(SurfacePoint::new(0, [0.25, 0.0])), 0.0);
    }
}
