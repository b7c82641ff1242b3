//! Shell fur as a Bevy asset: what a pelage shells file gives a furred
//! mesh (layers, length, the shell texture, colour, shading, dynamics,
//! level of detail). Loaded from a shells file by [`ShellFurLoader`]
//! (hot-reloaded when it changes) or made in code from a
//! [`ShellScene`]. The file's own mesh is read only for its size (the
//! fur's default length is a share of it); the fur grows on the Bevy mesh
//! the component is on.

use bevy::asset::io::Reader;
use bevy::asset::{AssetLoader, LoadContext};
use bevy::prelude::*;
use pelage::dynamics::DynamicsParams;
use pelage::shell::math::{Coupling, KajiyaKay};
use pelage::shell::{ShellScene, ShellTextures};
use std::path::PathBuf;
use std::sync::Arc;

/// Shell fur's settings and textures, ready to put on any mesh.
#[derive(Asset, TypePath, Debug, Clone)]
pub struct ShellFurAsset {
    /// Layers at full detail.
    pub layers: u32,
    /// The outermost layer's height above the skin (mesh units).
    pub length: f32,
    /// Shell texture repeats across the UV square.
    pub tiles: f32,
    /// The shell texture (one slice a layer).
    pub textures: Arc<ShellTextures>,
    /// The fur's colour (sRGB), read at the mesh's UVs.
    pub color: Arc<image::RgbaImage>,
    /// Kajiya-Kay's specular colour, exponent and `K_shadow`.
    pub shading: KajiyaKay,
    /// How the tips bend the layers.
    pub coupling: Coupling,
    /// The tips' spring, if the file has `[dynamics]`.
    pub dynamics: Option<DynamicsParams>,
    /// Level of detail: the most pixels between layers on screen, and the
    /// fewest layers; `None`: every layer at every distance.
    pub lod: Option<(f32, u32)>,
}

impl ShellFurAsset {
    /// The fur a loaded shells scene describes.
    pub fn from_scene(scene: &ShellScene) -> Self {
        let dynamics = scene.dynamics.as_ref();
        Self {
            layers: scene.fur.layers,
            length: scene.fur.length,
            tiles: scene.fur.tiles,
            textures: Arc::new(ShellTextures::generate(&scene.texture)),
            color: Arc::new(scene.color.clone()),
            shading: scene.shading.kajiya_kay,
            coupling: dynamics.map_or(Coupling::Bezier, |d| d.coupling),
            dynamics: dynamics.map(|d| d.params.clone()),
            lod: scene.lod.map(|l| (l.max_gap_px, l.min_layers)),
        }
    }
}

/// Reads pelage shells files (`*.shells.toml`, or any `*.toml` loaded as
/// shell fur) from the folder Bevy's assets are in.
#[derive(TypePath)]
pub struct ShellFurLoader {
    /// Bevy's asset folder on disk: a shells file names its mesh and
    /// colour relative to itself, and pelage reads them from there.
    pub(crate) folder: PathBuf,
}

/// Why a shells file did not load: pelage's error, with the file and line.
#[derive(Debug, thiserror::Error)]
pub enum ShellFurLoadError {
    /// The file could not be read.
    #[error("reading {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// pelage refused it (syntax, a key, a range, its mesh or colour).
    #[error(transparent)]
    Scene(#[from] pelage::shell::SceneError),
}

impl AssetLoader for ShellFurLoader {
    type Asset = ShellFurAsset;
    type Settings = ();
    type Error = ShellFurLoadError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<ShellFurAsset, ShellFurLoadError> {
        let path = self.folder.join(load_context.path().path());
        let mut bytes = Vec::new();
        reader
            .read_to_end(&mut bytes)
            .await
            .map_err(|source| ShellFurLoadError::Io {
                path: path.clone(),
                source,
            })?;
        let source = pelage::settings::SettingsSource {
            path: path.clone(),
            text: String::from_utf8_lossy(&bytes).into_owned(),
        };
        let scene = ShellScene::from_source(&source)?;
        Ok(ShellFurAsset::from_scene(&scene))
    }

    fn extensions(&self) -> &[&str] {
        &["shells.toml", "toml"]
    }
}
