//! A groom grown on the GPU every frame: a [`GroomRecipe`] uploaded once,
//! then, each frame, the frame's guides (in rest space) and posed skin in,
//! every hair's points out, by one compute dispatch a recipe pass
//! (`shaders/groom.wgsl`, one invocation a hair, its points in registers).
//! The CPU groom of the same frame (`Generator::part`, or
//! `AnimatedGroom::part` for a posed frame) is the reference:
//! `tests/groom.rs` grows both and compares hair by hair.
//!
//! The output buffer holds each point as `xyz` and its width in `w`,
//! point-major (point `j` of hair `h` at `j · hairs + h`, clump centres
//! first, the render hairs last), ready for a strand renderer to read.

use crate::layout::{UniformRing, compute_pipeline, entry, gpu_struct, group};
use crate::{GpuContext, GpuError, workgroups};
use glam::{Mat3, Vec3};
use pelage::Curves;
use pelage::anim::{SkinBinding, SkinPose};
use pelage::groom::{Generator, GroomError, GroomErrorKind, GroomRecipe};
use wgpu::util::DeviceExt;

/// The most points a hair has on the GPU (the shader's `MAX_POINTS`: a
/// hair's points live in registers).
pub const MAX_GPU_HAIR_POINTS: usize = 32;

gpu_struct! {
    /// The shader's `GroomPass` block: one recipe pass.
    pub(crate) struct GroomPassUniform {
        first: u32,
        count: u32,
        steps: u32,
        points: u32,
        guide_points: u32,
        hairs: u32,
        values_per_hair: u32,
        posed: u32,
        resample_at: u32,
        render_first: u32,
        width_scale: f32,
        weights_at: u32,
        normals_at: u32,
        values_at: u32,
        steps_at: u32,
        tables_at: u32,
        permutation_at: u32,
        widths_at: u32,
        outside: u32,
        gap: f32,
        pad0: u32,
        pad1: u32,
        pad2: u32,
    }
}

/// A [`GroomRecipe`] on the GPU, grown again each [`Self::grow`].
#[derive(Debug)]
pub struct GpuGroom {
    pipeline: wgpu::ComputePipeline,
    passes: Vec<GroomPassUniform>,
    ring: UniformRing<GroomPassUniform>,
    bind_group: wgpu::BindGroup,
    layout: wgpu::BindGroupLayout,
    /// The roots, the packed data and the rest skin's grid (bindings 0,
    /// 1 and 6), kept to bind again when the posed grid's buffer grows.
    static_buffers: [wgpu::Buffer; 3],
    posed_sdf: wgpu::Buffer,
    /// Turning GPU strands into the frame's guides: the pipeline, its
    /// group 0 (guides, skin, triangles), group 2's layout and the guides'
    /// roots.
    rest_pipeline: wgpu::ComputePipeline,
    rest_frame_group: wgpu::BindGroup,
    rest_strands_layout: wgpu::BindGroupLayout,
    guide_roots: wgpu::Buffer,
    guide_count: u32,
    /// `[finish] outside_skin`: the gap, and the hairs' segment for a
    /// posed skin's grid.
    keep_out: Option<(f32, f32)>,
    triangle_list: Vec<[u32; 3]>,
    guide_offsets: wgpu::Buffer,
    skin: wgpu::Buffer,
    triangles: wgpu::Buffer,
    triangle_count: u32,
    /// The rest pose as the skin buffer holds it, written back when a
    /// frame at rest follows a posed one.
    rest_skin: Vec<[f32; 4]>,
    posed: bool,
    points: wgpu::Buffer,
    colors_buffer: wgpu::Buffer,
    hairs: u32,
    n: u32,
    guide_values: usize,
    skin_vertices: usize,
    render: std::ops::Range<u32>,
    /// The render hairs' ids, colours and opacities, for read-back.
    ids: Vec<u64>,
    colors: Option<Vec<Vec3>>,
    opacities: Option<Vec<f32>>,
}

/// No usage beyond storage.
const NONE: wgpu::BufferUsages = wgpu::BufferUsages::empty();

