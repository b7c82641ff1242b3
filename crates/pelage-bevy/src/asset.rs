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
use pelage::shell::math::{ClumpParams, Coupling, CurlParams, KajiyaKay};
use pelage::shell::{ShellScene, ShellTextures, WetnessMask};
use pelage_shaders::groom::GroomUpload;
use pelage_shaders::hair::StrandLook;
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
    /// Curl (Eq. 4): its radius in mesh units; 0: straight.
    pub curl: CurlParams,
    /// Clumping (Alg. 2), where the wetness mask is wet; `None`: off.
    pub clump: Option<ClumpParams>,
    /// The wetness mask: the file's droplets all fallen (the mask the
    /// scene's timeline holds after its last droplet); `None`: dry.
    pub wetness: Option<Arc<WetnessMask>>,
    /// The tips' spring, if the file has `[dynamics]`.
    pub dynamics: Option<DynamicsParams>,
    /// Level of detail: the most pixels between layers on screen, and the
    /// fewest layers; `None`: every layer at every distance.
    pub lod: Option<(f32, u32)>,
    /// What the file asks for that Bevy does not draw (curl, clumps,
    /// fins, droplets), named so the loader can say so.
    pub left_out: Vec<&'static str>,
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
            curl: scene.curl,
            clump: scene.clump,
            wetness: wetness_after_droplets(scene),
            dynamics: dynamics.map(|d| d.params.clone()),
            lod: scene.lod.map(|l| (l.max_gap_px, l.min_layers)),
            left_out: left_out(scene),
        }
    }
}

/// The mask once every droplet of `scene` has fallen (drying between
/// them as the timeline does); `None` for a dry scene.
fn wetness_after_droplets(scene: &ShellScene) -> Option<Arc<WetnessMask>> {
    let last = scene.droplets.last()?.time;
    let mut timeline = scene.wetness_timeline();
    Some(Arc::new(timeline.advance_to(last).clone()))
}

/// The settings of `scene` that the Bevy plugin does not draw.
fn left_out(scene: &ShellScene) -> Vec<&'static str> {
    let mut out = Vec::new();
    if scene.fins.is_some() {
        out.push("[fins]");
    }
    if scene.droplets.len() > 1 || scene.drying_rate > 0.0 {
        out.push("droplets over time (Bevy draws the mask after the last one)");
    }
    out
}

/// A settings file Bevy could not read.
#[derive(Debug, thiserror::Error)]
#[error("reading {path}: {source}")]
pub struct FileReadError {
    /// The file.
    pub path: PathBuf,
    /// Why.
    #[source]
    pub source: std::io::Error,
}

