//! Animated skins: a mesh whose vertices move from frame to frame while
//! its triangles stay the same. Read from a USD mesh with time-sampled
//! `points`, from an OBJ sequence (`skin.####.obj`), from a glTF/GLB with
//! a skin and animations (posed by pelage, `gltf_skin.rs`), or made by a
//! program ([`AnimatedSkin::from_fn`]).

use super::gltf_skin::GltfAnimation;
use super::rig::SkinRig;
use crate::io::UsdSkin;
use crate::mesh::{FaceGroups, Mesh, MeshError, MeshErrorKind, Uvs, VertexAttribute};
use glam::{Mat4, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How an animated skin is read.
#[derive(Debug, Clone)]
pub struct SkinOptions {
    /// Frames per second: turns frames into a glTF animation's seconds
    /// (frame 1 is its time 0).
    pub fps: f64,
    /// The glTF animation to play, by name (or `#index`); the first one
    /// when `None`.
    pub clip: Option<String>,
    /// Midpoint subdivision steps applied to every frame.
    pub subdivide: u32,
}

impl Default for SkinOptions {
    fn default() -> Self {
        Self {
            fps: 24.0,
            clip: None,
            subdivide: 0,
        }
    }
}

/// Vertex positions of the base (unsubdivided) mesh at a frame.
type PositionsFn = dyn Fn(f64) -> Vec<Vec3> + Send + Sync;

enum Motion {
    Still(Vec<Vec3>),
    ObjSequence(PathBuf),
    Gltf(Box<GltfAnimation>),
    Usd(Box<UsdSkin>),
    Program(Arc<PositionsFn>),
}

/// A mesh moving over frames with fixed triangles.
pub struct AnimatedSkin {
    name: String,
    /// The base mesh's triangles, vertex count and UVs (before
    /// subdivision): every frame must have that many vertices.
    triangles: Vec<[u32; 3]>,
    vertex_count: usize,
    uvs: Option<Uvs>,
    /// The base mesh's paint layers and face sets: every frame's mesh
    /// has them (a painted or parted groom animates).
    vertex_attributes: Vec<VertexAttribute>,
    face_groups: Vec<FaceGroups>,
    fps: f64,
    subdivide: u32,
    motion: Motion,
}

impl std::fmt::Debug for AnimatedSkin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AnimatedSkin")
            .field("name", &self.name)
            .field("triangles", &self.triangles.len())
            .field("animated", &self.is_animated())
            .finish()
    }
}

/// `seconds` into a looping clip: a walk cycle walks on. The clip's end
/// is shown at its end, not folded back to its start.
fn clip_seconds(animation: &GltfAnimation, seconds: f64) -> f32 {
    let duration = f64::from(animation.duration);
    let mut s = seconds;
    if duration > 0.0 {
        s = seconds.rem_euclid(duration);
        if s == 0.0 && seconds > 0.0 {
            s = duration;
        }
    }
    s as f32
}

/// The `#` run of a sequence pattern: where it starts and how many digits.
fn frame_digits(pattern: &str) -> Option<(usize, usize)> {
    let start = pattern.find('#')?;
    let len = pattern[start..].chars().take_while(|&c| c == '#').count();
    Some((start, len))
}

/// The file of `frame` in an OBJ sequence `pattern` (`#` run = the frame
/// number, zero-padded to the run's length).
pub fn sequence_file(pattern: &Path, frame: i64) -> PathBuf {
    let text = pattern.to_string_lossy();
    match frame_digits(&text) {
        Some((start, len)) => {
            let number = if frame < 0 {
                format!("-{:0len$}", -frame, len = len)
            } else {
                format!("{frame:0len$}")
            };
            PathBuf::from(format!(
                "{}{number}{}",
                &text[..start],
                &text[start + len..]
            ))
        }
        None => pattern.to_path_buf(),
    }
}

