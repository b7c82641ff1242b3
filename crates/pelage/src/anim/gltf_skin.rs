//! glTF animation evaluated by pelage: node animations (translation,
//! rotation, scale; step, linear and cubic-spline samplers) and
//! linear-blend skinning (glTF 2.0 §3.7.3: a vertex is
//! `Σ wᵢ · G(jointᵢ) · IBMᵢ · v`, `G` a joint's global transform and `IBM`
//! its inverse bind matrix). Meshes without a skin follow their node.
//!
//! Vertices are those of pelage's welded glTF mesh (`mesh/gltf.rs`): each
//! is skinned as the first file vertex it was welded from.

use super::rig::{Influence, SkinRig};
use crate::mesh::gltf::{ParsedGltf, check_accessor};
use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::animation::{Interpolation, Property, util::ReadOutputs};

/// One animation of a glTF file, ready to pose its mesh at any time.
#[derive(Debug, Clone)]
pub(crate) struct GltfAnimation {
    /// The animation's name (or `#index`), for messages.
    pub name: String,
    /// Its length in seconds (the latest key).
    pub duration: f32,
    nodes: Vec<NodeRest>,
    /// Nodes, parents before children.
    order: Vec<usize>,
    channels: Vec<Channel>,
    skins: Vec<Skin>,
    rig: SkinRig,
}

#[derive(Debug, Clone, Copy)]
struct NodeRest {
    parent: Option<usize>,
    translation: Vec3,
    rotation: Quat,
    scale: Vec3,
}

#[derive(Debug, Clone)]
struct Channel {
    node: usize,
    property: Property,
    interpolation: Interpolation,
    times: Vec<f32>,
    /// Per key (three per key for cubic splines: in-tangent, value,
    /// out-tangent), xyz or xyzw.
    values: Vec<Vec4>,
}

#[derive(Debug, Clone)]
struct Skin {
    joints: Vec<usize>,
    inverse_bind: Vec<Mat4>,
}

/// The names of a file's animations, for messages.
pub(crate) fn animation_names(parsed: &ParsedGltf) -> Vec<String> {
    parsed
        .document
        .animations()
        .map(|a| {
            a.name()
                .map_or_else(|| format!("#{}", a.index()), str::to_string)
        })
        .collect()
}

/// The file's animation `wanted` (by name, or `#INDEX`); if it has none
/// such, the message naming the ones it has.
pub(crate) fn find_clip<'a>(
    parsed: &'a ParsedGltf,
    wanted: &str,
) -> Result<gltf::Animation<'a>, String> {
    parsed
        .document
        .animations()
        .find(|a| a.name() == Some(wanted) || format!("#{}", a.index()) == wanted)
        .ok_or_else(|| {
            format!(
                "no animation called {wanted:?}; the file has {}",
                list_or_none(&animation_names(parsed))
            )
        })
}

impl GltfAnimation {
    /// The animation called `name` (or the first one when `None`) of the
    /// parsed file. Errors are messages for the mesh's error.
    pub(crate) fn new(parsed: &ParsedGltf, name: Option<&str>) -> Result<Self, String> {
        let doc = &parsed.document;
        let buffers = &parsed.buffers;
        let animation = match name {
            Some(wanted) => find_clip(parsed, wanted)?,
            None => doc.animations().next().ok_or("the file has no animation")?,
        };
        let data = |b: gltf::Buffer| buffers.get(b.index()).map(|d| &d.0[..]);

        let mut nodes: Vec<NodeRest> = doc
            .nodes()
            .map(|n| {
                let (t, r, s) = n.transform().decomposed();
                NodeRest {
                    parent: None,
                    translation: Vec3::from(t),
                    rotation: Quat::from_array(r),
                    scale: Vec3::from(s),
                }
            })
            .collect();
        for node in doc.nodes() {
            for child in node.children() {
                if nodes[child.index()].parent.is_some() {
                    return Err(format!("node {} has two parents", child.index()));
                }
                nodes[child.index()].parent = Some(node.index());
            }
        }
        let order = parents_first(&nodes)?;

        let mut channels = Vec::new();
        let mut duration = 0.0f32;
        for channel in animation.channels() {
            let sampler = channel.sampler();
            check_accessor(&sampler.input(), buffers)?;
            check_accessor(&sampler.output(), buffers)?;
            let reader = channel.reader(data);
            let times: Vec<f32> = reader
                .read_inputs()
                .ok_or("an animation sampler has no input times")?
                .collect();
            let values: Vec<Vec4> = match reader.read_outputs() {
                Some(ReadOutputs::Translations(v)) | Some(ReadOutputs::Scales(v)) => {
                    v.map(|x| Vec3::from(x).extend(0.0)).collect()
                }
                Some(ReadOutputs::Rotations(r)) => r.into_f32().map(Vec4::from).collect(),
                // Morph target weights move no vertex pelage reads.
                Some(ReadOutputs::MorphTargetWeights(_)) | None => continue,
            };
            let interpolation = sampler.interpolation();
            let per_key = if interpolation == Interpolation::CubicSpline {
                3
            } else {
                1
            };
            if times.is_empty() || values.len() != times.len() * per_key {
                return Err(format!(
                    "animation {:?}: a sampler has {} times and {} values",
                    animation.name().unwrap_or_default(),
                    times.len(),
                    values.len()
                ));
            }
            if times.iter().any(|t| !t.is_finite()) || values.iter().any(|v| !v.is_finite()) {
                return Err("an animation sampler has a non-finite value".into());
            }
            if times.windows(2).any(|w| w[1] < w[0]) {
                return Err("an animation sampler's times go backwards".into());
            }
            duration = duration.max(*times.last().expect("checked non-empty"));
            channels.push(Channel {
                node: channel.target().node().index(),
                property: channel.target().property(),
                interpolation,
                times,
                values,
            });
        }

        let mut skins = Vec::new();
        for skin in doc.skins() {
            let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
            let inverse_bind = match skin.inverse_bind_matrices() {
                Some(accessor) => {
                    check_accessor(&accessor, buffers)?;
                    skin.reader(data)
                        .read_inverse_bind_matrices()
                        .map(|m| m.map(|c| Mat4::from_cols_array_2d(&c)).collect())
                        .unwrap_or_default()
                }
                None => vec![Mat4::IDENTITY; joints.len()],
            };
            if inverse_bind.len() < joints.len() {
                return Err(format!(
                    "skin {} has {} joints but {} inverse bind matrices",
                    skin.index(),
                    joints.len(),
                    inverse_bind.len()
                ));
            }
            skins.push(Skin {
                joints,
                inverse_bind,
            });
        }

        let rig = skin_rig(parsed, &skins, nodes.len())?;
        Ok(Self {
            name: animation
                .name()
                .map_or_else(|| format!("#{}", animation.index()), str::to_string),
            duration,
            nodes,
            order,
            channels,
            skins,
            rig,
        })
    }

