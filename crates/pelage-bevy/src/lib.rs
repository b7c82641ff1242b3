//! pelage in Bevy: shell fur and real-time strands on Bevy's own meshes
//! and skinned characters.
//!
//! Add [`PelagePlugin`], then put a [`ShellFur`] (a shells file) or a
//! [`GroomFur`] (a groom file: its hairs grown on the GPU every frame and
//! drawn as strands near the camera, its shell stand-in far) on an entity
//! with a [`Mesh3d`] — or on a glTF scene's root, and every mesh below it
//! wears the fur once the scene has spawned:
//!
//! ```no_run
//! use bevy::prelude::*;
//! use pelage_bevy::{PelagePlugin, ShellFur};
//!
//! fn setup(mut commands: Commands, assets: Res<AssetServer>) {
//!     commands.spawn((
//!         WorldAssetRoot(assets.load(GltfAssetLabel::Scene(0).from_asset("fox/Fox.gltf"))),
//!         ShellFur(assets.load("fox/fox.shells.toml")),
//!     ));
//! }
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, PelagePlugin::default()))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```
//!
//! The fur is drawn by Bevy's renderer (its device, pipeline cache and
//! main 3D pass) with a [`ShellFurMaterial`]: Bevy skins its layers with
//! the joint matrices it skins the character with, tests them against the
//! depth of everything opaque, lights them with the scene's directional
//! lights, curls and clumps them by the wetness mask, culls them with the
//! character and picks a level of detail per camera
//! ([`VisibilityRange`](bevy::camera::visibility::VisibilityRange)). Its
//! WGSL math and data (tangents, the shell texture's mips, a groom's
//! stand-in) are pelage's shared layer (`pelage-shaders`), the same
//! pelage-gpu draws with. Shells and groom files are assets: edit one and
//! the fur regrows. docs/bevy.md has the whole story and the limits.
//!
//! A groom's strands ([`GroomStrands`]) are grown by pelage's GPU groom
//! shader through Bevy's render device before the main pass, from the skin
//! posed with Bevy's joint matrices, and drawn with a [`StrandMaterial`]
//! (pelage's ribbons and hair model); [`StrandsLod`] hands them over to
//! the stand-in by the character's size on screen.
//!
//! The parts, lowest first: `material.rs` and `hair_material.rs` (the
//! materials, their uniform blocks, the shaders), `mesh.rs` (a fur mesh
//! from a Bevy mesh), `asset.rs` (shells and groom files as assets),
//! `dynamics.rs` (a coat's spring), `probe.rs` (the fur's drawn vertices
//! read back, for tests and tools), `fur.rs` (the shell systems),
//! `strands.rs` (the strands' systems), `grow.rs` (the render world's
//! growth).

mod asset;
mod dynamics;
mod fur;
mod grow;
mod hair_material;
mod material;
mod mesh;
mod probe;
mod strands;

pub use asset::{
    FileReadError, GroomFurAsset, GroomFurLoadError, GroomFurLoader, GroomStrandsSource,
    ShellFurAsset, ShellFurLoadError, ShellFurLoader,
};
pub use dynamics::{FurForces, FurMotion};
pub use fur::{FurLayers, GroomFur, ShellFur, lod_layers};
pub use hair_material::{ATTRIBUTE_RIBBON_CORNER, StrandMaterial, StrandUniform};
pub use material::{ATTRIBUTE_SHELL_LAYER, ShellFurMaterial, ShellFurUniform};
pub use mesh::{FurMeshError, fur_mesh};
pub use pelage_shaders::stand_in::FurLod;
pub use probe::{FurPositionProbe, FurPositionProbePlugin, ProbedShellFurMaterial};
pub use strands::{GroomStrands, StrandsLod};

use bevy::prelude::*;
use std::path::PathBuf;

/// Shell fur for Bevy: the asset and its loader, the material, and the
/// systems that grow, move and choose the fur's detail.
#[derive(Debug, Clone, Default)]
pub struct PelagePlugin {
    /// The folder Bevy reads assets from, as given to `AssetPlugin`
    /// (`None`: Bevy's default, `assets/` beside the app). A shells or
    /// groom file names its mesh, colour and guides relative to itself,
    /// and pelage reads them from disk there.
    pub asset_folder: Option<PathBuf>,
}

impl Plugin for PelagePlugin {
    fn build(&self, app: &mut App) {
        let folder = self.asset_folder.clone().unwrap_or_else(|| {
            bevy::asset::io::file::FileAssetReader::get_base_path().join("assets")
        });
        material::register_shaders(app);
        hair_material::register_shaders(app);
        app.add_plugins((
            MaterialPlugin::<ShellFurMaterial>::default(),
            MaterialPlugin::<StrandMaterial>::default(),
        ))
        .init_asset::<ShellFurAsset>()
        .init_asset::<GroomFurAsset>()
        .register_asset_loader(ShellFurLoader {
            folder: folder.clone(),
        })
        .register_asset_loader(GroomFurLoader { folder })
        .init_resource::<FurForces>()
        .init_resource::<fur::FurCache>()
        .init_resource::<strands::StrandsCache>()
        .init_resource::<StrandsLod>()
        .add_systems(
            Update,
            (
                fur::wear_grooms,
                fur::detach_fur,
                fur::attach_fur,
                strands::detach_strands,
                strands::attach_strands,
                fur::step_dynamics,
            )
                .chain(),
        )
        .add_systems(
            PostUpdate,
            (
                fur::choose_levels,
                // After Bevy's transforms (and the animation before
                // them): the pose Bevy skins this frame with.
                strands::pose_strands
                    .after(bevy::transform::TransformSystems::Propagate)
                    .before(bevy::camera::visibility::VisibilitySystems::CheckVisibility),
                strands::fit_ribbons,
            )
                .chain(),
        );
        grow::build(app);
    }
}
