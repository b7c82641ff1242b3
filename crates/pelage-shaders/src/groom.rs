//! A groom grown on the GPU every frame, without a GPU API: the compute
//! shader ([`GROOM_WGSL`]: one invocation a hair, every operator's math
//! mirroring pelage's CPU operators) and the arrays a host uploads for it
//! ([`GroomUpload`], made once from a [`GroomRecipe`] and the skin it
//! grows on). pelage-gpu's `GpuGroom` and pelage-bevy's strands build
//! their own buffers and pipelines over these, so both grow the same
//! hairs.
//!
//! The shader's bindings (group 0): 0 the roots ([`GroomUpload::roots`]),
//! 1 the packed data ([`GroomUpload::data`]), 2 this frame's guides in
//! rest space (written: `vec4` a guide point), 3 the skin now (position,
//! then normal, a vertex), 4 its triangles, 5 the points (written:
//! `xyz` and width, point-major: point `j` of hair `h` at `j · hairs +
//! h`), 6 and 7 the skin's distance grids at rest and posed ([`packed_sdf`]).
//! Group 1 is one [`GroomPassUniform`] a pass, at a dynamic offset.

use glam::{Mat3, Vec3};
use pelage::anim::{SkinBinding, SkinPose};
use pelage::groom::GroomRecipe;
use std::ops::Range;

/// `groom.wgsl` with what it calls: the skin's distance-grid queries
/// ([`SKIN_SDF_WGSL`]) and Perlin noise ([`NOISE_WGSL`]).
pub const GROOM_WGSL: &str = concat!(
    include_str!("wgsl/groom.wgsl"),
    include_str!("wgsl/skin_sdf.wgsl"),
    include_str!("wgsl/noise.wgsl")
);

/// `pelage::dynamics::SkinSdf`'s queries in WGSL, appended to a shader
/// that says where a grid's values are (the groom's and the guide
/// strands' compute shaders).
pub const SKIN_SDF_WGSL: &str = include_str!("wgsl/skin_sdf.wgsl");

/// `pelage::map::NoiseMap::perlin3_vector` in WGSL, appended to a shader
/// that declares `perm_at(i)`.
pub const NOISE_WGSL: &str = include_str!("wgsl/noise.wgsl");

/// The most points a hair has on the GPU (the shader's `MAX_POINTS`: a
/// hair's points live in registers).
pub const MAX_GPU_HAIR_POINTS: usize = 32;

/// The shader's `GroomPass` block: one recipe pass.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GroomPassUniform {
    /// The pass's first hair.
    pub first: u32,
    /// Its hairs.
    pub count: u32,
    /// Steps its hairs go through.
    pub steps: u32,
    /// Points a hair.
    pub points: u32,
    /// Points a guide.
    pub guide_points: u32,
    /// Hairs in all (the points buffer's row stride).
    pub hairs: u32,
    /// Per-hair values a hair.
    pub values_per_hair: u32,
    /// 1: carry the pass's hairs to the posed skin.
    pub posed: u32,
    /// Where the guide-to-hair resampling starts (`u32::MAX`: none).
    pub resample_at: u32,
    /// The first render hair.
    pub render_first: u32,
    /// Every width's factor.
    pub width_scale: f32,
    /// Where the guide weights start in `data`.
    pub weights_at: u32,
    /// Where the guides' normals start.
    pub normals_at: u32,
    /// Where the per-hair values start.
    pub values_at: u32,
    /// Where the steps start.
    pub steps_at: u32,
    /// Where the steps' tables start.
    pub tables_at: u32,
    /// Where the noise permutations start.
    pub permutation_at: u32,
    /// Where the widths start.
    pub widths_at: u32,
    /// Bit 0: keep hairs out of the skin; bit 1: a posed grid is bound.
    pub outside: u32,
    /// The gap kept from the skin.
    pub gap: f32,
    /// Padding to 16 bytes.
    pub pad0: u32,
    /// Padding.
    pub pad1: u32,
    /// Padding.
    pub pad2: u32,
}

impl GroomPassUniform {
    /// Each field's name and byte offset, in declaration order (checked
    /// against the WGSL struct).
    pub const FIELDS: &'static [(&'static str, usize)] = &[
        ("first", std::mem::offset_of!(Self, first)),
        ("count", std::mem::offset_of!(Self, count)),
        ("steps", std::mem::offset_of!(Self, steps)),
        ("points", std::mem::offset_of!(Self, points)),
        ("guide_points", std::mem::offset_of!(Self, guide_points)),
        ("hairs", std::mem::offset_of!(Self, hairs)),
        (
            "values_per_hair",
            std::mem::offset_of!(Self, values_per_hair),
        ),
        ("posed", std::mem::offset_of!(Self, posed)),
        ("resample_at", std::mem::offset_of!(Self, resample_at)),
        ("render_first", std::mem::offset_of!(Self, render_first)),
        ("width_scale", std::mem::offset_of!(Self, width_scale)),
        ("weights_at", std::mem::offset_of!(Self, weights_at)),
        ("normals_at", std::mem::offset_of!(Self, normals_at)),
        ("values_at", std::mem::offset_of!(Self, values_at)),
        ("steps_at", std::mem::offset_of!(Self, steps_at)),
        ("tables_at", std::mem::offset_of!(Self, tables_at)),
        ("permutation_at", std::mem::offset_of!(Self, permutation_at)),
        ("widths_at", std::mem::offset_of!(Self, widths_at)),
        ("outside", std::mem::offset_of!(Self, outside)),
        ("gap", std::mem::offset_of!(Self, gap)),
        ("pad0", std::mem::offset_of!(Self, pad0)),
        ("pad1", std::mem::offset_of!(Self, pad1)),
        ("pad2", std::mem::offset_of!(Self, pad2)),
    ];
}

