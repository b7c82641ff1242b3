//! The surface hair grows on: [`Mesh`], points on it ([`SurfacePoint`]),
//! loaders, topology queries and midpoint subdivision.
//!
//! A mesh is an indexed triangle list with f32 positions, per-vertex normals
//! (read, or computed area-weighted) and optional UVs (per vertex, or per
//! corner with their own index buffer, as OBJ stores them). It is immutable
//! once built, so derived data (triangle areas at construction, the edge list
//! on first use, the edge graph) is cached without invalidation.
//!
//! A mesh may also carry named per-vertex scalars ([`VertexAttribute`]:
//! PLY properties, OBJ vertex colours), which per-vertex maps read, and
//! named sets of faces ([`FaceGroups`]: OBJ `g` and `usemtl`), which
//! groom regions read.
//!
//! Degenerate triangles (a repeated vertex index, or an area that is zero
//! relative to the triangle's size) are kept so indices stay as in the file,
//! counted in [`Mesh::degenerate_triangle_count`], and given an area of
//! exactly zero, so every area-weighted sampler gives them zero probability.

mod closest;
mod error;
pub(crate) mod gltf;

/// The base colour texture of a glTF or GLB file's first textured
/// material, decoded (`None` for other formats, or a glTF without one):
/// what fur takes its colour from when a groom gives none.
pub fn base_color_texture(
    path: &std::path::Path,
) -> Result<Option<image::DynamicImage>, MeshError> {
    let name = path.display().to_string();
    let is_gltf = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"));
    if !is_gltf {
        return Ok(None);
    }
    let bytes = std::fs::read(path).map_err(|e| MeshError::whole(&name, MeshErrorKind::Io(e)))?;
    gltf::base_color_image(
        &name,
        &bytes,
        path.parent().unwrap_or(std::path::Path::new(".")),
    )
}
mod graph;
pub(crate) mod obj;
pub(crate) mod ply;
mod ray;
mod subdivide;
mod surface_point;
mod topology;

pub use closest::{ClosestPoint, TriangleBvh, closest_on_triangle};
pub use error::{MeshError, MeshErrorKind};
pub use graph::EdgeGraph;
pub(crate) use graph::morton;
pub(crate) use ply::scalar as ply_scalar;
pub use ray::{RayHit, first_hit};
pub use surface_point::{SurfacePoint, TangentFrame};
pub use topology::{EdgeList, TopologyReport, VertexAdjacency};

use glam::{Vec2, Vec3};
use std::sync::{Arc, OnceLock};

