//! Real-time strands, the render world's half: every frame, each drawn
//! [`GroomStrands`]' hairs grown on the GPU from the skin the main world
//! posed (pelage-shaders' `groom.wgsl` over its `GroomUpload`, one compute
//! dispatch a recipe pass, the same shader and arrays pelage-gpu grows
//! with), into the points buffer the strand material reads. Submitted on
//! Bevy's render queue before the frame's own command buffers, so the
//! main pass draws this frame's hairs.
//!
//! The shader's bindings (pelage-shaders' groom module docs): group 0 the
//! roots, packed data, guides, skin, triangles, points and the skin's two
//! distance grids; group 1 one pass block at a dynamic offset.

use crate::asset::GroomStrandsSource;
use crate::hair_material::GROOM_SHADER;
use crate::strands::GroomStrands;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::binding_types::{
    storage_buffer_read_only_sized, storage_buffer_sized, uniform_buffer_sized,
};
use bevy::render::render_resource::{
    BindGroup, BindGroupEntries, BindGroupLayoutDescriptor, BindGroupLayoutEntries, Buffer,
    BufferBinding, BufferInitDescriptor, BufferUsages, CachedComputePipelineId,
    CommandEncoderDescriptor, ComputePassDescriptor, ComputePipelineDescriptor, PipelineCache,
    ShaderStages,
};
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::storage::{GpuShaderBuffer, ShaderBuffer};
use bevy::render::{Extract, ExtractSchedule, Render, RenderApp, RenderStartup, RenderSystems};
use pelage_shaders::groom::GroomPassUniform;
use pelage_shaders::workgroups;
use std::num::NonZero;
use std::sync::Arc;

/// The groom pipeline and its two layouts.
#[derive(Resource)]
struct GroomPipeline {
    buffers: BindGroupLayoutDescriptor,
    pass: BindGroupLayoutDescriptor,
    id: CachedComputePipelineId,
}

/// One frame's strands to grow: main-world entity, what, on which pose,
/// into which buffer.
struct StrandsToGrow {
    entity: Entity,
    source: Arc<GroomStrandsSource>,
    pose: Arc<Vec<[f32; 4]>>,
    points: AssetId<ShaderBuffer>,
    /// Render hairs drawn: only these (the first by arrival) are grown.
    drawn: u32,
}

#[derive(Resource, Default)]
struct ExtractedStrands(Vec<StrandsToGrow>);

/// A strands entity's GPU buffers (uploaded once) and bind groups.
struct GrowBuffers {
    source: Arc<GroomStrandsSource>,
    /// Bindings 0–4, 6 and 7 (5, the points, is the material's buffer).
    fixed: [Buffer; 7],
    /// Each pass's block at `stride` bytes.
    passes: Buffer,
    stride: u32,
    bound: Option<(AssetId<ShaderBuffer>, BindGroup, BindGroup)>,
}

#[derive(Resource, Default)]
struct StrandsBuffers(HashMap<Entity, GrowBuffers>);

/// Adds the render world's growth to `app` (after Bevy's render plugin).
pub(crate) fn build(app: &mut App) {
    let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
        return;
    };
    render_app
        .init_resource::<ExtractedStrands>()
        .init_resource::<StrandsBuffers>()
        .add_systems(RenderStartup, init_pipeline)
        .add_systems(ExtractSchedule, extract_strands)
        .add_systems(
            Render,
            grow_strands
                .in_set(RenderSystems::PrepareBindGroups)
                .run_if(resource_exists::<GroomPipeline>),
        );
}

fn init_pipeline(mut commands: Commands, cache: Res<PipelineCache>) {
    let read = || storage_buffer_read_only_sized(false, None);
    let write = || storage_buffer_sized(false, None);
    let buffers = BindGroupLayoutDescriptor::new(
        "pelage groom",
        &BindGroupLayoutEntries::sequential(
            ShaderStages::COMPUTE,
            (
                read(),
                read(),
                write(),
                read(),
                read(),
                write(),
                read(),
                read(),
            ),
        ),
    );
    let pass = BindGroupLayoutDescriptor::new(
        "pelage groom pass",
        &BindGroupLayoutEntries::single(
            ShaderStages::COMPUTE,
            uniform_buffer_sized(true, NonZero::new(size_of::<GroomPassUniform>() as u64)),
        ),
    );
    let id = cache.queue_compute_pipeline(ComputePipelineDescriptor {
        label: Some("pelage groom".into()),
        layout: vec![buffers.clone(), pass.clone()],
        shader: GROOM_SHADER,
        entry_point: Some("grow_hairs".into()),
        ..default()
    });
    commands.insert_resource(GroomPipeline { buffers, pass, id });
}

/// The strands some camera sees this frame (a culled character's hairs
/// are not grown).
fn extract_strands(
    mut out: ResMut<ExtractedStrands>,
    strands: Extract<Query<(Entity, &GroomStrands, &ViewVisibility)>>,
) {
    out.0.clear();
    for (entity, s, seen) in &strands {
        if s.drawn == 0 || s.pose.is_empty() || !seen.get() {
            continue;
        }
        out.0.push(StrandsToGrow {
            entity,
            source: s.source.clone(),
            pose: s.pose.clone(),
            points: s.points.id(),
            drawn: s.drawn,
        });
    }
}

/// A storage buffer holding `words` (an empty array binds one element).
fn storage(device: &RenderDevice, label: &str, bytes: &[u8], extra: BufferUsages) -> Buffer {
    let zeros = [0u8; 64];
    device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some(label),
        contents: if bytes.is_empty() { &zeros } else { bytes },
        usage: BufferUsages::STORAGE | extra,
    })
}

