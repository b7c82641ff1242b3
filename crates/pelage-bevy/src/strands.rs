//! Real-time strands on Bevy's meshes, the main world's half: a loaded
//! [`GroomFur`] puts a strands entity on each mesh it grows on (a ribbon
//! mesh drawn with a [`StrandMaterial`]); every frame the skin is posed
//! here with the joint matrices Bevy skins it with, in pelage's vertex
//! order, and the level of detail is chosen ([`FurLod`]: every hair near,
//! the first hairs by arrival farther, widths × 1/√F, a cross-fade to the
//! groom's shell stand-in, the stand-in alone far away). The render
//! world's half (`grow.rs`) grows the hairs from that pose on the GPU
//! before Bevy's main pass draws them.
//!
//! The groom's skin is pelage's mesh of the groom's file (welded); its
//! vertices are found in Bevy's mesh of the same file by position, so the
//! hairs follow Bevy's skinning vertex for vertex.

use crate::asset::{GroomFurAsset, GroomStrandsSource};
use crate::fur::{FurLayers, GroomFur};
use crate::hair_material::{ATTRIBUTE_RIBBON_CORNER, StrandMaterial, StrandUniform};
use crate::material::ShellFurMaterial;
use bevy::asset::RenderAssetUsages;
use bevy::camera::primitives::Aabb;
use bevy::camera::visibility::NoAutoAabb;
use bevy::mesh::VertexAttributeValues;
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::render_resource::PrimitiveTopology;
use bevy::render::storage::ShaderBuffer;
use pelage_shaders::hair::StrandLook;
use pelage_shaders::stand_in::FurLod;
use std::sync::Arc;

/// A groom's real-time strands on one mesh (a child of the mesh entity).
#[derive(Component, Debug, Clone)]
pub struct GroomStrands {
    /// The mesh entity they grow on.
    pub skin: Entity,
    /// The entity with the [`GroomFur`] they come from.
    pub owner: Entity,
    /// The groom.
    pub(crate) asset: AssetId<GroomFurAsset>,
    /// Render hairs drawn this frame, the first by arrival (0: the shell
    /// stand-in alone).
    pub drawn: u32,
    pub(crate) source: Arc<GroomStrandsSource>,
    pub(crate) skinning: Arc<SkinWeights>,
    /// The skin this frame, pelage's vertices in world space (position,
    /// then normal), as the groom shader reads it.
    pub(crate) pose: Arc<Vec<[f32; 4]>>,
    /// Every hair's points, written by the render world's growth; a
    /// 16-byte stand-in while the strands are not drawn (a crowd keeps
    /// buffers only for its near characters).
    pub(crate) points: Handle<ShaderBuffer>,
    /// Frames the strands have not been drawn (their buffer is let go
    /// after [`KEEP_HIDDEN_BUFFER`] of them).
    hidden_frames: u32,
}

/// Frames strands keep their points buffer while not drawn: a character
/// crossing the hand-over back and forth does not reallocate it each time.
const KEEP_HIDDEN_BUFFER: u32 = 120;

impl GroomStrands {
    /// The buffer the GPU grows the hairs into: every hair's points, `xyz`
    /// and width, point-major (point `j` of hair `h` at `j · hairs + h`;
    /// clump centres first, then the render hairs by arrival).
    pub fn points(&self) -> &Handle<ShaderBuffer> {
        &self.points
    }

    /// Hairs in the points buffer, points a hair, and the render hairs
    /// among them.
    pub fn layout(&self) -> (u32, u32, std::ops::Range<u32>) {
        let u = &self.source.upload;
        (u.hairs, u.points, u.render.clone())
    }

    /// The skin as last posed, pelage's vertices in world space.
    pub fn posed_skin(&self) -> Vec<Vec3> {
        self.pose
            .iter()
            .step_by(2)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect()
    }
}

/// pelage's skin vertices found in Bevy's mesh: each one's rest position
/// and Bevy's joints and weights for it (none on a still mesh).
#[derive(Debug)]
pub(crate) struct SkinWeights {
    rest: Vec<Vec3>,
    joints: Vec<[u16; 4]>,
    weights: Vec<[f32; 4]>,
}

/// On a mesh that wears a groom's strands: whose, and the strands entity
/// (`None`: refused, and said so once).
#[derive(Component, Debug, Clone)]
pub(crate) struct StrandsOnSkin {
    owner: Entity,
    asset: AssetId<GroomFurAsset>,
    strands: Option<Entity>,
}

