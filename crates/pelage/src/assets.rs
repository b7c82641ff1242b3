//! Assets compiled into the library, so every command has something to work
//! on with no files at hand: Keenan Crane's "Spot" (public domain) and the
//! Khronos Fox, skinned and animated (CC0 mesh, CC BY 4.0 rig: see
//! `assets/README.md` and `assets/fox/LICENSE.md`).

use crate::map::{Channel, ImageMap, Wrap};
use crate::mesh::{Mesh, MeshFormat};

/// What errors and reports call the embedded mesh.
pub const SPOT_NAME: &str = "embedded spot";

/// Spot as OBJ text: 5,856 triangles, 2,930 vertices, per-corner UVs.
pub const SPOT_OBJ: &[u8] = include_bytes!("../assets/spot_triangulated.obj");

/// Spot's colour texture (PNG, 1024×1024).
pub const SPOT_TEXTURE_PNG: &[u8] = include_bytes!("../assets/spot_texture.png");

/// The Khronos Fox as a self-contained glTF: 576 triangles, a skin, and
/// the animations Survey, Walk and Run.
pub const FOX_GLTF: &[u8] = include_bytes!("../assets/fox/Fox.gltf");

/// The Fox's colour texture (PNG, 1024×1024), as its glTF embeds it.
pub const FOX_TEXTURE_PNG: &[u8] = include_bytes!("../assets/fox/fox.png");

/// The Fox's licences and credits (its rig and animations are CC BY 4.0:
/// ship this beside any copy).
pub const FOX_LICENSE: &str = include_str!("../assets/fox/LICENSE.md");

/// The embedded Spot mesh.
pub fn spot() -> Mesh {
    Mesh::from_bytes(SPOT_NAME, SPOT_OBJ, MeshFormat::Obj).expect("the embedded Spot mesh is valid")
}

/// One channel of Spot's colour texture as a map.
pub fn spot_texture(channel: Channel) -> ImageMap {
    ImageMap::from_bytes(
        "embedded spot texture",
        SPOT_TEXTURE_PNG,
        channel,
        Wrap::Repeat,
    )
    .expect("the embedded Spot texture is a valid PNG")
}

#[cfg(test)]
mod tests {
    #[test]
    fn embedded_spot_matches_its_description() {
        let spot = super::spot();
        assert_eq!((spot.triangle_count(), spot.vertex_count()), (5856, 2930));
        assert!(spot.has_uvs());
        let r = spot.topology_report();
        assert_eq!((r.boundary_edges, r.non_manifold_edges), (0, 0));
        assert_eq!(spot.degenerate_triangle_count(), 0);
    }
}
