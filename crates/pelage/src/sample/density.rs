//! The density-texture sampler of Sik §3: sub-triangle subdivision with
//! sibling merging (Fig. 5), 12-byte records with shared positions (Fig. 4),
//! selection by CDF + uniform grid (Fig. 7) or by an alias table, and a
//! uniform point in the chosen sub-triangle (Fig. 6).

use super::alias::AliasTable;
use super::cdf::CdfGrid;
use super::rng::SampleRng;
use super::subtriangle::{MAX_LEVEL, PositionTable, SubTriangle, WHOLE_TRIANGLE, child_index};
use super::{SampleError, SurfaceSampler, warp};
use crate::map::{Map, MapOnMesh};
use crate::mesh::{Mesh, SurfacePoint};
use glam::Vec2;
use rayon::prelude::*;

/// One sub-triangle of the distribution: 12 bytes, as in the paper.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct SubTriangleRecord {
    /// The mesh triangle it lies in.
    pub triangle: u32,
    /// Its position index inside that triangle (see [`super::subtriangle`]).
    pub position: u32,
    /// Its probability, unnormalised: area × density at its centroid.
    pub probability: f32,
}

const _: () = assert!(std::mem::size_of::<SubTriangleRecord>() == 12);

/// How a sub-triangle is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Selector {
    /// The paper's CDF with a uniform grid of `grid_percent` % as many cells
    /// as records (0 = bisection over the whole CDF).
    CdfGrid {
        /// Grid cells as a percentage of the record count.
        grid_percent: u32,
    },
    /// Walker's alias table: O(1) per sample.
    Alias,
}

impl Default for Selector {
    /// The alias table: measured faster than CDF + grid at every size in
    /// `pelage bench sampler` (see docs/benchmarks/sampler.md).
    fn default() -> Self {
        Selector::Alias
    }
}

/// Options of [`DensitySampler::new`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DensitySamplerOptions {
    /// How sub-triangles are chosen.
    pub selector: Selector,
    /// Deepest subdivision level (the paper stops at one texel per
    /// sub-triangle; this caps it for huge triangles on huge textures).
    pub max_level: u32,
}

impl Default for DensitySamplerOptions {
    fn default() -> Self {
        Self {
            selector: Selector::default(),
            max_level: 12,
        }
    }
}

#[derive(Debug, Clone)]
enum SelectorTable {
    Cdf(CdfGrid),
    Alias(AliasTable),
}

/// Samples points on a mesh with a density given by a [`Map`] (Sik §3).
#[derive(Debug, Clone)]
pub struct DensitySampler<'m> {
    mesh: &'m Mesh,
    records: Vec<SubTriangleRecord>,
    /// Records of triangle t are `records[first[t]..first[t + 1]]`.
    first_record: Vec<u32>,
    total: f64,
    selector: SelectorTable,
    positions: PositionTable,
}

/// What a triangle contributes: its records, or an error.
type TriangleRecords = Result<Vec<SubTriangleRecord>, SampleError>;