/// Each groom's ribbon mesh and colours, made once and shared by every
/// mesh wearing it.
#[derive(Resource, Default)]
pub(crate) struct StrandsCache {
    /// By groom and hairs: ribbons for the first `k` render hairs (`k` the
    /// whole groom, a half, a quarter, …).
    ribbons: HashMap<(AssetId<GroomFurAsset>, u32), Handle<Mesh>>,
    colors: HashMap<AssetId<GroomFurAsset>, Handle<ShaderBuffer>>,
}

/// When strands give way to the groom's shell stand-in (by the
/// character's height on screen), for every [`GroomFur`].
#[derive(Resource, Debug, Clone, Copy, Default)]
pub struct StrandsLod(pub FurLod);

/// Finds each of `source`'s skin vertices in `mesh` (same position, to
/// the bit) and takes Bevy's joints and weights for it.
fn skin_weights(source: &GroomStrandsSource, mesh: &Mesh) -> Result<SkinWeights, String> {
    if mesh.try_attributes().is_err() {
        return Err(crate::FurMeshError::RenderWorldOnly.to_string());
    }
    let Some(VertexAttributeValues::Float32x3(positions)) =
        mesh.attribute(Mesh::ATTRIBUTE_POSITION)
    else {
        return Err("the mesh has no positions".into());
    };
    let mut at: HashMap<[u32; 3], usize> = HashMap::default();
    for (i, p) in positions.iter().enumerate() {
        at.entry(p.map(f32::to_bits)).or_insert(i);
    }
    let found: Vec<Option<usize>> = source
        .rest
        .iter()
        .map(|p| at.get(&p.map(f32::to_bits)).copied())
        .collect();
    let missing = found.iter().filter(|f| f.is_none()).count();
    if missing > 0 {
        return Err(format!(
            "{missing} of the groom's {} skin vertices are not in this mesh of {} vertices: the groom grows on another mesh",
            source.rest.len(),
            positions.len()
        ));
    }
    let found: Vec<usize> = found.into_iter().flatten().collect();
    let (joints, weights) = match (
        mesh.attribute(Mesh::ATTRIBUTE_JOINT_INDEX),
        mesh.attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT),
    ) {
        (Some(VertexAttributeValues::Uint16x4(j)), Some(VertexAttributeValues::Float32x4(w))) => (
            found.iter().map(|&i| j[i]).collect(),
            found.iter().map(|&i| w[i]).collect(),
        ),
        _ => (Vec::new(), Vec::new()),
    };
    Ok(SkinWeights {
        rest: found.iter().map(|&i| Vec3::from(positions[i])).collect(),
        joints,
        weights,
    })
}

/// The ribbon mesh of a groom's first `hairs` render hairs: six vertices
/// a segment, each holding its own number.
fn ribbon_mesh(source: &GroomStrandsSource, hairs: u32) -> Mesh {
    let u = &source.upload;
    let count = hairs * pelage_shaders::hair::ribbon_vertices(u.points);
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::RENDER_WORLD,
    )
    .with_inserted_attribute(ATTRIBUTE_RIBBON_CORNER, (0..count).collect::<Vec<u32>>())
}

/// The strands' numbers at full detail.
fn strand_uniform(source: &GroomStrandsSource) -> StrandUniform {
    let (u, look) = (&source.upload, &source.look);
    StrandUniform {
        stride: u.hairs,
        points: u.points,
        first: u.render.start,
        drawn: u.render.len() as u32,
        width_scale: 1.0,
        opacity: 1.0,
        specular: look.specular,
        shift: StrandLook::SHIFT,
        base_color: Vec3::from_array(look.color.to_array()),
        roughness: look.roughness,
        trt: StrandLook::TRT,
        transmission: look.transmission,
        transmission_exponent: StrandLook::TRANSMISSION_EXPONENT,
        pad: 0.0,
    }
}

/// A mesh of the scene's own: neither shell fur nor strands.
type NotFur = (Without<FurLayers>, Without<GroomStrands>);