impl AnimatedSkin {
    /// Reads the skin at `path`: a `#` in the name makes it an OBJ/PLY
    /// sequence; a glTF/GLB with animations is posed by its clip; a USD
    /// mesh moves by its `points` samples; anything else stands still.
    pub fn load(path: &Path, options: &SkinOptions) -> Result<Self, MeshError> {
        let name = path.display().to_string();
        crate::io::note_input(path);
        if !(options.fps.is_finite() && options.fps > 0.0) {
            return Err(MeshError::whole(
                name,
                MeshErrorKind::Unsupported(format!(
                    "frames per second must be a positive number, not {}",
                    options.fps
                )),
            ));
        }
        let text = path.to_string_lossy();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        let plays_clips = frame_digits(&text).is_none() && (ext == "gltf" || ext == "glb");
        if let (Some(wanted), false) = (options.clip.as_deref(), plays_clips) {
            return Err(MeshError::whole(
                name,
                MeshErrorKind::Clip(format!(
                    "clip {wanted:?}: this skin has no clips to play; clips are glTF animations (a .gltf or .glb skin), and a USD skin or an OBJ/PLY sequence moves by its own frames: remove `clip`"
                )),
            ));
        }
        let (base, motion) = if frame_digits(&text).is_some() {
            // The sequence's topology and UVs come from its first file
            // found; frames are read on demand.
            let mesh = Mesh::load(sequence_file(path, 1)).or_else(|first| {
                (0..=1000)
                    .map(|f| sequence_file(path, f))
                    .find(|p| p.exists())
                    .map_or(Err(first), Mesh::load)
            })?;
            (mesh, Motion::ObjSequence(path.to_path_buf()))
        } else if ext == "gltf" || ext == "glb" {
            let bytes =
                std::fs::read(path).map_err(|e| MeshError::whole(&name, MeshErrorKind::Io(e)))?;
            let parsed = crate::mesh::gltf::parse_with_sources(&name, &bytes, path.parent())?;
            let has_animation = parsed.document.animations().next().is_some();
            if let Some(wanted) = options.clip.as_deref() {
                crate::anim::gltf_skin::find_clip(&parsed, wanted)
                    .map_err(|m| MeshError::whole(&name, MeshErrorKind::Clip(m)))?;
            }
            if !has_animation && options.clip.is_none() {
                (parsed.mesh, Motion::Still(Vec::new()))
            } else {
                let animation = GltfAnimation::new(&parsed, options.clip.as_deref())
                    .map_err(|m| MeshError::whole(&name, MeshErrorKind::Unsupported(m)))?;
                (parsed.mesh, Motion::Gltf(Box::new(animation)))
            }
        } else if matches!(ext.as_str(), "usda" | "usdc" | "usd") {
            let skin = crate::io::read_usd_skin(path).map_err(crate::io::usd_mesh_error)?;
            let mesh = Mesh::new(
                &name,
                skin.positions.clone(),
                skin.triangles.clone(),
                None,
                skin.uvs.clone(),
            )?;
            let motion = if skin.times.len() > 1 {
                Motion::Usd(Box::new(skin))
            } else {
                Motion::Still(Vec::new())
            };
            (mesh, motion)
        } else {
            (Mesh::load(path)?, Motion::Still(Vec::new()))
        };
        let mut skin = Self::from_mesh(&base, motion);
        skin.name = name;
        skin.fps = options.fps;
        skin.subdivide = options.subdivide;
        Ok(skin)
    }

    fn from_mesh(mesh: &Mesh, motion: Motion) -> Self {
        let motion = match motion {
            Motion::Still(_) => Motion::Still(mesh.positions().to_vec()),
            m => m,
        };
        Self {
            name: mesh.name().to_string(),
            triangles: mesh.triangles().to_vec(),
            vertex_count: mesh.vertex_count(),
            uvs: mesh.uvs().cloned(),
            vertex_attributes: mesh.vertex_attributes().to_vec(),
            face_groups: mesh
                .face_group_kinds()
                .into_iter()
                .filter_map(|kind| mesh.face_groups(kind).cloned())
                .collect(),
            fps: 24.0,
            subdivide: 0,
            motion,
        }
    }

    /// A skin that does not move.
    pub fn still(mesh: &Mesh) -> Self {
        Self::from_mesh(mesh, Motion::Still(Vec::new()))
    }

    /// A skin moved by a program: `positions(frame)` gives `mesh`'s
    /// vertices at a frame (as many as `mesh` has).
    pub fn from_fn(
        mesh: &Mesh,
        positions: impl Fn(f64) -> Vec<Vec3> + Send + Sync + 'static,
    ) -> Self {
        Self::from_mesh(mesh, Motion::Program(Arc::new(positions)))
    }

    /// What errors call the skin.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Whether the skin moves at all.
    pub fn is_animated(&self) -> bool {
        !matches!(self.motion, Motion::Still(_))
    }

    /// The glTF animation played, and its length in seconds.
    pub fn clip(&self) -> Option<(&str, f64)> {
        match &self.motion {
            Motion::Gltf(a) => Some((&a.name, f64::from(a.duration))),
            _ => None,
        }
    }

    /// A glTF skin's linear-blend skinning, over the base mesh's vertices
    /// (before `subdivide`; [`SkinRig::subdivided`] follows it), with
    /// rest positions in the space its palette maps from.
    pub fn rig(&self) -> Option<&SkinRig> {
        match &self.motion {
            Motion::Gltf(a) => Some(a.rig()),
            _ => None,
        }
    }

    /// The palette of [`Self::rig`] at `frame` (frame 1 is the clip's
    /// start, as [`Self::positions_at`] counts).
    pub fn palette_at_frame(&self, frame: f64) -> Option<Vec<Mat4>> {
        self.palette_at_seconds((frame - 1.0) / self.fps)
    }

