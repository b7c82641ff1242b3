//! A mesh prepared for the shell renderer, on the CPU and without wgpu:
//! triangle corners welded into indexed vertices ([`WeldedCorners`]),
//! per-vertex tangents ([`vertex_tangents`]) and the shell texture's mip
//! chain. The uploads of `upload.rs` and the fins of `fins.rs` read these.

use super::{PoseVertex, SurfaceVertex};
use glam::Vec3;
use pelage::Mesh;
use pelage::anim::SkinRig;
use pelage::shell::ShellTextures;

/// Per-vertex `dP/du` (the texture's x direction on the surface), averaged
/// over the triangles around each vertex and made perpendicular to its
/// normal, so neighbouring triangles curl the same way and layers do not
/// tear. Vertices where UVs give no direction get any tangent.
pub fn vertex_tangents(mesh: &Mesh) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; mesh.vertex_count()];
    for t in 0..mesh.triangle_count() {
        let Some([t0, t1, t2]) = mesh.triangle_uvs(t) else {
            break;
        };
        let [p0, p1, p2] = mesh.triangle_positions(t);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let (d1, d2) = (t1 - t0, t2 - t0);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() <= f32::EPSILON {
            continue;
        }
        // Area-weighted: the cross product's length is twice the area.
        let dp_du = ((e1 * d2.y - e2 * d1.y) / det).normalize_or_zero() * e1.cross(e2).length();
        for &v in &mesh.triangles()[t] {
            sum[v as usize] += dp_du;
        }
    }
    sum.iter()
        .zip(mesh.normals())
        .map(|(&s, &n)| {
            (s - n * n.dot(s))
                .try_normalize()
                .unwrap_or_else(|| n.any_orthonormal_vector())
        })
        .collect()
}

/// A mesh's triangle corners welded into indexed vertices.
#[derive(Debug)]
pub(super) struct WeldedCorners {
    /// Per vertex: the mesh vertex, its UV and a corner `3t + k` it
    /// stands for.
    pub(super) mesh_vertices: Vec<u32>,
    pub(super) uvs: Vec<glam::Vec2>,
    pub(super) corners: Vec<u32>,
    /// Three per triangle.
    pub(super) indices: Vec<u32>,
}

impl WeldedCorners {
    /// Corners that share a mesh vertex and a UV become one vertex (all of
    /// them, on a mesh with UVs per vertex); `per_corner` keeps every
    /// corner its own.
    pub(super) fn new(mesh: &Mesh, per_corner: bool) -> Self {
        let corners = mesh.triangle_count() * 3;
        let mut out = Self {
            mesh_vertices: Vec::new(),
            uvs: Vec::new(),
            corners: Vec::new(),
            indices: Vec::with_capacity(corners),
        };
        let mut index: std::collections::HashMap<(u32, [u32; 2]), u32> =
            std::collections::HashMap::with_capacity(if per_corner { 0 } else { corners / 2 });
        for t in 0..mesh.triangle_count() {
            let uvs = mesh.triangle_uvs(t).expect("checked: the mesh has UVs");
            for (k, &v) in mesh.triangles()[t].iter().enumerate() {
                let corner = (3 * t + k) as u32;
                let add = |out: &mut Self| {
                    out.mesh_vertices.push(v);
                    out.uvs.push(uvs[k]);
                    out.corners.push(corner);
                    out.mesh_vertices.len() as u32 - 1
                };
                let i = if per_corner {
                    add(&mut out)
                } else {
                    let key = (v, uvs[k].to_array().map(f32::to_bits));
                    match index.get(&key) {
                        Some(&i) => i,
                        None => {
                            let i = add(&mut out);
                            index.insert(key, i);
                            i
                        }
                    }
                };
                out.indices.push(i);
            }
        }
        out
    }
}

impl WeldedCorners {
    /// Each vertex's rest position, normal and tangent (the strand frame
    /// the shells stand on).
    pub(super) fn pose_vertices(&self, mesh: &Mesh) -> Vec<PoseVertex> {
        let tangents = vertex_tangents(mesh);
        self.mesh_vertices
            .iter()
            .map(|&v| PoseVertex {
                position: mesh.positions()[v as usize].to_array(),
                normal: mesh.normals()[v as usize].to_array(),
                tangent: tangents[v as usize].to_array(),
            })
            .collect()
    }

    /// Each vertex's UV as the wetness mask reads it.
    pub(super) fn surface_vertices(&self) -> Vec<SurfaceVertex> {
        self.uvs
            .iter()
            .map(|&uv| SurfaceVertex {
                uv: pelage::shell::wetness::mask_coordinates(uv).to_array(),
            })
            .collect()
    }