/// A storage buffer holding `bytes` (an empty array still binds a whole
/// element: a step is 32 bytes), with `extra` usages.
fn storage(
    device: &wgpu::Device,
    label: &str,
    bytes: &[u8],
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let zeros = [0u8; 32];
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: if bytes.is_empty() { &zeros } else { bytes },
        usage: wgpu::BufferUsages::STORAGE | extra,
    })
}

/// The groom shader's buffers, bindings 0 to 7: the roots, the packed
/// data, this frame's guides, the skin and its triangles, the points, the
/// skin's grids at rest and posed.
fn groom_buffers(
    device: &wgpu::Device,
    recipe: &GroomRecipe,
    skin: &SkinBinding,
    (roots, data): (&[[f32; 4]], &[u32]),
) -> [wgpu::Buffer; 8] {
    let dst = wgpu::BufferUsages::COPY_DST;
    let bytes = bytemuck::cast_slice::<[f32; 4], u8>;
    let (n, gp) = (recipe.points as usize, recipe.guide_points as usize);
    let triangles: Vec<u32> = skin.triangles().iter().flatten().copied().collect();
    let rest_grid = recipe
        .outside_skin
        .as_ref()
        .map_or_else(Vec::new, |(o, _)| packed_sdf(o.sdf(), 0));
    [
        storage(device, "groom roots", bytes(roots), NONE),
        storage(device, "groom data", bytemuck::cast_slice(data), NONE),
        storage(
            device,
            "groom guide offsets",
            &vec![0u8; recipe.guides as usize * gp * 16],
            dst,
        ),
        storage(
            device,
            "groom skin",
            bytes(&skin_vertices_of(skin.rest())),
            dst,
        ),
        storage(
            device,
            "groom skin triangles",
            bytemuck::cast_slice(&triangles),
            NONE,
        ),
        storage(
            device,
            "groom points",
            &vec![0u8; recipe.hair_count() * n * 16],
            wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::VERTEX,
        ),
        storage(
            device,
            "groom rest skin grid",
            bytemuck::cast_slice(&rest_grid),
            NONE,
        ),
        storage(device, "groom posed skin grid", &[0u8; 64], dst),
    ]
}

/// Where each section of the shader's `data` starts (its words), and the
/// guide-to-hair resampling's start within the tables (`u32::MAX`: none).
struct Sections {
    weights: u32,
    normals: u32,
    values: u32,
    steps: u32,
    tables: u32,
    resample: u32,
    permutation: u32,
    widths: u32,
}

/// Everything of `recipe` that does not change but the roots, as one
/// array of 32-bit words (floats by their bits): the shader's `data`.
fn packed(recipe: &GroomRecipe) -> (Vec<u32>, Sections) {
    let mut data: Vec<u32> = Vec::new();
    let mut section = |words: &mut dyn Iterator<Item = f32>| {
        let at = data.len() as u32;
        data.extend(words.map(f32::to_bits));
        at
    };
    let bits = f32::from_bits;
    let weights = section(
        &mut recipe
            .weights
            .iter()
            .flat_map(|w| [bits(w.guide), w.weight]),
    );
    let normals = section(&mut recipe.guide_normals.iter().flat_map(|v| v.to_array()));
    let values = section(&mut recipe.values.iter().copied());
    let steps = section(&mut recipe.steps.iter().flat_map(|s| {
        [
            s.kind as u32,
            s.values,
            u32::from(s.masked),
            s.table,
            s.permutation,
            s.vectors,
            s.centres,
            0,
        ]
        .map(bits)
    }));
    let tables = section(&mut recipe.tables.iter().copied());
    // The guide-to-hair resampling after the steps' tables, as pairs.
    let resample = if recipe.resampling.is_empty() {
        u32::MAX
    } else {
        let at = recipe.tables.len() as u32;
        section(&mut recipe.resampling.iter().flat_map(|&(j, f)| [j as f32, f]));
        at
    };
    let permutation = section(&mut recipe.permutations.iter().map(|&p| bits(p)));
    let widths = section(&mut recipe.widths.iter().copied());
    let sections = Sections {
        weights,
        normals,
        values,
        steps,
        tables,
        resample,
        permutation,
        widths,
    };
    (data, sections)
}

