//! glTF 2.0 / GLB reader (through the gltf crate): every triangle primitive
//! of the default scene (or of every scene, or every mesh when there is no
//! scene), with node transforms applied, merged into one mesh.
//!
//! UVs are flipped vertically on reading (`v → 1 − v`): glTF's origin is
//! the image's top-left corner, pelage's the bottom-left.
//!
//! glTF splits vertices wherever any attribute differs, so a UV seam becomes
//! an open border. pelage welds vertices whose positions are bit-identical
//! and keeps the UVs per corner, so a closed model stays closed for the
//! topology-based algorithms (style mesh colouring, boundary reports).

use super::{Mesh, MeshError, MeshErrorKind, Uvs};
use glam::{Mat3, Mat4, Vec2, Vec3};
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::Path;

/// Reads a glTF or GLB from bytes; `base` is the folder external buffers
/// are resolved against (None for self-contained files).
pub(crate) fn parse(name: &str, bytes: &[u8], base: Option<&Path>) -> Result<Mesh, MeshError> {
    parse_with_sources(name, bytes, base).map(|parsed| parsed.mesh)
}

/// The base colour texture of the first material a triangle primitive of
/// the glTF uses that has one (`pbrMetallicRoughness.baseColorTexture`),
/// decoded; `None` when no material has one. `base` is the folder
/// external buffers and images are resolved against.
pub(crate) fn base_color_image(
    name: &str,
    bytes: &[u8],
    base: &Path,
) -> Result<Option<image::DynamicImage>, MeshError> {
    let whole = |msg: String| MeshError::whole(name, MeshErrorKind::Syntax(msg));
    let gltf = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| whole(format!("not a readable glTF file: {e}")))?;
    validate(&gltf.document).map_err(whole)?;
    let Some(texture) = gltf
        .document
        .meshes()
        .flat_map(|m| m.primitives().collect::<Vec<_>>())
        .filter_map(|p| p.material().pbr_metallic_roughness().base_color_texture())
        .map(|info| info.texture())
        .next()
    else {
        return Ok(None);
    };
    let buffers = gltf::import_buffers(&gltf.document, Some(base), gltf.blob.clone())
        .map_err(|e| whole(format!("cannot load the glTF's buffers: {e}")))?;
    let data = gltf::image::Data::from_source(texture.source().source(), Some(base), &buffers)
        .map_err(|e| whole(format!("cannot read its base colour texture: {e}")))?;
    let (w, h) = (data.width, data.height);
    let image = match data.format {
        gltf::image::Format::R8G8B8A8 => {
            image::RgbaImage::from_raw(w, h, data.pixels).map(image::DynamicImage::ImageRgba8)
        }
        gltf::image::Format::R8G8B8 => {
            image::RgbImage::from_raw(w, h, data.pixels).map(image::DynamicImage::ImageRgb8)
        }
        gltf::image::Format::R8 => {
            image::GrayImage::from_raw(w, h, data.pixels).map(image::DynamicImage::ImageLuma8)
        }
        _ => None,
    };
    Ok(image)
}

/// A glTF read as one mesh, with what skinning it again needs: the
/// document, its buffers, and where each welded vertex came from.
pub(crate) struct ParsedGltf {
    pub mesh: Mesh,
    pub document: gltf::Document,
    pub buffers: Vec<gltf::buffer::Data>,
    /// Per welded vertex: the node that instanced its mesh, the primitive
    /// and the vertex's index in it (its first occurrence).
    pub sources: Vec<VertexSource>,
}

/// Where a welded vertex of a glTF mesh came from.
#[derive(Debug, Clone, Copy)]
pub(crate) struct VertexSource {
    /// The node instancing the mesh (`None` for meshes of a file with no
    /// scene).
    pub node: Option<usize>,
    pub mesh: usize,
    pub primitive: usize,
    pub vertex: u32,
}