impl<'m> DensitySampler<'m> {
    /// Builds the distribution (the paper's preprocess). Errors name the
    /// mesh: a map that needs UVs on a mesh without them, a negative or NaN
    /// density (with the triangle and UV), a density that is zero everywhere.
    pub fn new(
        mesh: &'m Mesh,
        density: &Map,
        options: DensitySamplerOptions,
    ) -> Result<Self, SampleError> {
        let map = density.on_mesh(mesh)?;
        let max_level = options.max_level.min(MAX_LEVEL);
        let texels = density.resolution();

        // Triangles are independent: build in parallel, in fixed chunks
        // concatenated in order, so the records never depend on threads.
        const CHUNK: usize = 4096;
        let chunks: Vec<TriangleRecords> = (0..mesh.triangle_count())
            .into_par_iter()
            .step_by(CHUNK)
            .map(|start| {
                let end = (start + CHUNK).min(mesh.triangle_count());
                let mut out = Vec::with_capacity((end - start) * 2);
                for t in start..end {
                    subdivide_triangle(mesh, &map, texels, max_level, t, &mut out)?;
                }
                Ok(out)
            })
            .collect();
        let mut records =
            Vec::with_capacity(chunks.iter().map(|c| c.as_ref().map_or(0, Vec::len)).sum());
        for chunk in chunks {
            records.extend(chunk?);
        }

        let total: f64 = records.iter().map(|r| f64::from(r.probability)).sum();
        if records.is_empty() || total <= 0.0 || !total.is_finite() {
            return Err(SampleError::ZeroDensity {
                mesh: mesh.name().to_string(),
            });
        }
        let mut first_record = vec![0u32; mesh.triangle_count() + 1];
        for r in &records {
            first_record[r.triangle as usize + 1] += 1;
        }
        for t in 0..mesh.triangle_count() {
            first_record[t + 1] += first_record[t];
        }
        let weights = records.iter().map(|r| f64::from(r.probability));
        let selector = match options.selector {
            Selector::CdfGrid { grid_percent } => {
                SelectorTable::Cdf(CdfGrid::new(weights, grid_percent))
            }
            Selector::Alias => SelectorTable::Alias(AliasTable::new(weights)),
        };
        Ok(Self {
            mesh,
            records,
            first_record,
            total,
            selector,
            positions: PositionTable::new(),
        })
    }

    /// The sub-triangle records (zero-probability ones are left out).
    pub fn records(&self) -> &[SubTriangleRecord] {
        &self.records
    }

    /// Sum of the records' probabilities: ∫ density dA by the centroid rule
    /// at texel resolution.
    pub fn total_probability(&self) -> f64 {
        self.total
    }

    /// Probability that a sample lands in triangle `t`.
    pub fn triangle_probability(&self, t: usize) -> f64 {
        let range = self.first_record[t] as usize..self.first_record[t + 1] as usize;
        self.records[range]
            .iter()
            .map(|r| f64::from(r.probability))
            .sum::<f64>()
            / self.total
    }

    /// Bytes of the distribution: records, selector, per-triangle offsets
    /// and the position table.
    pub fn memory_bytes(&self) -> usize {
        let selector = match &self.selector {
            SelectorTable::Cdf(c) => c.memory_bytes(),
            SelectorTable::Alias(a) => a.memory_bytes(),
        };
        self.records.len() * std::mem::size_of::<SubTriangleRecord>()
            + selector
            + self.first_record.len() * 4
            + self.positions.memory_bytes()
    }

    /// The mesh sampled.
    pub fn mesh(&self) -> &'m Mesh {
        self.mesh
    }
}

impl SurfaceSampler for DensitySampler<'_> {
    #[inline]
    fn sample(&self, seed: u64, index: u64) -> SurfacePoint {
        let mut rng = SampleRng::new(seed, index);
        let bits = rng.next_u64();
        let k = match &self.selector {
            SelectorTable::Cdf(c) => c.select(bits),
            SelectorTable::Alias(a) => a.select(bits),
        };
        let record = self.records[k];
        let sub = self.positions.get(record.position);
        let b = sub.to_parent(warp::sample_uniform_triangle(rng.uniform_f32_pair()));
        SurfacePoint {
            tri: record.triangle,
            bary: [b.x, b.y],
        }
    }

    /// Piecewise constant: the probability of the sub-triangle holding the
    /// point over its area.
    fn pdf(&self, point: SurfacePoint) -> f64 {
        let t = point.tri as usize;
        let area = f64::from(self.mesh.triangle_areas()[t]);
        let b = Vec2::from(point.bary);
        let range = self.first_record[t] as usize..self.first_record[t + 1] as usize;
        self.records[range]
            .iter()
            .map(|r| (r, self.positions.get(r.position)))
            .find(|(_, sub)| sub.contains(b, 1e-6))
            .map_or(0.0, |(r, sub)| {
                f64::from(r.probability) / self.total / (area * f64::from(sub.area_fraction()))
            })
    }
}

