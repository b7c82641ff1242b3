//! The mass-spring solvers on the GPU: the explicit solver's fused substep
//! of `pelage::dynamics` (force, velocity, position, constraints; Banisch &
//! Wüthrich, Silva §3.2.1) and, where no springs join the tips
//! (spring-sticks, separable spring-sticks, Silva strands), the implicit
//! solver's backward-Euler step with its direct 3×3 solve per tip — each a
//! compute shader, one invocation a tip, double buffered like the CPU pass.
//! Prisms' implicit step (conjugate gradients over the tip-tip springs)
//! stays on the CPU. `shaders/dynamics.wgsl` mirrors the
//! Rust function by function; `tests/dynamics.rs` steps both and compares.
//!
//! Why it exists: on two CPU cores a step of a million masses takes tens of
//! milliseconds (docs/benchmarks/dynamics.md) against a 3 ms budget; a
//! GPU moves the ~90 bytes a mass a step that bounds the CPU at hundreds of
//! GB/s. Many steps can be queued in one submission, as a real-time loop
//! would, and the state read back only when the CPU needs it.
//!
//! One file, past 600 lines: the explicit and implicit compute pipelines
//! share buffers, bind groups and the uniform ring.

use crate::layout::{compute_pipeline, entry, gpu_struct, group};
use crate::{GpuContext, GpuError, ShellModel, workgroups};
use glam::Vec3;
use pelage::dynamics::{DynamicsParams, MassSpringSystem, Topology};
use wgpu::util::DeviceExt;

/// Substeps queued in one submission: one uniform slot each.
const SLOTS: u32 = 64;
/// Bytes a uniform slot (the dynamic-offset alignment wgpu guarantees).
const SLOT_BYTES: u64 = 256;

/// Which of the shader's steps a dispatch runs.
#[derive(Debug, Clone, Copy)]
enum Pass {
    Explicit,
    Implicit,
}

gpu_struct! {
    /// The shader's `Step` block: everything one substep reads besides
    /// buffers.
    pub(crate) struct StepUniform {
        /// Acceleration.
        gravity: [f32; 3],
        /// The substep.
        h: f32,
        mass: f32,
        stiffness: f32,
        lateral_stiffness: f32,
        damping: f32,
        drag: f32,
        /// Banisch's restoring w (Eq. 5).
        restoring: f32,
        /// The wind's turbulence speed (no wind: 0).
        turbulence: f32,
        /// The turbulence's spatial scale.
        turbulence_scale: f32,
        /// The wind's gusting mean now.
        wind_mean: [f32; 3],
        /// The brush's radius (0: no brush).
        brush_radius: f32,
        /// The turbulence's drift now.
        wind_drift: [f32; 3],
        /// Tips stepped.
        tips: u32,
        brush_centre: [f32; 3],
        /// 1 for Silva strands (a spring to p0, a length limit).
        silva_strands: u32,
        brush_force: [f32; 3],
        pad0: f32,
    }
}

/// A [`MassSpringSystem`] uploaded to the GPU, stepped there with the
/// explicit solver. Build with [`new`](Self::new), step with
/// [`step_explicit`](Self::step_explicit), read with
/// [`read_state`](Self::read_state).
#[derive(Debug)]
pub struct GpuMassSpring {
    tips: u32,
    silva: bool,
    /// Whether tip-tip springs join the tips (prisms): no implicit step here.
    joined: bool,
    explicit: wgpu::ComputePipeline,
    implicit: wgpu::ComputePipeline,
    /// Writes the shell renderer's per-corner tip offsets.
    coupling: wgpu::ComputePipeline,
    coupling_layout: wgpu::BindGroupLayout,
    corner_sticks: wgpu::Buffer,
    corners: u32,
    uniforms: wgpu::Buffer,
    roots: wgpu::Buffer,
    normals: wgpu::Buffer,
    root_velocities: wgpu::Buffer,
    permutation: wgpu::Buffer,
    permutation_seed: Option<u64>,
    /// (tips, velocities), twice: substeps read one and write the other.
    state: [(wgpu::Buffer, wgpu::Buffer); 2],
    /// `bind_groups[k]` reads `state[k]` and writes `state[1 − k]`.
    bind_groups: [wgpu::BindGroup; 2],
    /// Which of `state` holds the current state.
    current: usize,
}