/// Checks a glTF document against the specification before anything reads
/// it. The gltf crate's own validation indexes a primitive's `POSITION`
/// accessor without checking it exists (it panics on a file whose POSITION
/// names a missing accessor), and does not check animation channels at
/// all (a channel's target node out of range, or a target path it does
/// not know, panics when read), so those references are checked here
/// first.
fn validate(document: &gltf::Document) -> Result<(), String> {
    let root = document.as_json();
    validate_animation_channels(root)?;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, accessor) in &primitive.attributes {
                if accessor.value() >= root.accessors.len() {
                    return Err(format!(
                        "mesh {m} primitive {p}: attribute {} names accessor {}, and the file has {} accessors",
                        semantic_name(semantic),
                        accessor.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    validate_with_crate(root)?;
    validate_accessors(root)
}

/// What a reader of the gltf crate assumes of the accessors it reads and
/// does not check (it asserts, or reaches `unreachable!`): each accessor's
/// elements fit its buffer view at the view's stride, and each use has
/// the type and component type the specification gives it.
fn validate_accessors(root: &gltf::json::Root) -> Result<(), String> {
    validate_accessor_ranges(root)?;
    validate_accessor_uses(root)
}

/// An accessor's component type, when it is one glTF knows.
fn component_type(a: &gltf::json::Accessor) -> Option<gltf::json::accessor::ComponentType> {
    match a.component_type {
        gltf::json::validation::Checked::Valid(c) => Some(c.0),
        _ => None,
    }
}

/// Each accessor's elements fit its buffer view at the view's stride,
/// and each view its buffer; sparse accessors are refused.
fn validate_accessor_ranges(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::Checked::Valid;
    for (i, accessor) in root.accessors.iter().enumerate() {
        let (Some(c), Valid(t)) = (component_type(accessor), accessor.type_) else {
            continue;
        };
        if accessor.sparse.is_some() {
            return Err(format!("accessor {i}: sparse accessors are not supported"));
        }
        let Some(view) = accessor
            .buffer_view
            .and_then(|v| root.buffer_views.get(v.value()))
        else {
            continue;
        };
        let element = (c.size() * t.multiplicity()) as u64;
        let stride = view.byte_stride.map_or(element, |s| s.0 as u64);
        let count = accessor.count.0;
        let offset = accessor.byte_offset.map_or(0, |o| o.0);
        let end = match count {
            0 => offset,
            n => offset + stride * (n - 1) + element,
        };
        if stride < element {
            return Err(format!(
                "accessor {i}: its buffer view's stride {stride} is shorter than one element ({element} bytes)"
            ));
        }
        if end > view.byte_length.0 {
            return Err(format!(
                "accessor {i} reaches past the end of its buffer view {}: {count} elements of {element} bytes at offset {offset}, stride {stride}, need {end} of its {} bytes",
                accessor.buffer_view.map_or(0, |v| v.value()),
                view.byte_length.0
            ));
        }
        let buffer = root.buffers.get(view.buffer.value());
        if buffer.is_none_or(|b| {
            view.byte_offset.map_or(0, |o| o.0) + view.byte_length.0 > b.byte_length.0
        }) {
            return Err(format!(
                "buffer view {} runs past the end of its buffer",
                accessor.buffer_view.map_or(0, |v| v.value())
            ));
        }
    }
    Ok(())
}

/// Accessor `index`, which `what` reads, exists and holds one of `types`
/// of one of `components`.
fn expect_accessor(
    root: &gltf::json::Root,
    what: &str,
    index: usize,
    types: &[gltf::json::accessor::Type],
    components: &[gltf::json::accessor::ComponentType],
) -> Result<(), String> {
    use gltf::json::accessor::{ComponentType as C, Type as T};
    use gltf::json::validation::Checked::Valid;
    let Some(a) = root.accessors.get(index) else {
        return Err(format!(
            "{what} names accessor {index}, which does not exist"
        ));
    };
    let list = |names: Vec<String>| names.join(" or ");
    let type_name = |t: &T| format!("{t:?}").to_uppercase();
    let component_name = |c: &C| format!("{c:?}").to_lowercase();
    match (a.type_, component_type(a)) {
        (Valid(t), Some(c)) if types.contains(&t) && components.contains(&c) => Ok(()),
        (t, c) => Err(format!(
            "{what}: accessor {index} holds {} of {}; glTF allows {} of {}",
            match t {
                Valid(t) => type_name(&t),
                _ => "an unknown type".into(),
            },
            c.map_or("an unknown component type".into(), |c| component_name(&c)),
            list(types.iter().map(type_name).collect()),
            list(components.iter().map(component_name).collect()),
        )),
    }
}

/// Each use of an accessor (a primitive's indices and attributes, a
/// skin's inverse bind matrices, an animation's samplers and channels) has
/// the type and component type the specification gives it.
fn validate_accessor_uses(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::accessor::{ComponentType as C, Type as T};
    use gltf::json::mesh::Semantic as S;
    use gltf::json::validation::Checked::Valid;
    let expect = |what: &str, index: usize, types: &[T], components: &[C]| {
        expect_accessor(root, what, index, types, components)
    };
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let at = |what: &str| format!("mesh {m} primitive {p}: {what}");
            if let Some(indices) = primitive.indices {
                expect(
                    &at("indices"),
                    indices.value(),
                    &[T::Scalar],
                    &[C::U8, C::U16, C::U32],
                )?;
            }
            for (semantic, accessor) in &primitive.attributes {
                let (types, components): (&[T], &[C]) = match semantic {
                    Valid(S::Positions | S::Normals) => (&[T::Vec3], &[C::F32]),
                    Valid(S::Tangents) => (&[T::Vec4], &[C::F32]),
                    Valid(S::TexCoords(_)) => (&[T::Vec2], &[C::F32, C::U8, C::U16]),
                    Valid(S::Colors(_)) => (&[T::Vec3, T::Vec4], &[C::F32, C::U8, C::U16]),
                    Valid(S::Joints(_)) => (&[T::Vec4], &[C::U8, C::U16]),
                    Valid(S::Weights(_)) => (&[T::Vec4], &[C::F32, C::U8, C::U16]),
                    _ => continue,
                };
                expect(
                    &at(&semantic_name(semantic)),
                    accessor.value(),
                    types,
                    components,
                )?;
            }
        }
    }
    for (s, skin) in root.skins.iter().enumerate() {
        if let Some(matrices) = skin.inverse_bind_matrices {
            expect(
                &format!("skin {s}: inverse bind matrices"),
                matrices.value(),
                &[T::Mat4],
                &[C::F32],
            )?;
        }
    }
    for (a, animation) in root.animations.iter().enumerate() {
        for (k, sampler) in animation.samplers.iter().enumerate() {
            let at = format!("animation {a} sampler {k}");
            expect(
                &format!("{at} input"),
                sampler.input.value(),
                &[T::Scalar],
                &[C::F32],
            )?;
            expect(
                &format!("{at} output"),
                sampler.output.value(),
                &[T::Scalar, T::Vec3, T::Vec4],
                &[C::F32, C::I8, C::U8, C::I16, C::U16],
            )?;
        }
        for (k, channel) in animation.channels.iter().enumerate() {
            let Some(sampler) = animation.samplers.get(channel.sampler.value()) else {
                continue;
            };
            let (types, components): (&[T], &[C]) = match channel.target.path {
                Valid(
                    gltf::json::animation::Property::Translation
                    | gltf::json::animation::Property::Scale,
                ) => (&[T::Vec3], &[C::F32]),
                Valid(gltf::json::animation::Property::Rotation) => {
                    (&[T::Vec4], &[C::F32, C::I8, C::U8, C::I16, C::U16])
                }
                Valid(gltf::json::animation::Property::MorphTargetWeights) => {
                    (&[T::Scalar], &[C::F32, C::I8, C::U8, C::I16, C::U16])
                }
                _ => continue,
            };
            expect(
                &format!("animation {a} channel {k}"),
                sampler.output.value(),
                types,
                components,
            )?;
        }
    }
    Ok(())
}

/// The gltf crate's own validation of references and enums.
/// Each animation channel's sampler, target node and target path exist.
fn validate_animation_channels(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::Checked;
    for (a, animation) in root.animations.iter().enumerate() {
        let name = match &animation.name {
            Some(name) => format!("animation {a} ({name:?})"),
            None => format!("animation {a}"),
        };
        for (c, channel) in animation.channels.iter().enumerate() {
            let node = channel.target.node.value();
            if node >= root.nodes.len() {
                return Err(format!(
                    "{name} channel {c}: its target names node {node}, and the file has {} nodes",
                    root.nodes.len()
                ));
            }
            let sampler = channel.sampler.value();
            if sampler >= animation.samplers.len() {
                return Err(format!(
                    "{name} channel {c}: it names sampler {sampler}, and the animation has {} samplers",
                    animation.samplers.len()
                ));
            }
            if let Checked::Invalid = channel.target.path {
                return Err(format!(
                    "{name} channel {c}: its target path is not translation, rotation, scale or weights"
                ));
            }
        }
    }
    Ok(())
}

fn validate_with_crate(root: &gltf::json::Root) -> Result<(), String> {
    // Unknown problems in the crate's validation are still errors, not a
    // crash of the whole program.
    let checked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        use gltf::json::validation::Validate;
        let mut errors = Vec::new();
        root.validate(root, gltf::json::Path::new, &mut |path, error| {
            errors.push(format!("{}: {error}", path()))
        });
        errors
    }));
    match checked {
        Ok(errors) if errors.is_empty() => Ok(()),
        Ok(errors) => Err(format!("not a valid glTF file: {}", errors.join("; "))),
        Err(_) => Err("not a valid glTF file (its validation failed)".into()),
    }
}