    /// Every vertex at `seconds` into the animation (clamped to its keys):
    /// [`Self::rig`] posed by [`Self::palette_at`].
    pub fn positions_at(&self, seconds: f32) -> Vec<Vec3> {
        self.rig.pose(&self.palette_at(seconds))
    }

    /// The skinning of every vertex, over the palette of
    /// [`Self::palette_at`].
    pub fn rig(&self) -> &SkinRig {
        &self.rig
    }

    /// The palette at `seconds`: the identity (vertices of no node), each
    /// node's global transform (vertices that follow a node), then each
    /// skin's joint matrices `G(joint) · IBM`, skin after skin.
    pub fn palette_at(&self, seconds: f32) -> Vec<Mat4> {
        let mut local: Vec<NodeRest> = self.nodes.clone();
        for channel in &self.channels {
            let v = channel.sample(seconds);
            let node = &mut local[channel.node];
            match channel.property {
                Property::Translation => node.translation = v.truncate(),
                Property::Scale => node.scale = v.truncate(),
                Property::Rotation => {
                    node.rotation = Quat::from_vec4(v).normalize();
                }
                Property::MorphTargetWeights => {}
            }
        }
        let mut global = vec![Mat4::IDENTITY; local.len()];
        for &n in &self.order {
            let node = &local[n];
            let own =
                Mat4::from_scale_rotation_translation(node.scale, node.rotation, node.translation);
            global[n] = match node.parent {
                Some(p) => global[p] * own,
                None => own,
            };
        }
        let mut palette = Vec::with_capacity(self.rig.palette_len());
        palette.push(Mat4::IDENTITY);
        palette.extend_from_slice(&global);
        for s in &self.skins {
            palette.extend(
                s.joints
                    .iter()
                    .zip(&s.inverse_bind)
                    .map(|(&j, ibm)| global[j] * *ibm),
            );
        }
        palette
    }
}

impl Channel {
    /// The channel's value at `t` (held before the first key and after the
    /// last).
    fn sample(&self, t: f32) -> Vec4 {
        let times = &self.times;
        let cubic = self.interpolation == Interpolation::CubicSpline;
        let value = |k: usize| {
            if cubic {
                self.values[3 * k + 1]
            } else {
                self.values[k]
            }
        };
        let last = times.len() - 1;
        if t <= times[0] {
            return value(0);
        }
        if t >= times[last] {
            return value(last);
        }
        let k = times.partition_point(|&x| x <= t) - 1;
        let (t0, t1) = (times[k], times[k + 1]);
        let span = t1 - t0;
        let s = if span > 0.0 { (t - t0) / span } else { 0.0 };
        match self.interpolation {
            Interpolation::Step => value(k),
            Interpolation::Linear => {
                let (a, b) = (value(k), value(k + 1));
                if self.property == Property::Rotation {
                    let (qa, qb) = (Quat::from_vec4(a), Quat::from_vec4(b));
                    Vec4::from(qa.slerp(qb, s))
                } else {
                    a.lerp(b, s)
                }
            }
            Interpolation::CubicSpline => {
                // glTF Appendix C: Hermite with tangents scaled by the span.
                let (p0, m0) = (self.values[3 * k + 1], self.values[3 * k + 2] * span);
                let (p1, m1) = (
                    self.values[3 * (k + 1) + 1],
                    self.values[3 * (k + 1)] * span,
                );
                let (s2, s3) = (s * s, s * s * s);
                (2.0 * s3 - 3.0 * s2 + 1.0) * p0
                    + (s3 - 2.0 * s2 + s) * m0
                    + (-2.0 * s3 + 3.0 * s2) * p1
                    + (s3 - s2) * m1
            }
        }
    }
}