/// The mesh file formats pelage reads ([`Mesh::load`] and
/// [`Mesh::from_bytes`], written in `io/mesh_file.rs`, beside the USD
/// reader they need).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ.
    Obj,
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`).
    Gltf,
    /// USD, text or binary (`.usda`, `.usdc`, `.usd`): every `Mesh` prim,
    /// at its first time sample.
    Usd,
}

impl MeshFormat {
    /// The format a file name's extension names (case-insensitive).
    pub fn from_path(path: &std::path::Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Self::Obj),
            "ply" => Some(Self::Ply),
            "gltf" | "glb" => Some(Self::Gltf),
            "usda" | "usdc" | "usd" => Some(Self::Usd),
            _ => None,
        }
    }
}

/// A named scalar per vertex: a PLY vertex property other than position,
/// normal and UV (`red`, `green`, `blue` and `alpha` scaled to 0–1 when
/// stored as integers), or an OBJ vertex colour (`v x y z r g b`:
/// `red`, `green`, `blue`). Per-vertex maps (`vertex:NAME`) read it,
/// interpolated barycentrically.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexAttribute {
    /// The name maps refer to it by.
    pub name: String,
    /// One value a vertex.
    pub values: Arc<[f32]>,
}

/// Named sets of triangles of one kind: OBJ groups (`g`, or `o` in a
/// file without `g`) or OBJ materials (`usemtl`). Each triangle is in
/// exactly one set; triangles before the first statement are in a set
/// named `default`.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceGroups {
    /// `"groups"` or `"materials"`.
    pub kind: String,
    /// The set names, in order of first appearance.
    pub names: Vec<String>,
    /// For each triangle, the index of its set in `names`.
    pub of_triangle: Vec<u32>,
}

/// Texture coordinates of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub enum Uvs {
    /// One UV per vertex, indexed by the triangles' vertex indices.
    PerVertex(Vec<Vec2>),
    /// UVs with their own per-corner index buffer (one `[u32; 3]` per
    /// triangle), so a vertex on a UV seam can have several UVs.
    PerCorner {
        /// The distinct UV values.
        values: Vec<Vec2>,
        /// For each triangle, the UV index of each corner.
        indices: Vec<[u32; 3]>,
    },
}

/// A triangle mesh. Build one with [`Mesh::new`] (validated) or load one
/// with [`Mesh::load`] / [`Mesh::from_bytes`].
///
/// ```
/// use glam::Vec3;
/// use pelage::Mesh;
///
/// // A unit square from two triangles; normals are computed.
/// let square = Mesh::new(
///     "square",
///     vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
///     vec![[0, 1, 2], [0, 2, 3]],
///     None,
///     None,
/// )?;
/// assert_eq!(square.triangle_count(), 2);
/// assert!((square.surface_area() - 1.0).abs() < 1e-6);
/// // Bad input is an error naming the mesh, never a panic.
/// let err = Mesh::new("bad", vec![Vec3::ZERO], vec![[0, 1, 2]], None, None).unwrap_err();
/// assert!(err.to_string().starts_with("bad"), "{err}");
/// # Ok::<(), pelage::MeshError>(())
/// ```
#[derive(Debug)]
pub struct Mesh {
    name: String,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    normals: Vec<Vec3>,
    uvs: Option<Uvs>,
    areas: Vec<f32>,
    degenerate_count: usize,
    vertex_attributes: Vec<VertexAttribute>,
    face_groups: Vec<FaceGroups>,
    edges: OnceLock<EdgeList>,
    edge_graph: OnceLock<EdgeGraph>,
}

impl Clone for Mesh {
    fn clone(&self) -> Self {
        Self {
            name: self.name.clone(),
            positions: self.positions.clone(),
            triangles: self.triangles.clone(),
            normals: self.normals.clone(),
            uvs: self.uvs.clone(),
            areas: self.areas.clone(),
            degenerate_count: self.degenerate_count,
            vertex_attributes: self.vertex_attributes.clone(),
            face_groups: self.face_groups.clone(),
            edges: OnceLock::new(),
            edge_graph: OnceLock::new(),
        }
    }
}

/// A triangle is degenerate when its doubled area is below this fraction of
/// its longest edge squared: a sliver so thin that f32 cannot tell it from a
/// segment.
const DEGENERATE_RELATIVE_AREA: f32 = 1e-10;