fn semantic_name(semantic: &gltf::json::validation::Checked<gltf::json::mesh::Semantic>) -> String {
    match semantic {
        gltf::json::validation::Checked::Valid(s) => s.to_string(),
        gltf::json::validation::Checked::Invalid => "(unknown)".into(),
    }
}

/// [`parse`], keeping the document and the vertices' sources.
pub(crate) fn parse_with_sources(
    name: &str,
    bytes: &[u8],
    base: Option<&Path>,
) -> Result<ParsedGltf, MeshError> {
    let whole = |msg: String| MeshError::whole(name, MeshErrorKind::Syntax(msg));
    let gltf = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| whole(format!("not a readable glTF file: {e}")))?;
    validate(&gltf.document).map_err(whole)?;
    let buffers = gltf::import_buffers(&gltf.document, base, gltf.blob.clone())
        .map_err(|e| whole(format!("cannot load the glTF's buffers: {e}")))?;
    let mut merged = Merged::new();
    for (mesh, world, node) in mesh_instances(&gltf.document).map_err(whole)? {
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        for primitive in mesh.primitives() {
            let placed = Placed {
                world,
                normal_matrix,
                node,
                mesh: mesh.index(),
            };
            merged.add(name, &primitive, &buffers, placed)?;
        }
    }
    let (mesh, sources) = merged.finish(name)?;
    Ok(ParsedGltf {
        mesh,
        document: gltf.document,
        buffers,
        sources,
    })
}

