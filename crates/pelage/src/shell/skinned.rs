//! A shell scene's skinned character: a glTF skin and one of its
//! animations, posed by linear-blend skinning ([`SkinRig`]). The GPU poses
//! the shells from [`ShellAnimation::rig`] and [`ShellAnimation::palette_at`]
//! every frame; the mass-spring fur reads the same pose on the CPU
//! ([`ShellAnimation::posed`]) for its roots' motion.

use crate::Mesh;
use crate::anim::{AnimatedSkin, PosedFrames, SkinOptions, SkinRig};
use crate::mesh::{MeshError, MeshErrorKind};
use glam::{Mat4, Vec3};
use std::path::Path;

/// A skinned mesh playing one animation, looped.
#[derive(Debug)]
pub struct ShellAnimation {
    skin: AnimatedSkin,
    rig: SkinRig,
    rest: Mesh,
    clip: String,
    duration: f32,
}

impl ShellAnimation {
    /// The glTF/GLB at `path` playing `clip` (a name or `#index`),
    /// subdivided `subdivide` times (a midpoint vertex takes the blend of
    /// its edge's weights, [`SkinRig::subdivided`]).
    pub fn load(path: &Path, clip: &str, subdivide: u32) -> Result<Self, MeshError> {
        let name = path.display().to_string();
        let options = SkinOptions {
            clip: Some(clip.to_string()),
            ..Default::default()
        };
        let skin = AnimatedSkin::load(path, &options)?;
        let (Some(rig), Some((clip, duration))) = (skin.rig(), skin.clip()) else {
            return Err(MeshError::whole(
                name,
                MeshErrorKind::Unsupported(
                    "an animation clip is played from a glTF or GLB skin; this file is not one"
                        .into(),
                ),
            ));
        };
        let base = skin.base_mesh_at(rig.rest_positions().to_vec())?;
        let rest = base.subdivided_within_limits(subdivide)?;
        let rig = rig.subdivided(&base, subdivide);
        Ok(Self {
            rig,
            rest,
            clip: clip.to_string(),
            duration: duration as f32,
            skin,
        })
    }

    /// Each vertex's skinning, over [`Self::rest_mesh`]'s vertices.
    pub fn rig(&self) -> &SkinRig {
        &self.rig
    }

    /// The mesh at rest, in the space the palette maps from (the bind
    /// pose), with its UVs and normals.
    pub fn rest_mesh(&self) -> &Mesh {
        &self.rest
    }

    /// The clip's name and length in seconds.
    pub fn clip(&self) -> (&str, f32) {
        (&self.clip, self.duration)
    }

    /// The palette at `seconds` (the clip loops).
    pub fn palette_at(&self, seconds: f32) -> Vec<Mat4> {
        self.skin
            .palette_at_seconds(f64::from(seconds))
            .expect("a glTF skin has a palette")
    }

    /// Positions and normals at `seconds`, as the GPU poses them.
    pub fn posed(&self, seconds: f32) -> PosedFrames {
        self.rig
            .pose_frames(&self.palette_at(seconds), self.rest.normals(), &[])
    }

    /// Bounds of every pose of the clip, sampled 32 times over its length
    /// and grown by a tenth for the poses between the samples.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let samples = 32;
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for k in 0..=samples {
            let palette = self.palette_at(self.duration * k as f32 / samples as f32);
            for p in self.rig.pose(&palette) {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        let margin = 0.1 * (hi - lo);
        (lo - margin, hi + margin)
    }

    /// The whole mesh at `seconds`, its normals those the rig carries
    /// ([`Self::posed`]); an error if the pose is not finite.
    pub fn mesh_at(&self, seconds: f32) -> Result<Mesh, MeshError> {
        let posed = self.posed(seconds);
        Mesh::new(
            self.rest.name(),
            posed.positions,
            self.rest.triangles().to_vec(),
            Some(posed.normals),
            self.rest.uvs().cloned(),
        )
    }
}
