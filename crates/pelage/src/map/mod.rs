//! [`Map`]: a scalar field over the surface that any parameter can read: a
//! constant, an image (PNG 8/16-bit, EXR float; bilinear; wrap or clamp;
//! one channel; UDIM tiles), procedural Perlin/fBm noise (over UV, or
//! over the rest position on meshes without UVs), a per-vertex scalar of
//! the mesh, or the product of two maps (a painted layer scaling a
//! groom's density).
//!
//! Every groom parameter is a map, as in Stubble (Sik, section 4: "every
//! user parameter … is also specified by a texture"). A map is read at a
//! [`MapSite`] (a surface point's UV, rest position and triangle corners);
//! [`Map::bind`] prepares it for a mesh once, checking that the mesh has
//! the UVs or vertex attribute the map needs, so per-point evaluation
//! cannot fail.
//!
//! Texture orientation follows OBJ/USD/Blender: UV (0, 0) is the image's
//! bottom-left corner. Image values are used as stored (no sRGB decoding):
//! a density painted at 50 % grey reads 0.5.

mod image;
mod noise;
mod spec;
pub use spec::image_path_in_spec;
mod udim;
mod vertex;

pub use self::image::{Channel, Filter, ImageMap, Wrap, open_image};
pub use self::noise::{NoiseMap, NoiseSpace};
pub use self::udim::{UDIM_TOKEN, UdimMap};
pub use self::vertex::VertexMap;

use crate::mesh::{Mesh, SurfacePoint};
use glam::{Vec2, Vec3};

/// A scalar field over the surface.
#[derive(Debug, Clone, PartialEq)]
pub enum Map {
    /// The same value everywhere.
    Constant(f32),
    /// One channel of an image, bilinearly filtered.
    Image(ImageMap),
    /// Perlin fBm noise.
    Noise(NoiseMap),
    /// One image a UDIM tile.
    Udim(UdimMap),
    /// A per-vertex scalar of the mesh, interpolated barycentrically.
    Vertex(VertexMap),
    /// One map times another, point by point.
    Product(Box<[Map; 2]>),
}

/// Where a map is read: what every kind of map needs of a surface point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapSite {
    /// The point's UV (`None` on a mesh without UVs).
    pub uv: Option<Vec2>,
    /// Its position on the mesh the groom grows on (the rest pose of an
    /// animated skin), where object-space noise is read.
    pub position: Vec3,
    /// Its triangle's vertex indices, where per-vertex maps are read.
    pub corners: [u32; 3],
    /// The weights of those corners (they sum to 1).
    pub weights: [f32; 3],
}

impl MapSite {
    /// The site of `point` on `mesh`.
    pub fn on(mesh: &Mesh, point: SurfacePoint) -> Self {
        Self::with_position(mesh, point, point.position(mesh))
    }

    /// [`Self::on`] for a point whose position the caller has at hand.
    #[inline]
    pub fn with_position(mesh: &Mesh, point: SurfacePoint, position: Vec3) -> Self {
        let [b1, b2] = point.bary;
        Self {
            uv: point.uv(mesh),
            position,
            corners: mesh.triangles()[point.tri as usize],
            weights: [1.0 - b1 - b2, b1, b2],
        }
    }

    /// A site known only by its UV (maps that read UVs only).
    pub fn at_uv(uv: Vec2) -> Self {
        Self {
            uv: Some(uv),
            position: Vec3::ZERO,
            corners: [0; 3],
            weights: [1.0, 0.0, 0.0],
        }
    }
}

/// A map could not be read, parsed or used. Displays as `SOURCE: what is
/// wrong`, where SOURCE is the image file, the spec string or the mesh.
/// The error underneath, if any, is in its kind.
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

/// Prints its cause in its message and returns none as `source()`:
/// front ends print each cause once by walking the chain. The cause stays
/// in its kind for programs that inspect it.
impl std::error::Error for MapError {}

