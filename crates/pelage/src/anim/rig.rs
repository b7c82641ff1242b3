//! Linear-blend skinning (glTF 2.0 §3.7.3) as one small value:
//! [`SkinRig`], each vertex's rest position and up to four weighted
//! entries of a *palette* of matrices, and [`SkinRig::pose`], which blends
//! them. The palette of a glTF animation at a time comes from
//! `GltfAnimation::palette_at`; pelage's CPU posing (grooms on animated
//! skins) and the GPU's skinning pass (`pelage-gpu`'s `skin.wgsl`, shell
//! fur on game characters) both run this function, the GPU's a line-by-line
//! copy, so the CPU result is the GPU's reference.
//!
//! A vertex is `v' = (Σ wᵢ · P[jᵢ]) · v`: the weighted matrices are summed
//! first and the sum applied once, in that order on both sides. Normals
//! and tangents take the blended matrix's linear part and are normalised
//! again (exact for rotations and uniform scales, which is what rigs use).

use crate::Mesh;
use glam::{Mat4, Vec3};

/// Up to four palette entries and their weights (summing to 1) for one
/// vertex; unused slots have weight 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Influence {
    /// Palette indices.
    pub joints: [u32; 4],
    /// Weights, summing to 1.
    pub weights: [f32; 4],
}

impl Influence {
    /// Follows palette entry `joint` alone.
    pub fn rigid(joint: u32) -> Self {
        Self {
            joints: [joint, 0, 0, 0],
            weights: [1.0, 0.0, 0.0, 0.0],
        }
    }

    /// The blend of two influences half and half, as a midpoint of their
    /// vertices takes it: the union of their joints, the four heaviest kept
    /// and their weights scaled back to a sum of 1.
    pub fn midpoint(a: &Self, b: &Self) -> Self {
        let mut merged: Vec<(u32, f32)> = Vec::with_capacity(8);
        for (j, w) in a
            .joints
            .iter()
            .zip(a.weights)
            .chain(b.joints.iter().zip(b.weights))
        {
            if w == 0.0 {
                continue;
            }
            match merged.iter_mut().find(|(k, _)| k == j) {
                Some((_, sum)) => *sum += 0.5 * w,
                None => merged.push((*j, 0.5 * w)),
            }
        }
        // Heaviest first; ties by joint so the result does not depend on
        // the order of a and b.
        merged.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
        merged.truncate(4);
        let total: f32 = merged.iter().map(|m| m.1).sum();
        let mut out = Self {
            joints: [0; 4],
            weights: [0.0; 4],
        };
        for (k, (j, w)) in merged.into_iter().enumerate() {
            out.joints[k] = j;
            out.weights[k] = w / total;
        }
        out
    }
}

/// Each vertex's rest position (in the space the palette maps from) and
/// its influences.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinRig {
    rest: Vec<Vec3>,
    influences: Vec<Influence>,
    palette_len: usize,
}

/// A posed skin: positions, and normals and tangents carried by the same
/// matrices.
#[derive(Debug, Clone, PartialEq)]
pub struct PosedFrames {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit normals.
    pub normals: Vec<Vec3>,
    /// Unit tangents.
    pub tangents: Vec<Vec3>,
}

impl SkinRig {
    /// A rig of `rest` positions moved by `influences` (one each) over a
    /// palette of `palette_len` matrices. Panics if the counts differ or a
    /// joint is outside the palette: rigs are built by pelage's readers,
    /// which check the file.
    pub fn new(rest: Vec<Vec3>, influences: Vec<Influence>, palette_len: usize) -> Self {
        assert_eq!(rest.len(), influences.len(), "one influence a vertex");
        assert!(
            influences
                .iter()
                .all(|i| i.joints.iter().all(|&j| (j as usize) < palette_len)),
            "a joint outside the palette"
        );
        Self {
            rest,
            influences,
            palette_len,
        }
    }

    /// Vertices.
    pub fn vertex_count(&self) -> usize {
        self.rest.len()
    }

    /// How many matrices a palette for this rig has.
    pub fn palette_len(&self) -> usize {
        self.palette_len
    }

    /// Rest positions, in the space the palette maps from.
    pub fn rest_positions(&self) -> &[Vec3] {
        &self.rest
    }

    /// Each vertex's influences.
    pub fn influences(&self) -> &[Influence] {
        &self.influences
    }

    /// Vertex `i`'s blended matrix `Σ wᵢ · P[jᵢ]` (slots of weight 0 are
    /// skipped, so an unused slot's joint never matters).
    pub fn blend(&self, palette: &[Mat4], i: usize) -> Mat4 {
        let influence = &self.influences[i];
        let mut blended = Mat4::ZERO;
        for (j, &w) in influence.joints.iter().zip(&influence.weights) {
            if w != 0.0 {
                blended += palette[*j as usize] * w;
            }
        }
        blended
    }

    /// Every vertex posed by `palette` (of [`Self::palette_len`] matrices).
    pub fn pose(&self, palette: &[Mat4]) -> Vec<Vec3> {
        assert_eq!(
            palette.len(),
            self.palette_len,
            "a palette of the rig's size"
        );
        (0..self.rest.len())
            .map(|i| self.blend(palette, i).transform_point3(self.rest[i]))
            .collect()
    }

