//! The systems that put shell fur on Bevy's meshes and keep it there: a
//! [`ShellFur`] component grows fur on its entity's mesh, or on every
//! mesh below it (a glTF scene, spawned later); a reloaded or replaced
//! asset regrows it; the coat's spring steps with the entity's motion;
//! each level of detail is shown at the distances where its layers stand
//! at most the file's pixel gap apart on the camera's screen.

use crate::asset::{GroomFurAsset, ShellFurAsset};
use crate::dynamics::{FurForces, FurMotion};
use crate::material::{ShellFurMaterial, ShellFurUniform};
use crate::mesh::fur_mesh;
use bevy::asset::RenderAssetUsages;
use bevy::camera::primitives::Aabb;
use bevy::camera::visibility::{NoFrustumCulling, VisibilityRange};
use bevy::image::{ImageAddressMode, ImageFilterMode, ImageSampler, ImageSamplerDescriptor};
use bevy::mesh::skinning::SkinnedMesh;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};

/// Shell fur on this entity's mesh, or, on an entity without a
/// [`Mesh3d`] (a glTF scene's root), on every mesh below it.
#[derive(Component, Debug, Clone)]
pub struct ShellFur(pub Handle<ShellFurAsset>);

/// A groom on this entity's mesh, or on every mesh below it: drawn as
/// the shell fur that stands in for it (the plugin gives the entity that
/// [`ShellFur`] once the groom has loaded, and takes it away with this).
#[derive(Component, Debug, Clone)]
pub struct GroomFur(pub Handle<GroomFurAsset>);

/// A fur entity (a child of the mesh it grows on): its layers and level
/// of detail.
#[derive(Component, Debug, Clone)]
pub struct FurLayers {
    /// The mesh entity it grows on.
    pub skin: Entity,
    /// The entity with the [`ShellFur`] it comes from.
    pub owner: Entity,
    /// Layers of this level.
    pub layers: u32,
    /// 0: full detail; each next level has half the layers.
    pub level: usize,
}

/// On a mesh that wears fur: what it wears and its fur entities.
#[derive(Component, Debug, Clone)]
pub(crate) struct FurredSkin {
    owner: Entity,
    asset: AssetId<ShellFurAsset>,
    fur: Vec<Entity>,
}

/// Each asset's shell texture and colour as Bevy images, and each
/// (mesh, layers)'s fur mesh, made once and shared (a crowd of one
/// character holds one copy).
#[derive(Resource, Default)]
pub(crate) struct FurCache {
    images: HashMap<AssetId<ShellFurAsset>, FurImages>,
    meshes: HashMap<(AssetId<Mesh>, u32), Handle<Mesh>>,
}

/// One asset's images: shell texture, colour, wetness mask.
#[derive(Clone)]
struct FurImages {
    layers: Handle<Image>,
    color: Handle<Image>,
    wetness: Handle<Image>,
}

/// The layer counts of the levels of detail: all, then halves down to
/// the file's fewest.
pub fn lod_layers(fur: &ShellFurAsset) -> Vec<u32> {
    let mut levels = vec![fur.layers.max(1)];
    if let Some((_, min_layers)) = fur.lod {
        while let Some(&last) = levels.last() {
            let next = last / 2;
            if next < min_layers.max(1) || next == 0 {
                break;
            }
            levels.push(next);
        }
    }
    levels
}

/// A mesh fur may grow on: its mesh, its skin (if skinned), what it
/// wears now, and whether it is exempt from culling.
type SkinItem = (
    &'static Mesh3d,
    Option<&'static SkinnedMesh>,
    Option<&'static FurredSkin>,
    Has<NoFrustumCulling>,
);

