//! The shell-fur renderer (Silva §4, Lengyel et al.): a skinned model
//! posed by a compute pass (`shaders/skin.wgsl`, `pelage::anim::SkinRig`'s
//! copy), then the skin once with depth write, the layers in one instanced
//! indexed draw — depth test on, depth write off, blended in layer order —
//! and the fins on the edges seen edge-on (Lengyel et al. 2001). Layer
//! displacement (Eq. 1, curl Eq. 4) runs in the vertex shader, clumping
//! (Alg. 2) and shading (Eq. 6) in the fragment shader;
//! `shaders/shells.wgsl` mirrors `pelage::shell::math` function by
//! function. A [`ShellLod`] chooses the layers and the texture's mip level
//! by size on screen; objects outside the view are not drawn.
//!
//! Pipelines are specialised with WGSL override constants — plain shells,
//! with curl, with curl and clumps, back faces culled ([`ShellFeatures`]) —
//! so the benchmark compares like with like, and built for pelage's
//! targets or a caller's ([`ShellTargetFormats`], docs/embedding.md).
//!
//! The parts, lowest first (each uses only those above it in this list):
//!
//! - `prepare.rs`: a mesh prepared on the CPU, without wgpu: welded
//!   corners, pose and surface vertices with tangents ([`vertex_tangents`],
//!   from `pelage_shaders::shell`, which also makes the texture's mips),
//!   skin influences;
//! - `fins.rs`: the fin records of a mesh's edges;
//! - `model.rs`: [`ShellModel`] (a furry mesh on the GPU: welded vertices,
//!   pose, textures with mips, rig);
//! - `renderer.rs`: [`ShellRenderer`], its pipelines, the skinning pass
//!   and what a frame records, and [`ShellTarget`] (the images drawn into);
//! - `upload.rs`: [`ShellRenderer::upload_with`], a mesh made a model with
//!   the renderer's layouts, and a model's tips and wetness changed.
//!
//! [`ShellScenePlayer`](crate::ShellScenePlayer), a scene file drawn frame
//! by frame with its motion, is a layer above (`player.rs` beside
//! `motion.rs`).

mod fins;
mod model;
mod prepare;
mod renderer;
mod upload;

pub use model::{ShellModel, ShellUpload};
pub use pelage_shaders::shell::vertex_tangents;
pub use renderer::{ShellRenderer, ShellTarget, ShellTargetFormats};

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
    /// Skin and layers drawn only where they face the camera (closed
    /// meshes wound counter-clockwise seen from outside): the far side's
    /// layers are hidden behind the near side's skin anyway, and fins
    /// cover the silhouette.
    pub cull_back: bool,
}

impl ShellFeatures {
    /// Plain shells: layers along the strand, no curl, no clumps.
    pub const PLAIN: Self = Self {
        curl: false,
        clump: false,
        cull_back: false,
    };
    /// Curl and clumps.
    pub const ALL: Self = Self {
        curl: true,
        clump: true,
        cull_back: false,
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
    /// Fins at the silhouette (Lengyel et al. 2001), if drawn.
    pub fins: Option<FinParams>,
    /// Level of detail by projected size, if on (else every layer, mip 0).
    pub lod: Option<ShellLod>,
    /// The layers' and fins' opacity, 0 to 1 (1: as the shader makes
    /// them; less where real-time strands hand over to the shells).
    pub opacity: f32,
}

/// Fins: quads standing on the mesh's edges, textured with a vertical
/// slice through the same blades as the layers, drawn where an edge is
/// seen edge-on — where layers show as stacked lines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FinParams {
    /// Opacity of a fin seen exactly edge-on.
    pub opacity: f32,
    /// A fin fades out as `|n · e|` (edge normal, unit direction to the
    /// eye) grows to this; silhouette edges (one face towards the eye, one
    /// away) are drawn however far they are from edge-on.
    pub width: f32,
}

impl Default for FinParams {
    fn default() -> Self {
        Self {
            opacity: 1.0,
            width: 0.15,
        }
    }
}

/// Level of detail: how many layers an object gets from its size on
/// screen. The layers' spacing on screen (the fur length in pixels over
/// the layer count) is the screen-space error: layers are dropped while
/// they stay at most `max_gap_px` apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellLod {
    /// The largest spacing between layers on screen, in pixels.
    pub max_gap_px: f32,
    /// Never fewer layers than this.
    pub min_layers: u32,
}

impl Default for ShellLod {
    fn default() -> Self {
        Self {
            max_gap_px: 0.75,
            min_layers: 4,
        }
    }
}

/// The level of detail an object is drawn at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellLevel {
    /// Layers, continuous: ⌈layers⌉ are drawn, the innermost faded in by
    /// the fraction, so a change of distance never pops a layer in or out.
    pub layers: f32,
    /// The fur texture's mip level.
    pub mip: f32,
    /// The fur length on screen, pixels.
    pub fur_px: f32,
}

impl ShellLevel {
    /// Not drawn: outside the view.
    pub const CULLED: Self = Self {
        layers: 0.0,
        mip: 0.0,
        fur_px: 0.0,
    };

    /// Every layer, mip 0.
    pub fn full(layers: u32) -> Self {
        Self {
            layers: layers as f32,
            mip: 0.0,
            fur_px: f32::INFINITY,
        }
    }