/// What is wrong with a map.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MapErrorKind {
    /// The image file could not be opened or read.
    #[error("cannot read the file: {0}")]
    Io(std::io::Error),
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
        "this map is evaluated at UVs, and the mesh has no UVs (texture coordinates); add UVs to the mesh, or use a map that needs none: a constant, \"noise\" (read in object space on a mesh without UVs), or a per-vertex map \"vertex:NAME\" (a PLY vertex property or OBJ vertex colour){attributes}"
    )]
    MeshHasNoUvs {
        /// `; this mesh has …` listing the vertex attributes, or empty.
        attributes: String,
    },
    /// A per-vertex map names an attribute the mesh does not have.
    #[error("the mesh has no vertex attribute '{name}'{attributes}")]
    NoVertexAttribute {
        /// The name asked for.
        name: String,
        /// `; it has …` or `; it has none …`.
        attributes: String,
    },
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
    /// The map's value at `uv`, for maps that read nothing but UVs (a
    /// per-vertex map reads 0 here; use [`Self::at`]).
    pub fn eval(&self, uv: Vec2) -> f32 {
        self.at(&MapSite::at_uv(uv))
    }

    /// The map's value at a site. A map that reads UVs reads (0, 0) at a
    /// site without one; [`Self::bind`] refuses such maps on meshes
    /// without UVs.
    #[inline]
    pub fn at(&self, site: &MapSite) -> f32 {
        match self {
            Map::Constant(c) => *c,
            Map::Image(image) => image.eval(site.uv.unwrap_or(Vec2::ZERO)),
            Map::Noise(noise) => match (noise.space, site.uv) {
                (NoiseSpace::Object, _) | (NoiseSpace::Auto, None) => noise.eval3(site.position),
                (_, uv) => noise.eval(uv.unwrap_or(Vec2::ZERO)),
            },
            Map::Udim(udim) => udim.eval(site.uv.unwrap_or(Vec2::ZERO)),
            Map::Vertex(vertex) => vertex.eval(site.corners, site.weights),
            Map::Product(maps) => maps[0].at(site) * maps[1].at(site),
        }
    }

    /// `a` times `b` (either alone when the other is the constant 1).
    pub fn product(a: Map, b: Map) -> Map {
        match (a, b) {
            (a, Map::Constant(c)) | (Map::Constant(c), a) if c == 1.0 => a,
            (a, b) => Map::Product(Box::new([a, b])),
        }
    }

    /// A value no evaluation exceeds: the constant, the largest texel or
    /// vertex value, or `offset + |scale|` for noise (fBm is normalised to
    /// [−1, 1]). A product's bound is its factors' bounds multiplied,
    /// which holds for maps that are never negative (densities, where it
    /// is read).
    pub fn upper_bound(&self) -> f32 {
        match self {
            Map::Constant(c) => *c,
            Map::Image(image) => image.max_texel(),
            Map::Noise(noise) => noise.offset + noise.scale.abs(),
            Map::Udim(udim) => udim.max_texel(),
            Map::Vertex(vertex) => vertex.max_value(),
            Map::Product(maps) => maps[0].upper_bound().max(0.0) * maps[1].upper_bound().max(0.0),
        }
    }

    /// Prepares the map for reading on `mesh`: a per-vertex map takes the
    /// mesh's values. Fails, naming the mesh, when the map reads UVs and
    /// the mesh has none, or names a vertex attribute it does not have.
    pub fn bind(&mut self, mesh: &Mesh) -> Result<(), MapError> {
        if let Map::Product(maps) = self {
            // Each factor checks itself.
            return maps.iter_mut().try_for_each(|map| map.bind(mesh));
        }
        self.check_on(mesh)?;
        if let Map::Vertex(vertex) = self {
            let attribute = mesh
                .vertex_attribute(&vertex.name)
                .expect("on_mesh checked the attribute");
            vertex.values = Some(attribute.values.clone());
        }
        Ok(())
    }

    /// The map bound to `mesh` ([`Self::bind`]) when it needs binding, as
    /// a copy; otherwise itself.
    pub fn bound(&self, mesh: &Mesh) -> Result<std::borrow::Cow<'_, Map>, MapError> {
        if self.is_bound_to(mesh) {
            self.check_on(mesh)?;
            Ok(std::borrow::Cow::Borrowed(self))
        } else {
            let mut map = self.clone();
            map.bind(mesh)?;
            Ok(std::borrow::Cow::Owned(map))
        }
    }

    /// Whether every per-vertex map in it holds values for `mesh`'s
    /// vertices.
    fn is_bound_to(&self, mesh: &Mesh) -> bool {
        match self {
            Map::Vertex(v) => v.values.as_ref().map(|x| x.len()) == Some(mesh.vertex_count()),
            Map::Product(maps) => maps.iter().all(|m| m.is_bound_to(mesh)),
            _ => true,
        }
    }

    /// How finely the map varies, as a texel grid `(width, height)` over
    /// the unit UV square: the image size, or for noise four samples per
    /// cell of its finest octave; `None` for a constant. Samplers subdivide
    /// triangles until each covers at most one such texel (Sik §3.1).
    /// Maps read in object space (noise on a mesh without UVs) and
    /// per-vertex maps have no texel grid over UV: `None`; see
    /// [`Self::object_resolution`] and [`Self::varies_within_triangles`].
    pub fn resolution(&self) -> Option<(u32, u32)> {
        match self {
            Map::Constant(_) | Map::Vertex(_) => None,
            Map::Noise(noise) if noise.space == NoiseSpace::Object => None,
            Map::Image(image) => Some((image.width(), image.height())),
            Map::Udim(udim) => Some(udim.resolution()),
            Map::Noise(noise) => {
                let n = noise_samples(noise);
                Some((n, n))
            }
            // The finer grid of the two along each axis.
            Map::Product(maps) => match (maps[0].resolution(), maps[1].resolution()) {
                (Some((w0, h0)), Some((w1, h1))) => Some((w0.max(w1), h0.max(h1))),
                (a, b) => a.or(b),
            },
        }
    }

    /// For noise read in object space (on a mesh without UVs, or with
    /// `space=object`): samples a world unit, four a cell of its finest
    /// octave, as [`Self::resolution`] counts them over UV.
    pub fn object_resolution(&self, mesh_has_uvs: bool) -> Option<f32> {
        match self {
            Map::Noise(noise)
                if noise.space == NoiseSpace::Object
                    || (noise.space == NoiseSpace::Auto && !mesh_has_uvs) =>
            {
                Some(noise_samples(noise) as f32)
            }
            Map::Product(maps) => {
                let [a, b] = [0, 1].map(|i| maps[i].object_resolution(mesh_has_uvs));
                match (a, b) {
                    (Some(a), Some(b)) => Some(a.max(b)),
                    (a, b) => a.or(b),
                }
            }
            _ => None,
        }
    }

    /// Whether the map varies inside a triangle without a texel grid
    /// (per-vertex maps: linearly from corner to corner).
    pub fn varies_within_triangles(&self) -> bool {
        match self {
            Map::Vertex(_) => true,
            Map::Product(maps) => maps.iter().any(Map::varies_within_triangles),
            _ => false,
        }
    }

    /// Whether evaluating the map needs texture coordinates: images, UDIM
    /// tiles and noise with `space=uv`.
    pub fn needs_uvs(&self) -> bool {
        match self {
            Map::Image(_) | Map::Udim(_) => true,
            Map::Noise(noise) => noise.space == NoiseSpace::Uv,
            Map::Constant(_) | Map::Vertex(_) => false,
            Map::Product(maps) => maps.iter().any(Map::needs_uvs),
        }
    }

    /// Checks that the map can be read on `mesh` and pairs them for
    /// evaluation at surface points. Fails, naming the mesh, if the map
    /// needs UVs and the mesh has none, or names a vertex attribute the
    /// mesh lacks.
    pub fn on_mesh<'a>(&'a self, mesh: &'a Mesh) -> Result<MapOnMesh<'a>, MapError> {
        Ok(MapOnMesh {
            map: self.bound(mesh)?,
            mesh,
        })
    }

    /// Fails, naming the mesh, if the map cannot be read on it.
    fn check_on(&self, mesh: &Mesh) -> Result<(), MapError> {
        if let Map::Product(maps) = self {
            return maps.iter().try_for_each(|m| m.check_on(mesh));
        }
        let attributes = |intro: &str| {
            let names: Vec<&str> = mesh
                .vertex_attributes()
                .iter()
                .map(|a| a.name.as_str())
                .collect();
            if names.is_empty() {
                String::new()
            } else {
                format!("; {intro} {}", names.join(", "))
            }
        };
        if self.needs_uvs() && !mesh.has_uvs() {
            let attributes = attributes("its vertex attributes are");
            return Err(MapError::new(
                mesh.name(),
                MapErrorKind::MeshHasNoUvs { attributes },
            ));
        }
        if let Map::Vertex(vertex) = self
            && mesh.vertex_attribute(&vertex.name).is_none()
        {
            let mut listed = attributes("it has");
            if listed.is_empty() {
                listed = "; it has none (PLY vertex properties beyond x y z, normals and UVs, and OBJ vertex colours, become vertex attributes)".into();
            }
            return Err(MapError::new(
                mesh.name(),
                MapErrorKind::NoVertexAttribute {
                    name: vertex.name.clone(),
                    attributes: listed,
                },
            ));
        }
        Ok(())
    }
}