/// Each hair's root record (the shader's `HairRoot`, six `vec4`s): its
/// rest position and triangle, rest normal and barycentrics, whether it
/// grows bare, and — for render hairs — the rest skin frame it is carried
/// from.
fn root_records(recipe: &GroomRecipe, skin: &SkinBinding) -> Vec<[f32; 4]> {
    let render = recipe.render_hairs();
    (0..recipe.hair_count())
        .flat_map(|i| {
            let root = recipe.roots[i];
            let (origin, frame) = if render.contains(&(i as u32)) {
                skin.rest().frame_at(skin.triangles(), root)
            } else {
                (recipe.root_positions[i], Mat3::IDENTITY)
            };
            [
                v4(recipe.root_positions[i], f32::from_bits(root.tri)),
                v4(recipe.root_normals[i], root.bary[0]),
                v4(origin, root.bary[1]),
                v4(frame.x_axis, if recipe.bare[i] { 1.0 } else { 0.0 }),
                v4(frame.y_axis, 0.0),
                v4(frame.z_axis, 0.0),
            ]
        })
        .collect()
}

/// The groom shader's bind group layouts (its buffers; the pass ring) and
/// pipeline.
fn groom_pipeline(
    device: &wgpu::Device,
) -> (
    wgpu::BindGroupLayout,
    wgpu::BindGroupLayout,
    wgpu::ComputePipeline,
) {
    let compute = wgpu::ShaderStages::COMPUTE;
    // The guides (2) and the points (5) are written.
    let entries: Vec<_> = (0..8)
        .map(|b| entry::storage(b, compute, b != 2 && b != 5))
        .collect();
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("groom"),
        entries: &entries,
    });
    let ring_layout = UniformRing::<GroomPassUniform>::layout(device, "groom pass", compute);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("groom.wgsl"),
        source: wgpu::ShaderSource::Wgsl(crate::shader_source("groom.wgsl")),
    });
    let pipeline = compute_pipeline(
        device,
        "groom",
        &module,
        "grow_hairs",
        &[&layout, &ring_layout],
    );
    (layout, ring_layout, pipeline)
}

/// A skin's distance grid as the groom shader reads it (skin_sdf.wgsl's
/// `Grid` header, then the nodes' distances, their nearest triangles and
/// the triangles' corners and corner normals, all as words); `which`: 0 at
/// rest, 1 posed (the header's pad0).
fn packed_sdf(sdf: &pelage::dynamics::SkinSdf, which: u32) -> Vec<u32> {
    const HEADER: u32 = 12;
    let (origin, cell, dims) = sdf.layout();
    let nodes = sdf.distances().len() as u32;
    let mut out = vec![
        origin.x.to_bits(),
        origin.y.to_bits(),
        origin.z.to_bits(),
        cell.to_bits(),
        dims[0] as u32,
        dims[1] as u32,
        dims[2] as u32,
        sdf.band_depth().to_bits(),
        HEADER,
        0,
        which,
        HEADER + nodes,
    ];
    out.extend(sdf.distances().iter().map(|d| d.to_bits()));
    out.extend_from_slice(sdf.nearest_triangles());
    let (corners, normals) = sdf.triangles();
    for (c, n) in corners.iter().zip(normals) {
        for v in c.iter().chain(n) {
            out.extend([v.x, v.y, v.z, 0.0].map(f32::to_bits));
        }
    }
    out
}