/// Subdivision level of a triangle: the smallest level at which each
/// sub-triangle covers at most one texel (Sik §3.1), capped.
fn level_for(mesh: &Mesh, texels: Option<(u32, u32)>, max_level: u32, t: usize) -> u32 {
    let (Some((w, h)), Some([t0, t1, t2])) = (texels, mesh.triangle_uvs(t)) else {
        return 0;
    };
    let (d1, d2) = (t1 - t0, t2 - t0);
    let footprint = 0.5 * (d1.x * d2.y - d2.x * d1.y).abs() * w as f32 * h as f32;
    let mut level = 0;
    let mut per_sub = footprint;
    while per_sub > 1.0 && level < max_level {
        per_sub *= 0.25;
        level += 1;
    }
    level
}

/// Fig. 5 for one triangle: subdivide to its level, evaluate the density at
/// each leaf's centroid, merge equal siblings, append the records.
fn subdivide_triangle(
    mesh: &Mesh,
    map: &MapOnMesh,
    texels: Option<(u32, u32)>,
    max_level: u32,
    t: usize,
    out: &mut Vec<SubTriangleRecord>,
) -> Result<(), SampleError> {
    let area = mesh.triangle_areas()[t];
    if area == 0.0 {
        return Ok(()); // degenerate: zero probability, no records
    }
    let level = level_for(mesh, texels, max_level, t);
    let leaf = Leaf {
        mesh,
        map,
        t: t as u32,
        area,
        level,
    };
    if let Some(p) = leaf.visit(WHOLE_TRIANGLE, SubTriangle::WHOLE, 0, out)? {
        push(out, leaf.t, WHOLE_TRIANGLE, p);
    }
    Ok(())
}

struct Leaf<'a> {
    mesh: &'a Mesh,
    map: &'a MapOnMesh<'a>,
    t: u32,
    area: f32,
    level: u32,
}

impl Leaf<'_> {
    /// Returns `Some(probability)` when the node is uniform (a leaf, or four
    /// equal children merged), leaving it to the caller to store; `None`
    /// when its records have been stored already.
    fn visit(
        &self,
        position: u32,
        sub: SubTriangle,
        depth: u32,
        out: &mut Vec<SubTriangleRecord>,
    ) -> Result<Option<f32>, SampleError> {
        if depth == self.level {
            let point = SurfacePoint {
                tri: self.t,
                bary: sub.centroid().to_array(),
            };
            let density = self.map.eval(point);
            if density.is_nan() || density < 0.0 || density.is_infinite() {
                return Err(SampleError::BadDensity {
                    mesh: self.mesh.name().to_string(),
                    triangle: self.t,
                    uv: point.uv(self.mesh).map(|uv| uv.to_array()),
                    value: density,
                });
            }
            // area · s² is exact in binary (s = ±2^−level), so four equal
            // children sum exactly to the parent's probability.
            return Ok(Some(self.area * sub.area_fraction() * density));
        }
        let mut children = [None; 4];
        for (j, child) in children.iter_mut().enumerate() {
            let j = j as u32;
            *child = self.visit(child_index(position, j), sub.child(j), depth + 1, out)?;
        }
        // Fig. 5 step 3(b): four unsubdivided siblings with the same
        // probability are replaced by their parent.
        if let [Some(a), Some(b), Some(c), Some(d)] = children
            && a == b
            && b == c
            && c == d
        {
            return Ok(Some(4.0 * a));
        }
        for (j, child) in children.iter().enumerate() {
            if let Some(p) = child {
                push(out, self.t, child_index(position, j as u32), *p);
            }
        }
        Ok(None)
    }
}

/// Stores a record unless its probability is zero: zero-density regions
/// are then never selected, and cost no memory.
fn push(out: &mut Vec<SubTriangleRecord>, triangle: u32, position: u32, probability: f32) {
    if probability > 0.0 {
        out.push(SubTriangleRecord {
            triangle,
            position,
            probability,
        });
    }
}