/// Why a recipe cannot be grown on the GPU.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GroomUploadError(pub String);

impl std::fmt::Display for GroomUploadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for GroomUploadError {}

/// Everything a host uploads to grow a [`GroomRecipe`] on the GPU, as
/// flat arrays of 32-bit words (module docs: where each is bound).
#[derive(Debug, Clone)]
pub struct GroomUpload {
    /// Each hair's root record (the shader's `HairRoot`, six `vec4`s).
    pub roots: Vec<[f32; 4]>,
    /// What does not change but the roots: weights, guide normals,
    /// per-hair values, steps, tables, permutations, widths.
    pub data: Vec<u32>,
    /// One block a recipe pass, in order (`posed` and bit 1 of `outside`
    /// set per frame by the host).
    pub passes: Vec<GroomPassUniform>,
    /// A render point's colour (`rgb`; negative: the hairs have none) and
    /// opacity, hair after hair.
    pub shade: Vec<[f32; 4]>,
    /// Each guide's root as `guides_to_rest` reads it.
    pub guide_roots: Vec<[f32; 4]>,
    /// The skin at rest ([`skin_vertices`]).
    pub rest_skin: Vec<[f32; 4]>,
    /// The skin's triangles, three indices each.
    pub triangles: Vec<u32>,
    /// The rest skin's distance grid (empty without `outside_skin`).
    pub rest_grid: Vec<u32>,
    /// Hairs in all (clump centres first, then the render hairs).
    pub hairs: u32,
    /// Points a hair.
    pub points: u32,
    /// Guides.
    pub guides: u32,
    /// Guide points in all (the guide buffer's `vec4`s).
    pub guide_values: usize,
    /// The render hairs among [`Self::hairs`].
    pub render: Range<u32>,
}

impl GroomUpload {
    /// The arrays for `recipe` grown on `skin` (its rest pose is the one
    /// the groom was grown on).
    ///
    /// # Errors
    /// When hairs or guides have more than [`MAX_GPU_HAIR_POINTS`] points,
    /// or there are more hairs than a 32-bit index counts.
    pub fn new(recipe: &GroomRecipe, skin: &SkinBinding) -> Result<Self, GroomUploadError> {
        let (n, gp) = (recipe.points as usize, recipe.guide_points as usize);
        if n > MAX_GPU_HAIR_POINTS || gp > MAX_GPU_HAIR_POINTS {
            return Err(GroomUploadError(format!(
                "hairs of {n} points from guides of {gp}: the GPU groom takes at most {MAX_GPU_HAIR_POINTS}; lower [finish] points or resample the guides"
            )));
        }
        let hairs = recipe.hair_count();
        let hairs32 = u32::try_from(hairs)
            .map_err(|_| GroomUploadError(format!("{hairs} hairs: too many for a GPU index")))?;
        let render = recipe.render_hairs();
        let (data, sections) = packed(recipe);
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
        let shade = (0..render.len() * n)
            .map(|k| {
                let c = recipe.colors.as_ref().map_or(Vec3::splat(-1.0), |c| c[k]);
                v4(c, recipe.opacities.as_ref().map_or(1.0, |o| o[k]))
            })
            .collect();
        Ok(Self {
            roots: root_records(recipe, skin),
            data,
            passes,
            shade,
            guide_roots: guide_root_records(recipe, skin),
            rest_skin: skin_vertices(skin.rest()),
            triangles: skin.triangles().iter().flatten().copied().collect(),
            rest_grid: recipe
                .outside_skin
                .as_ref()
                .map_or_else(Vec::new, |(o, _)| packed_sdf(o.sdf(), 0)),
            hairs: hairs32,
            points: n as u32,
            guides: recipe.guides,
            guide_values: recipe.guides as usize * gp,
            render,
        })
    }

    /// Bytes of the points buffer: every hair's points, a `vec4` each.
    pub fn points_bytes(&self) -> u64 {
        u64::from(self.hairs) * u64::from(self.points) * 16
    }

    /// Gives every point of render hair `r` the colour `colors[r]`, where
    /// the groom gave the hairs none.
    pub fn color_hairs(&mut self, colors: &[Vec3]) {
        let n = self.points as usize;
        for (r, c) in colors.iter().enumerate().take(self.render.len()) {
            for shade in &mut self.shade[r * n..(r + 1) * n] {
                if shade[0] < 0.0 {
                    shade[..3].copy_from_slice(&c.to_array());
                }
            }
        }
    }

    /// A frame's guides in rest space as the shader reads them.
    pub fn guide_words(guide_offsets: &[Vec3]) -> Vec<[f32; 4]> {
        guide_offsets.iter().map(|&v| v4(v, 0.0)).collect()
    }
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

/// A skin's distance grid as the groom shader reads it (skin_sdf.wgsl's
/// `Grid` header, then the nodes' distances, their nearest triangles and
/// the triangles' corners and corner normals, all as words); `which`: 0 at
/// rest, 1 posed (the header's pad0).
pub fn packed_sdf(sdf: &pelage::dynamics::SkinSdf, which: u32) -> Vec<u32> {
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

/// A pose's vertices as the shaders read them: position, then normal.
pub fn skin_vertices(pose: &SkinPose) -> Vec<[f32; 4]> {
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