/// The pipeline turning GPU strands into the frame's guide offsets
/// (`guides_to_rest`): its layouts for group 0 (the guides, written; the
/// skin and its triangles) and group 2 (the strands' points, the guides'
/// roots), the pass ring's as group 1.
fn rest_pipeline(
    device: &wgpu::Device,
    ring_layout: &wgpu::BindGroupLayout,
) -> (
    wgpu::BindGroupLayout,
    wgpu::BindGroupLayout,
    wgpu::ComputePipeline,
) {
    let compute = wgpu::ShaderStages::COMPUTE;
    let frame = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("groom guides to rest"),
        entries: &[
            entry::storage(2, compute, false),
            entry::storage(3, compute, true),
            entry::storage(4, compute, true),
        ],
    });
    let strands = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("groom strands"),
        entries: &[
            entry::storage(0, compute, true),
            entry::storage(1, compute, true),
        ],
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("groom.wgsl"),
        source: wgpu::ShaderSource::Wgsl(crate::shader_source("groom.wgsl")),
    });
    let pipeline = compute_pipeline(
        device,
        "groom guides to rest",
        &module,
        "guides_to_rest",
        &[&frame, ring_layout, &strands],
    );
    (frame, strands, pipeline)
}

/// Each guide's root as `guides_to_rest` reads it: (triangle bits, b1,
/// b2, 0), then its rest frame's columns.
fn guide_root_records(recipe: &GroomRecipe, skin: &SkinBinding) -> Vec<[f32; 4]> {
    recipe
        .guide_roots
        .iter()
        .flat_map(|&root| {
            let (_, frame) = skin.rest().frame_at(skin.triangles(), root);
            [
                [f32::from_bits(root.tri), root.bary[0], root.bary[1], 0.0],
                v4(frame.x_axis, 0.0),
                v4(frame.y_axis, 0.0),
                v4(frame.z_axis, 0.0),
            ]
        })
        .collect()
}

/// A pose's vertices as the shaders read them: position, then normal.
fn skin_vertices_of(pose: &SkinPose) -> Vec<[f32; 4]> {
    pose.positions()
        .iter()
        .zip(pose.normals())
        .flat_map(|(&p, &n)| [v4(p, 0.0), v4(n, 0.0)])
        .collect()
}

/// `v` as a `vec4` with `w`.
fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

