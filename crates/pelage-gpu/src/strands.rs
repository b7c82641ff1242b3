//! Guide strands on the GPU: a frame of `pelage::dynamics::GuideStrands::step`
//! (Dynamic Follow-The-Leader with bending, follow, wind, collisions with
//! the skin's distance grids and friction) as one compute dispatch, one
//! invocation a strand looping over the frame's substeps with the
//! strand's points in registers. `shaders/strands.wgsl` mirrors the Rust
//! function by function; `tests/strands.rs` steps both and compares.
//!
//! The CPU still makes what depends on the skin (the roots' frames and
//! the grids, a few milliseconds for a character); the GPU moves the
//! points, which is what grows with the groom. Points are kept
//! point-major on the GPU so a workgroup's reads are contiguous.

use crate::layout::{compute_pipeline, entry, gpu_struct};
use crate::{GpuContext, GpuError, workgroups};
use glam::Vec3;
use pelage::dynamics::{GuideStrandParams, GuideStrands, RootFrame, SkinSdf};
use wgpu::util::DeviceExt;

/// The most points a strand has on the GPU (the shader's `MAX_POINTS`:
/// its per-strand arrays live in registers).
pub const MAX_GPU_STRAND_POINTS: usize = 32;
/// The most substeps a frame (wind slots).
const MAX_SUBSTEPS: usize = 64;

gpu_struct! {
    /// The shader's `StrandStep` block.
    pub(crate) struct StrandStepUniform {
        gravity_h: [f32; 3],
        h: f32,
        decay: f32,
        drag: f32,
        follow: f32,
        bend: f32,
        ftl: f32,
        thickness: f32,
        friction: f32,
        turbulence: f32,
        turbulence_scale: f32,
        iterations: u32,
        substeps: u32,
        strands: u32,
        points: u32,
        grids: u32,
        pad0: u32,
        pad1: u32,
    }
}

gpu_struct! {
    /// The shader's `Grid`: where one skin grid's nodes and triangles are.
    pub(crate) struct GridHeader {
        origin: [f32; 3],
        cell: f32,
        nx: u32,
        ny: u32,
        nz: u32,
        far: f32,
        node_offset: u32,
        triangle_offset: u32,
        pad0: u32,
        pad1: u32,
    }
}

/// A growable storage buffer.
#[derive(Debug)]
struct Storage {
    label: &'static str,
    buffer: wgpu::Buffer,
}

impl Storage {
    fn new(ctx: &GpuContext, label: &'static str, bytes: &[u8]) -> Self {
        let contents = if bytes.is_empty() {
            &[0u8; 16][..]
        } else {
            bytes
        };
        let buffer = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
            });
        Self { label, buffer }
    }

    /// Writes `bytes`, growing the buffer first when they do not fit;
    /// true when it grew (bind groups must be made again).
    fn write(&mut self, ctx: &GpuContext, bytes: &[u8]) -> bool {
        if bytes.len() as u64 > self.buffer.size() {
            *self = Self::new(ctx, self.label, bytes);
            return true;
        }
        if !bytes.is_empty() {
            ctx.queue.write_buffer(&self.buffer, 0, bytes);
        }
        false
    }
}

/// [`GuideStrands`] uploaded to the GPU and stepped there a frame at a time.
#[derive(Debug)]
pub struct GpuStrands {
    strands: u32,
    points: u32,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    positions: Storage,
    velocities: Storage,
    rest: Storage,
    roots: Storage,
    winds: Storage,
    permutation: Storage,
    permutation_seed: Option<u64>,
    grids: Storage,
    distances: Storage,
    nearest: Storage,
    triangles: Storage,
    bind_group: Option<wgpu::BindGroup>,
    /// The roots where the last frame ended.
    last_roots: Vec<RootFrame>,
}

/// `values` (strand-major, `n` a strand) point-major, xyz + `w`.
fn point_major(values: &[Vec3], w: &[f32], n: usize) -> Vec<[f32; 4]> {
    let strands = values.len() / n.max(1);
    let mut out = vec![[0.0; 4]; values.len()];
    for s in 0..strands {
        for i in 0..n {
            let v = values[s * n + i];
            out[i * strands + s] = [v.x, v.y, v.z, w.get(s * n + i).copied().unwrap_or(0.0)];
        }
    }
    out
}