/// Grows fur on every mesh that should wear it and doesn't yet.
#[allow(clippy::too_many_arguments)]
pub(crate) fn attach_fur(
    mut commands: Commands,
    owners: Query<(Entity, &ShellFur, Option<&Mesh3d>)>,
    children: Query<&Children>,
    // Not pelage's own fur: shell levels, or strands' ribbons.
    skins: Query<
        SkinItem,
        (
            Without<FurLayers>,
            Without<MeshMaterial3d<crate::hair_material::StrandMaterial>>,
        ),
    >,
    assets: Res<Assets<ShellFurAsset>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut images: ResMut<Assets<Image>>,
    mut materials: ResMut<Assets<ShellFurMaterial>>,
    mut cache: ResMut<FurCache>,
) {
    for (owner, shell_fur, own_mesh) in &owners {
        let Some(fur) = assets.get(&shell_fur.0) else {
            continue;
        };
        let targets: Vec<Entity> = if own_mesh.is_some() {
            vec![owner]
        } else {
            children.iter_descendants(owner).collect()
        };
        for skin in targets {
            let Ok((mesh3d, skinned, furred, unculled)) = skins.get(skin) else {
                continue;
            };
            if furred.is_some_and(|f| f.asset == shell_fur.0.id() && f.owner == owner) {
                continue;
            }
            // A mesh's own ShellFur wins over a scene root's above it; of
            // two roots, the one that furred it first keeps it.
            if let Some(f) = furred
                && f.owner != owner
                && owner != skin
                && owners.contains(f.owner)
            {
                continue;
            }
            let Some(skin_mesh) = meshes.get(&mesh3d.0) else {
                continue;
            };
            if let Some(old) = furred {
                for &e in &old.fur {
                    commands.entity(e).despawn();
                }
            }
            // Each level's fur mesh: shared by every mesh of this shape.
            let levels = lod_layers(fur);
            let mut made = Vec::new();
            let mut refused = false;
            for &layers in &levels {
                if !cache.meshes.contains_key(&(mesh3d.0.id(), layers)) {
                    match fur_mesh(skin_mesh, layers) {
                        Ok(m) => made.push((layers, m)),
                        Err(e) => {
                            bevy::log::warn!("pelage: no shell fur on mesh entity {skin}: {e}");
                            refused = true;
                            break;
                        }
                    }
                }
            }
            if refused {
                // Said once: the mesh is not tried again until the asset
                // or the component changes.
                commands.entity(skin).insert(FurredSkin {
                    owner,
                    asset: shell_fur.0.id(),
                    fur: Vec::new(),
                });
                continue;
            }
            for (layers, m) in made {
                let handle = meshes.add(m);
                cache.meshes.insert((mesh3d.0.id(), layers), handle);
            }
            let textures = cache
                .images
                .entry(shell_fur.0.id())
                .or_insert_with(|| fur_images(fur, &mut images))
                .clone();
            let mut spawned = Vec::new();
            for (level, layers) in levels.into_iter().enumerate() {
                let Some(mesh) = cache.meshes.get(&(mesh3d.0.id(), layers)).cloned() else {
                    break;
                };
                let material = materials.add(ShellFurMaterial {
                    fur: uniform(fur, layers),
                    layers: textures.layers.clone(),
                    color: textures.color.clone(),
                    wetness: textures.wetness.clone(),
                });
                let mut e = commands.spawn((
                    Name::new(format!("pelage fur ({layers} layers)")),
                    Mesh3d(mesh),
                    MeshMaterial3d(material),
                    Transform::IDENTITY,
                    FurLayers {
                        skin,
                        owner,
                        layers,
                        level,
                    },
                    ChildOf(skin),
                ));
                if let Some(s) = skinned {
                    e.insert(s.clone());
                }
                if unculled {
                    e.insert(NoFrustumCulling);
                }
                spawned.push(e.id());
            }
            commands.entity(skin).insert(FurredSkin {
                owner,
                asset: shell_fur.0.id(),
                fur: spawned,
            });
            commands.entity(owner).insert_if_new(FurMotion::default());
        }
    }
}

/// Gives an entity with a loaded [`GroomFur`] its stand-in's
/// [`ShellFur`]; a removed `GroomFur` takes it away.
pub(crate) fn wear_grooms(
    mut commands: Commands,
    grooms: Query<(Entity, &GroomFur, Option<&ShellFur>)>,
    mut removed: RemovedComponents<GroomFur>,
    assets: Res<Assets<GroomFurAsset>>,
) {
    for (entity, groom, worn) in &grooms {
        let Some(asset) = assets.get(&groom.0) else {
            continue;
        };
        if worn.is_none_or(|w| w.0 != asset.shells) {
            commands
                .entity(entity)
                .insert(ShellFur(asset.shells.clone()));
        }
    }
    for entity in removed.read() {
        if let Ok(mut e) = commands.get_entity(entity) {
            e.remove::<ShellFur>();
        }
    }
}

