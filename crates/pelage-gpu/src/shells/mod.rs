//! The shell-fur renderer (Silva §4, Lengyel et al.): the skin once with
//! depth write, then the N layers in one instanced draw — depth test on,
//! depth write off, blended in layer order. Layer displacement (Eq. 1,
//! curl Eq. 4) runs in the vertex shader, clumping (Alg. 2) and shading
//! (Eq. 6) in the fragment shader; `shaders/shells.wgsl` mirrors
//! `pelage::shell::math` function by function.
//!
//! Pipelines are specialised with WGSL override constants — plain shells,
//! with curl, with curl and clumps ([`ShellFeatures`]) — so the benchmark
//! compares like with like.
//!
//! - `renderer.rs`: [`ShellRenderer`], its pipelines and the frame it
//!   records;
//! - `model.rs`: [`ShellModel`] (a furry mesh uploaded) and
//!   [`ShellTarget`] (the images drawn into);
//! - `player.rs`: [`ShellScenePlayer`], a scene file drawn frame by frame.

mod model;
mod player;
mod renderer;

pub use model::{ShellModel, ShellTarget, vertex_tangents};
pub use player::ShellScenePlayer;
pub use renderer::ShellRenderer;

use crate::Camera;
use crate::layout::{gpu_struct, gpu_vertex};
use glam::{Mat4, Vec3};

use pelage::shell::ShellScene;
use pelage::shell::math::{ClumpParams, Coupling, CurlParams, KajiyaKay, ShadingMode};

/// Which effects a pipeline computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ShellFeatures {
    /// Curl (Eq. 4) in the vertex shader: reads the wetness mask per vertex.
    pub curl: bool,
    /// Clumping (Alg. 2) in the fragment shader: reads the mask per fragment.
    pub clump: bool,
}

impl ShellFeatures {
    /// Plain shells: layers along the strand, no curl, no clumps.
    pub const PLAIN: Self = Self {
        curl: false,
        clump: false,
    };
    /// Curl and clumps.
    pub const ALL: Self = Self {
        curl: true,
        clump: true,
    };
}

/// How to draw the fur: everything the shaders read besides textures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellParams {
    /// Number of layers N.
    pub layers: u32,
    /// Shell length L0 (world units).
    pub length: f32,
    /// Shell texture repeats across the UV square.
    pub tiles: f32,
    /// Curl (Eq. 4).
    pub curl: CurlParams,
    /// How the strands' tips bend the layers (Silva's Bézier, Banisch's
    /// linear or bent layers).
    pub coupling: Coupling,
    /// The whole skin moved by this (an object being shaken).
    pub offset: Vec3,
    /// Clumping (Eq. 5).
    pub clump: ClumpParams,
    /// Shading stage.
    pub mode: ShadingMode,
    /// Specular colour, exponent and `K_shadow`.
    pub kajiya_kay: KajiyaKay,
    /// Behind the fur (linear RGB).
    pub background: [f32; 3],
}

/// Where the fur is seen from, and lit from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellView {
    /// Clip from world (wgpu depth 0..1).
    pub clip_from_world: Mat4,
    /// The eye, for `E` in Eq. 6.
    pub eye: Vec3,
    /// Unit direction towards the light.
    pub light: Vec3,
}

impl ShellView {
    /// A perspective view through `camera` (framed on the mesh's bounds
    /// grown by the shell length when `None`), with a key light above and
    /// beside the camera unless `light` is given.
    pub fn new(
        camera: Option<Camera>,
        bounds: (Vec3, Vec3),
        length: f32,
        aspect: f32,
        light: Option<Vec3>,
    ) -> Self {
        let (lo, hi) = (
            bounds.0 - Vec3::splat(length),
            bounds.1 + Vec3::splat(length),
        );
        let camera = camera.unwrap_or_else(|| Camera::framing(lo, hi, aspect));
        let radius =
            (0.5 * (hi - lo)).length().max(1e-6) + (0.5 * (lo + hi) - camera.target).length();
        let view = (camera.eye - camera.target).normalize();
        let side = view.cross(Vec3::Y).normalize_or_zero();
        Self {
            clip_from_world: camera.clip_from_world(aspect, radius),
            eye: camera.eye,
            light: light.unwrap_or((view + 0.9 * Vec3::Y + 0.6 * side).normalize()),
        }
    }
}

gpu_vertex! {
    /// A skin vertex, one a triangle corner (`VertexIn` of `shells.wgsl`,
    /// locations 0 to 3).
    pub(crate) struct ShellVertex at location 0 {
        position: [f32; 3],
        normal: [f32; 3],
        /// Mask (image) coordinates: (u, 1 − v).
        uv: [f32; 2],
        /// dP/du, the texture's x direction on the surface.
        tangent: [f32; 3],
    }
}

gpu_vertex! {
    /// `p − p0`: how far a corner's strand tip has moved (0 at rest), from
    /// a second buffer rewritten as the fur moves (location 4).
    pub(crate) struct TipOffset at location 4 {
        tip_offset: [f32; 3],
    }
}

gpu_struct! {
    /// The uniform block of `shells.wgsl` (`struct Shell`).
    pub(crate) struct ShellUniforms {
        view_proj: [[f32; 4]; 4],
        eye: [f32; 3],
        /// L0: the outermost layer's height above the skin.
        shell_length: f32,
        /// Unit direction towards the light.
        light_dir: [f32; 3],
        /// N: layers drawn.
        layers: u32,
        /// Kajiya-Kay's K_s.
        specular: [f32; 3],
        /// p_phong.
        specular_exponent: f32,
        /// The whole skin moved by this (a shaken object).
        motion: [f32; 3],
        /// Eq. 4's k, for the bent coupling.
        coupling_exponent: f32,
        /// Shell texture repeats across the UV square.
        tiles: f32,
        k_shadow: f32,
        /// K_α and ω of the curl.
        curl_radius: f32,
        curl_frequency: f32,
        /// [`ShadingMode::index`](pelage::shell::math::ShadingMode::index).
        shading_mode: u32,
        /// [`Coupling::index`](pelage::shell::Coupling::index).
        coupling: u32,
        clump_w: f32,
        clump_strength: f32,
        /// The wetness mask's size in texels.
        wetness_size: [f32; 2],
        pad0: [f32; 2],
    }
}

impl ShellParams {
    /// The parameters a scene file sets, on the grey-blue background of
    /// the groom previews (white fur on white would vanish).
    pub fn from_scene(scene: &ShellScene) -> Self {
        Self {
            layers: scene.fur.layers,
            length: scene.fur.length,
            tiles: scene.fur.tiles,
            curl: scene.curl,
            clump: scene.clump.unwrap_or(ClumpParams {
                w: 0.0,
                strength: 0.0,
            }),
            coupling: Coupling::Bezier,
            offset: Vec3::ZERO,
            mode: scene.shading.mode,
            kajiya_kay: scene.shading.kajiya_kay,
            background: [0.62, 0.66, 0.72],
        }
    }
}