/// The file `load_context` is loading, read whole, as pelage's settings
/// parsers take it: named by its path on disk under `folder` (errors and
/// relative paths in it need that).
async fn read_settings(
    folder: &std::path::Path,
    reader: &mut dyn Reader,
    load_context: &LoadContext<'_>,
) -> Result<pelage::settings::SettingsSource, FileReadError> {
    let path = folder.join(load_context.path().path());
    let mut bytes = Vec::new();
    match reader.read_to_end(&mut bytes).await {
        Ok(_) => Ok(pelage::settings::SettingsSource {
            path,
            text: String::from_utf8_lossy(&bytes).into_owned(),
        }),
        Err(source) => Err(FileReadError { path, source }),
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
    #[error(transparent)]
    Io(#[from] FileReadError),
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
        let source = read_settings(&self.folder, reader, load_context).await?;
        let scene = ShellScene::from_source(&source)?;
        let fur = ShellFurAsset::from_scene(&scene);
        if !fur.left_out.is_empty() {
            bevy::log::warn!(
                "{}: {} not drawn in Bevy (pelage's own renderer draws them; docs/bevy.md, Limits)",
                source.path.display(),
                fur.left_out.join(", ")
            );
        }
        Ok(fur)
    }

    fn extensions(&self) -> &[&str] {
        &["shells.toml", "toml"]
    }
}

/// Layers of the shell fur that stands in for a groom.
const STAND_IN_LAYERS: u32 = 16;

/// A groom file as Bevy fur: its hairs as real-time strands, grown on
/// the GPU every frame near the camera, and the shell fur that stands in
/// for them far away (their density, length and colour), as a labelled
/// [`ShellFurAsset`].
#[derive(Asset, TypePath, Debug, Clone)]
pub struct GroomFurAsset {
    /// The stand-in, drawn as any shell fur is.
    pub shells: Handle<ShellFurAsset>,
    /// Hairs the groom grows.
    pub hairs: u64,
    /// What the GPU grows the hairs from (`None`: the groom cannot be
    /// grown on the GPU, and the loader said why; the stand-in is drawn
    /// at every distance).
    pub strands: Option<Arc<GroomStrandsSource>>,
}

impl GroomFurAsset {
    /// A groom made in code (or edited) as Bevy fur: its stand-in added to
    /// `shells`, its strands readied for the GPU. A groom file is loaded
    /// as one by [`GroomFurLoader`].
    ///
    /// # Errors
    /// When pelage cannot grow the groom (its mesh, guides or maps).
    pub fn from_groom(
        groom: &pelage::groom::Groom,
        shells: &mut Assets<ShellFurAsset>,
    ) -> Result<Self, GroomFurLoadError> {
        let (stand_in, hairs, strands) = Self::parts(groom)?;
        Ok(Self {
            shells: shells.add(stand_in),
            hairs,
            strands,
        })
    }

    /// The stand-in, the hair count and the strands (`None`, said why in
    /// a warning, when the GPU cannot grow them).
    fn parts(
        groom: &pelage::groom::Groom,
    ) -> Result<(ShellFurAsset, u64, Option<Arc<GroomStrandsSource>>), GroomFurLoadError> {
        let generator = groom.generator(None)?;
        let (shells, hairs) = ShellFurAsset::stand_in_for(groom, &generator)?;
        let path = groom.path().display();
        let strands = match GroomStrandsSource::of(groom, &generator, shells.length) {
            Ok(source) => Some(Arc::new(source)),
            Err(why) => {
                bevy::log::warn!(
                    "pelage: {path}: no real-time strands ({why}); its shell stand-in is drawn at every distance"
                );
                None
            }
        };
        Ok((shells, hairs, strands))
    }
}

/// A groom made ready to grow on the GPU: the arrays uploaded once
/// (pelage-shaders' [`GroomUpload`], its hairs ordered by arrival so the
/// first `k` are a preview fraction's), the guides at rest, the skin it
/// was grown on (to find its vertices in Bevy's mesh) and the look.
#[derive(Debug)]
pub struct GroomStrandsSource {
    /// The recipe's arrays.
    pub upload: GroomUpload,
    /// The guides in rest space, as the shader reads them.
    pub guides: Vec<[f32; 4]>,
    /// The groom's skin at rest, pelage's vertices (welded).
    pub rest: Vec<[f32; 3]>,
    /// Its triangles.
    pub triangles: Vec<[u32; 3]>,
    /// The hair model's numbers.
    pub look: StrandLook,
    /// The guides' mean length (mesh units).
    pub length: f32,
}

impl GroomStrandsSource {
    /// `groom`'s hairs (its `generator`'s) made ready for the GPU; hairs
    /// the groom gives no colour take its skin texture's at their roots.
    ///
    /// # Errors
    /// When the recipe cannot be made, or is too large for the GPU's
    /// registers (more than 32 points a hair).
    pub fn of(
        groom: &pelage::groom::Groom,
        generator: &pelage::groom::Generator,
        length: f32,
    ) -> Result<Self, String> {
        let (roots, ids) = pelage::groom::roots_by_arrival(generator);
        let recipe =
            pelage::groom::GroomRecipe::new(generator, &roots, &ids).map_err(|e| e.to_string())?;
        let mesh = generator.mesh();
        let triangles = mesh.triangles().to_vec();
        let rest = pelage::anim::SkinPose::new(mesh.positions().to_vec(), &triangles);
        let skin = pelage::anim::SkinBinding::new(triangles.clone(), rest);
        let mut upload = GroomUpload::new(&recipe, &skin).map_err(|e| e.to_string())?;
        let render = recipe.render_hairs();
        let render_roots = &recipe.roots[render.start as usize..render.end as usize];
        if let Some(colors) = pelage_shaders::stand_in::root_colors(groom, mesh, render_roots)
            .map_err(|e| e.to_string())?
        {
            upload.color_hairs(&colors);
        }
        let offsets = pelage::groom::GroomRecipe::guide_offsets(generator.guides());
        Ok(Self {
            upload,
            guides: GroomUpload::guide_words(&offsets),
            rest: mesh.positions().iter().map(|p| p.to_array()).collect(),
            triangles,
            look: StrandLook::default(),
            length,
        })
    }
}

/// Reads pelage groom files (`*.groom.toml`, or any `*.toml` loaded as a
/// [`GroomFurAsset`]) from the folder Bevy's assets are in.
#[derive(TypePath)]
pub struct GroomFurLoader {
    /// Bevy's asset folder on disk: a groom file names its mesh, guides
    /// and maps relative to itself.
    pub(crate) folder: PathBuf,
}

/// Why a groom file did not load: pelage's error, with the file and line.
#[derive(Debug, thiserror::Error)]
pub enum GroomFurLoadError {
    /// The file could not be read.
    #[error(transparent)]
    Io(#[from] FileReadError),
    /// pelage refused it (syntax, a key, a range, its mesh, guides, maps).
    #[error(transparent)]
    Groom(#[from] pelage::groom::GroomError),
}

impl ShellFurAsset {
    /// The shell fur standing in for `groom`: pelage's stand-in (the
    /// groom's density of hairs on the skin, its guides' mean length, its
    /// colour texture brightened to meet the strands', its first clump's
    /// clumps), Kajiya-Kay shaded
    /// as a shells file without `[shading]`, with a level of detail.
    pub fn stand_in_for(
        groom: &pelage::groom::Groom,
        generator: &pelage::groom::Generator,
    ) -> Result<(Self, u64), GroomFurLoadError> {
        let hairs = generator.parts().iter().map(|p| p.hair_count).sum();
        let stand_in = pelage_shaders::stand_in::ShellStandIn::of(generator, STAND_IN_LAYERS);
        // The strands' default look (melanin 0.5, redness 0.3), where the
        // groom has no colour texture.
        let hair = StrandLook::default().color;
        let color = stand_in.color_texture(groom, hair)?;
        // Clumped as the groom's first clump is.
        let clumps = pelage_shaders::stand_in::clump_mask(generator);
        Ok((
            Self {
                layers: STAND_IN_LAYERS,
                length: stand_in.length,
                tiles: stand_in.tiles,
                textures: Arc::new(ShellTextures::generate(&stand_in.texture)),
                color: Arc::new(color),
                shading: KajiyaKay {
                    specular: glam::Vec3::new(0.12, 0.11, 0.1),
                    exponent: 30.0,
                    k_shadow: 2.0,
                },
                coupling: Coupling::Bezier,
                curl: CurlParams {
                    radius: 0.0,
                    frequency: 0.0,
                },
                clump: clumps.as_ref().map(|(_, params)| *params),
                wetness: clumps.map(|(mask, _)| Arc::new(mask)),
                dynamics: None,
                lod: Some((0.75, 4)),
                left_out: Vec::new(),
            },
            hairs,
        ))
    }
}

impl AssetLoader for GroomFurLoader {
    type Asset = GroomFurAsset;
    type Settings = ();
    type Error = GroomFurLoadError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<GroomFurAsset, GroomFurLoadError> {
        let source = read_settings(&self.folder, reader, load_context).await?;
        let groom = pelage::groom::Groom::from_source(source)?;
        let (shells, hairs, strands) = GroomFurAsset::parts(&groom)?;
        let shells = load_context.add_labeled_asset("shells", shells);
        Ok(GroomFurAsset {
            shells,
            hairs,
            strands,
        })
    }

    fn extensions(&self) -> &[&str] {
        &["groom.toml", "toml"]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fur_of(text: &str) -> ShellFurAsset {
        let scene = ShellScene::from_source(&pelage::settings::SettingsSource {
            path: "test.shells.toml".into(),
            text: text.into(),
        })
        .unwrap();
        ShellFurAsset::from_scene(&scene)
    }

    fn spot_groom(points: u32) -> pelage::groom::Groom {
        let text = format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 500\nseed = 2\n\
             [guides]\npoints = 6\ngenerate = {{ count = 30, length = 0.08, seed = 5 }}\n\
             [finish]\npoints = {points}\n"
        );
        pelage::groom::Groom::from_text("spot.toml", &text).unwrap()
    }

    /// A groom made in code becomes Bevy fur: its stand-in, and its
    /// strands for the GPU (every hair, in the recipe's order); one the
    /// GPU cannot grow (over 32 points a hair) keeps its stand-in alone.
    #[test]
    fn a_groom_value_becomes_fur_with_strands_where_the_gpu_can_grow_them() {
        let mut shells = Assets::<ShellFurAsset>::default();
        let fur = GroomFurAsset::from_groom(&spot_groom(9), &mut shells).unwrap();
        assert_eq!(fur.hairs, 500);
        assert_eq!(
            shells.get(&fur.shells).map(|s| s.layers),
            Some(STAND_IN_LAYERS)
        );
        let strands = fur.strands.expect("strands");
        assert_eq!(strands.upload.render.len(), 500);
        assert_eq!(strands.upload.points, 9);
        assert_eq!(strands.guides.len(), 30 * 6);
        let too_long = GroomFurAsset::from_groom(&spot_groom(40), &mut shells).unwrap();
        assert!(too_long.strands.is_none());
        assert!(shells.get(&too_long.shells).is_some());
    }

    /// A file's settings reach the asset, and what Bevy does not draw is
    /// named, never dropped silently.
    #[test]
    fn a_shells_file_becomes_fur_and_names_what_bevy_leaves_out() {
        let plain = fur_of("[fur]\nlayers = 12\nlength = 0.5\ntiles = 4\n[lod]\nmax_gap = 1.5\n");
        assert_eq!((plain.layers, plain.length, plain.tiles), (12, 0.5, 4.0));
        assert_eq!(plain.lod, Some((1.5, 4)));
        assert_eq!(plain.textures.layers(), 12);
        assert!(plain.left_out.is_empty(), "{:?}", plain.left_out);
        assert!(plain.dynamics.is_none());
        let fancy = fur_of("[curl]\nradius = 0.3\n[fins]\n[dynamics]\nstiffness = 4.0\n");
        assert_eq!(fancy.left_out, vec!["[fins]"]);
        assert!(fancy.curl.radius > 0.0 && fancy.wetness.is_none());
        assert_eq!(fancy.dynamics.as_ref().map(|d| d.stiffness), Some(4.0));
    }
}