/// A changed or removed asset, or a removed [`ShellFur`], takes its fur
/// away; [`attach_fur`] grows the new one.
pub(crate) fn detach_fur(
    mut commands: Commands,
    mut events: MessageReader<AssetEvent<ShellFurAsset>>,
    mut removed: RemovedComponents<ShellFur>,
    skins: Query<(Entity, &FurredSkin)>,
    mut cache: ResMut<FurCache>,
) {
    let mut stale = Vec::new();
    for event in events.read() {
        if let AssetEvent::Modified { id } | AssetEvent::Removed { id } = event {
            cache.images.remove(id);
            stale.push(*id);
        }
    }
    let gone: Vec<Entity> = removed.read().collect();
    for (skin, furred) in &skins {
        if stale.contains(&furred.asset) || gone.contains(&furred.owner) {
            for &e in &furred.fur {
                commands.entity(e).despawn();
            }
            commands.entity(skin).remove::<FurredSkin>();
        }
    }
}

/// Steps each coat's spring and hands its tips' offset to its materials.
pub(crate) fn step_dynamics(
    time: Res<Time>,
    forces: Res<FurForces>,
    assets: Res<Assets<ShellFurAsset>>,
    mut owners: Query<(&ShellFur, &GlobalTransform, &mut FurMotion)>,
    fur: Query<(&FurLayers, &MeshMaterial3d<ShellFurMaterial>)>,
    mut materials: ResMut<Assets<ShellFurMaterial>>,
) {
    let dt = time.delta_secs();
    for (shell_fur, transform, mut motion) in &mut owners {
        let Some(asset) = assets.get(&shell_fur.0) else {
            continue;
        };
        let Some(params) = &asset.dynamics else {
            continue;
        };
        let reach = 0.9 * asset.length * transform.scale().max_element();
        motion.step(params, &forces, transform.translation(), dt, reach);
    }
    for (layers, material) in &fur {
        let Ok((_, _, motion)) = owners.get(layers.owner) else {
            continue;
        };
        // Only a spring that moved visibly touches the material (a touched
        // material is uploaded again); one settling by less than a
        // thousandth of the fur's length leaves it.
        if materials
            .get(&material.0)
            .is_some_and(|m| m.fur.tip_offset.distance(motion.offset) > 1e-3 * m.fur.length)
            && let Some(mut m) = materials.get_mut(&material.0)
        {
            m.fur.tip_offset = motion.offset;
        }
    }
}

/// Each level of detail drawn only at the distances where its layers
/// stand at most the file's gap apart on screen (and no fur where all of
/// it would be shorter than one gap), for the camera's
/// projection (the first perspective camera); and the fur's bounds are
/// its skin's, grown by the fur's length, so it is culled with it.
pub(crate) fn choose_levels(
    mut commands: Commands,
    cameras: Query<(&Camera, &Projection)>,
    assets: Res<Assets<ShellFurAsset>>,
    owners: Query<(&ShellFur, &GlobalTransform)>,
    skins: Query<&Aabb, Without<FurLayers>>,
    fur: Query<(Entity, &FurLayers, Option<&VisibilityRange>, Option<&Aabb>)>,
) {
    let screen = cameras
        .iter()
        .find_map(|(camera, projection)| match projection {
            Projection::Perspective(p) => {
                camera.logical_viewport_size().map(|size| (size.y, p.fov))
            }
            _ => None,
        });
    for (entity, layers, range, aabb) in &fur {
        let Ok((shell_fur, owner)) = owners.get(layers.owner) else {
            continue;
        };
        let Some(asset) = assets.get(&shell_fur.0) else {
            continue;
        };
        let length = asset.length * owner.scale().max_element();
        if let Ok(skin) = skins.get(layers.skin) {
            let grown = Aabb {
                center: skin.center,
                half_extents: skin.half_extents + bevy::math::Vec3A::splat(asset.length),
            };
            if aabb != Some(&grown) {
                commands.entity(entity).insert(grown);
            }
        }
        let (Some((max_gap, _)), Some((height_px, fov))) = (asset.lod, screen) else {
            continue;
        };
        // Layers of n stand length·px_per_unit / n apart: at distance d
        // px_per_unit = height / (2 d tan(fov/2)), so n layers are enough
        // from d = D / n on, D = length · height / (2 tan(fov/2) · gap).
        let d = length * height_px / (2.0 * (fov / 2.0).tan() * max_gap.max(1e-3));
        let levels = lod_layers(asset);
        let start = if layers.level == 0 {
            0.0
        } else {
            d / layers.layers as f32
        };
        // Past d the whole fur is shorter on screen than one gap: none is
        // drawn there (the skin's own colour carries it).
        let end = match levels.get(layers.level + 1) {
            Some(&next) => d / next as f32,
            None => d,
        };
        let wanted = VisibilityRange::abrupt(start, end);
        if range != Some(&wanted) {
            commands.entity(entity).insert(wanted);
        }
    }
}