impl GpuStrands {
    /// Uploads `strands` (their state, groomed shapes and roots).
    pub fn new(ctx: &GpuContext, strands: &GuideStrands) -> Result<Self, GpuError> {
        let n = strands.points_per_strand();
        if n > MAX_GPU_STRAND_POINTS {
            return Err(GpuError::Mismatch(format!(
                "strands of {n} points: the GPU solver takes at most {MAX_GPU_STRAND_POINTS}; resample the guides or simulate on the CPU"
            )));
        }
        let count = u32::try_from(strands.len())
            .map_err(|_| GpuError::Mismatch("too many strands for a GPU index".into()))?;
        let bytes = (strands.positions().len().max(1) * 16) as u64;
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(GpuError::Mismatch(format!(
                "{} points need {bytes} bytes a buffer; the adapter binds at most {limit}",
                strands.positions().len()
            )));
        }
        let cast = |v: &[[f32; 4]]| bytemuck::cast_slice::<[f32; 4], u8>(v).to_vec();
        let positions = Storage::new(
            ctx,
            "strands positions",
            &cast(&point_major(strands.positions(), &[], n)),
        );
        let velocities = Storage::new(
            ctx,
            "strands velocities",
            &cast(&point_major(strands.velocities(), &[], n)),
        );
        let rest = Storage::new(
            ctx,
            "strands rest",
            &cast(&point_major(
                strands.rest_local(),
                strands.rest_lengths(),
                n,
            )),
        );
        let roots = Storage::new(ctx, "strands roots", &vec![0u8; strands.len() * 96]);
        let winds = Storage::new(ctx, "strands winds", &[0u8; MAX_SUBSTEPS * 32]);
        let permutation = Storage::new(ctx, "strands noise permutation", &[0u8; 512 * 4]);
        let grids = Storage::new(ctx, "strands grids", &[0u8; 48]);
        let distances = Storage::new(ctx, "strands grid distances", &[0u8; 16]);
        let nearest = Storage::new(ctx, "strands grid triangles", &[0u8; 16]);
        let triangles = Storage::new(ctx, "strands skin triangles", &[0u8; 96]);
        let uniform = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("strands step"),
            size: std::mem::size_of::<StrandStepUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![entry::buffer(
            0,
            compute,
            wgpu::BufferBindingType::Uniform,
            false,
        )];
        entries.push(entry::storage(1, compute, false));
        entries.push(entry::storage(2, compute, false));
        entries.extend((3..=10).map(|b| entry::storage(b, compute, true)));
        let layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("strands"),
                entries: &entries,
            });
        let module = ctx
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("strands.wgsl"),
                source: wgpu::ShaderSource::Wgsl(crate::shader_source("strands.wgsl")),
            });
        let pipeline = compute_pipeline(
            &ctx.device,
            "strands frame",
            &module,
            "strands_frame",
            &[&layout],
        );
        Ok(Self {
            strands: count,
            points: n as u32,
            pipeline,
            layout,
            uniform,
            positions,
            velocities,
            rest,
            roots,
            winds,
            permutation,
            permutation_seed: None,
            grids,
            distances,
            nearest,
            triangles,
            bind_group: None,
            last_roots: strands.roots().to_vec(),
        })
    }

    /// Queues a frame of `dt` seconds ending at `time`: `params.substeps`
    /// substeps while the roots move to `roots`, colliding with `skin`
    /// (one grid a substep, or one for all; empty: no collisions), as
    /// [`GuideStrands::step`] does.
    pub fn step(
        &mut self,
        ctx: &GpuContext,
        params: &GuideStrandParams,
        dt: f32,
        time: f32,
        roots: &[RootFrame],
        skin: &[SkinSdf],
    ) -> Result<(), GpuError> {
        if roots.len() != self.strands as usize {
            return Err(GpuError::Mismatch(format!(
                "{} roots for {} strands",
                roots.len(),
                self.strands
            )));
        }
        let substeps = params.substeps.max(1) as usize;
        if substeps > MAX_SUBSTEPS {
            return Err(GpuError::Mismatch(format!(
                "{substeps} substeps a frame: the GPU solver takes at most {MAX_SUBSTEPS}"
            )));
        }
        if skin.len() > 1 && skin.len() != substeps {
            return Err(GpuError::Mismatch(format!(
                "{} skin grids for {substeps} substeps: give one, or one a substep",
                skin.len()
            )));
        }
        let k = params.substep_constants(dt);
        let mut grew = false;
        // Roots: where each frame starts and ends.
        let root_data: Vec<[f32; 4]> = self
            .last_roots
            .iter()
            .zip(roots)
            .flat_map(|(from, to)| {
                let v = |p: Vec3| [p.x, p.y, p.z, 0.0];
                [
                    v(from.position),
                    v(from.frame.x_axis),
                    v(from.frame.z_axis),
                    v(to.position),
                    v(to.frame.x_axis),
                    v(to.frame.z_axis),
                ]
            })
            .collect();
        grew |= self.roots.write(ctx, bytemuck::cast_slice(&root_data));
        // Wind: the gusting mean and drift at each substep's end.
        let (mut turbulence, mut scale) = (0.0, 0.0);
        let mut winds = vec![[0.0f32; 4]; 2 * substeps];
        if let Some(wind) = &params.wind {
            turbulence = wind.turbulence;
            scale = wind.scale;
            for s in 0..substeps {
                let now = wind.now(time - dt + k.h * (s + 1) as f32);
                let (m, d) = (now.mean(), now.drift());
                winds[2 * s] = [m.x, m.y, m.z, 0.0];
                winds[2 * s + 1] = [d.x, d.y, d.z, 0.0];
            }
            let seed = wind.now(time).noise().seed;
            if self.permutation_seed != Some(seed) {
                let table: Vec<u32> = wind
                    .now(time)
                    .noise()
                    .permutation_table()
                    .iter()
                    .map(|&p| u32::from(p))
                    .collect();
                grew |= self.permutation.write(ctx, bytemuck::cast_slice(&table));
                self.permutation_seed = Some(seed);
            }
        }
        grew |= self.winds.write(ctx, bytemuck::cast_slice(&winds));
        // The skin's grids, one after the other.
        let (mut headers, mut distances, mut nearest, mut triangles) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::<[f32; 4]>::new());
        for grid in skin {
            let (origin, cell, dims) = grid.layout();
            let (corners, normals) = grid.triangles();
            headers.push(GridHeader {
                origin: origin.to_array(),
                cell,
                nx: dims[0] as u32,
                ny: dims[1] as u32,
                nz: dims[2] as u32,
                far: grid.band_depth(),
                node_offset: distances.len() as u32,
                triangle_offset: (triangles.len() / 6) as u32,
                pad0: 0,
                pad1: 0,
            });
            distances.extend_from_slice(grid.distances());
            nearest.extend_from_slice(grid.nearest_triangles());
            for (c, n) in corners.iter().zip(normals) {
                for v in c.iter().chain(n) {
                    triangles.push([v.x, v.y, v.z, 0.0]);
                }
            }
        }
        if !skin.is_empty() {
            grew |= self.grids.write(ctx, bytemuck::cast_slice(&headers));
            grew |= self.distances.write(ctx, bytemuck::cast_slice(&distances));
            grew |= self.nearest.write(ctx, bytemuck::cast_slice(&nearest));
            grew |= self.triangles.write(ctx, bytemuck::cast_slice(&triangles));
        }
        let uniform = StrandStepUniform {
            gravity_h: k.gravity_h.to_array(),
            h: k.h,
            decay: k.decay,
            drag: if params.wind.is_some() { k.drag } else { 0.0 },
            follow: k.follow,
            bend: k.bend,
            ftl: k.ftl,
            thickness: k.thickness,
            friction: k.friction,
            turbulence,
            turbulence_scale: scale,
            iterations: k.iterations,
            substeps: substeps as u32,
            strands: self.strands,
            points: self.points,
            grids: skin.len() as u32,
            pad0: 0,
            pad1: 0,
        };
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        if grew || self.bind_group.is_none() {
            self.bind_group = Some(self.make_bind_group(ctx));
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("strands frame"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, self.bind_group.as_ref(), &[]);
            let (x, y) = workgroups(self.strands);
            pass.dispatch_workgroups(x, y, 1);
        }
        ctx.queue.submit([encoder.finish()]);
        self.last_roots = roots.to_vec();
        Ok(())
    }

    fn make_bind_group(&self, ctx: &GpuContext) -> wgpu::BindGroup {
        let buffers = [
            &self.uniform,
            &self.positions.buffer,
            &self.velocities.buffer,
            &self.rest.buffer,
            &self.roots.buffer,
            &self.winds.buffer,
            &self.permutation.buffer,
            &self.grids.buffer,
            &self.distances.buffer,
            &self.nearest.buffer,
            &self.triangles.buffer,
        ];
        let entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .enumerate()
            .map(|(b, buffer)| wgpu::BindGroupEntry {
                binding: b as u32,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("strands"),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// Every point now, point-major (point `i` of strand `s` at
    /// `i · strands + s`, `xyz`), and the strands and points a strand: what
    /// a [`crate::GpuGroom`] reads its frame's guides from without a
    /// read-back.
    pub fn positions_buffer(&self) -> (&wgpu::Buffer, u32, u32) {
        (&self.positions.buffer, self.strands, self.points)
    }

    /// Waits for every queued frame to finish.
    pub fn wait(&self, ctx: &GpuContext) -> Result<(), GpuError> {
        ctx.wait()
    }

    /// Every point now, strand after strand (as [`GuideStrands::positions`]).
    pub fn read_positions(&self, ctx: &GpuContext) -> Result<Vec<Vec3>, GpuError> {
        let buffer = &self.positions.buffer;
        let size = buffer.size();
        let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("strands readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &readback, 0, size);
        ctx.queue.submit([encoder.finish()]);
        let (strands, n) = (self.strands as usize, self.points as usize);
        crate::readback::map_read(ctx, &readback, |mapped| {
            let values: &[[f32; 4]] = bytemuck::cast_slice(mapped);
            let mut out = vec![Vec3::ZERO; strands * n];
            for s in 0..strands {
                for i in 0..n {
                    let v = values[i * strands + s];
                    out[s * n + i] = Vec3::new(v[0], v[1], v[2]);
                }
            }
            out
        })
    }
}