impl Mesh {
    /// Builds a mesh from its parts, validating everything: at least one
    /// vertex and one triangle, finite positions/normals/UVs, indices in
    /// range, buffer sizes that agree. `normals`, when given, must hold one
    /// normal per vertex; when `None` they are computed (area-weighted).
    ///
    /// `name` is what errors and reports call the mesh (usually its path).
    pub fn new(
        name: impl Into<String>,
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Uvs>,
    ) -> Result<Self, MeshError> {
        let name = name.into();
        if positions.is_empty() {
            return Err(MeshError::whole(name, MeshErrorKind::Empty("no vertices")));
        }
        if triangles.is_empty() {
            return Err(MeshError::whole(name, MeshErrorKind::Empty("no triangles")));
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            let kind = MeshErrorKind::NonFinite {
                what: "vertex position",
            };
            return Err(MeshError::at_element(name, "vertex", i, kind));
        }
        check_indices(&name, &triangles, positions.len(), "vertex", "vertices")?;
        if let Some(n) = &normals {
            if n.len() != positions.len() {
                let msg = format!("{} normals for {} vertices", n.len(), positions.len());
                return Err(MeshError::whole(name, MeshErrorKind::Inconsistent(msg)));
            }
            if let Some(i) = n.iter().position(|v| !v.is_finite()) {
                let kind = MeshErrorKind::NonFinite {
                    what: "vertex normal",
                };
                return Err(MeshError::at_element(name, "vertex", i, kind));
            }
        }
        match &uvs {
            None => {}
            Some(Uvs::PerVertex(values)) => {
                if values.len() != positions.len() {
                    let msg = format!("{} UVs for {} vertices", values.len(), positions.len());
                    return Err(MeshError::whole(name, MeshErrorKind::Inconsistent(msg)));
                }
                check_finite_uvs(&name, values)?;
            }
            Some(Uvs::PerCorner { values, indices }) => {
                if indices.len() != triangles.len() {
                    let msg = format!(
                        "{} UV triangles for {} triangles",
                        indices.len(),
                        triangles.len()
                    );
                    return Err(MeshError::whole(name, MeshErrorKind::Inconsistent(msg)));
                }
                check_finite_uvs(&name, values)?;
                check_indices(&name, indices, values.len(), "uv", "uvs")?;
            }
        }

        let (areas, degenerate_count) = triangle_areas(&positions, &triangles);
        let normals = match normals {
            Some(n) => n,
            None => area_weighted_normals(&positions, &triangles),
        };
        Ok(Self {
            name,
            positions,
            triangles,
            normals,
            uvs,
            areas,
            degenerate_count,
            vertex_attributes: Vec::new(),
            face_groups: Vec::new(),
            edges: OnceLock::new(),
            edge_graph: OnceLock::new(),
        })
    }