fn padded(v: &[Vec3]) -> Vec<[f32; 4]> {
    v.iter().map(|p| [p.x, p.y, p.z, 0.0]).collect()
}

/// Each stick's root with its rest length in w, as the shader reads them.
fn roots_and_lengths(system: &MassSpringSystem) -> Vec<[f32; 4]> {
    system
        .roots()
        .iter()
        .zip(system.lengths())
        .map(|(r, &l)| [r.x, r.y, r.z, l])
        .collect()
}

impl GpuMassSpring {
    /// Uploads `system` (its sticks, tip-tip springs and current state).
    pub fn new(ctx: &GpuContext, system: &MassSpringSystem) -> Result<Self, GpuError> {
        let device = &ctx.device;
        let n = system.mass_count();
        let tips = u32::try_from(n)
            .map_err(|_| GpuError::Mismatch(format!("{n} masses do not fit a GPU index")))?;
        let bytes = (n.max(1) * 16) as u64;
        let limit = device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(GpuError::Mismatch(format!(
                "{n} masses need {bytes} bytes a state buffer; the adapter binds at most {limit}"
            )));
        }
        let buffers = SystemBuffers::new(device, system);
        let compute = wgpu::ShaderStages::COMPUTE;
        let uniform = wgpu::BufferBindingType::Uniform;
        let mut entries = vec![entry::buffer(0, compute, uniform, true)];
        entries.extend((1..=8).map(|b| entry::storage(b, compute, true)));
        entries.extend((9..=10).map(|b| entry::storage(b, compute, false)));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dynamics"),
            entries: &entries,
        });
        let bind_groups = [0usize, 1].map(|k| buffers.step_group(device, &layout, k));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("dynamics.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::shader_source("dynamics.wgsl")),
        });
        let explicit = compute_pipeline(
            device,
            "dynamics explicit substep",
            &module,
            "explicit_substep",
            &[&layout],
        );
        let implicit = compute_pipeline(
            device,
            "dynamics implicit step",
            &module,
            "implicit_unjoined_step",
            &[&layout],
        );
        let coupling_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dynamics coupling"),
            entries: &[
                entry::storage(1, compute, true),
                entry::storage(2, compute, true),
                entry::storage(7, compute, true),
                entry::storage(11, compute, true),
                entry::storage(12, compute, false),
                entry::storage(13, compute, true),
            ],
        });
        let coupling = compute_pipeline(
            device,
            "dynamics corner tip offsets",
            &module,
            "corner_tip_offsets",
            &[&coupling_layout],
        );
        let SystemBuffers {
            roots,
            normals,
            root_velocities,
            permutation,
            state,
            corner_sticks,
            uniforms,
            ..
        } = buffers;
        Ok(Self {
            tips,
            silva: system.topology() == Topology::SilvaStrands,
            joined: system.joins_tips(),
            explicit,
            implicit,
            coupling,
            coupling_layout,
            corners: system.corner_sticks().len() as u32,
            corner_sticks,
            uniforms,
            roots,
            normals,
            root_velocities,
            permutation,
            permutation_seed: None,
            state,
            bind_groups,
            current: 0,
        })
    }

    /// Number of masses.
    pub fn mass_count(&self) -> usize {
        self.tips as usize
    }

    /// Uploads the skin's current state — roots, rest directions and root
    /// velocities — after [`MassSpringSystem::move_roots`].
    pub fn upload_roots(&self, ctx: &GpuContext, system: &MassSpringSystem) {
        ctx.queue.write_buffer(
            &self.roots,
            0,
            bytemuck::cast_slice(&roots_and_lengths(system)),
        );
        ctx.queue.write_buffer(
            &self.normals,
            0,
            bytemuck::cast_slice(&padded(system.normals())),
        );
        ctx.queue.write_buffer(
            &self.root_velocities,
            0,
            bytemuck::cast_slice(&padded(system.root_velocities())),
        );
    }

    /// Queues `steps` explicit steps of `dt` seconds, `substeps` each,
    /// starting at `time` (the wind's clock), as the CPU's
    /// `Solver::Explicit { substeps }` steps (at least 1 here: resolve the
    /// CPU's automatic 0 with `MassSpringSystem::explicit_substeps`).
    /// Returns once they are
    /// submitted; [`wait`](Self::wait) or [`read_state`](Self::read_state)
    /// for them to finish.
    pub fn step_explicit(
        &mut self,
        ctx: &GpuContext,
        dt: f32,
        params: &DynamicsParams,
        substeps: u32,
        time: f32,
        steps: u32,
    ) {
        let substeps = substeps.max(1);
        let h = dt / substeps as f32;
        let times: Vec<f32> = (0..steps)
            .flat_map(|s| (0..substeps).map(move |k| time + s as f32 * dt + k as f32 * h))
            .collect();
        self.queue(ctx, Pass::Explicit, params, h, &times);
    }

    /// Whether [`step_implicit`](Self::step_implicit) can step this system:
    /// no tip-tip springs join its tips (spring-sticks, separable
    /// spring-sticks, Silva strands).
    pub fn steps_implicit(&self) -> bool {
        !self.joined
    }

    /// Queues `steps` implicit (backward-Euler) steps of `dt` seconds from
    /// `time`, as the CPU's `Solver::Implicit` steps a system whose tips no
    /// springs join: each tip's 3×3 system solved directly. Prisms (tip-tip
    /// springs, conjugate gradients) are refused: step them on the CPU.
    pub fn step_implicit(
        &mut self,
        ctx: &GpuContext,
        dt: f32,
        params: &DynamicsParams,
        time: f32,
        steps: u32,
    ) -> Result<(), GpuError> {
        if self.joined {
            return Err(GpuError::Mismatch(
                "the GPU's implicit step solves each tip on its own; tip-tip springs (prisms) \
                 join these tips: use the explicit solver on the GPU, or the CPU"
                    .into(),
            ));
        }
        let times: Vec<f32> = (0..steps).map(|s| time + s as f32 * dt).collect();
        self.queue(ctx, Pass::Implicit, params, dt, &times);
        Ok(())
    }

    /// Queues one `pass` of `h` seconds for each of `times`, one uniform
    /// slot each, [`SLOTS`] to a submission.
    fn queue(
        &mut self,
        ctx: &GpuContext,
        pass_kind: Pass,
        params: &DynamicsParams,
        h: f32,
        times: &[f32],
    ) {
        if let Some(wind) = &params.wind {
            let noise = wind.now(times.first().copied().unwrap_or(0.0));
            let seed = noise.noise().seed;
            if self.permutation_seed != Some(seed) {
                let table: Vec<u32> = noise
                    .noise()
                    .permutation_table()
                    .iter()
                    .map(|&p| u32::from(p))
                    .collect();
                ctx.queue
                    .write_buffer(&self.permutation, 0, bytemuck::cast_slice(&table));
                self.permutation_seed = Some(seed);
            }
        }
        let (groups_x, groups_y) = workgroups(self.tips);
        let pipeline = match pass_kind {
            Pass::Explicit => &self.explicit,
            Pass::Implicit => &self.implicit,
        };
        for chunk in times.chunks(SLOTS as usize) {
            let mut slots = vec![0u8; chunk.len() * SLOT_BYTES as usize];
            for (k, &t) in chunk.iter().enumerate() {
                let uniform = self.uniform(params, h, t);
                let at = k * SLOT_BYTES as usize;
                slots[at..at + std::mem::size_of::<StepUniform>()]
                    .copy_from_slice(bytemuck::bytes_of(&uniform));
            }
            ctx.queue.write_buffer(&self.uniforms, 0, &slots);
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("dynamics steps"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(pipeline);
                for k in 0..chunk.len() {
                    pass.set_bind_group(
                        0,
                        &self.bind_groups[self.current],
                        &[(k as u64 * SLOT_BYTES) as u32],
                    );
                    pass.dispatch_workgroups(groups_x, groups_y, 1);
                    self.current = 1 - self.current;
                }
            }
            ctx.queue.submit([encoder.finish()]);
        }
    }

    fn uniform(&self, p: &DynamicsParams, h: f32, time: f32) -> StepUniform {
        let (mean, drift, turbulence, scale) = match &p.wind {
            Some(w) => {
                let now = w.now(time);
                (now.mean(), now.drift(), w.turbulence, w.scale)
            }
            None => (Vec3::ZERO, Vec3::ZERO, 0.0, 0.0),
        };
        let (centre, radius, force) = match p.brush {
            Some(b) => (b.centre, b.radius, b.force),
            None => (Vec3::ZERO, 0.0, Vec3::ZERO),
        };
        StepUniform {
            gravity: p.gravity.to_array(),
            h,
            mass: p.mass,
            stiffness: p.stiffness,
            lateral_stiffness: p.lateral_stiffness,
            damping: p.damping,
            drag: p.drag,
            restoring: p.restoring,
            turbulence,
            turbulence_scale: scale,
            wind_mean: mean.to_array(),
            // A zero radius means no brush to the shader; the CPU's brush
            // of radius 0 pushes nothing either.
            brush_radius: radius,
            wind_drift: drift.to_array(),
            tips: self.tips,
            brush_centre: centre.to_array(),
            silva_strands: u32::from(self.silva),
            brush_force: force.to_array(),
            pad0: 0.0,
        }
    }

    /// Writes each model vertex's tip offset `p − p0` (its stick's, through
    /// the model's vertex → corner map) straight into `model`'s vertex
    /// buffer — what
    /// [`ShellRenderer::set_tip_offsets`](crate::ShellRenderer::set_tip_offsets)
    /// uploads from the CPU — so the renderer draws the GPU's state with no
    /// read-back. `model` must be of the mesh this system was built on.
    pub fn write_tip_offsets(&self, ctx: &GpuContext, model: &ShellModel) -> Result<(), GpuError> {
        if model.corner_count != self.corners {
            return Err(GpuError::Mismatch(format!(
                "the shell model has {} triangle corners; the mass-spring system follows {}",
                model.corner_count, self.corners
            )));
        }
        if self.corners == 0 {
            return Ok(());
        }
        let (tips, _) = &self.state[self.current];
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dynamics coupling"),
            layout: &self.coupling_layout,
            entries: &group::buffers_at([
                (1, &self.roots),
                (2, &self.normals),
                (7, tips),
                (11, &self.corner_sticks),
                (12, &model.tip_offsets),
                (13, &model.vertex_corners),
            ]),
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("dynamics coupling"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.coupling);
            pass.set_bind_group(0, &bind_group, &[]);
            let (x, y) = workgroups(model.vertex_count);
            pass.dispatch_workgroups(x, y, 1);
        }
        ctx.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// Waits for every queued step to finish.
    pub fn wait(&self, ctx: &GpuContext) -> Result<(), GpuError> {
        ctx.wait()
    }

    /// The current tip positions and velocities, read back.
    pub fn read_state(&self, ctx: &GpuContext) -> Result<(Vec<Vec3>, Vec<Vec3>), GpuError> {
        let (tips, velocities) = &self.state[self.current];
        let size = tips.size();
        let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dynamics readback"),
            size: 2 * size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(tips, 0, &readback, 0, size);
        encoder.copy_buffer_to_buffer(velocities, 0, &readback, size, size);
        ctx.queue.submit([encoder.finish()]);
        crate::readback::map_read(ctx, &readback, |mapped| {
            let values: &[[f32; 4]] = bytemuck::cast_slice(mapped);
            let n = self.tips as usize;
            let to_vec3 = |v: &[f32; 4]| Vec3::new(v[0], v[1], v[2]);
            let tips = values[..n].iter().map(to_vec3).collect();
            let velocities = values[size as usize / 16..][..n]
                .iter()
                .map(to_vec3)
                .collect();
            (tips, velocities)
        })
    }

    /// Copies the GPU's state into `system` (the one this was built from).
    pub fn download_into(
        &self,
        ctx: &GpuContext,
        system: &mut MassSpringSystem,
    ) -> Result<(), GpuError> {
        if system.mass_count() != self.tips as usize {
            return Err(GpuError::Mismatch(format!(
                "the system has {} masses; the GPU one {}",
                system.mass_count(),
                self.tips
            )));
        }
        let (tips, velocities) = self.read_state(ctx)?;
        system.set_state(&tips, &velocities);
        Ok(())
    }
}