impl GpuGroom {
    /// Uploads `recipe`. `skin` is the skin the hairs grow on: its rest
    /// pose is the one the groom was grown on, [`Self::grow`] carries the
    /// hairs to its other poses, and a strand renderer's shadows fall
    /// from it ([`Self::skin_at_rest`] makes one of a still mesh).
    ///
    /// # Errors
    /// When hairs or guides have more than [`MAX_GPU_HAIR_POINTS`] points,
    /// or a buffer is larger than the adapter binds.
    pub fn new(
        ctx: &GpuContext,
        recipe: &GroomRecipe,
        skin: &SkinBinding,
    ) -> Result<Self, GpuError> {
        let (n, gp) = (recipe.points as usize, recipe.guide_points as usize);
        if n > MAX_GPU_HAIR_POINTS || gp > MAX_GPU_HAIR_POINTS {
            return Err(GpuError::Mismatch(format!(
                "hairs of {n} points from guides of {gp}: the GPU groom takes at most {MAX_GPU_HAIR_POINTS}; lower [finish] points or resample the guides"
            )));
        }
        let hairs = recipe.hair_count();
        let hairs32 = u32::try_from(hairs)
            .map_err(|_| GpuError::Mismatch(format!("{hairs} hairs: too many for a GPU index")))?;
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        let largest = (hairs * n * 16) as u64;
        if largest > limit {
            return Err(GpuError::Mismatch(format!(
                "{hairs} hairs of {n} points need {largest} bytes a buffer; the adapter binds at most {limit}: grow fewer hairs (a fraction) or fewer points"
            )));
        }
        let render = recipe.render_hairs();
        let roots = root_records(recipe, skin);
        let (data, sections) = packed(recipe);
        let skin_vertices = skin.rest().positions().len();
        let device = &ctx.device;
        let buffers = groom_buffers(device, recipe, skin, (&roots, &data));
        let (layout, ring_layout, pipeline) = groom_pipeline(device);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("groom"),
            layout: &layout,
            entries: &group::buffers(buffers.each_ref()),
        });
        let ring = UniformRing::new(device, "groom pass", &ring_layout);
        let (rest_frame_layout, rest_strands_layout, rest_pipeline) =
            rest_pipeline(device, &ring_layout);
        let guide_roots = storage(
            device,
            "groom guide roots",
            bytemuck::cast_slice(&guide_root_records(recipe, skin)),
            NONE,
        );
        let passes = recipe
            .passes
            .iter()
            .map(|p| GroomPassUniform {
                first: p.hairs.start,
                count: p.hairs.len() as u32,
                steps: p.steps,
                points: n as u32,
                guide_points: gp as u32,
                hairs: hairs32,
                values_per_hair: recipe.values_per_hair,
                posed: 0,
                resample_at: sections.resample,
                render_first: render.start,
                width_scale: 1.0,
                weights_at: sections.weights,
                normals_at: sections.normals,
                values_at: sections.values,
                steps_at: sections.steps,
                tables_at: sections.tables,
                permutation_at: sections.permutation,
                widths_at: sections.widths,
                outside: u32::from(recipe.outside_skin.is_some()),
                gap: recipe.outside_skin.as_ref().map_or(0.0, |(o, _)| o.gap()),
                pad0: 0,
                pad1: 0,
                pad2: 0,
            })
            .collect();
        let [
            roots_buffer,
            data_buffer,
            guide_offsets,
            skin_buffer,
            triangles_buffer,
            points,
            rest_sdf,
            posed_sdf,
        ] = buffers;
        // A render point's colour (negative: the hairs have none) and
        // opacity, for a strand renderer.
        let shade: Vec<[f32; 4]> = (0..render.len() * n)
            .map(|k| {
                let c = recipe.colors.as_ref().map_or(Vec3::splat(-1.0), |c| c[k]);
                v4(c, recipe.opacities.as_ref().map_or(1.0, |o| o[k]))
            })
            .collect();
        let colors_buffer = storage(device, "groom colours", bytemuck::cast_slice(&shade), NONE);
        Ok(Self {
            pipeline,
            passes,
            ring,
            bind_group,
            layout,
            rest_frame_group: device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("groom guides to rest"),
                layout: &rest_frame_layout,
                entries: &group::buffers_at([
                    (2, &guide_offsets),
                    (3, &skin_buffer),
                    (4, &triangles_buffer),
                ]),
            }),
            rest_strands_layout,
            rest_pipeline,
            guide_roots,
            guide_count: recipe.guides,
            static_buffers: [roots_buffer, data_buffer, rest_sdf],
            posed_sdf,
            keep_out: recipe
                .outside_skin
                .as_ref()
                .map(|(o, segment)| (o.gap(), *segment)),
            triangle_list: skin.triangles().to_vec(),
            guide_offsets,
            skin: skin_buffer,
            triangles: triangles_buffer,
            triangle_count: skin.triangles().len() as u32,
            rest_skin: skin_vertices_of(skin.rest()),
            posed: false,
            points,
            colors_buffer,
            hairs: hairs32,
            n: n as u32,
            guide_values: recipe.guides as usize * gp,
            skin_vertices,
            render: render.clone(),
            ids: recipe.ids[render.start as usize..render.end as usize].to_vec(),
            colors: recipe.colors.clone(),
            opacities: recipe.opacities.clone(),
        })
    }

    /// Queues a frame: every hair grown from `guide_offsets` (the frame's
    /// guides in rest space, [`GroomRecipe::guide_offsets`]) and, with a
    /// `pose`, carried from the rest skin to it (the binding's skin, as
    /// `SkinBinding::carry_in_place` carries the CPU's hairs).
    ///
    /// # Errors
    /// When the guides or the pose do not match what was uploaded.
    pub fn grow(
        &mut self,
        ctx: &GpuContext,
        guide_offsets: &[Vec3],
        pose: Option<&SkinPose>,
    ) -> Result<(), GpuError> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.record(ctx, &mut encoder, guide_offsets, pose)?;
        ctx.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// [`Self::grow`] recorded into a caller's encoder (a host's frame):
    /// the guides and pose are written through the context's queue, the
    /// compute pass is recorded; submit after it. With `[finish]
    /// outside_skin`, a pose's distance grid is built here on the CPU (a
    /// few milliseconds for a character) and the carried hairs are kept
    /// out of it, as an animated groom's frames are.
    ///
    /// # Errors
    /// When the guides or the pose do not match what was uploaded.
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        guide_offsets: &[Vec3],
        pose: Option<&SkinPose>,
    ) -> Result<(), GpuError> {
        if guide_offsets.len() != self.guide_values {
            return Err(GpuError::Mismatch(format!(
                "{} guide points for a groom of {}",
                guide_offsets.len(),
                self.guide_values
            )));
        }
        let offsets: Vec<[f32; 4]> = guide_offsets.iter().map(|&v| v4(v, 0.0)).collect();
        ctx.queue
            .write_buffer(&self.guide_offsets, 0, bytemuck::cast_slice(&offsets));
        self.record_frame(ctx, encoder, pose, None)
    }

    /// [`Self::record`] with the frame's guides read from `strands` on the
    /// GPU (stepped on `pose`, the same guides in the same order) and
    /// turned to rest space there: no read-back, nothing waits.
    ///
    /// # Errors
    /// When the strands are not this groom's guides, or the pose does not
    /// match the skin.
    pub fn record_from_strands(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        strands: &crate::GpuStrands,
        pose: &SkinPose,
    ) -> Result<(), GpuError> {
        let (_, count, points) = strands.positions_buffer();
        if count != self.guide_count || count as usize * points as usize != self.guide_values {
            return Err(GpuError::Mismatch(format!(
                "{count} strands of {points} points for a groom of {} guide points in {} guides",
                self.guide_values, self.guide_count
            )));
        }
        self.record_frame(ctx, encoder, Some(pose), Some(strands))
    }

    /// A frame's passes: the pose and its grid written, the guides turned
    /// to rest from `strands` when given, then every pass of hairs.
    fn record_frame(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        pose: Option<&SkinPose>,
        strands: Option<&crate::GpuStrands>,
    ) -> Result<(), GpuError> {
        let queue = &ctx.queue;
        let posed_grid = self.posed_grid(ctx, pose);
        match pose {
            Some(pose) => {
                if pose.positions().len() != self.skin_vertices {
                    return Err(GpuError::Mismatch(format!(
                        "a pose of {} vertices for a skin of {}",
                        pose.positions().len(),
                        self.skin_vertices
                    )));
                }
                let skin = skin_vertices_of(pose);
                queue.write_buffer(&self.skin, 0, bytemuck::cast_slice(&skin));
                self.posed = true;
            }
            None => {
                if std::mem::take(&mut self.posed) {
                    queue.write_buffer(&self.skin, 0, bytemuck::cast_slice(&self.rest_skin));
                }
            }
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("groom"),
            timestamp_writes: None,
        });
        if let Some(strands) = strands {
            let (points, count, _) = strands.positions_buffer();
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("groom strands"),
                layout: &self.rest_strands_layout,
                entries: &group::buffers([points, &self.guide_roots]),
            });
            let uniform = GroomPassUniform {
                first: 0,
                count: self.guide_count,
                hairs: count,
                ..self.passes[0]
            };
            let offset = self.ring.write(queue, &uniform);
            pass.set_pipeline(&self.rest_pipeline);
            pass.set_bind_group(0, &self.rest_frame_group, &[]);
            pass.set_bind_group(1, self.ring.group(), &[offset]);
            pass.set_bind_group(2, &group, &[]);
            let (x, y) = workgroups(self.guide_count);
            pass.dispatch_workgroups(x, y, 1);
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        let last = self.passes.len().saturating_sub(1);
        for (i, p) in self.passes.iter().enumerate() {
            if p.count == 0 {
                continue;
            }
            let last_pass = i == last;
            let uniform = GroomPassUniform {
                posed: u32::from(pose.is_some() && last_pass),
                outside: p.outside | if posed_grid && last_pass { 2 } else { 0 },
                ..*p
            };
            let offset = self.ring.write(queue, &uniform);
            pass.set_bind_group(1, self.ring.group(), &[offset]);
            let (x, y) = workgroups(p.count);
            pass.dispatch_workgroups(x, y, 1);
        }
        Ok(())
    }

    /// With `[finish] outside_skin` and a pose other than the rest pose:
    /// the pose's distance grid written for the shader (its buffer grown,
    /// and bound again, when it does not fit). Whether there is one.
    fn posed_grid(&mut self, ctx: &GpuContext, pose: Option<&SkinPose>) -> bool {
        let (Some((gap, segment)), Some(pose)) = (self.keep_out, pose) else {
            return false;
        };
        let rest = &self.rest_skin;
        let at_rest = pose.positions().len() * 2 == rest.len()
            && pose
                .positions()
                .iter()
                .zip(rest.iter().step_by(2))
                .all(|(p, r)| p.to_array() == [r[0], r[1], r[2]]);
        if at_rest {
            return false;
        }
        let skin = (pose.positions(), pose.normals(), &self.triangle_list[..]);
        let posed = pelage::groom::OutsideSkin::posed(skin, gap, segment);
        let words = packed_sdf(posed.sdf(), 1);
        let bytes: &[u8] = bytemuck::cast_slice(&words);
        if bytes.len() as u64 > self.posed_sdf.size() {
            self.posed_sdf = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("groom posed skin grid"),
                size: (bytes.len() as u64).next_power_of_two(),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let [roots, data, rest_sdf] = &self.static_buffers;
            let entries = group::buffers([
                roots,
                data,
                &self.guide_offsets,
                &self.skin,
                &self.triangles,
                &self.points,
                rest_sdf,
                &self.posed_sdf,
            ]);
            self.bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("groom"),
                layout: &self.layout,
                entries: &entries,
            });
        }
        ctx.queue.write_buffer(&self.posed_sdf, 0, bytes);
        true
    }

    /// Every hair's points, `xyz` and width, point-major (module docs).
    pub fn points(&self) -> &wgpu::Buffer {
        &self.points
    }

    /// A still mesh as the skin hairs grow on, for [`Self::new`]: its
    /// rest pose is the mesh.
    pub fn skin_at_rest(mesh: &pelage::Mesh) -> SkinBinding {
        let triangles = mesh.triangles().to_vec();
        let rest = SkinPose::new(mesh.positions().to_vec(), &triangles);
        SkinBinding::new(triangles, rest)
    }

    /// The skin as last grown on (a vertex's position, then its normal)
    /// and its triangles (three indices each), and how many triangles.
    pub fn skin(&self) -> (&wgpu::Buffer, &wgpu::Buffer, u32) {
        (&self.skin, &self.triangles, self.triangle_count)
    }

    /// Each render hair's points' colours (`rgb`, negative where the
    /// groom has none) and opacities (`w`), hair after hair.
    pub fn colors(&self) -> &wgpu::Buffer {
        &self.colors_buffer
    }

    /// The render hairs: which hairs of [`Self::points`] to draw.
    pub fn render_hairs(&self) -> std::ops::Range<u32> {
        self.render.clone()
    }

    /// Hairs in [`Self::points`] (its rows' stride) and points a hair.
    pub fn layout(&self) -> (u32, u32) {
        (self.hairs, self.n)
    }

    /// The render hairs as last grown, read back: points, widths and ids
    /// (with the recipe's colours and opacities).
    ///
    /// # Errors
    /// When the read-back fails or a value is not finite.
    pub fn read_curves(&self, ctx: &GpuContext) -> Result<Curves, GpuError> {
        let (points, widths) = self.read_points(ctx)?;
        let n = self.n;
        let offsets = (0..=self.ids.len() as u32).map(|i| i * n).collect();
        let bad = |e: pelage::curves::CurvesError| GpuError::Mismatch(format!("grown hairs: {e}"));
        let mut curves = Curves::new(points, widths, offsets)
            .map_err(bad)?
            .with_ids(self.ids.clone())
            .map_err(bad)?;
        if let Some(colors) = &self.colors {
            curves = curves.with_colors(colors.clone()).map_err(bad)?;
        }
        if let Some(opacities) = &self.opacities {
            curves = curves.with_opacities(opacities.clone()).map_err(bad)?;
        }
        Ok(curves)
    }

    /// The render hairs' points and widths as last grown, read back, hair
    /// after hair.
    ///
    /// # Errors
    /// When the read-back fails.
    pub fn read_points(&self, ctx: &GpuContext) -> Result<(Vec<Vec3>, Vec<f32>), GpuError> {
        let size = self.points.size();
        let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("groom readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.points, 0, &readback, 0, size);
        ctx.queue.submit([encoder.finish()]);
        let (hairs, n) = (self.hairs as usize, self.n as usize);
        let render = self.render.start as usize..self.render.end as usize;
        crate::readback::map_read(ctx, &readback, |mapped| {
            let values: &[[f32; 4]] = bytemuck::cast_slice(mapped);
            let mut points = Vec::with_capacity(render.len() * n);
            let mut widths = Vec::with_capacity(render.len() * n);
            for h in render.clone() {
                for j in 0..n {
                    let v = values[j * hairs + h];
                    points.push(Vec3::new(v[0], v[1], v[2]));
                    widths.push(v[3]);
                }
            }
            (points, widths)
        })
    }
}

