//! pelage in Bevy: shell fur on Bevy's own meshes and skinned characters.
//!
//! Add [`PelagePlugin`], then put a [`ShellFur`] (a shells file) or a
//! [`GroomFur`] (a groom file, drawn as its shell stand-in) on an entity
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
//! The parts, lowest first: `material.rs` (the material, its uniform
//! block, the shaders), `mesh.rs` (a fur mesh from a Bevy mesh),
//! `asset.rs` (shells and groom files as assets), `dynamics.rs` (a coat's
//! spring), `fur.rs` (the systems), `probe.rs` (the fur's drawn vertices
//! read back, for tests and tools).

mod asset;
mod dynamics;
mod fur;
mod material;
mod mesh;
mod probe;

pub use asset::{
    FileReadError, GroomFurAsset, GroomFurLoadError, GroomFurLoader, ShellFurAsset,
    ShellFurLoadError, ShellFurLoader,
};
pub use dynamics::{FurForces, FurMotion};
pub use fur::{FurLayers, GroomFur, ShellFur, lod_layers};
pub use material::{ATTRIBUTE_SHELL_LAYER, ShellFurMaterial, ShellFurUniform};
pub use mesh::{FurMeshError, fur_mesh};
pub use probe::{FurPositionProbe, FurPositionProbePlugin, ProbedShellFurMaterial};

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
        app.add_plugins(MaterialPlugin::<ShellFurMaterial>::default())
            .init_asset::<ShellFurAsset>()
            .init_asset::<GroomFurAsset>()
            .register_asset_loader(ShellFurLoader {
                folder: folder.clone(),
            })
            .register_asset_loader(GroomFurLoader { folder })
            .init_resource::<FurForces>()
            .init_resource::<fur::FurCache>()
            .add_systems(
                Update,
                (
                    fur::wear_grooms,
                    fur::detach_fur,
                    fur::attach_fur,
                    fur::step_dynamics,
                )
                    .chain(),
            )
            .add_systems(PostUpdate, fur::choose_levels);
    }
}