    /// Frames per second of a glTF clip's time.
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// The palette of [`Self::rig`] at `seconds` into the clip (clips
    /// loop, as frames do).
    pub fn palette_at_seconds(&self, seconds: f64) -> Option<Vec<Mat4>> {
        match &self.motion {
            Motion::Gltf(a) => Some(a.palette_at(clip_seconds(a, seconds))),
            _ => None,
        }
    }

    /// The base mesh's triangles, UVs, paint layers and face sets at the
    /// positions `positions` (as many as its vertices), not subdivided.
    pub fn base_mesh_at(&self, positions: Vec<Vec3>) -> Result<Mesh, MeshError> {
        let mut mesh = Mesh::new(
            &self.name,
            positions,
            self.triangles.clone(),
            None,
            self.uvs.clone(),
        )?;
        for a in &self.vertex_attributes {
            mesh = mesh.with_vertex_attribute(a.name.clone(), a.values.to_vec())?;
        }
        for groups in &self.face_groups {
            mesh = mesh.with_face_groups(groups.clone())?;
        }
        Ok(mesh)
    }

    /// The time codes a USD skin is sampled at (empty for other skins).
    pub fn sample_times(&self) -> &[f64] {
        match &self.motion {
            Motion::Usd(s) => &s.times,
            _ => &[],
        }
    }

    /// The base mesh's vertices at `frame` (before subdivision).
    fn base_positions(&self, frame: f64) -> Result<Vec<Vec3>, MeshError> {
        let at_frame = |message: String| {
            MeshError::whole(
                &self.name,
                MeshErrorKind::Inconsistent(format!("frame {frame}: {message}")),
            )
        };
        let positions = match &self.motion {
            Motion::Still(p) => p.clone(),
            Motion::Program(f) => f(frame),
            Motion::Gltf(animation) => {
                animation.positions_at(clip_seconds(animation, (frame - 1.0) / self.fps))
            }
            Motion::Usd(skin) => skin.positions_at(frame).map_err(at_frame)?,
            Motion::ObjSequence(pattern) => {
                if frame.fract() != 0.0 {
                    // Between two files: their positions interpolated.
                    let (a, b) = (frame.floor(), frame.ceil());
                    let (pa, pb) = (
                        self.sequence_frame(pattern, a)?,
                        self.sequence_frame(pattern, b)?,
                    );
                    let s = (frame - a) as f32;
                    pa.iter().zip(&pb).map(|(p, q)| p.lerp(*q, s)).collect()
                } else {
                    self.sequence_frame(pattern, frame)?
                }
            }
        };
        let expected = self.vertex_count;
        if positions.len() != expected {
            return Err(at_frame(format!(
                "{} vertices, not {expected}: the skin's topology must not change over time",
                positions.len()
            )));
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(at_frame(format!("vertex {i} is not a finite position")));
        }
        Ok(positions)
    }

    /// One file of an OBJ/PLY sequence, checked against the first.
    fn sequence_frame(&self, pattern: &Path, frame: f64) -> Result<Vec<Vec3>, MeshError> {
        let file = sequence_file(pattern, frame as i64);
        let mesh = Mesh::load(&file)?;
        if mesh.positions().len() != self.vertex_count {
            return Err(MeshError::whole(
                file.display().to_string(),
                MeshErrorKind::Inconsistent(format!(
                    "frame {frame} has {} vertices, not the {} of the sequence's first file: the skin's topology must not change over time",
                    mesh.positions().len(),
                    self.vertex_count
                )),
            ));
        }
        if mesh.triangles() != self.triangles.as_slice() {
            return Err(MeshError::whole(
                file.display().to_string(),
                MeshErrorKind::Inconsistent(format!(
                    "frame {frame} has other triangles than the sequence's first file: the skin's topology must not change over time"
                )),
            ));
        }
        Ok(mesh.positions().to_vec())
    }

    /// The skin at `frame`, whole (UVs included, subdivided as asked).
    pub fn mesh_at(&self, frame: f64) -> Result<Mesh, MeshError> {
        let base = self.base_mesh_at(self.base_positions(frame)?)?;
        Ok(match self.subdivide {
            0 => base,
            n => base.subdivided(n),
        })
    }

    /// The vertex positions at `frame` (subdivided as asked), in the
    /// vertex order of [`Self::mesh_at`].
    pub fn positions_at(&self, frame: f64) -> Result<Vec<Vec3>, MeshError> {
        if self.subdivide == 0 {
            return self.base_positions(frame);
        }
        // Midpoint subdivision is linear in the positions.
        Ok(self.mesh_at(frame)?.positions().to_vec())
    }
}