/// A mass-spring system's buffers on the GPU: roots with rest lengths,
/// normals, root velocities, the tip-tip springs (CSR), the wind's
/// permutation, two states to ping-pong, the corner sticks and the step
/// uniforms.
struct SystemBuffers {
    roots: wgpu::Buffer,
    normals: wgpu::Buffer,
    root_velocities: wgpu::Buffer,
    spring_offsets: wgpu::Buffer,
    spring_ends: wgpu::Buffer,
    permutation: wgpu::Buffer,
    state: [(wgpu::Buffer, wgpu::Buffer); 2],
    corner_sticks: wgpu::Buffer,
    uniforms: wgpu::Buffer,
}

impl SystemBuffers {
    fn new(device: &wgpu::Device, system: &MassSpringSystem) -> Self {
        let n = system.mass_count();
        let storage = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            // wgpu refuses empty bindings: a system without tip-tip springs
            // still binds one (unread) element.
            let contents = if contents.is_empty() {
                &[0u8; 16][..]
            } else {
                contents
            };
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE | usage,
            })
        };
        let copy_dst = wgpu::BufferUsages::COPY_DST;
        let roots = storage(
            "dynamics roots",
            bytemuck::cast_slice(&roots_and_lengths(system)),
            copy_dst,
        );
        let normals = storage(
            "dynamics normals",
            bytemuck::cast_slice(&padded(system.normals())),
            copy_dst,
        );
        let root_velocities = storage(
            "dynamics root velocities",
            bytemuck::cast_slice(&padded(system.root_velocities())),
            copy_dst,
        );
        let (offsets, index) = system.tip_spring_adjacency();
        let springs = system.tip_tip_springs();
        let ends: Vec<[u32; 2]> = (0..n)
            .flat_map(|i| {
                index[offsets[i] as usize..offsets[i + 1] as usize]
                    .iter()
                    .map(move |&s| {
                        let spring = springs[s as usize];
                        let other = if spring.a as usize == i {
                            spring.b
                        } else {
                            spring.a
                        };
                        [other, spring.rest.to_bits()]
                    })
            })
            .collect();
        let spring_offsets = storage(
            "dynamics spring offsets",
            bytemuck::cast_slice(offsets),
            wgpu::BufferUsages::empty(),
        );
        let spring_ends = storage(
            "dynamics spring ends",
            bytemuck::cast_slice(&ends),
            wgpu::BufferUsages::empty(),
        );
        let permutation = storage(
            "dynamics noise permutation",
            bytemuck::cast_slice(&[0u32; 512]),
            copy_dst,
        );
        let state_usage = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
        let state = [0, 1].map(|_| {
            (
                storage(
                    "dynamics tips",
                    bytemuck::cast_slice(&padded(system.tips())),
                    state_usage,
                ),
                storage(
                    "dynamics velocities",
                    bytemuck::cast_slice(&padded(system.velocities())),
                    state_usage,
                ),
            )
        });
        let corner_sticks = storage(
            "dynamics corner sticks",
            bytemuck::cast_slice(system.corner_sticks()),
            wgpu::BufferUsages::empty(),
        );
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dynamics steps"),
            size: SLOT_BYTES * u64::from(SLOTS),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            roots,
            normals,
            root_velocities,
            spring_offsets,
            spring_ends,
            permutation,
            state,
            corner_sticks,
            uniforms,
        }
    }

    /// The step's bind group reading state `k` and writing the other.
    fn step_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        k: usize,
    ) -> wgpu::BindGroup {
        let (tips_in, velocities_in) = &self.state[k];
        let (tips_out, velocities_out) = &self.state[1 - k];
        let entries = group::sequential([
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &self.uniforms,
                offset: 0,
                size: wgpu::BufferSize::new(std::mem::size_of::<StepUniform>() as u64),
            }),
            self.roots.as_entire_binding(),
            self.normals.as_entire_binding(),
            self.root_velocities.as_entire_binding(),
            self.spring_offsets.as_entire_binding(),
            self.spring_ends.as_entire_binding(),
            self.permutation.as_entire_binding(),
            tips_in.as_entire_binding(),
            velocities_in.as_entire_binding(),
            tips_out.as_entire_binding(),
            velocities_out.as_entire_binding(),
        ]);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dynamics"),
            layout,
            entries: &entries,
        })
    }
}