/// The uniform block of one level.
fn uniform(fur: &ShellFurAsset, layers: u32) -> ShellFurUniform {
    let (coupling, coupling_exponent) = match fur.coupling {
        pelage::shell::Coupling::Bent { exponent } => (2, exponent),
        c => (c.index(), 2.0),
    };
    ShellFurUniform {
        tip_offset: Vec3::ZERO,
        length: fur.length,
        specular: Vec3::from_array(fur.shading.specular.to_array()),
        exponent: fur.shading.exponent,
        layers,
        coupling,
        coupling_exponent,
        tiles: fur.tiles,
        k_shadow: fur.shading.k_shadow,
        opacity: 1.0,
        color_gain: 1.0,
        effects: effects(fur),
        curl_radius: fur.curl.radius,
        curl_frequency: fur.curl.frequency,
        clump_w: fur.clump.map_or(0.0, |c| c.w),
        clump_strength: fur.clump.map_or(0.0, |c| c.strength),
        wetness_size: fur.wetness.as_ref().map_or(Vec2::ONE, |m| {
            Vec2::new(m.width() as f32, m.height() as f32)
        }),
    }
}

/// Which of curl and clumps `fur` draws: curl wherever it has a radius
/// (dry fur curls most), clumps only where the mask is wet.
fn effects(fur: &ShellFurAsset) -> u32 {
    let mut bits = 0;
    if fur.curl.radius > 0.0 {
        bits |= ShellFurUniform::CURL;
    }
    if fur.wetness.is_some() && fur.clump.is_some_and(|c| c.strength > 0.0) {
        bits |= ShellFurUniform::CLUMP;
    }
    bits
}

/// The shell texture (one slice a layer, pelage's mip chain, repeating),
/// the colour (sRGB) and the wetness mask (a dry texel without one) as
/// Bevy images.
fn fur_images(fur: &ShellFurAsset, images: &mut Assets<Image>) -> FurImages {
    let t = &fur.textures;
    let (data, mips) = pelage_shaders::shell::fur_mip_chain(t);
    // Every level of every layer, layer by layer (Bevy's default
    // layer-major order, as pelage-gpu uploads them).
    let mut layers = Image::new_uninit(
        Extent3d {
            width: t.resolution(),
            height: t.resolution(),
            depth_or_array_layers: t.layers(),
        },
        TextureDimension::D2,
        TextureFormat::Rgba8Unorm,
        RenderAssetUsages::RENDER_WORLD,
    );
    layers.data = Some(data);
    layers.texture_descriptor.mip_level_count = mips;
    layers.sampler = ImageSampler::Descriptor(ImageSamplerDescriptor {
        address_mode_u: ImageAddressMode::Repeat,
        address_mode_v: ImageAddressMode::Repeat,
        mag_filter: ImageFilterMode::Linear,
        min_filter: ImageFilterMode::Linear,
        mipmap_filter: ImageFilterMode::Linear,
        ..default()
    });
    let c = &fur.color;
    let color = Image::new(
        Extent3d {
            width: c.width(),
            height: c.height(),
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        c.as_raw().clone(),
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    );
    let (size, texels) = match &fur.wetness {
        Some(m) => ((m.width(), m.height()), m.to_rgba()),
        None => ((1, 1), vec![[0.0; 4]]),
    };
    let wetness = Image::new(
        Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        texels
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect(),
        TextureFormat::Rgba32Float,
        RenderAssetUsages::RENDER_WORLD,
    );
    FurImages {
        layers: images.add(layers),
        color: images.add(color),
        wetness: images.add(wetness),
    }
}
