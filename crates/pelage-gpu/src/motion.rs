//! [`FurMotion`]: a shell scene's moving fur, stepped on the CPU or the
//! GPU, as the scene player and the viewer use it.

use crate::{GpuContext, GpuError, GpuMassSpring, ShellModel};
use glam::Vec3;
use pelage::dynamics::{MassSpringSystem, Solver, Topology};
use pelage::shell::ShellAnimation;
use pelage::shell::scene::DynamicsSettings;

/// Where the skin under the fur is at the end of a step.
#[derive(Debug, Clone, Copy)]
pub enum SkinMotion<'a> {
    /// The skin at rest, moved whole by an offset (a shake).
    Offset(Vec3),
    /// The skin posed (a skinned character): each vertex's position and
    /// unit normal, of the mesh the motion was built on, then moved by
    /// `offset`.
    Posed {
        /// Vertex positions.
        positions: &'a [Vec3],
        /// Unit vertex normals.
        normals: &'a [Vec3],
        /// Added to every position.
        offset: Vec3,
    },
}

/// A scene's moving fur as the renderer uses it: the mass-spring system
/// stepped on the CPU, or on the GPU where the settings say `gpu` (and,
/// for the implicit solver, no springs join the tips); the skin's rest
/// pose it is moved from; its clock.
/// [`ShellScenePlayer`](crate::ShellScenePlayer) and the viewer step it
/// frame by frame.
#[derive(Debug)]
pub struct FurMotion {
    /// The CPU's system; while the GPU steps, it holds the skin's motion
    /// and the tips only as of the last copy.
    system: MassSpringSystem,
    on_gpu: Option<GpuMassSpring>,
    rest_roots: Vec<Vec3>,
    rest_normals: Vec<Vec3>,
    /// The skin's triangles: a posed skin's vertices become the sticks'
    /// roots through them.
    triangles: Vec<[u32; 3]>,
    /// The skin's offset at the last step, and whether that step moved it
    /// (root velocities not zero): the GPU's copy of the roots is
    /// refreshed only while either changes.
    skin_offset: Vec3,
    skin_moving: bool,
    time: f32,
}

impl FurMotion {
    /// `topology` over `mesh` with sticks `length` long, at rest at time 0.
    pub fn new(mesh: &pelage::Mesh, topology: Topology, length: f32) -> Self {
        let system = MassSpringSystem::new(mesh, topology, length);
        Self {
            rest_roots: system.roots().to_vec(),
            rest_normals: system.normals().to_vec(),
            triangles: mesh.triangles().to_vec(),
            system,
            on_gpu: None,
            skin_offset: Vec3::ZERO,
            skin_moving: false,
            time: 0.0,
        }
    }

    /// A warning when `settings` ask for automatic explicit substeps
    /// (`substeps = 0`) and steps of `dt` would need more than the ceiling
    /// ([`MassSpringSystem::stable_substeps`] stops there): the fur may
    /// blow up, and the message says what to change.
    pub fn substeps_warning(&self, dt: f32, settings: &DynamicsSettings) -> Option<String> {
        let Solver::Explicit { substeps: 0 } = settings.solver else {
            return None;
        };
        let needed = self.system.substeps_for_stability(dt, &settings.params);
        let ceiling = pelage::limits::MAX_DYNAMICS_STEPS;
        (needed > ceiling).then(|| {
            format!(
                "dynamics: a stable explicit step needs {} substeps at this stiffness and mass, more than pelage's limit of {}; it takes {} and the fur may blow up: use solver = \"implicit\", a lower stiffness or a higher mass",
                match needed {
                    u64::MAX => "endless".to_string(),
                    n => pelage::limits::grouped(n as f64),
                },
                pelage::limits::grouped(ceiling as f64),
                pelage::limits::grouped(ceiling as f64),
            )
        })
    }

    /// The topology stepped.
    pub fn topology(&self) -> Topology {
        self.system.topology()
    }

    /// Seconds simulated so far.
    pub fn time(&self) -> f32 {
        self.time
    }