    /// Positions, and `normals` and `tangents` (rest directions, one a
    /// vertex; `tangents` may be empty, then none are posed) carried by
    /// each vertex's blended matrix and normalised.
    pub fn pose_frames(
        &self,
        palette: &[Mat4],
        normals: &[Vec3],
        tangents: &[Vec3],
    ) -> PosedFrames {
        assert_eq!(
            palette.len(),
            self.palette_len,
            "a palette of the rig's size"
        );
        let n = self.rest.len();
        assert_eq!(normals.len(), n, "one normal a vertex");
        let mut out = PosedFrames {
            positions: Vec::with_capacity(n),
            normals: Vec::with_capacity(n),
            tangents: Vec::with_capacity(n),
        };
        for (i, (&rest, &normal)) in self.rest.iter().zip(normals).enumerate() {
            let m = self.blend(palette, i);
            out.positions.push(m.transform_point3(rest));
            out.normals
                .push(m.transform_vector3(normal).normalize_or(normal));
            if let Some(&t) = tangents.get(i) {
                out.tangents.push(m.transform_vector3(t).normalize_or(t));
            }
        }
        out
    }

    /// The rig of `mesh` (whose vertices are this rig's, in order)
    /// subdivided `levels` times as [`Mesh::subdivided`] does it: a
    /// midpoint vertex rests at its edge's middle and takes
    /// [`Influence::midpoint`] of its ends.
    pub fn subdivided(&self, mesh: &Mesh, levels: u32) -> Self {
        assert_eq!(mesh.vertex_count(), self.rest.len(), "the rig's mesh");
        let mut rig = self.clone();
        let mut level_mesh = Mesh::new(
            mesh.name(),
            self.rest.clone(),
            mesh.triangles().to_vec(),
            None,
            None,
        )
        .expect("the rig's mesh is valid");
        for _ in 0..levels {
            let edges = level_mesh.edges();
            for &[a, b] in &edges.edges {
                let (a, b) = (a as usize, b as usize);
                rig.rest.push(0.5 * (rig.rest[a] + rig.rest[b]));
                rig.influences
                    .push(Influence::midpoint(&rig.influences[a], &rig.influences[b]));
            }
            level_mesh = level_mesh.subdivided(1);
        }
        rig
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn a_vertex_between_two_joints_is_the_blend_of_their_moves() {
        let rig = SkinRig::new(
            vec![Vec3::new(1.0, 0.0, 0.0)],
            vec![Influence {
                joints: [0, 1, 0, 0],
                weights: [0.25, 0.75, 0.0, 0.0],
            }],
            2,
        );
        let palette = [
            Mat4::from_translation(Vec3::new(0.0, 4.0, 0.0)),
            Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2),
        ];
        let p = rig.pose(&palette)[0];
        // 0.25 · (1, 4, 0) + 0.75 · (0, 1, 0)
        assert!((p - Vec3::new(0.25, 1.75, 0.0)).length() < 1e-6, "{p}");
    }

    #[test]
    fn normals_turn_with_their_joint() {
        let rig = SkinRig::new(vec![Vec3::ZERO], vec![Influence::rigid(0)], 1);
        let palette = [Mat4::from_scale_rotation_translation(
            Vec3::splat(3.0),
            Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            Vec3::ONE,
        )];
        let frames = rig.pose_frames(&palette, &[Vec3::X], &[Vec3::Y]);
        assert!((frames.normals[0] - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        assert!((frames.tangents[0] - Vec3::Y).length() < 1e-6);
        assert_eq!(frames.positions[0], Vec3::ONE);
    }

    #[test]
    fn midpoints_keep_the_four_heaviest_joints_and_sum_to_one() {
        let a = Influence {
            joints: [1, 2, 3, 4],
            weights: [0.4, 0.3, 0.2, 0.1],
        };
        let b = Influence {
            joints: [1, 5, 6, 7],
            weights: [0.5, 0.25, 0.15, 0.1],
        };
        let m = Influence::midpoint(&a, &b);
        assert_eq!(m.joints[0], 1);
        assert!((m.weights.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        assert_eq!(m, Influence::midpoint(&b, &a));
        // A rigid pair stays rigid.
        let r = Influence::midpoint(&Influence::rigid(3), &Influence::rigid(3));
        assert_eq!(r, Influence::rigid(3));
    }

    #[test]
    fn a_subdivided_rig_poses_the_subdivided_rest_mesh_under_one_joint() {
        let mesh = Mesh::new(
            "tri",
            vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            vec![[0, 1, 2]],
            None,
            None,
        )
        .unwrap();
        let rig = SkinRig::new(mesh.positions().to_vec(), vec![Influence::rigid(0); 3], 1);
        let fine = rig.subdivided(&mesh, 2);
        let m = Mat4::from_rotation_x(0.7) * Mat4::from_translation(Vec3::Z);
        let posed = fine.pose(&[m]);
        let expected: Vec<Vec3> = mesh
            .subdivided(2)
            .positions()
            .iter()
            .map(|&p| m.transform_point3(p))
            .collect();
        assert_eq!(posed.len(), expected.len());
        for (p, q) in posed.iter().zip(&expected) {
            assert!(p.distance(*q) < 1e-6);
        }
    }
}