/// Node indices with every parent before its children; an error for a
/// cycle.
fn parents_first(nodes: &[NodeRest]) -> Result<Vec<usize>, String> {
    const UNKNOWN: usize = usize::MAX;
    let mut depth = vec![UNKNOWN; nodes.len()];
    for start in 0..nodes.len() {
        // Walk up to a node whose depth is known, or to a root.
        let mut chain = Vec::new();
        let mut at = start;
        while depth[at] == UNKNOWN {
            chain.push(at);
            if chain.len() > nodes.len() {
                return Err(format!(
                    "node {start} is its own ancestor: the node hierarchy has a cycle"
                ));
            }
            match nodes[at].parent {
                Some(p) => at = p,
                None => break,
            }
        }
        let base = if depth[at] == UNKNOWN {
            0
        } else {
            depth[at] + 1
        };
        for (d, &c) in chain.iter().rev().enumerate() {
            depth[c] = base + d;
        }
    }
    let mut order: Vec<usize> = (0..nodes.len()).collect();
    order.sort_by_key(|&n| depth[n]);
    Ok(order)
}

/// Each welded vertex's local position and what moves it, over the
/// palette of [`GltfAnimation::palette_at`] (`node_count` nodes).
fn skin_rig(parsed: &ParsedGltf, skins: &[Skin], node_count: usize) -> Result<SkinRig, String> {
    // Where each skin's joints start in the palette.
    let mut skin_base = Vec::with_capacity(skins.len());
    let mut palette_len = 1 + node_count;
    for s in skins {
        skin_base.push(palette_len as u32);
        palette_len += s.joints.len();
    }
    let doc = &parsed.document;
    let data = |b: gltf::Buffer| parsed.buffers.get(b.index()).map(|d| &d.0[..]);
    // Per (mesh, primitive): local positions, joints, weights.
    type Attributes = (Vec<Vec3>, Option<Vec<[u16; 4]>>, Option<Vec<[f32; 4]>>);
    let mut read: std::collections::HashMap<(usize, usize), Attributes> = Default::default();
    let mut rest = Vec::with_capacity(parsed.sources.len());
    let mut influences = Vec::with_capacity(parsed.sources.len());
    for source in &parsed.sources {
        let key = (source.mesh, source.primitive);
        if let std::collections::hash_map::Entry::Vacant(slot) = read.entry(key) {
            let mesh = doc.meshes().nth(source.mesh).ok_or("a mesh vanished")?;
            let primitive = mesh
                .primitives()
                .nth(source.primitive)
                .ok_or("a primitive vanished")?;
            let reader = primitive.reader(data);
            let positions: Vec<Vec3> = reader
                .read_positions()
                .map(|p| p.map(Vec3::from).collect())
                .unwrap_or_default();
            let joints: Option<Vec<[u16; 4]>> =
                reader.read_joints(0).map(|j| j.into_u16().collect());
            let weights: Option<Vec<[f32; 4]>> =
                reader.read_weights(0).map(|w| w.into_f32().collect());
            slot.insert((positions, joints, weights));
        }
        let (positions, joints, weights) = &read[&key];
        let k = source.vertex as usize;
        let local = positions[k];
        let node = source.node.and_then(|n| doc.nodes().nth(n));
        let skin = node.as_ref().and_then(|n| n.skin());
        rest.push(local);
        influences.push(match (skin, joints, weights) {
            (Some(skin), Some(j), Some(w)) => {
                let (joints, mut weights) = (j[k], w[k]);
                let count = skins[skin.index()].joints.len();
                if let Some(bad) = joints.iter().find(|&&j| j as usize >= count) {
                    return Err(format!(
                        "a vertex names joint {bad} of skin {}, which has {count}",
                        skin.index()
                    ));
                }
                let total: f32 = weights.iter().sum();
                if !(total > 0.0 && total.is_finite()) {
                    return Err(format!(
                        "a vertex of mesh {} has skin weights adding up to {total}",
                        source.mesh
                    ));
                }
                weights.iter_mut().for_each(|w| *w /= total);
                let base = skin_base[skin.index()];
                Influence {
                    joints: joints.map(|j| base + u32::from(j)),
                    weights,
                }
            }
            _ => Influence::rigid(source.node.map_or(0, |n| 1 + n as u32)),
        });
    }
    Ok(SkinRig::new(rest, influences, palette_len))
}

fn list_or_none(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names
            .iter()
            .map(|n| format!("{n:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}