/// Where a primitive's mesh is placed: its world transform (and the one
/// for normals), the node that places it and the mesh's index.
struct Placed {
    world: Mat4,
    normal_matrix: Mat3,
    node: Option<usize>,
    mesh: usize,
}

/// Every primitive read so far, merged into one mesh: positions welded
/// where bit-identical, UVs per corner.
struct Merged {
    positions: Vec<Vec3>,
    normal_sums: Vec<Vec3>,
    welded: HashMap<[u32; 3], u32>,
    triangles: Vec<[u32; 3]>,
    uv_values: Vec<Vec2>,
    uv_triangles: Vec<[u32; 3]>,
    /// Whether every primitive so far has normals.
    all_have_normals: bool,
    /// Whether the primitives have UVs (all must, or none).
    uv_presence: Option<bool>,
    sources: Vec<VertexSource>,
}

impl Merged {
    fn new() -> Self {
        Self {
            positions: Vec::new(),
            normal_sums: Vec::new(),
            welded: HashMap::new(),
            triangles: Vec::new(),
            uv_values: Vec::new(),
            uv_triangles: Vec::new(),
            all_have_normals: true,
            uv_presence: None,
            sources: Vec::new(),
        }
    }

    /// Adds a triangle primitive (points and lines carry no surface),
    /// placed by `placed`: its vertices welded into the merged mesh, its
    /// normals turned, its UVs flipped to pelage's origin.
    fn add(
        &mut self,
        name: &str,
        primitive: &gltf::Primitive<'_>,
        buffers: &[gltf::buffer::Data],
        placed: Placed,
    ) -> Result<(), MeshError> {
        let whole = |msg: String| MeshError::whole(name, MeshErrorKind::Syntax(msg));
        let what = format!("mesh {} primitive {}", placed.mesh, primitive.index());
        if !matches!(
            primitive.mode(),
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Ok(()); // points and lines carry no surface
        }
        for (_, accessor) in primitive.attributes() {
            check_accessor(&accessor, buffers).map_err(|m| whole(format!("{what}: {m}")))?;
        }
        if let Some(a) = primitive.indices() {
            check_accessor(&a, buffers).map_err(|m| whole(format!("{what}: {m}")))?;
        }
        let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let local: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| whole(format!("{what} has no POSITION attribute")))?
            .map(Vec3::from)
            .collect();
        let normals: Option<Vec<Vec3>> = reader.read_normals().map(|n| n.map(Vec3::from).collect());
        // glTF puts UV (0, 0) at the image's top-left corner; pelage's
        // maps (as OBJ, PLY and USD) at its bottom-left: v is flipped,
        // as Blender's importer does.
        let uvs: Option<Vec<Vec2>> = reader
            .read_tex_coords(0)
            .map(|t| t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect());
        match self.uv_presence {
            None => self.uv_presence = Some(uvs.is_some()),
            Some(p) if p != uvs.is_some() => {
                return Err(MeshError::whole(
                    name,
                    MeshErrorKind::Unsupported(format!(
                        "{what} {} TEXCOORD_0 but earlier primitives {}; pelage needs UVs on all primitives or on none",
                        if uvs.is_some() { "has" } else { "has no" },
                        if p { "do" } else { "do not" }
                    )),
                ));
            }
            Some(_) => {}
        }
        self.all_have_normals &= normals.is_some();
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..local.len() as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= local.len()) {
            return Err(MeshError::whole(
                name,
                MeshErrorKind::IndexOutOfRange {
                    what: "vertex",
                    what_plural: "vertices",
                    index: i64::from(bad),
                    count: local.len(),
                    hint: "",
                },
            ));
        }

        // Weld this primitive's vertices into the merged mesh.
        let uv_base = self.uv_values.len() as u32;
        let mut remap = Vec::with_capacity(local.len());
        for (k, p) in local.iter().enumerate() {
            let p = placed.world.transform_point3(*p);
            if !p.is_finite() {
                let kind = MeshErrorKind::NonFinite {
                    what: "vertex position",
                };
                return Err(MeshError::whole(name, kind));
            }
            let next = self.positions.len() as u32;
            let id = *self
                .welded
                .entry(p.to_array().map(f32::to_bits))
                .or_insert(next);
            if id == next {
                self.positions.push(p);
                self.normal_sums.push(Vec3::ZERO);
                self.sources.push(VertexSource {
                    node: placed.node,
                    mesh: placed.mesh,
                    primitive: primitive.index(),
                    vertex: k as u32,
                });
            }
            if let Some(n) = &normals {
                self.normal_sums[id as usize] += (placed.normal_matrix * n[k]).normalize_or_zero();
            }
            remap.push(id);
        }
        if let Some(uvs) = uvs {
            self.uv_values.extend(uvs);
        }
        for tri in triangle_indices(primitive.mode(), &indices) {
            self.triangles.push(tri.map(|i| remap[i as usize]));
            if self.uv_presence == Some(true) {
                self.uv_triangles.push(tri.map(|i| uv_base + i));
            }
        }
        Ok(())
    }

    /// The merged mesh, with per-vertex normals where every primitive had
    /// them, and each vertex's source.
    fn finish(self, name: &str) -> Result<(Mesh, Vec<VertexSource>), MeshError> {
        if self.triangles.is_empty() {
            return Err(MeshError::whole(
                name,
                MeshErrorKind::Empty("no triangle primitives"),
            ));
        }
        let normals = self.all_have_normals.then(|| {
            let computed = super::area_weighted_normals(&self.positions, &self.triangles);
            self.normal_sums
                .into_iter()
                .zip(computed)
                .map(|(s, c)| {
                    if s.is_finite() {
                        s.try_normalize().unwrap_or(c)
                    } else {
                        s
                    }
                })
                .collect()
        });
        let uvs = (self.uv_presence == Some(true)).then_some(Uvs::PerCorner {
            values: self.uv_values,
            indices: self.uv_triangles,
        });
        let mesh = Mesh::new(name, self.positions, self.triangles, normals, uvs)?;
        Ok((mesh, self.sources))
    }
}