    /// The mesh with a per-vertex scalar `name` (replacing one of that
    /// name). Fails, naming the mesh, unless there is one finite value a
    /// vertex.
    pub fn with_vertex_attribute(
        mut self,
        name: impl Into<String>,
        values: Vec<f32>,
    ) -> Result<Self, MeshError> {
        let name = name.into();
        if values.len() != self.positions.len() {
            let msg = format!(
                "vertex attribute '{name}' has {} values for {} vertices",
                values.len(),
                self.positions.len()
            );
            return Err(MeshError::whole(
                &self.name,
                MeshErrorKind::Inconsistent(msg),
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            let kind = MeshErrorKind::NonFinite {
                what: "vertex attribute value",
            };
            return Err(MeshError::at_element(&self.name, "vertex", i, kind));
        }
        self.vertex_attributes.retain(|a| a.name != name);
        self.vertex_attributes.push(VertexAttribute {
            name,
            values: values.into(),
        });
        Ok(self)
    }

    /// The per-vertex scalars, in the order they were added.
    pub fn vertex_attributes(&self) -> &[VertexAttribute] {
        &self.vertex_attributes
    }

    /// The per-vertex scalar called `name`, if the mesh has one.
    pub fn vertex_attribute(&self, name: &str) -> Option<&VertexAttribute> {
        self.vertex_attributes.iter().find(|a| a.name == name)
    }

    /// The mesh with named sets of faces (replacing sets of the same
    /// kind). Fails, naming the mesh, unless every triangle is in one of
    /// the sets.
    pub fn with_face_groups(mut self, groups: FaceGroups) -> Result<Self, MeshError> {
        if groups.of_triangle.len() != self.triangles.len() {
            let msg = format!(
                "{} '{}' entries for {} triangles",
                groups.of_triangle.len(),
                groups.kind,
                self.triangles.len()
            );
            return Err(MeshError::whole(
                &self.name,
                MeshErrorKind::Inconsistent(msg),
            ));
        }
        if let Some(t) = groups
            .of_triangle
            .iter()
            .position(|&g| g as usize >= groups.names.len())
        {
            let msg = format!(
                "is in {} set {} of {}",
                groups.kind,
                groups.of_triangle[t],
                groups.names.len()
            );
            return Err(MeshError::at_element(
                &self.name,
                "triangle",
                t,
                MeshErrorKind::Inconsistent(msg),
            ));
        }
        self.face_groups.retain(|g| g.kind != groups.kind);
        self.face_groups.push(groups);
        Ok(self)
    }

    /// The sets of faces of kind `kind` (`"groups"`, `"materials"`), if
    /// the mesh has them.
    pub fn face_groups(&self, kind: &str) -> Option<&FaceGroups> {
        self.face_groups.iter().find(|g| g.kind == kind)
    }

    /// Every kind of face set the mesh has.
    pub fn face_group_kinds(&self) -> Vec<&str> {
        self.face_groups.iter().map(|g| g.kind.as_str()).collect()
    }

    /// What errors and reports call this mesh: its path, or a name such as
    /// `embedded spot`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Triangles as three vertex indices, counter-clockwise seen from outside.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Unit vertex normals (read from the file, or area-weighted).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Texture coordinates, if the mesh has them.
    pub fn uvs(&self) -> Option<&Uvs> {
        self.uvs.as_ref()
    }

    /// Whether the mesh has texture coordinates.
    pub fn has_uvs(&self) -> bool {
        self.uvs.is_some()
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Area of every triangle; exactly 0 for degenerate ones.
    pub fn triangle_areas(&self) -> &[f32] {
        &self.areas
    }

    /// Total surface area, summed in f64.
    pub fn surface_area(&self) -> f64 {
        self.areas.iter().map(|&a| f64::from(a)).sum()
    }

    /// Number of degenerate (zero-area) triangles. They are kept, with zero area.
    pub fn degenerate_triangle_count(&self) -> usize {
        self.degenerate_count
    }

    /// The corner positions of triangle `tri`.
    pub fn triangle_positions(&self, tri: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[tri];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// The corner UVs of triangle `tri`, if the mesh has UVs.
    pub fn triangle_uvs(&self, tri: usize) -> Option<[Vec2; 3]> {
        match self.uvs.as_ref()? {
            Uvs::PerVertex(values) => {
                let [a, b, c] = self.triangles[tri];
                Some([values[a as usize], values[b as usize], values[c as usize]])
            }
            Uvs::PerCorner { values, indices } => {
                let [a, b, c] = indices[tri];
                Some([values[a as usize], values[b as usize], values[c as usize]])
            }
        }
    }

    /// Unit geometric normal of triangle `tri` (zero for degenerate triangles).
    pub fn face_normal(&self, tri: usize) -> Vec3 {
        let [p0, p1, p2] = self.triangle_positions(tri);
        (p1 - p0).cross(p2 - p0).normalize_or_zero()
    }

    /// Axis-aligned bounds `(min, max)` of the vertex positions.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        bounds_of(&self.positions)
    }

    /// The mesh's unique undirected edges with the number of triangles using
    /// each; built on first use and cached.
    pub fn edges(&self) -> &EdgeList {
        self.edges.get_or_init(|| EdgeList::build(&self.triangles))
    }

    /// The mesh as a graph for shortest paths along edges (vertices in a
    /// locality-preserving order, edge lengths); built on first use and
    /// cached, so a style mesh rebuilt for new guides on the same mesh
    /// does not pay for it again.
    pub fn edge_graph(&self) -> &EdgeGraph {
        self.edge_graph
            .get_or_init(|| EdgeGraph::new(&self.positions, self.edges()))
    }
}

fn check_indices(
    name: &str,
    triangles: &[[u32; 3]],
    count: usize,
    what: &'static str,
    what_plural: &'static str,
) -> Result<(), MeshError> {
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= count) {
            let kind = MeshErrorKind::IndexOutOfRange {
                what,
                what_plural,
                index: i64::from(bad),
                count,
                hint: "",
            };
            return Err(MeshError::at_element(name, "triangle", t, kind));
        }
    }
    Ok(())
}

fn check_finite_uvs(name: &str, values: &[Vec2]) -> Result<(), MeshError> {
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        let kind = MeshErrorKind::NonFinite {
            what: "texture coordinate",
        };
        return Err(MeshError::at_element(name, "uv", i, kind));
    }
    Ok(())
}

