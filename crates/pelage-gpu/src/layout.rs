//! Structs shared with WGSL, declared once with [`gpu_struct!`], and the
//! [`UniformRing`] that holds a uniform block on the GPU. A `gpu_struct` is a
//! `#[repr(C)]` Pod struct with named fields, and `FIELDS`, each field's
//! name and byte offset. A test reflects every WGSL struct with naga and
//! checks its size, member names and offsets against these, so a field
//! added, renamed or moved on one side only fails the build's tests
//! instead of drawing garbage.
//!
//! WGSL's layout rules are met by construction here: every `[f32; 3]`
//! (a `vec3<f32>`, 16-byte aligned in WGSL) starts at a multiple of 16 and
//! is followed by a 4-byte scalar; structs are padded by named `pad`
//! members to a multiple of 16 bytes. Vertex and instance structs
//! ([`gpu_vertex!`]) are checked the same way against the shader's
//! `@location` inputs: names, locations and formats.

/// Declares a struct shared with a WGSL struct of the same fields (see the
/// module docs).
macro_rules! gpu_struct {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$field_meta:meta])* $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        $vis struct $name {
            $( $(#[$field_meta])* pub $field: $ty ),*
        }

        impl $name {
            /// Each field's name and byte offset, in declaration order.
            #[allow(dead_code, reason = "read by the layout test")]
            pub const FIELDS: &'static [(&'static str, usize)] = &[
                $( (stringify!($field), std::mem::offset_of!($name, $field)) ),*
            ];
        }
    };
}

pub(crate) use gpu_struct;

/// A vertex (or instance) attribute's Rust type, and the format wgpu reads
/// it as.
pub(crate) trait VertexField {
    const FORMAT: wgpu::VertexFormat;
}

impl VertexField for [f32; 2] {
    const FORMAT: wgpu::VertexFormat = wgpu::VertexFormat::Float32x2;
}
impl VertexField for [f32; 3] {
    const FORMAT: wgpu::VertexFormat = wgpu::VertexFormat::Float32x3;
}
impl VertexField for [f32; 4] {
    const FORMAT: wgpu::VertexFormat = wgpu::VertexFormat::Float32x4;
}