/// Grows strands on every mesh a loaded groom should be on and isn't yet.
#[allow(clippy::too_many_arguments)]
pub(crate) fn attach_strands(
    mut commands: Commands,
    owners: Query<(Entity, &GroomFur, Option<&Mesh3d>)>,
    children: Query<&Children>,
    skins: Query<(&Mesh3d, Option<&StrandsOnSkin>), NotFur>,
    assets: Res<Assets<GroomFurAsset>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    mut materials: ResMut<Assets<StrandMaterial>>,
    mut cache: ResMut<StrandsCache>,
) {
    for (owner, groom, own_mesh) in &owners {
        let Some(source) = assets.get(&groom.0).and_then(|a| a.strands.clone()) else {
            continue;
        };
        let id = groom.0.id();
        let targets: Vec<Entity> = if own_mesh.is_some() {
            vec![owner]
        } else {
            children.iter_descendants(owner).collect()
        };
        for skin in targets {
            let Ok((mesh3d, worn)) = skins.get(skin) else {
                continue;
            };
            if worn.is_some_and(|w| w.asset == id && w.owner == owner) {
                continue;
            }
            if let Some(old) = worn.and_then(|w| w.strands) {
                commands.entity(old).despawn();
            }
            let Some(mesh) = meshes.get(&mesh3d.0) else {
                continue;
            };
            let skinning = match skin_weights(&source, mesh) {
                Ok(w) => Arc::new(w),
                Err(why) => {
                    bevy::log::warn!("pelage: no strands on mesh entity {skin}: {why}");
                    commands.entity(skin).insert(StrandsOnSkin {
                        owner,
                        asset: id,
                        strands: None,
                    });
                    continue;
                }
            };
            let all = source.upload.render.len() as u32;
            let ribbons = cache
                .ribbons
                .entry((id, all))
                .or_insert_with(|| meshes.add(ribbon_mesh(&source, all)))
                .clone();
            let colors = cache
                .colors
                .entry(id)
                .or_insert_with(|| {
                    let shade = bytemuck::cast_slice(&source.upload.shade);
                    buffers.add(ShaderBuffer::new(shade, RenderAssetUsages::RENDER_WORLD))
                })
                .clone();
            let points = buffers.add(ShaderBuffer::with_size(16, RenderAssetUsages::RENDER_WORLD));
            let material = materials.add(StrandMaterial {
                strands: strand_uniform(&source),
                points: points.clone(),
                colors,
            });
            let strands = commands
                .spawn((
                    Name::new("pelage strands"),
                    Mesh3d(ribbons),
                    MeshMaterial3d(material),
                    Transform::IDENTITY,
                    // Shown once posed and in range (pose_strands).
                    Visibility::Hidden,
                    // Bevy's bounds of the ribbon mesh would say nothing
                    // of where the hairs are: pose_strands sets them from
                    // the posed skin each frame, so each camera culls.
                    NoAutoAabb,
                    Aabb::default(),
                    GroomStrands {
                        skin,
                        owner,
                        asset: id,
                        drawn: 0,
                        source: source.clone(),
                        skinning,
                        pose: Arc::default(),
                        points,
                        hidden_frames: KEEP_HIDDEN_BUFFER,
                    },
                    ChildOf(skin),
                ))
                .id();
            commands.entity(skin).insert(StrandsOnSkin {
                owner,
                asset: id,
                strands: Some(strands),
            });
        }
    }
}

/// A changed or removed groom, or a removed [`GroomFur`], takes its
/// strands away; [`attach_strands`] grows the new ones.
pub(crate) fn detach_strands(
    mut commands: Commands,
    mut events: MessageReader<AssetEvent<GroomFurAsset>>,
    mut removed: RemovedComponents<GroomFur>,
    skins: Query<(Entity, &StrandsOnSkin)>,
    mut cache: ResMut<StrandsCache>,
) {
    let mut stale = Vec::new();
    for event in events.read() {
        if let AssetEvent::Modified { id } | AssetEvent::Removed { id } = event {
            cache.ribbons.retain(|(asset, _), _| asset != id);
            cache.colors.remove(id);
            stale.push(*id);
        }
    }
    let gone: Vec<Entity> = removed.read().collect();
    for (skin, worn) in &skins {
        if stale.contains(&worn.asset) || gone.contains(&worn.owner) {
            if let Some(e) = worn.strands {
                commands.entity(e).despawn();
            }
            commands.entity(skin).remove::<StrandsOnSkin>();
        }
    }
}