    /// Each vertex's four joints and their weights (as bits), as the
    /// skinning pass reads them.
    pub(super) fn skin_influences(&self, rig: &SkinRig) -> Vec<[u32; 8]> {
        self.mesh_vertices
            .iter()
            .map(|&v| {
                let i = rig.influences()[v as usize];
                let w = i.weights.map(f32::to_bits);
                [
                    i.joints[0],
                    i.joints[1],
                    i.joints[2],
                    i.joints[3],
                    w[0],
                    w[1],
                    w[2],
                    w[3],
                ]
            })
            .collect()
    }
}

/// The shell texture's layers with a mip chain, layer by layer, each
/// layer's levels in turn (wgpu's layer-major order): each
/// level a box filter of the one above, colour weighted by alpha (a
/// transparent texel's direction must not leak into its neighbours).
pub(super) fn fur_mip_chain(textures: &ShellTextures) -> (Vec<u8>, u32) {
    let r = textures.resolution() as usize;
    let texels: &[u8] = bytemuck::cast_slice(textures.texels());
    // Halving to one texel: a texture that is not a power of two gets
    // wgpu's sizes, max(1, r >> level).
    let levels = usize::BITS - r.leading_zeros();
    let mut data = Vec::with_capacity(texels.len() * 4 / 3 + 4 * textures.layers() as usize);
    for layer in texels.chunks_exact(r * r * 4) {
        data.extend_from_slice(layer);
        let mut above = layer.to_vec();
        let mut size = r;
        while size > 1 {
            let half = size / 2;
            let mut next = vec![0u8; half * half * 4];
            for y in 0..half {
                for x in 0..half {
                    let mut rgb = [0.0f32; 3];
                    let mut alpha = 0.0f32;
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let i = ((2 * y + dy) * size + 2 * x + dx) * 4;
                        let a = f32::from(above[i + 3]);
                        for c in 0..3 {
                            rgb[c] += a * f32::from(above[i + c]);
                        }
                        alpha += a;
                    }
                    let o = (y * half + x) * 4;
                    for c in 0..3 {
                        next[o + c] = if alpha > 0.0 {
                            (rgb[c] / alpha).round() as u8
                        } else {
                            128
                        };
                    }
                    next[o + 3] = (alpha / 4.0).round() as u8;
                }
            }
            data.extend_from_slice(&next);
            above = next;
            size = half;
        }
    }
    (data, levels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;
    use pelage::mesh::Uvs;

    /// Two triangles over a square sharing the diagonal 0–2; vertex 2's
    /// UV differs between them when `seam` (a UV seam along the diagonal's
    /// end).
    fn square(seam: bool) -> Mesh {
        let values = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(0.5, 0.5),
        ];
        let second = if seam { [0, 4, 3] } else { [0, 2, 3] };
        Mesh::new(
            "square",
            vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            vec![[0, 1, 2], [0, 2, 3]],
            None,
            Some(Uvs::PerCorner {
                values,
                indices: vec![[0, 1, 2], second],
            }),
        )
        .unwrap()
    }

    #[test]
    fn corners_weld_where_vertex_and_uv_agree_and_a_seam_keeps_two() {
        let welded = WeldedCorners::new(&square(false), false);
        assert_eq!(welded.mesh_vertices.len(), 4);
        assert_eq!(welded.indices, vec![0, 1, 2, 0, 2, 3]);
        let seam = WeldedCorners::new(&square(true), false);
        assert_eq!(seam.mesh_vertices.len(), 5);
        assert_eq!(
            seam.mesh_vertices[3], 2,
            "vertex 2 again, with its other UV"
        );
        assert_eq!(seam.uvs[3], Vec2::new(0.5, 0.5));
        assert_eq!(seam.indices, vec![0, 1, 2, 0, 3, 4]);
        let corners = WeldedCorners::new(&square(false), true);
        assert_eq!(corners.mesh_vertices.len(), 6);
        // Every vertex stands for a corner of its own mesh vertex.
        for (i, &c) in seam.corners.iter().enumerate() {
            let (t, k) = (c as usize / 3, c as usize % 3);
            assert_eq!(square(true).triangles()[t][k], seam.mesh_vertices[i]);
        }
    }

    #[test]
    fn the_mip_chain_halves_to_one_texel_and_keeps_coverage() {
        let textures = ShellTextures::generate(&pelage::shell::ShellTextureParams {
            resolution: 16,
            layers: 2,
            ..Default::default()
        });
        let (data, levels) = fur_mip_chain(&textures);
        assert_eq!(levels, 5, "16, 8, 4, 2, 1");
        let per_layer: usize = [16, 8, 4, 2, 1].iter().map(|s| s * s * 4).sum();
        assert_eq!(data.len(), 2 * per_layer);
        // The last level of layer 0 is the mean alpha of its 256 texels.
        let texels: &[u8] = bytemuck::cast_slice(textures.texels());
        let mean: f32 = texels[..16 * 16 * 4]
            .chunks(4)
            .map(|t| f32::from(t[3]))
            .sum::<f32>()
            / 256.0;
        let last = data[per_layer - 1];
        assert!((f32::from(last) - mean).abs() <= 2.0, "{last} vs {mean}");
    }
}