/// Declares a vertex (or instance) struct whose fields are the shader's
/// `@location(first..)` inputs in order: a [`gpu_struct!`], plus
/// `ATTRIBUTES` (each field's format, offset and location) for its
/// `wgpu::VertexBufferLayout`. The layout test compares the fields' names
/// and the attributes with the WGSL input struct.
macro_rules! gpu_vertex {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident at location $first:literal {
            $( $(#[$field_meta:meta])* $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $crate::layout::gpu_struct! {
            $(#[$meta])*
            $vis struct $name {
                $( $(#[$field_meta])* $field: $ty ),*
            }
        }

        impl $name {
            /// Each field's format, offset and shader location.
            pub const ATTRIBUTES: &'static [wgpu::VertexAttribute] = &{
                let formats = [$(<$ty as $crate::layout::VertexField>::FORMAT),*];
                let mut attributes = [wgpu::VertexAttribute {
                    format: wgpu::VertexFormat::Float32,
                    offset: 0,
                    shader_location: 0,
                }; [$(stringify!($field)),*].len()];
                let mut i = 0;
                while i < attributes.len() {
                    attributes[i] = wgpu::VertexAttribute {
                        format: formats[i],
                        offset: Self::FIELDS[i].1 as u64,
                        shader_location: $first + i as u32,
                    };
                    i += 1;
                }
                attributes
            };

            /// The buffer layout of an array of these, stepped per vertex
            /// or per instance.
            pub fn layout(step_mode: wgpu::VertexStepMode) -> wgpu::VertexBufferLayout<'static> {
                wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<$name>() as u64,
                    step_mode,
                    attributes: Self::ATTRIBUTES,
                }
            }
        }
    };
}

pub(crate) use gpu_vertex;

/// A uniform block's buffer, made once and rewritten each frame with
/// `write_buffer`: a ring of slots bound at a dynamic offset, each frame
/// its own slot. Writes wait in the queue until the next submission, so
/// frames recorded on several threads before their submissions (renderers
/// are shared, `&self`) each keep their own values; a slot is reused only
/// after [`UniformRing::SLOTS`] frames.
#[derive(Debug)]
pub(crate) struct UniformRing<T> {
    buffer: wgpu::Buffer,
    group: wgpu::BindGroup,
    next: std::sync::atomic::AtomicUsize,
    block: std::marker::PhantomData<T>,
}

impl<T: bytemuck::Pod> UniformRing<T> {
    /// Slots in the ring.
    pub(crate) const SLOTS: u64 = 1024;
    /// Bytes a slot: the largest uniform offset alignment wgpu allows.
    const SLOT_BYTES: u64 = 256;

    /// The bind group layout of a ring bound at `binding` 0, seen by
    /// `visibility`.
    pub(crate) fn layout(
        device: &wgpu::Device,
        label: &str,
        visibility: wgpu::ShaderStages,
    ) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: std::num::NonZeroU64::new(Self::size()),
                },
                count: None,
            }],
        })
    }

    /// The ring, bound by a group of `layout` (from [`Self::layout`]).
    pub(crate) fn new(device: &wgpu::Device, label: &str, layout: &wgpu::BindGroupLayout) -> Self {
        const { assert!(std::mem::size_of::<T>() as u64 <= Self::SLOT_BYTES) };
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: Self::SLOTS * Self::SLOT_BYTES,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &buffer,
                    offset: 0,
                    size: std::num::NonZeroU64::new(Self::size()),
                }),
            }],
        });
        Self {
            buffer,
            group,
            next: Default::default(),
            block: std::marker::PhantomData,
        }
    }

    fn size() -> u64 {
        std::mem::size_of::<T>() as u64
    }

    /// Writes `value` into the next slot; bind [`Self::group`] at the
    /// returned dynamic offset.
    pub(crate) fn write(&self, queue: &wgpu::Queue, value: &T) -> u32 {
        let slot =
            self.next.fetch_add(1, std::sync::atomic::Ordering::Relaxed) as u64 % Self::SLOTS;
        let offset = slot * Self::SLOT_BYTES;
        queue.write_buffer(&self.buffer, offset, bytemuck::bytes_of(value));
        offset as u32
    }

    /// The bind group (at the offset [`Self::write`] returned).
    pub(crate) fn group(&self) -> &wgpu::BindGroup {
        &self.group
    }
}

/// A compute pipeline of `module`'s `entry_point` over bind groups of
/// `layouts` (group `i` is `layouts[i]`), its layout made for it.
pub(crate) fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    entry_point: &str,
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().copied().map(Some).collect();
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        module,
        entry_point: Some(entry_point),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// Bind-group entries, numbered by position where a group's bindings run
/// 0, 1, 2, … (as Bevy's `BindGroupEntries::sequential`), or at the
/// bindings given where a layout skips some.
pub(crate) mod group {
    use wgpu::{BindGroupEntry, BindingResource, Buffer};

