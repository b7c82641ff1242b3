//! pelage-gpu: the wgpu renderer. Everything pelage makes can be looked at
//! through it: the skin mesh, points (hair roots, samples), curves, and
//! shell fur ([`ShellRenderer`]); and it steps moving fur's explicit
//! mass-spring solver in a compute shader ([`GpuMassSpring`]). It renders headless into an image (CI,
//! render farms without GPUs, docs) and, for the viewer, into a window,
//! with the same pipelines. WGSL lives in `src/shaders/`.
//!
//! Its own crate because wgpu is the heaviest dependency by far: the
//! library and its tests build without it.
//!
//! Without a GPU, Mesa's software Vulkan driver (lavapipe; Debian package
//! `mesa-vulkan-drivers`) serves: CI renders for real with it.

mod camera;
mod context;
mod dynamics;
mod fur_lod;
mod groom;
mod hair_render;
mod layout;
mod motion;
mod player;
mod readback;
mod realtime;
mod renderer;
mod shells;
mod strands;

pub use camera::{Camera, OrbitCamera};
pub use context::GpuContext;
pub use dynamics::GpuMassSpring;
pub use fur_lod::{FurLevel, FurLevelParams, FurLod, ShellStandIn};
pub use groom::{GpuGroom, GpuPartGrower, MAX_GPU_HAIR_POINTS};
pub use hair_render::{StrandBinding, StrandFrame, StrandLook, StrandParams, StrandRenderer};
pub use motion::{FurMotion, SkinMotion};
pub use pelage::Curves;
pub use player::ShellScenePlayer;
pub use readback::read_texture;
pub use realtime::{RealtimeError, RealtimeFur, RealtimeStats};
pub use renderer::{GpuScene, PreviewScene, PreviewStyle, Renderer};
pub use shells::{
    FinParams, ShellFeatures, ShellLevel, ShellLod, ShellModel, ShellParams, ShellRenderer,
    ShellTarget, ShellTargetFormats, ShellUpload, ShellView, vertex_tangents,
};
pub use strands::{GpuStrands, MAX_GPU_STRAND_POINTS};
/// wgpu itself, so callers (a window, the viewer) build surfaces with the same version.
pub use wgpu;

/// The renderer could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GpuError {
    /// No adapter: no GPU, and no software Vulkan driver either.
    #[error(
        "no GPU adapter found; for a software renderer install Mesa's Vulkan drivers (Debian/Ubuntu: apt-get install mesa-vulkan-drivers), or choose a backend with WGPU_BACKEND=vulkan|gl"
    )]
    NoAdapter(#[source] wgpu::RequestAdapterError),
    /// The adapter refused to create a device.
    #[error("the GPU adapter {adapter} could not open a device")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// wgpu's error.
        #[source]
        error: wgpu::RequestDeviceError,
    },
    /// The GPU reported an error while drawing (out of memory, a limit).
    #[error("the GPU ({adapter}) failed: {message}")]
    Failed {
        /// The adapter in words.
        adapter: String,
        /// What it reported.
        message: String,
    },
    /// Reading the rendered image back failed.
    #[error("reading back from the GPU failed")]
    Readback(#[source] Box<dyn std::error::Error + Send + Sync>),
    /// Images are read back only from 8-bit RGBA or BGRA targets.
    #[error("images can be read back from Rgba8/Bgra8 renderers only, not {0}")]
    Format(String),
    /// Shell fur needs UVs: its textures and wetness mask are read at them.
    #[error(
        "the mesh {0} has no UVs; shell fur reads its textures and wetness mask at the mesh's UVs"
    )]
    NoUvs(String),
    /// Inputs that do not fit together.
    #[error("{0}")]
    Mismatch(String),
    /// The requested image size is not possible.
    #[error("an image of {width}×{height} pixels cannot be rendered (1 to {max} per side)")]
    Size {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The adapter's limit.
        max: u32,
    },
}

/// The WGSL of each pipeline: the shared `Frame` uniform block
/// (`frame.wgsl`) followed by the pipeline's own shader. Shell fur's
/// functions come from the layer both GPU hosts share
/// ([`pelage_shaders::shell::MATH_WGSL`]), put first when the shader is made.
pub const SHADERS: &[(&str, &str)] = &[
    (
        "mesh.wgsl",
        concat!(
            include_str!("shaders/frame.wgsl"),
            include_str!("shaders/mesh.wgsl")
        ),
    ),
    (
        "points.wgsl",
        concat!(
            include_str!("shaders/frame.wgsl"),
            include_str!("shaders/points.wgsl")
        ),
    ),
    (
        "curves.wgsl",
        concat!(
            include_str!("shaders/frame.wgsl"),
            include_str!("shaders/curves.wgsl")
        ),
    ),
    // Shell fur has its own uniform block; its math is shared (see above).
    ("shells.wgsl", include_str!("shaders/shells.wgsl")),
    // The explicit mass-spring substep (compute).
    ("dynamics.wgsl", include_str!("shaders/dynamics.wgsl")),
    // Guide strands' substeps (compute).
    ("strands.wgsl", include_str!("shaders/strands.wgsl")),
    // A groom's hairs grown from the frame's guides and skin (compute).
    ("groom.wgsl", pelage_shaders::groom::GROOM_WGSL),
    // Real-time strands: the GPU groom's hairs drawn, and their shadows.
    ("hair.wgsl", include_str!("shaders/hair.wgsl")),
    // Linear-blend skinning of shell models (compute).
    ("skin.wgsl", include_str!("shaders/skin.wgsl")),
];

pub(crate) use pelage_shaders::workgroups;

/// The WGSL source of the named shader (with its prelude; shell fur and
/// strands with their shared math before them; the compute shaders with the shared
/// noise and skin-grid queries after them, from pelage-shaders).
pub(crate) fn shader_source(name: &str) -> std::borrow::Cow<'static, str> {
    let own = SHADERS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| *s)
        .expect("the shader exists");
    use pelage_shaders::groom::{NOISE_WGSL, SKIN_SDF_WGSL};
    match name {
        "shells.wgsl" => format!("{}\n{own}", pelage_shaders::shell::MATH_WGSL).into(),
        "hair.wgsl" => format!("{}\n{own}", pelage_shaders::hair::MATH_WGSL).into(),
        "dynamics.wgsl" => format!("{own}{NOISE_WGSL}").into(),
        "strands.wgsl" => format!("{own}{SKIN_SDF_WGSL}{NOISE_WGSL}").into(),
        _ => own.into(),
    }
}

#[cfg(test)]
mod tests {
    /// Every shader parses and validates with naga, with no GPU needed.
    #[test]
    fn shaders_validate_with_naga() {
        for (name, _) in super::SHADERS {
            let source = &*super::shader_source(name);
            let module = naga::front::wgsl::parse_str(source)
                .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::default(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
        }
    }
}