    /// One step of `dt` seconds with the skin where `skin` says at its end
    /// (the roots' velocities are taken from the move, so the tips lag by
    /// inertia). The step runs where `settings` says; a change of place
    /// carries the state over (back to the CPU: copied down).
    pub fn step(
        &mut self,
        ctx: &GpuContext,
        dt: f32,
        skin: SkinMotion<'_>,
        settings: &DynamicsSettings,
    ) -> Result<(), GpuError> {
        let explicit = match settings.solver {
            Solver::Explicit { substeps } => Some(substeps),
            Solver::Implicit { .. } => None,
        };
        // The GPU steps every explicit system and the implicit ones whose
        // tips no springs join; prisms' implicit step stays on the CPU.
        let on_gpu = settings.gpu && (explicit.is_some() || !self.system.joins_tips());
        match (on_gpu, self.on_gpu.take()) {
            (true, None) => self.on_gpu = Some(GpuMassSpring::new(ctx, &self.system)?),
            (false, Some(gpu)) => gpu.download_into(ctx, &mut self.system)?,
            (_, kept) => self.on_gpu = kept,
        }
        let (skin_offset, posed) = match skin {
            SkinMotion::Offset(offset) => {
                let roots: Vec<Vec3> = self.rest_roots.iter().map(|&r| r + offset).collect();
                self.system.move_roots(&roots, &self.rest_normals, dt);
                (offset, false)
            }
            SkinMotion::Posed {
                positions,
                normals,
                offset,
            } => {
                let (mut roots, normals) = MassSpringSystem::sticks_on(
                    self.topology(),
                    &self.triangles,
                    positions,
                    normals,
                );
                roots.iter_mut().for_each(|r| *r += offset);
                self.system.move_roots(&roots, &normals, dt);
                (offset, true)
            }
        };
        let moving = posed || skin_offset != self.skin_offset;
        match &mut self.on_gpu {
            Some(gpu) => {
                if moving || self.skin_moving {
                    gpu.upload_roots(ctx, &self.system);
                }
                match explicit {
                    Some(substeps) => {
                        let substeps =
                            self.system
                                .explicit_substeps(dt, &settings.params, substeps);
                        gpu.step_explicit(ctx, dt, &settings.params, substeps, self.time, 1);
                    }
                    None => gpu.step_implicit(ctx, dt, &settings.params, self.time, 1)?,
                }
            }
            None => self
                .system
                .step(dt, &settings.params, settings.solver, self.time),
        }
        self.skin_offset = skin_offset;
        self.skin_moving = moving;
        self.time += dt;
        Ok(())
    }

    /// [`Self::step`] with a scene's skin: its character posed at
    /// `seconds` into the clip ([`ShellAnimation::posed`], the pose the GPU
    /// draws), or without one the skin at rest; either moved by `offset`.
    pub fn step_scene(
        &mut self,
        ctx: &GpuContext,
        dt: f32,
        animation: Option<&ShellAnimation>,
        seconds: f32,
        offset: Vec3,
        settings: &DynamicsSettings,
    ) -> Result<(), GpuError> {
        match animation {
            Some(animation) => {
                let posed = animation.posed(seconds);
                let skin = SkinMotion::Posed {
                    positions: &posed.positions,
                    normals: &posed.normals,
                    offset,
                };
                self.step(ctx, dt, skin, settings)
            }
            None => self.step(ctx, dt, SkinMotion::Offset(offset), settings),
        }
    }

    /// Hands the tips to `renderer` for `model`: written in place where the
    /// GPU steps, uploaded from the CPU otherwise.
    pub fn show(
        &self,
        ctx: &GpuContext,
        renderer: &crate::ShellRenderer,
        model: &ShellModel,
    ) -> Result<(), GpuError> {
        match &self.on_gpu {
            Some(gpu) => gpu.write_tip_offsets(ctx, model),
            None => renderer.set_tip_offsets(ctx, model, &self.system.corner_tip_offsets()),
        }
    }
}