    /// Binding `i` is `resources[i]`.
    pub(crate) fn sequential<const N: usize>(
        resources: [BindingResource<'_>; N],
    ) -> [BindGroupEntry<'_>; N] {
        let mut binding = 0;
        resources.map(|resource| {
            binding += 1;
            BindGroupEntry {
                binding: binding - 1,
                resource,
            }
        })
    }

    /// Whole buffers, binding `i` being `buffers[i]`.
    pub(crate) fn buffers<'a, const N: usize>(buffers: [&'a Buffer; N]) -> [BindGroupEntry<'a>; N] {
        sequential(buffers.map(Buffer::as_entire_binding))
    }

    /// Whole buffers at the bindings given.
    pub(crate) fn buffers_at<'a, const N: usize>(
        buffers: [(u32, &'a Buffer); N],
    ) -> [BindGroupEntry<'a>; N] {
        buffers.map(|(binding, buffer)| BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
    }
}

/// Bind-group layout entries, one constructor a kind of binding, so each
/// pipeline lists its bindings instead of spelling wgpu's structs out.
pub(crate) mod entry {
    use wgpu::{BindGroupLayoutEntry, BindingType, ShaderStages};

    /// A float texture of `dimension`, sampled (`filterable`) or loaded.
    pub(crate) fn texture(
        binding: u32,
        visibility: ShaderStages,
        dimension: wgpu::TextureViewDimension,
        filterable: bool,
    ) -> BindGroupLayoutEntry {
        BindGroupLayoutEntry {
            binding,
            visibility,
            ty: BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable },
                view_dimension: dimension,
                multisampled: false,
            },
            count: None,
        }
    }

    /// A filtering sampler.
    pub(crate) fn sampler(binding: u32, visibility: ShaderStages) -> BindGroupLayoutEntry {
        BindGroupLayoutEntry {
            binding,
            visibility,
            ty: BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        }
    }

    /// A buffer: uniform or storage (`ty`), at a dynamic offset or not.
    pub(crate) fn buffer(
        binding: u32,
        visibility: ShaderStages,
        ty: wgpu::BufferBindingType,
        dynamic: bool,
    ) -> BindGroupLayoutEntry {
        BindGroupLayoutEntry {
            binding,
            visibility,
            ty: BindingType::Buffer {
                ty,
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            count: None,
        }
    }

    /// A storage buffer, read only or read-write.
    pub(crate) fn storage(
        binding: u32,
        visibility: ShaderStages,
        read_only: bool,
    ) -> BindGroupLayoutEntry {
        buffer(
            binding,
            visibility,
            wgpu::BufferBindingType::Storage { read_only },
            false,
        )
    }
}

#[cfg(test)]
mod tests {
    use crate::dynamics::StepUniform;
    use crate::groom::GroomPassUniform;
    use crate::hair_render::StrandUniforms;
    use crate::renderer::FrameUniforms;
    use crate::shells::ShellUniforms;
    use crate::strands::{GridHeader, StrandStepUniform};

