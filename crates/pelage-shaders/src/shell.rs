//! The shell-fur data every GPU host of pelage feeds its pipelines, with
//! no GPU API: the WGSL of the shell math ([`MATH_WGSL`], mirroring
//! `pelage::shell::math` function by function), the strand frame's
//! tangents ([`vertex_tangents`]) and the shell texture's mip chain
//! ([`fur_mip_chain`]). `pelage-gpu` (wgpu) and `pelage-bevy` (Bevy's
//! renderer, another wgpu) build their own pipelines over these, so the
//! two draw the same fur.

use glam::Vec3;
use pelage::Mesh;
use pelage::shell::ShellTextures;

/// The shell math in WGSL (Silva Eq. 1, the couplings, curl Eq. 4, clumps
/// Eq. 5 and Alg. 2, Kajiya-Kay Eq. 6): pure functions without bindings.
/// pelage-gpu puts it before `shells.wgsl`; Bevy imports it as
/// [`MATH_IMPORT_PATH`].
pub const MATH_WGSL: &str = include_str!("wgsl/shell_math.wgsl");

/// The module path a shader composer (Bevy's naga_oil) imports
/// [`MATH_WGSL`] under.
pub const MATH_IMPORT_PATH: &str = "pelage::shell_math";

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

/// The shell texture's layers with a mip chain, layer by layer, each
/// layer's levels in turn (wgpu's layer-major order): each
/// level a box filter of the one above, colour weighted by alpha (a
/// transparent texel's direction must not leak into its neighbours).
pub fn fur_mip_chain(textures: &ShellTextures) -> (Vec<u8>, u32) {
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

    /// The shared math is a module of its own: it parses and validates
    /// without any host's bindings, as Bevy's composer needs.
    #[test]
    fn the_math_validates_alone() {
        let module = naga::front::wgsl::parse_str(MATH_WGSL)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(MATH_WGSL)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .expect("shell_math.wgsl validates");
        for f in [
            "coupled_offset",
            "curl_offset",
            "kajiya_kay_lit",
            "layer_height",
        ] {
            assert!(
                module
                    .functions
                    .iter()
                    .any(|(_, g)| g.name.as_deref() == Some(f)),
                "{f}"
            );
        }
    }
}