    /// Layers drawn: ⌈layers⌉.
    pub fn drawn(&self) -> u32 {
        self.layers.ceil() as u32
    }
}

impl ShellLod {
    /// The level for fur `fur_px` pixels long on screen, of `layers` at
    /// most, its texture `texels` wide and repeated `tiles` times, the
    /// object `object_px` wide on screen.
    pub fn level(
        &self,
        layers: u32,
        fur_px: f32,
        texels: u32,
        tiles: f32,
        object_px: f32,
    ) -> ShellLevel {
        let most = layers as f32;
        let least = (self.min_layers.max(1) as f32).min(most);
        let wanted = fur_px / self.max_gap_px.max(1e-3);
        // Texels across the object over pixels across it: the UV square
        // wraps around the object, about half of it in view.
        let texels_per_px = 0.5 * texels as f32 * tiles / object_px.max(1.0);
        ShellLevel {
            layers: if wanted.is_finite() {
                wanted.clamp(least, most)
            } else {
                most
            },
            mip: texels_per_px.max(1.0).log2(),
            fur_px,
        }
    }
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
    /// Whether a sphere may be in view: not wholly outside any of the six
    /// planes of the view's frustum (Gribb & Hartmann's planes from the
    /// rows of `clip_from_world`, wgpu's depth 0..1).
    pub fn sees_sphere(&self, centre: Vec3, radius: f32) -> bool {
        let m = self.clip_from_world;
        let (x, y, z, w) = (m.row(0), m.row(1), m.row(2), m.row(3));
        let p = centre.extend(1.0);
        [w + x, w - x, w + y, w - y, z, w - z].iter().all(|plane| {
            let length = plane.truncate().length();
            length == 0.0 || plane.dot(p) / length >= -radius
        })
    }

    /// How long `length` (world units) at `point` looks on screen, in
    /// pixels of an image `height` pixels high, measured across the line
    /// of sight.
    pub fn projected_length(&self, point: Vec3, length: f32, height: f32) -> f32 {
        let sight = (point - self.eye).normalize_or(Vec3::Z);
        let across = sight.any_orthonormal_vector();
        let ndc = |p: Vec3| {
            let c = self.clip_from_world * p.extend(1.0);
            (c.w > 1e-9).then(|| glam::Vec2::new(c.x, c.y) / c.w)
        };
        match (ndc(point), ndc(point + length * across)) {
            (Some(a), Some(b)) => 0.5 * height * a.distance(b),
            // Behind the eye: treat as huge, so nothing is dropped.
            _ => f32::INFINITY,
        }
    }

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
    /// Where a skin vertex is and how it is oriented (`VertexIn` of
    /// `shells.wgsl`, locations 0 to 2): written once for a still mesh,
    /// by the skinning pass (`skin.wgsl`) every frame for a skinned one.
    pub(crate) struct PoseVertex at location 0 {
        position: [f32; 3],
        normal: [f32; 3],
        /// dP/du, the texture's x direction on the surface.
        tangent: [f32; 3],
    }
}

gpu_vertex! {
    /// What does not move with the skin (location 3).
    pub(crate) struct SurfaceVertex at location 3 {
        /// Mask (image) coordinates: (u, 1 − v).
        uv: [f32; 2],
    }
}

gpu_vertex! {
    /// `p − p0`: how far a vertex's strand tip has moved (0 at rest), from
    /// a buffer rewritten as the fur moves (location 4).
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
        /// L: the layers of this level of detail, continuous (N for full
        /// detail); ⌈L⌉ are drawn, the innermost faded by L's fraction.
        lod_layers: f32,
        /// The fur texture's mip level for this object.
        fur_mip: f32,
        /// Fins: opacity at the silhouette (0: no fins).
        fin_opacity: f32,
        /// Fins: how far from edge-on (|n·e|) a fin fades out.
        fin_width: f32,
        /// The layers' and fins' opacity.
        fur_opacity: f32,
        pad0: f32,
    }
}

impl ShellParams {
    /// Plain fur: `layers` shells `length` long, Kajiya-Kay shaded as a
    /// scene file without a `[shading]` table is, without curl, clumps,
    /// fins or a level of detail (`layers = 0`: the skin alone, as a host
    /// drawing strands over it wants).
    pub fn plain(layers: u32, length: f32) -> Self {
        Self {
            layers,
            length,
            tiles: 1.0,
            curl: CurlParams {
                radius: 0.0,
                frequency: 0.0,
            },
            clump: ClumpParams {
                w: 0.0,
                strength: 0.0,
            },
            coupling: Coupling::Bezier,
            offset: Vec3::ZERO,
            mode: ShadingMode::KajiyaKay,
            kajiya_kay: KajiyaKay {
                specular: Vec3::new(0.12, 0.11, 0.1),
                exponent: 30.0,
                k_shadow: 2.0,
            },
            background: [0.62, 0.66, 0.72],
            fins: None,
            lod: None,
            opacity: 1.0,
        }
    }

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
            fins: scene.fins.map(|f| FinParams {
                opacity: f.opacity,
                width: f.width,
            }),
            lod: scene.lod.map(|l| ShellLod {
                max_gap_px: l.max_gap_px,
                min_layers: l.min_layers,
            }),
            opacity: 1.0,
        }
    }
}
