//! Regions of the skin: parts of the surface that share no guides and no
//! clumps, so hair on one side of a parting never takes its shape from
//! the other side (the groomer's parting line, a mane against the neck, a
//! tail against the legs). Regions come from a map (an image channel, a
//! per-vertex scalar: its value times `scale`, rounded, is the region id)
//! or from the mesh's named face sets (OBJ `g`/`usemtl`).
//!
//! A hair's region is read at its root; a guide's and a clump centre's
//! at theirs. Interpolation then uses only the guides of the hair's
//! region ([`crate::interp::RegionWeights`]), and clumps only its centres.

use super::error::GroomErrorKind;
use crate::map::{Map, MapSite};
use crate::mesh::{Mesh, SurfacePoint};

/// Region ids run from 0 to this, inclusive: map values are clamped to it.
pub const MAX_REGION: u32 = 1023;

/// Where regions come from.
#[derive(Debug, Clone)]
pub enum RegionSource {
    /// Region id `round(value · scale)` of a map, clamped to
    /// 0..=[`MAX_REGION`].
    Map {
        /// The map.
        map: Map,
        /// Multiplies the value before rounding.
        scale: f32,
    },
    /// The mesh's face sets of this kind (`"groups"`, `"materials"`):
    /// each set a region, numbered in order of first appearance.
    Faces(String),
}

/// `[regions]`: how the skin is split.
#[derive(Debug, Clone)]
pub struct RegionsSpec {
    /// Where the regions come from.
    pub source: RegionSource,
}

impl RegionsSpec {
    /// Regions from a map's values (`scale` 1: painted 0 and 1, or ids in
    /// an EXR or a vertex attribute).
    pub fn from_map(map: Map, scale: f32) -> Self {
        Self {
            source: RegionSource::Map { map, scale },
        }
    }

    /// Regions from the mesh's face sets of `kind`.
    pub fn from_faces(kind: impl Into<String>) -> Self {
        Self {
            source: RegionSource::Faces(kind.into()),
        }
    }

    /// The maps the regions read, to bind to a mesh.
    pub fn maps_mut(&mut self) -> Vec<&mut Map> {
        match &mut self.source {
            RegionSource::Map { map, .. } => vec![map],
            RegionSource::Faces(_) => Vec::new(),
        }
    }

    /// The regions ready for lookups on `mesh` (the spec's maps bound to
    /// it). Fails ([`GroomErrorKind::Missing`]) when the mesh has no face
    /// sets of the kind asked for.
    pub fn lookup(&self, mesh: &Mesh) -> Result<RegionLookup, GroomErrorKind> {
        Ok(match &self.source {
            RegionSource::Map { map, scale } => RegionLookup::Map {
                map: map.clone(),
                scale: *scale,
            },
            RegionSource::Faces(kind) => {
                let groups = mesh.face_groups(kind).ok_or_else(|| {
                    let kinds = mesh.face_group_kinds();
                    GroomErrorKind::Missing(if kinds.is_empty() {
                        format!(
                            "the mesh has no face sets ('{kind}'): OBJ files name them with g (groups) and usemtl (materials), Blender's are its Sculpt mode face sets and material slots; or use a region map"
                        )
                    } else {
                        format!(
                            "the mesh has no face sets of kind '{kind}'; it has {}",
                            kinds.join(", ")
                        )
                    })
                })?;
                RegionLookup::Faces {
                    of_triangle: groups.of_triangle.clone(),
                    names: groups.names.clone(),
                }
            }
        })
    }
}

/// Regions ready to answer "which region is this point in".
#[derive(Debug, Clone)]
pub enum RegionLookup {
    /// From a map's values.
    Map {
        /// The map, bound to the mesh.
        map: Map,
        /// Multiplies the value before rounding.
        scale: f32,
    },
    /// From face sets.
    Faces {
        /// Each triangle's set.
        of_triangle: Vec<u32>,
        /// The sets' names.
        names: Vec<String>,
    },
}

impl RegionLookup {
    /// The region of a point of the mesh, with its map site at hand.
    #[inline]
    pub fn at(&self, point: SurfacePoint, site: &MapSite) -> u32 {
        match self {
            RegionLookup::Map { map, scale } => {
                let id = (map.at(site) * scale).round();
                if id.is_nan() {
                    0
                } else {
                    id.clamp(0.0, MAX_REGION as f32) as u32
                }
            }
            RegionLookup::Faces { of_triangle, .. } => of_triangle[point.tri as usize],
        }
    }

    /// The region of a point of `mesh`.
    pub fn of(&self, mesh: &Mesh, point: SurfacePoint) -> u32 {
        self.at(point, &MapSite::on(mesh, point))
    }

    /// What reports call region `id`: its face set's name, or its number.
    pub fn name(&self, id: u32) -> String {
        match self {
            RegionLookup::Faces { names, .. } => names
                .get(id as usize)
                .cloned()
                .unwrap_or_else(|| id.to_string()),
            RegionLookup::Map { .. } => id.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tests::unit_square;

    #[test]
    fn map_regions_round_and_clamp_and_face_regions_read_the_triangle() {
        let mesh = unit_square();
        // Left half 0, right half 1, by a 2×1 image read at UV = xy.
        let image =
            crate::map::ImageMap::from_texels(2, 1, vec![0.0, 1.0], crate::map::Wrap::Clamp)
                .unwrap()
                .with_filter(crate::map::Filter::Nearest);
        let lookup = RegionsSpec::from_map(Map::Image(image), 1.0)
            .lookup(&mesh)
            .unwrap();
        // Triangle 0 is (0,0),(1,0),(1,1): bary [0.75, 0.2] is x 0.95.
        assert_eq!(lookup.of(&mesh, SurfacePoint::new(0, [0.75, 0.2])), 1);
        assert_eq!(lookup.of(&mesh, SurfacePoint::new(1, [0.1, 0.8])), 0);
        let big = RegionsSpec::from_map(Map::Constant(5000.0), 1.0)
            .lookup(&mesh)
            .unwrap();
        assert_eq!(big.of(&mesh, SurfacePoint::new(0, [0.3, 0.3])), MAX_REGION);
        let err = RegionsSpec::from_faces("groups").lookup(&mesh).unwrap_err();
        assert!(matches!(err, GroomErrorKind::Missing(_)), "{err}");
        assert!(err.to_string().contains("no face sets"), "{err}");
        let grouped = mesh
            .with_face_groups(crate::mesh::FaceGroups {
                kind: "groups".into(),
                names: vec!["left".into(), "right".into()],
                of_triangle: vec![1, 0],
            })
            .unwrap();
        let faces = RegionsSpec::from_faces("groups").lookup(&grouped).unwrap();
        assert_eq!(faces.of(&grouped, SurfacePoint::new(0, [0.3, 0.3])), 1);
        assert_eq!(faces.name(1), "right");
    }
}
