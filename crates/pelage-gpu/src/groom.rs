//! A groom grown on the GPU every frame: a [`GroomRecipe`] uploaded once,
//! then, each frame, the frame's guides (in rest space) and posed skin in,
//! every hair's points out, by one compute dispatch a recipe pass
//! (pelage-shaders' `groom.wgsl` over its `GroomUpload`, one invocation a
//! hair, its points in registers).
//! The CPU groom of the same frame (`Generator::part`, or
//! `AnimatedGroom::part` for a posed frame) is the reference:
//! `tests/groom.rs` grows both and compares hair by hair.
//!
//! The output buffer holds each point as `xyz` and its width in `w`,
//! point-major (point `j` of hair `h` at `j · hairs + h`, clump centres
//! first, the render hairs last), ready for a strand renderer to read.

use crate::layout::{UniformRing, compute_pipeline, entry, group};
use crate::{GpuContext, GpuError, workgroups};
use glam::Vec3;
use pelage::Curves;
use pelage::anim::{SkinBinding, SkinPose};
use pelage::groom::{Generator, GroomError, GroomErrorKind, GroomRecipe};
pub(crate) use pelage_shaders::groom::GroomPassUniform;
pub use pelage_shaders::groom::MAX_GPU_HAIR_POINTS;
use pelage_shaders::groom::{GroomUpload, packed_sdf, skin_vertices};
use wgpu::util::DeviceExt;

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
fn groom_buffers(device: &wgpu::Device, upload: &GroomUpload) -> [wgpu::Buffer; 8] {
    let dst = wgpu::BufferUsages::COPY_DST;
    let bytes = bytemuck::cast_slice::<[f32; 4], u8>;
    [
        storage(device, "groom roots", bytes(&upload.roots), NONE),
        storage(
            device,
            "groom data",
            bytemuck::cast_slice(&upload.data),
            NONE,
        ),
        storage(
            device,
            "groom guide offsets",
            &vec![0u8; upload.guide_values * 16],
            dst,
        ),
        storage(device, "groom skin", bytes(&upload.rest_skin), dst),
        storage(
            device,
            "groom skin triangles",
            bytemuck::cast_slice(&upload.triangles),
            NONE,
        ),
        storage(
            device,
            "groom points",
            &vec![0u8; upload.points_bytes() as usize],
            wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::VERTEX,
        ),
        storage(
            device,
            "groom rest skin grid",
            bytemuck::cast_slice(&upload.rest_grid),
            NONE,
        ),
        storage(device, "groom posed skin grid", &[0u8; 64], dst),
    ]
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
        let upload =
            GroomUpload::new(recipe, skin).map_err(|e| GpuError::Mismatch(e.to_string()))?;
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        let largest = upload.points_bytes();
        if largest > limit {
            return Err(GpuError::Mismatch(format!(
                "{} hairs of {} points need {largest} bytes a buffer; the adapter binds at most {limit}: grow fewer hairs (a fraction) or fewer points",
                upload.hairs, upload.points
            )));
        }
        let render = upload.render.clone();
        let skin_vertices = skin.rest().positions().len();
        let device = &ctx.device;
        let buffers = groom_buffers(device, &upload);
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
            bytemuck::cast_slice(&upload.guide_roots),
            NONE,
        );
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
        let colors_buffer = storage(
            device,
            "groom colours",
            bytemuck::cast_slice(&upload.shade),
            NONE,
        );
        Ok(Self {
            pipeline,
            passes: upload.passes,
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
            rest_skin: upload.rest_skin,
            posed: false,
            points,
            colors_buffer,
            hairs: upload.hairs,
            n: upload.points,
            guide_values: upload.guide_values,
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
        let offsets = GroomUpload::guide_words(guide_offsets);
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
                let skin = skin_vertices(pose);
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
    pub fn new(ctx: &'a GpuContext, generator: &'a Generator) -> Self {
        Self {
            ctx,
            generator,
            skin: GpuGroom::skin_at_rest(generator.mesh()),
        }
    }

    /// Part `p`, grown on the GPU.
    ///
    /// # Errors
    /// When the GPU fails, or a hair grew a value that is not finite.
    pub fn part(&self, p: usize) -> Result<Curves, GroomError> {
        self.part_of(self.generator, p)
    }

    /// Part `p` of `generator`, grown on the GPU: a generator on the same
    /// mesh with the same operators as this grower's, in other guide
    /// shapes (a frame's of an animated groom, [`pelage::groom::GeneratorGrower`]).
    ///
    /// # Errors
    /// As [`Self::part`].
    pub fn part_of(&self, generator: &Generator, p: usize) -> Result<Curves, GroomError> {
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