/// The buffers of `source`, uploaded: its fixed arrays, and its passes'
/// blocks, the last carrying the hairs to the posed skin.
fn upload(device: &RenderDevice, source: &Arc<GroomStrandsSource>) -> GrowBuffers {
    let u = &source.upload;
    let none = BufferUsages::empty();
    let bytes = bytemuck::cast_slice::<[f32; 4], u8>;
    let fixed = [
        storage(device, "pelage groom roots", bytes(&u.roots), none),
        storage(
            device,
            "pelage groom data",
            bytemuck::cast_slice(&u.data),
            none,
        ),
        storage(device, "pelage groom guides", bytes(&source.guides), none),
        storage(
            device,
            "pelage groom skin",
            bytes(&u.rest_skin),
            BufferUsages::COPY_DST,
        ),
        storage(
            device,
            "pelage groom triangles",
            bytemuck::cast_slice(&u.triangles),
            none,
        ),
        storage(
            device,
            "pelage groom rest grid",
            bytemuck::cast_slice(&u.rest_grid),
            none,
        ),
        storage(device, "pelage groom posed grid", &[], none),
    ];
    // Dynamic offsets are multiples of the device's alignment.
    let stride = (size_of::<GroomPassUniform>() as u32)
        .next_multiple_of(device.limits().min_uniform_buffer_offset_alignment);
    let last = u.passes.len().saturating_sub(1);
    let mut blocks = vec![0u8; stride as usize * u.passes.len().max(1)];
    for (i, p) in u.passes.iter().enumerate() {
        // Every frame is posed: the skin is in world space, not the
        // groom's rest space. Hairs are kept out of the rest skin
        // (no posed grid), then carried.
        let block = GroomPassUniform {
            posed: u32::from(i == last),
            ..*p
        };
        let at = i * stride as usize;
        blocks[at..at + size_of::<GroomPassUniform>()].copy_from_slice(bytemuck::bytes_of(&block));
    }
    GrowBuffers {
        source: source.clone(),
        fixed,
        passes: device.create_buffer_with_data(&BufferInitDescriptor {
            label: Some("pelage groom passes"),
            contents: &blocks,
            usage: BufferUsages::UNIFORM,
        }),
        stride,
        bound: None,
    }
}

#[allow(clippy::too_many_arguments)]
fn grow_strands(
    extracted: Res<ExtractedStrands>,
    mut buffers: ResMut<StrandsBuffers>,
    pipeline: Res<GroomPipeline>,
    cache: Res<PipelineCache>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    gpu_buffers: Res<RenderAssets<GpuShaderBuffer>>,
) {
    buffers
        .0
        .retain(|entity, _| extracted.0.iter().any(|s| s.entity == *entity));
    let Some(compute) = cache.get_compute_pipeline(pipeline.id) else {
        return;
    };
    let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor {
        label: Some("pelage strands"),
    });
    let mut grown = false;
    for s in &extracted.0 {
        let Some(points) = gpu_buffers.get(s.points) else {
            continue;
        };
        let b = buffers
            .0
            .entry(s.entity)
            .or_insert_with(|| upload(&device, &s.source));
        if !Arc::ptr_eq(&b.source, &s.source) {
            *b = upload(&device, &s.source);
        }
        if b.bound.as_ref().is_none_or(|(id, ..)| *id != s.points) {
            let [roots, data, guides, skin, triangles, rest_grid, posed_grid] = &b.fixed;
            let group = device.create_bind_group(
                "pelage groom",
                &cache.get_bind_group_layout(&pipeline.buffers),
                &BindGroupEntries::sequential((
                    roots.as_entire_binding(),
                    data.as_entire_binding(),
                    guides.as_entire_binding(),
                    skin.as_entire_binding(),
                    triangles.as_entire_binding(),
                    points.buffer.as_entire_binding(),
                    rest_grid.as_entire_binding(),
                    posed_grid.as_entire_binding(),
                )),
            );
            let pass = device.create_bind_group(
                "pelage groom pass",
                &cache.get_bind_group_layout(&pipeline.pass),
                &BindGroupEntries::single(BufferBinding {
                    buffer: &b.passes,
                    offset: 0,
                    size: NonZero::new(size_of::<GroomPassUniform>() as u64),
                }),
            );
            b.bound = Some((s.points, group, pass));
        }
        queue.write_buffer(&b.fixed[3], 0, bytemuck::cast_slice(&s.pose));
        let Some((_, group, pass_group)) = &b.bound else {
            continue;
        };
        let mut pass = encoder.begin_compute_pass(&ComputePassDescriptor {
            label: Some("pelage groom"),
            timestamp_writes: None,
        });
        pass.set_pipeline(compute);
        pass.set_bind_group(0, group, &[]);
        let render_first = s.source.upload.render.start;
        for (i, p) in s.source.upload.passes.iter().enumerate() {
            // The render hairs' pass grows the drawn ones only: a level of
            // detail draws the first by arrival, which come first.
            let count = if p.first == render_first {
                p.count.min(s.drawn)
            } else {
                p.count
            };
            if count == 0 {
                continue;
            }
            pass.set_bind_group(1, pass_group, &[i as u32 * b.stride]);
            let (x, y) = workgroups(count);
            pass.dispatch_workgroups(x, y, 1);
        }
        grown = true;
    }
    if grown {
        queue.submit([encoder.finish()]);
    }
}