    /// The size and `(member, offset)` list of the struct `name` in `wgsl`,
    /// as naga lays it out.
    fn reflect(wgsl: &str, name: &str) -> (usize, Vec<(String, usize)>) {
        let module = naga::front::wgsl::parse_str(wgsl).expect("the shader parses");
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name} in the shader"));
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("{name} is not a struct");
        };
        let fields = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
            .collect();
        (*span as usize, fields)
    }

    fn check(shader: &str, wgsl_name: &str, size: usize, fields: &[(&str, usize)]) {
        let (wgsl_size, wgsl_fields) = reflect(&crate::shader_source(shader), wgsl_name);
        let rust: Vec<(String, usize)> = fields.iter().map(|(n, o)| (n.to_string(), *o)).collect();
        assert_eq!(
            rust, wgsl_fields,
            "{shader}: struct {wgsl_name}: Rust fields (left) and WGSL members (right) differ"
        );
        assert_eq!(size, wgsl_size, "{shader}: struct {wgsl_name}: size");
    }

    #[test]
    fn rust_uniform_structs_match_their_wgsl_structs() {
        let frame = std::mem::size_of::<FrameUniforms>();
        for shader in ["mesh.wgsl", "points.wgsl", "curves.wgsl"] {
            check(shader, "Frame", frame, FrameUniforms::FIELDS);
        }
        let shell = std::mem::size_of::<ShellUniforms>();
        check("shells.wgsl", "Shell", shell, ShellUniforms::FIELDS);
        let step = std::mem::size_of::<StepUniform>();
        check("dynamics.wgsl", "Step", step, StepUniform::FIELDS);
        let strand = std::mem::size_of::<StrandStepUniform>();
        check(
            "strands.wgsl",
            "StrandStep",
            strand,
            StrandStepUniform::FIELDS,
        );
        let grid = std::mem::size_of::<GridHeader>();
        check("strands.wgsl", "Grid", grid, GridHeader::FIELDS);
        let groom = std::mem::size_of::<GroomPassUniform>();
        check("groom.wgsl", "GroomPass", groom, GroomPassUniform::FIELDS);
        let strands = std::mem::size_of::<StrandUniforms>();
        check("hair.wgsl", "Strands", strands, StrandUniforms::FIELDS);
    }

    /// A vertex input: name, location and type (`f32x3`).
    type Input = (String, u32, String);

    /// The `@location` members of the WGSL struct `name`.
    fn reflect_inputs(wgsl: &str, name: &str) -> Vec<Input> {
        let module = naga::front::wgsl::parse_str(wgsl).expect("the shader parses");
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name} in the shader"));
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!("{name} is not a struct");
        };
        members
            .iter()
            .map(|m| {
                let Some(naga::Binding::Location { location, .. }) = m.binding else {
                    panic!("{name}.{:?} is not a @location input", m.name);
                };
                let ty = match &module.types[m.ty].inner {
                    naga::TypeInner::Vector { size, .. } => format!("f32x{}", *size as u8),
                    naga::TypeInner::Scalar(_) => "f32".to_string(),
                    other => panic!("{other:?}"),
                };
                (m.name.clone().unwrap_or_default(), location, ty)
            })
            .collect()
    }

    /// The same triples for Rust vertex structs, in order.
    /// A vertex struct's `FIELDS` and `ATTRIBUTES`.
    type VertexParts<'a> = (&'a [(&'a str, usize)], &'a [wgpu::VertexAttribute]);

    fn inputs(parts: &[VertexParts]) -> Vec<Input> {
        parts
            .iter()
            .flat_map(|(fields, attributes)| fields.iter().zip(attributes.iter()))
            .map(|((n, _), a)| {
                let ty = match a.format {
                    wgpu::VertexFormat::Float32 => "f32",
                    wgpu::VertexFormat::Float32x2 => "f32x2",
                    wgpu::VertexFormat::Float32x3 => "f32x3",
                    wgpu::VertexFormat::Float32x4 => "f32x4",
                    other => panic!("{other:?}"),
                };
                (n.to_string(), a.shader_location, ty.to_string())
            })
            .collect()
    }

    #[test]
    fn rust_vertex_structs_match_their_wgsl_inputs() {
        use crate::renderer::{MeshVertex, PointInstance, SegmentInstance};
        use crate::shells::{PoseVertex, SurfaceVertex, TipOffset};
        let cases: [(&str, &str, Vec<Input>); 4] = [
            (
                "mesh.wgsl",
                "VertexIn",
                inputs(&[(MeshVertex::FIELDS, MeshVertex::ATTRIBUTES)]),
            ),
            (
                "points.wgsl",
                "PointIn",
                inputs(&[(PointInstance::FIELDS, PointInstance::ATTRIBUTES)]),
            ),
            (
                "curves.wgsl",
                "SegmentIn",
                inputs(&[(SegmentInstance::FIELDS, SegmentInstance::ATTRIBUTES)]),
            ),
            (
                "shells.wgsl",
                "VertexIn",
                inputs(&[
                    (PoseVertex::FIELDS, PoseVertex::ATTRIBUTES),
                    (SurfaceVertex::FIELDS, SurfaceVertex::ATTRIBUTES),
                    (TipOffset::FIELDS, TipOffset::ATTRIBUTES),
                ]),
            ),
        ];
        for (shader, name, rust) in cases {
            let wgsl = reflect_inputs(&crate::shader_source(shader), name);
            assert_eq!(
                rust, wgsl,
                "{shader}: {name}: Rust (left) and WGSL (right) differ"
            );
        }
    }

    #[test]
    fn a_moved_field_is_caught() {
        // The check itself: the Shell block with two fields swapped on the
        // Rust side must not pass.
        let mut swapped: Vec<(&str, usize)> = ShellUniforms::FIELDS.to_vec();
        let (a, b) = (swapped[1].1, swapped[2].1);
        swapped[1].1 = b;
        swapped[2].1 = a;
        let size = std::mem::size_of::<ShellUniforms>();
        let caught = std::panic::catch_unwind(|| check("shells.wgsl", "Shell", size, &swapped));
        assert!(caught.is_err());
    }
}