/// Every mesh the scenes place, with its world transform and node (or,
/// in a file without scenes, every mesh as it is). glTF's nodes form
/// trees: a node with two parents (a file that would be walked once per
/// path, exponentially many in a lattice) is refused, and a node reached
/// twice on one path is a cycle (a malformed file that would otherwise be
/// walked forever); the depth bounds the walk.
fn mesh_instances(
    doc: &gltf::Document,
) -> Result<Vec<(gltf::Mesh<'_>, Mat4, Option<usize>)>, String> {
    let mut instances: Vec<(gltf::Mesh, Mat4, Option<usize>)> = Vec::new();
    let scenes: Vec<gltf::Scene> = match doc.default_scene() {
        Some(s) => vec![s],
        None => doc.scenes().collect(),
    };
    if scenes.is_empty() {
        instances.extend(doc.meshes().map(|m| (m, Mat4::IDENTITY, None)));
    }
    let node_count = doc.nodes().len();
    let mut has_parent = vec![false; node_count];
    for node in doc.nodes() {
        for child in node.children() {
            if std::mem::replace(&mut has_parent[child.index()], true) {
                return Err(format!(
                    "node {} has two parents; glTF's node hierarchy must be a tree",
                    child.index()
                ));
            }
        }
    }
    for scene in scenes {
        let mut stack: Vec<(gltf::Node, Mat4, usize)> =
            scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
        while let Some((node, parent, depth)) = stack.pop() {
            if depth > node_count {
                return Err(format!(
                    "node {} is its own ancestor: the node hierarchy has a cycle",
                    node.index()
                ));
            }
            let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            if let Some(mesh) = node.mesh() {
                instances.push((mesh, world, Some(node.index())));
            }
            stack.extend(node.children().map(|c| (c, world, depth + 1)));
        }
    }
    Ok(instances)
}