/// The skin in world space this frame, pelage's vertices: Bevy's joint
/// matrices (each joint's world transform times its inverse bind pose,
/// weighted per vertex, as Bevy skins), or the mesh's own transform.
fn posed_skin(
    weights: &SkinWeights,
    skin: (&GlobalTransform, Option<&SkinnedMesh>),
    joints: &Query<&GlobalTransform>,
    bindposes: &Assets<SkinnedMeshInverseBindposes>,
) -> Option<Vec<Vec3>> {
    let (transform, skinned) = skin;
    let Some(skinned) = skinned.filter(|_| !weights.joints.is_empty()) else {
        let m = transform.affine();
        return Some(
            weights
                .rest
                .iter()
                .map(|&p| m.transform_point3(p))
                .collect(),
        );
    };
    let inverse = bindposes.get(&skinned.inverse_bindposes)?;
    let matrices: Vec<Mat4> = skinned
        .joints
        .iter()
        .zip(inverse.iter())
        .map(|(&j, ibp)| Some(joints.get(j).ok()?.affine() * *ibp))
        .collect::<Option<_>>()?;
    let posed = weights
        .rest
        .iter()
        .zip(&weights.joints)
        .zip(&weights.weights)
        .map(|((&p, j), w)| {
            let m: Mat4 = (0..4)
                .map(|k| matrices.get(j[k] as usize).copied().unwrap_or(Mat4::ZERO) * w[k])
                .fold(Mat4::ZERO, |a, b| a + b);
            m.transform_point3(p)
        })
        .collect();
    Some(posed)
}

/// The hairs' bounds in the strands entity's space (it sits at its skin's
/// `transform`): the posed skin's world bounds, grown by `reach` (a hair's
/// length).
fn local_bounds((lo, hi): (Vec3, Vec3), reach: f32, transform: &GlobalTransform) -> Aabb {
    let (lo, hi) = (lo - Vec3::splat(reach), hi + Vec3::splat(reach));
    let local = transform.affine().inverse();
    let (a, b) = (0..8)
        .map(|corner| {
            let pick = |bit: usize, a: f32, b: f32| if corner & bit == 0 { a } else { b };
            local.transform_point3(Vec3::new(
                pick(1, lo.x, hi.x),
                pick(2, lo.y, hi.y),
                pick(4, lo.z, hi.z),
            ))
        })
        .fold((Vec3::MAX, Vec3::MIN), |(a, b), p| (a.min(p), b.max(p)));
    Aabb::from_min_max(a, b)
}

/// The first perspective camera's position, field of view and target
/// height in pixels.
fn first_camera(
    cameras: &Query<(&Camera, &Projection, &GlobalTransform)>,
) -> Option<(Vec3, f32, f32)> {
    cameras
        .iter()
        .find_map(|(camera, projection, at)| match projection {
            Projection::Perspective(p) if camera.is_active => camera
                .logical_viewport_size()
                .map(|size| (at.translation(), p.fov, size.y)),
            _ => None,
        })
}