/// A still groom's parts grown on the GPU, for
/// [`Generator::write_grown_until`]: each part's recipe uploaded and grown,
/// its hairs read back and finished by [`Generator::part_from_grown`]
/// (normals, root UVs, the look), so the files are the CPU's within
/// rounding (`pelage groom --gpu`).
#[derive(Debug)]
pub struct GpuPartGrower<'a> {
    ctx: &'a GpuContext,
    generator: &'a Generator,
    skin: SkinBinding,
}

impl<'a> GpuPartGrower<'a> {
    /// The grower of `generator`'s parts on `ctx`.
    ///
    /// # Errors
    /// When the groom has what the GPU evaluator leaves out
    /// ([`GroomRecipe::left_out`]): growing it there would write a
    /// different groom.
    pub fn new(ctx: &'a GpuContext, generator: &'a Generator) -> Result<Self, GroomError> {
        let probe = GroomRecipe::new(generator, &[], &[])?;
        if let Some(first) = probe.left_out.first() {
            let all: Vec<String> = probe.left_out.iter().map(|l| l.key.clone()).collect();
            return Err(generator.error(
                &first.key,
                GroomErrorKind::Conflict(format!(
                    "the GPU evaluator leaves out {} ({}): grow this groom without --gpu",
                    all.join(", "),
                    first.why
                )),
            ));
        }
        Ok(Self {
            ctx,
            generator,
            skin: GpuGroom::skin_at_rest(generator.mesh()),
        })
    }

    /// Part `p`, grown on the GPU.
    ///
    /// # Errors
    /// When the GPU fails, or a hair grew a value that is not finite.
    pub fn part(&self, p: usize) -> Result<Curves, GroomError> {
        let generator = self.generator;
        let (roots, ids) = generator.part_roots(p);
        let recipe = GroomRecipe::new(generator, &roots, &ids)?;
        let evaluator =
            |e: GpuError| generator.error("finish", GroomErrorKind::Evaluator(Box::new(e)));
        let mut gpu = GpuGroom::new(self.ctx, &recipe, &self.skin).map_err(evaluator)?;
        let offsets = GroomRecipe::guide_offsets(generator.guides());
        gpu.grow(self.ctx, &offsets, None).map_err(evaluator)?;
        let (points, widths) = gpu.read_points(self.ctx).map_err(evaluator)?;
        // The hairs the recipe kept (a cut can take some away whole).
        let render = recipe.render_hairs();
        let kept = render.start as usize..render.end as usize;
        let (roots, ids) = (
            recipe.roots[kept.clone()].to_vec(),
            recipe.ids[kept].to_vec(),
        );
        generator.part_from_grown(roots, ids, points, widths, recipe.colors, recipe.opacities)
    }
}
