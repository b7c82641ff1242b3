//! [`GroomReport`]: what a groom grew, part by part and region by region,
//! which guides it left out and why, and how long it took. Every front end
//! shows the same value: `pelage groom --report` writes it as JSON, Python
//! returns it as a dict, the Blender add-on lists its lost guides.

use super::generator::Generator;
use super::load::Groom;
use crate::Curves;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// What a groom grew and left out (the fields serialize as the JSON of
/// `pelage groom --report`).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct GroomReport {
    /// The groom file (or the groom's name).
    pub groom: String,
    /// Where the hairs were written (empty when they were not).
    pub output: String,
    /// Hairs grown, all parts.
    pub hairs: u64,
    /// Each part grown, in the order grown.
    pub parts: Vec<PartReport>,
    /// The guides: kept, and left out with why.
    pub guides: GuidesReport,
    /// Each region's guides and hairs (empty when the skin is one region).
    pub regions: Vec<RegionReport>,
    /// Timings.
    pub seconds: Timings,
}

/// One part of a [`GroomReport`].
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct PartReport {
    /// The part's index.
    pub part: usize,
    /// Hairs the layout planned (before `strands` and `cut`).
    pub hairs_planned: u64,
    /// Hairs grown.
    pub hairs: usize,
    /// Points grown.
    pub points: usize,
    /// Triangles of the skin in the part.
    pub triangles: usize,
}

/// The guides of a [`GroomReport`].
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct GuidesReport {
    /// Guides bound to the skin.
    pub kept: usize,
    /// Guides of the file left out when binding, with why.
    pub dropped: Vec<GuideNote>,
    /// Guides the style mesh never uses, with why.
    pub unused_by_style_mesh: Vec<LostGuideNote>,
}

/// A guide left out when binding.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GuideNote {
    /// Its index in the file.
    pub guide: usize,
    /// Why, in words.
    pub why: String,
}

/// A guide the style mesh does not use.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LostGuideNote {
    /// The guide.
    pub guide: u32,
    /// The guide nearer its vertex, which kept it.
    pub kept_by: u32,
    /// The vertex both are nearest.
    pub vertex: u32,
    /// Why, in words.
    pub why: String,
}

/// One region of a [`GroomReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegionReport {
    /// The region id.
    pub region: u32,
    /// Its face set's name, or its number.
    pub name: String,
    /// Guides rooted in it.
    pub guides: usize,
    /// Hairs grown in it.
    pub hairs: u64,
}

/// How long a groom took, in seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Timings {
    /// Loading and preparing (mesh, guides, sampler, interpolation,
    /// clump centres).
    pub setup: f64,
    /// Growing and writing the parts.
    pub grow_and_write: f64,
}

/// Gathers a [`GroomReport`] part by part while a groom grows.
#[derive(Debug)]
pub struct ReportBuilder {
    report: GroomReport,
    /// Per region id: guides, hairs grown (only when the skin is split).
    regions: Option<BTreeMap<u32, (usize, u64)>>,
}

impl ReportBuilder {
    /// A report of `generator`'s groom, with its lost guides and each
    /// region's guides counted.
    pub fn new(generator: &Generator) -> Self {
        let regions = generator.regions().map(|_| {
            let mut regions = BTreeMap::new();
            for root in generator.guides().roots() {
                regions
                    .entry(generator.region_of(*root))
                    .or_insert((0, 0))
                    .0 += 1;
            }
            regions
        });
        let unused = generator
            .lost_guides()
            .iter()
            .map(|l| LostGuideNote {
                guide: l.guide,
                kept_by: l.kept_by,
                vertex: l.vertex,
                why: l.to_string(),
            })
            .collect();
        Self {
            report: GroomReport {
                guides: GuidesReport {
                    kept: generator.guides().len(),
                    unused_by_style_mesh: unused,
                    ..Default::default()
                },
                ..Default::default()
            },
            regions,
        }
    }

    /// Counts part `p`, grown as `curves`.
    pub fn add_part(&mut self, generator: &Generator, p: usize, curves: &Curves) {
        let part = &generator.parts()[p];
        self.report.hairs += curves.curve_count() as u64;
        self.report.parts.push(PartReport {
            part: p,
            hairs_planned: part.hair_count,
            hairs: curves.curve_count(),
            points: curves.points().len(),
            triangles: part.triangles.len(),
        });
        if let (Some(regions), Some(roots)) = (&mut self.regions, curves.roots()) {
            for root in roots {
                regions
                    .entry(generator.region_of(*root))
                    .or_insert((0, 0))
                    .1 += 1;
            }
        }
    }

    /// The report of `groom` (its file's name and the guides its binding
    /// left out) written to `output`, with its timings.
    pub fn finish(
        mut self,
        generator: &Generator,
        groom: Option<&Groom>,
        output: Option<&Path>,
        seconds: Timings,
    ) -> GroomReport {
        let report = &mut self.report;
        if let Some(groom) = groom {
            report.groom = groom.path().display().to_string();
            report.guides.dropped = groom
                .bind_report()
                .map(|r| {
                    r.dropped
                        .iter()
                        .map(|d| GuideNote {
                            guide: d.index,
                            why: d.to_string(),
                        })
                        .collect()
                })
                .unwrap_or_default();
        }
        report.output = output.map(|p| p.display().to_string()).unwrap_or_default();
        report.seconds = seconds;
        let lookup = generator.regions();
        report.regions = self
            .regions
            .iter()
            .flatten()
            .map(|(&region, &(guides, hairs))| RegionReport {
                region,
                name: lookup.map_or_else(|| region.to_string(), |l| l.name(region)),
                guides,
                hairs,
            })
            .collect();
        self.report
    }
}

impl GroomReport {
    /// Regions whose hairs had no guide of their own: they took their
    /// shape from every guide (front ends warn: add guides there).
    pub fn regions_without_guides(&self) -> impl Iterator<Item = &RegionReport> {
        self.regions.iter().filter(|r| r.guides == 0 && r.hairs > 0)
    }
}