/// Noise samples a unit (of UV or of space): four a cell of the finest
/// octave.
fn noise_samples(noise: &NoiseMap) -> u32 {
    let finest = noise.frequency.abs() * 2f32.powi(noise.octaves as i32 - 1);
    (4.0 * finest).ceil().clamp(1.0, 65_536.0) as u32
}

/// A map bound to a mesh it can be evaluated on (see [`Map::on_mesh`]).
#[derive(Debug, Clone)]
pub struct MapOnMesh<'a> {
    map: std::borrow::Cow<'a, Map>,
    mesh: &'a Mesh,
}

impl MapOnMesh<'_> {
    /// The map's value at a point of the mesh.
    pub fn eval(&self, point: SurfacePoint) -> f32 {
        match &*self.map {
            Map::Constant(c) => *c,
            map => map.at(&MapSite::on(self.mesh, point)),
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
    fn noise_reads_the_rest_position_on_a_mesh_without_uvs() {
        let mesh = tetrahedron();
        let map = Map::parse("noise:frequency=3,octaves=2").unwrap();
        let bound = map.on_mesh(&mesh).unwrap();
        let point = SurfacePoint::new(1, [0.2, 0.3]);
        let Map::Noise(noise) = &map else { panic!() };
        assert_eq!(bound.eval(point), noise.eval3(point.position(&mesh)));
        // Object space varies over the surface; the values are not all alike.
        let values: Vec<f32> = (0..4)
            .map(|t| bound.eval(SurfacePoint::new(t, [0.3, 0.3])))
            .collect();
        assert!(values.windows(2).any(|w| w[0] != w[1]), "{values:?}");
        // space=uv asks for UVs.
        let err = Map::parse("noise:space=uv")
            .unwrap()
            .on_mesh(&mesh)
            .unwrap_err();
        assert!(err.to_string().contains("\"vertex:NAME\""), "{err}");
    }

    #[test]
    fn a_product_multiplies_point_by_point_and_binds_both_factors() {
        let mesh = unit_square()
            .with_vertex_attribute("scale", vec![0.0, 1.0, 2.0, 3.0])
            .unwrap();
        let noise = Map::parse("noise:frequency=3,offset=1,scale=0.5").unwrap();
        let scale = Map::parse("vertex:scale").unwrap();
        // Times the constant 1 is the map itself.
        assert_eq!(Map::product(noise.clone(), Map::Constant(1.0)), noise);
        assert_eq!(Map::product(Map::Constant(1.0), scale.clone()), scale);
        let product = Map::product(noise.clone(), scale.clone());
        let bound = product.on_mesh(&mesh).unwrap();
        let (noise, scale) = (noise.on_mesh(&mesh).unwrap(), scale.on_mesh(&mesh).unwrap());
        for bary in [[0.1, 0.2], [0.6, 0.3], [0.0, 1.0]] {
            let p = SurfacePoint::new(0, bary);
            assert_eq!(bound.eval(p), noise.eval(p) * scale.eval(p));
        }
        // The sampler subdivides for the finer factor, and follows the
        // layer's gradient inside triangles.
        assert_eq!(
            product.resolution(),
            Map::parse("noise:frequency=3").unwrap().resolution()
        );
        assert!(product.varies_within_triangles());
        let mut bound_product = product.clone();
        bound_product.bind(&mesh).unwrap();
        assert_eq!(bound_product.upper_bound(), 1.5 * 3.0);
        // A factor the mesh cannot serve is named.
        let missing = Map::product(Map::Constant(2.0), Map::parse("vertex:red").unwrap());
        assert!(
            missing
                .on_mesh(&mesh)
                .unwrap_err()
                .to_string()
                .contains("'red'")
        );
    }

    #[test]
    fn vertex_maps_interpolate_the_corners_and_name_missing_attributes() {
        let mesh = unit_square()
            .with_vertex_attribute("density", vec![0.0, 1.0, 2.0, 3.0])
            .unwrap();
        let mut map = Map::parse("vertex:density").unwrap();
        map.bind(&mesh).unwrap();
        // Triangle 0 is vertices 0, 1, 2: bary [0.25, 0.5] weighs them 0.25, 0.25, 0.5.
        let site = MapSite::on(&mesh, SurfacePoint::new(0, [0.25, 0.5]));
        assert!((map.at(&site) - (0.25 + 1.0)).abs() < 1e-6);
        assert_eq!(map.upper_bound(), 3.0);
        let err = Map::parse("vertex:red")
            .unwrap()
            .bind(&mesh)
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "square: the mesh has no vertex attribute 'red'; it has density"
        );
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