/// The gltf crate's readers index buffers without bounds checks of their
/// own; this checks that the accessor's bytes lie inside its view and the
/// view inside its buffer, so a malformed file is an error, not a panic.
pub(crate) fn check_accessor(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
) -> Result<(), String> {
    let Some(view) = accessor.view() else {
        return Err(format!(
            "accessor {} has no buffer view (sparse accessors are not supported)",
            accessor.index()
        ));
    };
    let buffer_len = buffers.get(view.buffer().index()).map_or(0, |b| b.0.len());
    if view.offset() + view.length() > buffer_len {
        return Err(format!(
            "buffer view {} reaches past the end of its buffer",
            view.index()
        ));
    }
    let element = accessor.size();
    let stride = view.stride().unwrap_or(element);
    let count = accessor.count();
    if count > 0 && accessor.offset() + stride * (count - 1) + element > view.length() {
        return Err(format!(
            "accessor {} reaches past the end of its buffer view",
            accessor.index()
        ));
    }
    Ok(())
}

fn triangle_indices(mode: Mode, indices: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (2..indices.len())
            .map(|k| {
                // Alternate winding so every strip triangle faces the same way.
                if k % 2 == 0 {
                    [indices[k - 2], indices[k - 1], indices[k]]
                } else {
                    [indices[k - 1], indices[k - 2], indices[k]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len())
            .map(|k| [indices[0], indices[k - 1], indices[k]])
            .collect(),
        _ => indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
    }
}