/// Poses every strands entity's skin for the render world to grow the
/// hairs on, and picks its level of detail: how many hairs, how wide,
/// how opaque, and how opaque the shell stand-in beside them is.
#[allow(clippy::too_many_arguments)]
pub(crate) fn pose_strands(
    mut strands: Query<(
        &mut GroomStrands,
        &MeshMaterial3d<StrandMaterial>,
        &mut Visibility,
        &mut Aabb,
    )>,
    skins: Query<(&GlobalTransform, Option<&SkinnedMesh>)>,
    joints: Query<&GlobalTransform>,
    bindposes: Res<Assets<SkinnedMeshInverseBindposes>>,
    cameras: Query<(&Camera, &Projection, &GlobalTransform)>,
    lod: Res<StrandsLod>,
    mut materials: ResMut<Assets<StrandMaterial>>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    mut shells: Query<
        (
            &FurLayers,
            &MeshMaterial3d<ShellFurMaterial>,
            &mut Visibility,
        ),
        Without<GroomStrands>,
    >,
    mut shell_materials: ResMut<Assets<ShellFurMaterial>>,
) {
    let camera = first_camera(&cameras);
    for (mut hairs, material, mut visibility, mut bounds) in &mut strands {
        let Ok(skin) = skins.get(hairs.skin) else {
            continue;
        };
        let Some(posed) = posed_skin(&hairs.skinning, skin, &joints, &bindposes) else {
            continue;
        };
        let (lo, hi) = posed.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
        let reach = hairs.source.length * skin.0.scale().max_element();
        let wanted = local_bounds((lo, hi), reach, skin.0);
        if *bounds != wanted {
            *bounds = wanted;
        }
        // The character's size on screen (its largest side at its centre's
        // distance), as pelage-gpu's RealtimeFur measures it.
        let height_px = camera.map_or(f32::INFINITY, |(eye, fov, screen)| {
            let centre = 0.5 * (lo + hi);
            let d = eye.distance(centre).max(1e-6);
            (hi - lo).max_element() * screen / (2.0 * d * (fov / 2.0).tan())
        });
        let level = lod.0.level(height_px);
        let render = hairs.source.upload.render.len() as u32;
        let drawn = if level.strand_opacity > 0.0 {
            ((render as f32 * level.fraction * level.strand_opacity).round() as u32).min(render)
        } else {
            0
        };
        hairs.drawn = drawn;
        // The skin's normals and the shader's layout only for strands the
        // render world grows: a far crowd's are not.
        if drawn > 0 {
            let pelage_posed = posed
                .iter()
                .map(|p| glam::Vec3::from_array(p.to_array()))
                .collect();
            let pose = pelage::anim::SkinPose::new(pelage_posed, &hairs.source.triangles);
            hairs.pose = Arc::new(pelage_shaders::groom::skin_vertices(&pose));
        }
        hairs.hidden_frames = if drawn > 0 {
            0
        } else {
            hairs.hidden_frames.saturating_add(1)
        };
        let bytes = hairs.source.upload.points_bytes();
        let has_buffer = buffers
            .get(&hairs.points)
            .is_some_and(|b| b.buffer_description.size == bytes);
        let swap = if drawn > 0 && !has_buffer {
            Some(ShaderBuffer::with_size(
                bytes as usize,
                RenderAssetUsages::RENDER_WORLD,
            ))
        } else if hairs.hidden_frames == KEEP_HIDDEN_BUFFER && has_buffer {
            Some(ShaderBuffer::with_size(16, RenderAssetUsages::RENDER_WORLD))
        } else {
            None
        };
        if let Some(buffer) = swap {
            buffers.remove(&hairs.points);
            hairs.points = buffers.add(buffer);
            if let Some(mut m) = materials.get_mut(&material.0) {
                m.points = hairs.points.clone();
            }
        }
        let wanted = if drawn > 0 {
            Visibility::Inherited
        } else {
            Visibility::Hidden
        };
        visibility.set_if_neq(wanted);
        // Written only when they change: a changed material is prepared
        // again.
        let numbers = (drawn, 1.0 / level.fraction.sqrt(), level.strand_opacity);
        let now = materials
            .get(&material.0)
            .map(|m| (m.strands.drawn, m.strands.width_scale, m.strands.opacity));
        if now.is_some_and(|now| now != numbers)
            && let Some(mut m) = materials.get_mut(&material.0)
        {
            (m.strands.drawn, m.strands.width_scale, m.strands.opacity) = numbers;
        }
        for (layers, shell, mut shown) in &mut shells {
            if layers.owner != hairs.owner || layers.skin != hairs.skin {
                continue;
            }
            let wanted = if level.shell_opacity > 0.0 {
                Visibility::Inherited
            } else {
                Visibility::Hidden
            };
            shown.set_if_neq(wanted);
            let opacity = level.shell_opacity.max(1e-3);
            if shell_materials
                .get(&shell.0)
                .is_some_and(|m| m.fur.opacity != opacity)
                && let Some(mut m) = shell_materials.get_mut(&shell.0)
            {
                m.fur.opacity = opacity;
            }
        }
    }
}

/// Gives each strands entity the ribbon mesh of the fewest hairs that
/// holds the ones drawn (the whole groom, a half, a quarter, … down to a
/// 64th): far characters run the vertex stage for about the hairs they
/// draw, not for every hair of the groom.
pub(crate) fn fit_ribbons(
    mut strands: Query<(&GroomStrands, &mut Mesh3d)>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut cache: ResMut<StrandsCache>,
) {
    for (hairs, mut mesh) in &mut strands {
        if hairs.drawn == 0 {
            continue;
        }
        let all = hairs.source.upload.render.len() as u32;
        let mut k = all;
        for _ in 0..6 {
            if k / 2 < hairs.drawn {
                break;
            }
            k /= 2;
        }
        let ribbons = cache
            .ribbons
            .entry((hairs.asset, k))
            .or_insert_with(|| meshes.add(ribbon_mesh(&hairs.source, k)))
            .clone();
        if mesh.0 != ribbons {
            mesh.0 = ribbons;
        }
    }
}