/// Triangle areas with degenerate triangles set to exactly zero, and how
/// many there were.
fn triangle_areas(positions: &[Vec3], triangles: &[[u32; 3]]) -> (Vec<f32>, usize) {
    let mut degenerate = 0;
    let areas = triangles
        .iter()
        .map(|&[a, b, c]| {
            let (p0, p1, p2) = (
                positions[a as usize],
                positions[b as usize],
                positions[c as usize],
            );
            let doubled = (p1 - p0).cross(p2 - p0).length();
            let longest_sq = (p1 - p0)
                .length_squared()
                .max((p2 - p1).length_squared())
                .max((p0 - p2).length_squared());
            let repeated = a == b || b == c || c == a;
            let too_thin = doubled <= DEGENERATE_RELATIVE_AREA * longest_sq || doubled.is_nan();
            if repeated || too_thin {
                degenerate += 1;
                0.0
            } else {
                0.5 * doubled
            }
        })
        .collect();
    (areas, degenerate)
}

/// Axis-aligned bounds `(min, max)` of `points` (inverted, infinite ones
/// for none): a posed skin's, where there is no [`Mesh`].
pub(crate) fn bounds_of(points: &[Vec3]) -> (Vec3, Vec3) {
    points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// Vertex normals as the normalised sum of the unnormalised face normals of
/// the triangles around each vertex, i.e. weighted by triangle area. A vertex
/// touched by no proper triangle gets +Z so the buffer stays unit length.
pub(crate) fn area_weighted_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for &[a, b, c] in triangles {
        let (p0, p1, p2) = (
            positions[a as usize],
            positions[b as usize],
            positions[c as usize],
        );
        let n = (p1 - p0).cross(p2 - p0);
        for i in [a, b, c] {
            sums[i as usize] += n;
        }
    }
    sums.into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Z))
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A unit square in the z = 0 plane made of two triangles, with UVs
    /// equal to xy.
    pub(crate) fn unit_square() -> Mesh {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let uvs = positions.iter().map(|p| p.truncate()).collect();
        Mesh::new(
            "square",
            positions,
            vec![[0, 1, 2], [0, 2, 3]],
            None,
            Some(Uvs::PerVertex(uvs)),
        )
        .unwrap()
    }

    /// A regular tetrahedron-like closed mesh (4 vertices, 4 triangles).
    pub(crate) fn tetrahedron() -> Mesh {
        let positions = vec![
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ];
        let triangles = vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
        Mesh::new("tetrahedron", positions, triangles, None, None).unwrap()
    }

    #[test]
    fn square_area_and_normals() {
        let m = unit_square();
        assert_eq!(m.triangle_areas(), &[0.5, 0.5]);
        assert!((m.surface_area() - 1.0).abs() < 1e-12);
        assert!(m.normals().iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
        assert_eq!(m.bounds(), (Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)));
    }

    #[test]
    fn tetrahedron_normals_point_outward() {
        let m = tetrahedron();
        for (p, n) in m.positions().iter().zip(m.normals()) {
            assert!(p.normalize().dot(*n) > 0.99, "{p} {n}");
        }
    }

    #[test]
    fn degenerate_triangles_are_kept_with_zero_area() {
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(2.0, 0.0, 0.0), // collinear with 0 and 1
        ];
        let m = Mesh::new(
            "degenerate",
            positions,
            vec![[0, 1, 2], [0, 1, 3], [1, 1, 2]],
            None,
            None,
        )
        .unwrap();
        assert_eq!(m.triangle_count(), 3);
        assert_eq!(m.degenerate_triangle_count(), 2);
        assert_eq!(m.triangle_areas(), &[0.5, 0.0, 0.0]);
    }

    #[test]
    fn out_of_range_index_names_the_triangle() {
        let err = Mesh::new("m", vec![Vec3::ZERO; 3], vec![[0, 1, 3]], None, None).unwrap_err();
        assert_eq!(
            err.to_string(),
            "m: triangle 0: vertex index 3 is out of range: there are 3 vertices"
        );
    }
}
