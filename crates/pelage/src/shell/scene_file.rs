//! Shell scene files as written (docs/shells-format.md): the serde types
//! of every section, unknown keys refused, names as enums. `scene.rs`
//! turns them into a [`super::ShellScene`].

use crate::dynamics::Topology;
use crate::groom::file::MeshSection;
use crate::shell::math::ShadingMode;
use crate::shell::textures::TextureStyle;
use serde::Deserialize;
use toml::Spanned;

/// The file as written.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneFile {
    pub(super) mesh: Option<MeshSection>,
    pub(super) color: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) fur: FurSection,
    #[serde(default)]
    pub(super) texture: TextureSection,
    #[serde(default)]
    pub(super) curl: CurlSection,
    #[serde(default)]
    pub(super) clump: ClumpSection,
    #[serde(default)]
    pub(super) shading: ShadingSection,
    #[serde(default)]
    pub(super) wetness: WetnessSection,
    #[serde(default)]
    pub(super) droplets: Vec<DropletsSection>,
    pub(super) light: Option<[f32; 3]>,
    pub(super) camera: Option<CameraSection>,
    #[serde(default)]
    pub(super) animation: AnimationSection,
    pub(super) dynamics: Option<DynamicsSection>,
    pub(super) fins: Option<FinsSection>,
    pub(super) lod: Option<LodSection>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct DynamicsSection {
    pub(super) topology: Option<Topology>,
    pub(super) solver: Option<SolverName>,
    pub(super) substeps: Option<u32>,
    pub(super) iterations: Option<u32>,
    pub(super) gpu: Option<Spanned<bool>>,
    pub(super) steps_per_frame: Option<u32>,
    pub(super) coupling: Option<CouplingName>,
    pub(super) exponent: Option<f32>,
    pub(super) mass: Option<f32>,
    pub(super) stiffness: Option<f32>,
    pub(super) lateral_stiffness: Option<f32>,
    pub(super) damping: Option<f32>,
    pub(super) drag: Option<f32>,
    pub(super) restoring: Option<f32>,
    pub(super) gravity: Option<[f32; 3]>,
    pub(super) wind: Option<WindSection>,
    pub(super) shake: Option<ShakeSection>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct WindSection {
    pub(super) velocity: [f32; 3],
    pub(super) gust: Option<f32>,
    pub(super) gust_frequency: Option<f32>,
    pub(super) turbulence: Option<f32>,
    pub(super) scale: Option<f32>,
    pub(super) seed: Option<u64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ShakeSection {
    pub(super) amplitude: [f32; 3],
    pub(super) frequency: Option<f32>,
    pub(super) duration: Option<f32>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct FurSection {
    pub(super) layers: Option<Spanned<u32>>,
    pub(super) length: Option<Spanned<f32>>,
    pub(super) tiles: Option<f32>,
    pub(super) cull_back: Option<bool>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct TextureSection {
    pub(super) style: Option<TextureStyle>,
    pub(super) resolution: Option<Spanned<u32>>,
    pub(super) density: Option<f32>,
    pub(super) thickness: Option<f32>,
    pub(super) length_variance: Option<f32>,
    pub(super) lean: Option<f32>,
    pub(super) bend: Option<f32>,
    pub(super) undercoat_ratio: Option<f32>,
    pub(super) undercoat_length: Option<f32>,
    pub(super) seed: Option<u64>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct CurlSection {
    pub(super) radius: Option<f32>,
    pub(super) turns: Option<f32>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct ClumpSection {
    pub(super) w: Option<f32>,
    pub(super) strength: Option<f32>,
    pub(super) enabled: Option<bool>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct ShadingSection {
    pub(super) mode: Option<ShadingMode>,
    pub(super) specular: Option<[f32; 3]>,
    pub(super) exponent: Option<f32>,
    pub(super) shadow: Option<f32>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct WetnessSection {
    pub(super) resolution: Option<Spanned<u32>>,
    pub(super) drying_rate: Option<f32>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DropletsSection {
    /// Seconds into the sequence when they fall.
    #[serde(default)]
    pub(super) time: f32,
    /// One droplet at a mesh UV.
    pub(super) at: Option<[f32; 2]>,
    /// Random droplets over the surface.
    pub(super) count: Option<usize>,
    /// Droplets along the bright pixels of an image (mask coordinates).
    pub(super) image: Option<Spanned<String>>,
    /// Grid spacing for `image`.
    pub(super) spacing: Option<f32>,
    /// Radius, or `[min, max]`.
    pub(super) radius: Option<RadiusText>,
    pub(super) wetness: Option<f32>,
    pub(super) seed: Option<u64>,
}

/// `[dynamics] solver`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(super) enum SolverName {
    Implicit,
    Explicit,
}

/// `[dynamics] coupling`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(super) enum CouplingName {
    Bezier,
    Linear,
    Bent,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(untagged)]
pub(super) enum RadiusText {
    One(f32),
    Range([f32; 2]),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraSection {
    pub(super) eye: Option<[f32; 3]>,
    pub(super) target: Option<[f32; 3]>,
    pub(super) fov: Option<f32>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct AnimationSection {
    pub(super) frames: Option<u32>,
    pub(super) fps: Option<f32>,
    /// A glTF skin's animation to play (by name or `#index`).
    pub(super) clip: Option<Spanned<String>>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct FinsSection {
    pub(super) enabled: Option<bool>,
    pub(super) opacity: Option<f32>,
    pub(super) width: Option<f32>,
}

#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct LodSection {
    pub(super) enabled: Option<bool>,
    pub(super) max_gap: Option<f32>,
    pub(super) min_layers: Option<Spanned<u32>>,
}
