//! `pelage bench sampler`: the structure of Sik's Tables 1–3 and Figs. 8–9
//! on the shared meshes (blub ×1 ≈ the bunny's size, spot ×2, spot ×4 ≈
//! Buddha), Perlin density textures at 512²–2048², grid sizes 0–400 %,
//! density means 1.0 / 0.5 / 0.25 / 0.1, for CDF + grid, alias and
//! rejection side by side, with the paper's figures in a column.

use super::{median_seconds, on_threads};
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use pelage::map::{ImageMap, Map, NoiseMap, Wrap};
use pelage::mesh::{Mesh, SurfacePoint};
use pelage::sample::{
    AliasTable, CdfGrid, DensitySampler, DensitySamplerOptions, RejectionSampler, Selector,
    SubTriangleRecord, SurfaceSampler, mix64, sample_into,
};
use rand::SeedableRng;
use rand::rngs::SmallRng;
use rand_distr::Distribution;
use rand_distr::weighted::WeightedAliasIndex;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `pelage bench sampler`.
#[derive(Debug, Args)]
pub struct SamplerBenchArgs {
    /// A reduced run that finishes in under 30 s.
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Folder with blub_triangulated.obj (default: the repository's
    /// tests/data/meshes).
    #[arg(long)]
    pub meshes: Option<PathBuf>,
    /// Measure a peer in the same run: `blender` times Blender's Poisson
    /// Disk distribution for the blue noise's count and spacing, with
    /// Blender as a Python module (bpy, set up in a cached venv by
    /// tools/bpy-python).
    #[arg(long, value_enum)]
    pub peer: Option<crate::groom::Peer>,
}

impl SamplerBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

struct Plan {
    samples: usize,
    /// Side of the Perlin density textures (the paper's 1024²).
    texture: u32,
    /// Blue-noise samples.
    blue_noise: u64,
    /// Density means against rejection sampling.
    means: Vec<f32>,
    runs: usize,
    resolutions: Vec<u32>,
    grids: Vec<u32>,
    models: Vec<(&'static str, u32)>,
}

/// A Perlin density texture like the paper's: fBm noise baked into an image,
/// values in [0, 1], scaled so its mean is `mean` (1.0 = uniform).
fn perlin_texture(size: u32, mean: f32) -> Map {
    if mean >= 1.0 {
        return Map::Constant(1.0);
    }
    let noise = NoiseMap::new(8.0, 4, 1, 0.5, 0.5);
    let texels: Vec<f32> = (0..size * size)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % size, i / size);
            let uv = glam::Vec2::new(
                (x as f32 + 0.5) / size as f32,
                1.0 - (y as f32 + 0.5) / size as f32,
            );
            noise.eval(uv).clamp(0.0, 1.0)
        })
        .collect();
    let average = texels.iter().map(|&t| f64::from(t)).sum::<f64>() / texels.len() as f64;
    let scale = (f64::from(mean) / average) as f32;
    let texels = texels.into_iter().map(|t| (t * scale).min(1.0)).collect();
    Map::Image(
        ImageMap::from_texels(size, size, texels, Wrap::Repeat).expect("texture size is valid"),
    )
}

fn options(selector: Selector) -> DensitySamplerOptions {
    DensitySamplerOptions {
        selector,
        ..Default::default()
    }
}

/// Samples per second: median over runs of filling a buffer of `n`.
fn rate(
    sampler: &(impl SurfaceSampler + ?Sized),
    n: usize,
    runs: usize,
    threads: usize,
) -> anyhow::Result<f64> {
    let mut buffer = vec![SurfacePoint::default(); n];
    let (seconds, ()) = on_threads(threads, || {
        median_seconds(runs, true, || sample_into(sampler, 1, 0, &mut buffer))
    })?;
    Ok(n as f64 / seconds)
}

struct Row {
    cells: Vec<String>,
}

fn table(title: &str, header: &[&str], rows: &[Row]) -> String {
    let mut widths: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (w, c) in widths.iter_mut().zip(&r.cells) {
            *w = (*w).max(c.chars().count());
        }
    }
    let mut out = format!("\n{title}\n");
    let line = |cells: Vec<&str>| {
        cells
            .iter()
            .zip(&widths)
            .map(|(c, w)| format!("{c:>w$}"))
            .collect::<Vec<_>>()
            .join("  ")
    };
    let _ = writeln!(out, "{}", line(header.to_vec()));
    for r in rows {
        let _ = writeln!(
            out,
            "{}",
            line(r.cells.iter().map(String::as_str).collect())
        );
    }
    out
}

fn mega(x: f64) -> String {
    format!("{:.1} M/s", x / 1e6)
}

fn mb(bytes: usize) -> String {
    format!("{:.2} MB", bytes as f64 / 1e6)
}

/// What the tables share: the plan, the meshes, the headline's texture,
/// and the report and JSON each table adds to.
struct SamplerRun {
    plan: Plan,
    threads: usize,
    blub: Mesh,
    spot: Mesh,
    perlin_1024: Map,
    report: String,
    json: serde_json::Map<String, serde_json::Value>,
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &SamplerBenchArgs) -> anyhow::Result<()> {
    let mut run = SamplerRun::new(args)?;
    let (sampler, rate_all) = run.headline()?;
    run.stable_ids(&sampler, rate_all);
    run.blue_noise(&sampler);
    run.blue_noise_against_blender(args.peer.is_some());
    run.selectors(&sampler);
    drop(sampler);
    run.table1()?;
    run.table2()?;
    run.table3()?;
    run.against_rejection()?;
    if args.json {
        println!("{}", serde_json::Value::Object(run.json));
    } else {
        print!("{}", run.report);
    }
    Ok(())
}

impl SamplerRun {
    /// The plan (`--quick` or full), the meshes, and the report's heading.
    fn new(args: &SamplerBenchArgs) -> anyhow::Result<Self> {
        let plan = args.scale().pick(
            Plan {
                samples: 10_000_000,
                texture: 1024,
                // Elimination holds every candidate's neighbours: a count
                // that runs in seconds, not the random rate's ten million.
                blue_noise: 1_000_000,
                means: vec![1.0, 0.5, 0.25, 0.1],
                runs: 5,
                resolutions: vec![512, 1024, 2048],
                grids: vec![0, 13, 25, 50, 100, 200, 400],
                models: vec![("blub ×1", 1), ("spot ×2", 2), ("spot ×4", 4)],
            },
            Plan {
                samples: 2_000_000,
                texture: 1024,
                blue_noise: 200_000,
                means: vec![1.0, 0.1],
                runs: 3,
                resolutions: vec![1024],
                grids: vec![0, 100],
                models: vec![("blub ×1", 1)],
            },
            Plan {
                samples: 20_000,
                texture: 64,
                blue_noise: 2_000,
                means: vec![1.0, 0.1],
                runs: 1,
                resolutions: vec![64],
                grids: vec![0, 100],
                models: vec![("blub ×1", 1)],
            },
        );
        let threads = rayon::current_num_threads();
        let blub_path = args
            .meshes
            .clone()
            .unwrap_or_else(super::test_meshes)
            .join("blub_triangulated.obj");
        let blub = Mesh::load(&blub_path)
            .context("the sampler benchmark needs blub (give the folder with --meshes)")?
            .subdivided(1);
        let spot = pelage::assets::spot();

        let mut report = String::new();
        let json = serde_json::Map::new();
        let _ = writeln!(
            report,
            "pelage bench sampler{} — {threads} threads, {} samples per rate, median of {} runs",
            args.scale().flag(),
            thousands(plan.samples as u64),
            plan.runs
        );
        let _ = writeln!(
            report,
            "blub ×1: {} triangles. Paper: one core of a 3.07 GHz PC (2012); bunny 69k triangles.",
            thousands(blub.triangle_count() as u64)
        );
        let perlin_1024 = perlin_texture(plan.texture, 0.5);
        Ok(Self {
            plan,
            threads,
            blub,
            spot,
            perlin_1024,
            report,
            json,
        })
    }

    /// blub ×1 (as is) or Spot subdivided `k` times.
    fn mesh_for(&self, name: &str, k: u32) -> Mesh {
        if name.starts_with("blub") {
            self.blub.clone()
        } else {
            self.spot.subdivided(k)
        }
    }

    /// Headline case: blub ×1, 1024² Perlin, the default selector; its
    /// sampler and its rate on every thread, which later tables compare
    /// against.
    fn headline(&mut self) -> anyhow::Result<(DensitySampler, f64)> {
        // Headline case: self.blub ×1, 1024² Perlin, the default selector.
        let (pre_s, sampler) = median_seconds(self.plan.runs, true, || {
            DensitySampler::new(
                &self.blub,
                &self.perlin_1024,
                DensitySamplerOptions::default(),
            )
        });
        let sampler = sampler?;
        let rate_1t = rate(&sampler, self.plan.samples, self.plan.runs, 1)?;
        let rate_all = rate(&sampler, self.plan.samples, self.plan.runs, self.threads)?;
        let rows = vec![
            Row {
                cells: vec![
                    "preprocess".into(),
                    format!("{:.1} ms", pre_s * 1e3),
                    "70 ms".into(),
                    "≤ 20 ms".into(),
                ],
            },
            Row {
                cells: vec![
                    "records".into(),
                    thousands(sampler.records().len() as u64),
                    "—".into(),
                    "".into(),
                ],
            },
            Row {
                cells: vec![
                    "bytes per record".into(),
                    std::mem::size_of::<SubTriangleRecord>().to_string(),
                    "12".into(),
                    "≤ 12".into(),
                ],
            },
            Row {
                cells: vec![
                    "memory".into(),
                    mb(sampler.memory_bytes()),
                    "5.33 MB".into(),
                    "".into(),
                ],
            },
            Row {
                cells: vec![
                    "samples/s, 1 thread".into(),
                    mega(rate_1t),
                    "6.3 M/s".into(),
                    "≥ 60 M/s".into(),
                ],
            },
            Row {
                cells: vec![
                    format!("samples/s, {} threads", self.threads),
                    mega(rate_all),
                    "—".into(),
                    "Blender 5 ≈ 10 M/s on 2 threads".into(),
                ],
            },
        ];
        self.report += &table(
            "Headline: blub ×1, 1024² Perlin density, alias selector (default)",
            &["", "pelage", "paper", "target"],
            &rows,
        );
        self.json.insert("preprocess_s".into(), pre_s.into());
        self.json.insert(
            "bytes_per_record".into(),
            std::mem::size_of::<SubTriangleRecord>().into(),
        );
        self.json
            .insert("records".into(), sampler.records().len().into());
        self.json
            .insert("memory_bytes".into(), sampler.memory_bytes().into());
        self.json
            .insert("samples_per_s_1t".into(), rate_1t.round().into());
        self.json
            .insert("samples_per_s_all_threads".into(), rate_all.round().into());
        self.json.insert("threads".into(), self.threads.into());
        Ok((sampler, rate_all))
    }

    /// Blue-noise samples (dart throwing over the whole mesh's
    /// candidates) against random samples of the same count, mesh and density,
    /// on every thread, with where the blue noise's time goes.
    fn blue_noise(&mut self, sampler: &DensitySampler) {
        let n = self.plan.blue_noise;
        let runs = self.plan.runs;
        let (random_s, _) = median_seconds(runs, true, || {
            pelage::sample::sample_range(sampler, 1, 0..n).len()
        });
        let (blue_s, (_, phases)) = median_seconds(runs, true, || {
            pelage::sample::blue_noise::blue_noise_samples_timed(sampler, &self.blub, 1, n)
        });
        let ratio = blue_s / random_s;
        let share = |s: f64| format!("{:.0} %", 100.0 * s / blue_s);
        self.report += &table(
            &format!(
                "Blue noise: {} samples on blub ×1, 1024² Perlin, {} threads (last run's steps)",
                thousands(n),
                self.threads
            ),
            &["", "time", "time ratio", "target"],
            &[
                Row {
                    cells: vec![
                        "random (alias sampler)".into(),
                        format!("{:.1} ms", random_s * 1e3),
                        "1.00".into(),
                        "".into(),
                    ],
                },
                Row {
                    cells: vec![
                        "blue noise (2× candidates, dart throwing)".into(),
                        format!("{:.1} ms", blue_s * 1e3),
                        format!("{ratio:.1}"),
                        "≤ 3".into(),
                    ],
                },
                Row {
                    cells: vec![
                        "  drawing candidates, positions, radii".into(),
                        format!("{:.1} ms", phases.candidates * 1e3),
                        share(phases.candidates),
                        "".into(),
                    ],
                },
                Row {
                    cells: vec![
                        "  grid of cells (sort by cell)".into(),
                        format!("{:.1} ms", phases.neighbours * 1e3),
                        share(phases.neighbours),
                        "".into(),
                    ],
                },
                Row {
                    cells: vec![
                        "  dart throwing and the count".into(),
                        format!("{:.1} ms", phases.elimination * 1e3),
                        share(phases.elimination),
                        "".into(),
                    ],
                },
            ],
        );
        self.json
            .insert("blue_noise_vs_random".into(), ratio.into());
        self.json.insert(
            "blue_noise_samples_per_s".into(),
            (n as f64 / blue_s).round().into(),
        );
        self.json
            .insert("blue_noise_candidates_s".into(), phases.candidates.into());
        self.json
            .insert("blue_noise_neighbours_s".into(), phases.neighbours.into());
        self.json
            .insert("blue_noise_elimination_s".into(), phases.elimination.into());
    }

    /// Blue noise against Blender's own, same run: Distribute Points on
    /// Faces in Poisson Disk mode (`blender_poisson.py`) on the same mesh,
    /// uniform density, for the count of pelage's blue noise and its
    /// minimum distance (`2 · SPACING · r`, which no two of pelage's
    /// points come closer than once the count needed only removals).
    fn blue_noise_against_blender(&mut self, measure: bool) {
        use pelage::sample::blue_noise::{SPACING, blue_noise_samples, radius};
        let n = self.plan.blue_noise;
        let uniform = DensitySampler::new(
            &self.blub,
            &Map::Constant(1.0),
            DensitySamplerOptions::default(),
        )
        .expect("a constant density samples");
        let (pelage_s, points) = median_seconds(self.plan.runs, true, || {
            blue_noise_samples(&uniform, &self.blub, 1, n)
        });
        let area = self.blub.surface_area();
        let distance = 2.0 * SPACING * radius(n as f64 / area);
        let closest = closest_pair(&self.blub, &points);
        let peer = if measure {
            measure_blender_poisson(&self.blub, n, distance, self.plan.runs)
                .map_err(|e| format!("{e:#}"))
        } else {
            Err("run with --peer blender".to_string())
        };
        let title = format!(
            "Blue noise against Blender: {} points on blub ×1, uniform, at least {distance:.5} apart",
            thousands(n)
        );
        let mut rows = vec![Row {
            cells: vec![
                "pelage (dart throwing)".into(),
                format!("{:.1} ms", pelage_s * 1e3),
                thousands(points.len() as u64),
                format!("{closest:.5}"),
                "".into(),
            ],
        }];
        match &peer {
            Ok(b) => {
                let speedup = b.seconds / pelage_s;
                rows.push(Row {
                    cells: vec![
                        format!("Blender {} Poisson Disk", b.version),
                        format!("{:.1} ms", b.seconds * 1e3),
                        thousands(b.points),
                        format!("{distance:.5}"),
                        format!("pelage {speedup:.2}× faster (target ≥ 1)"),
                    ],
                });
                self.json
                    .insert("blender_poisson_s".into(), b.seconds.into());
                self.json
                    .insert("blender_poisson_points".into(), b.points.into());
                self.json
                    .insert("blue_noise_speedup_over_blender".into(), speedup.into());
            }
            Err(why) => rows.push(Row {
                cells: vec![
                    "Blender Poisson Disk".into(),
                    "not measured".into(),
                    "".into(),
                    "".into(),
                    why.clone(),
                ],
            }),
        }
        self.report += &table(&title, &["", "time", "points", "closest pair", ""], &rows);
        self.json
            .insert("blue_noise_uniform_s".into(), pelage_s.into());
        self.json
            .insert("blue_noise_min_distance".into(), f64::from(distance).into());
    }

    /// Stable hair ids: root cells against the whole-mesh alias sampler.
    fn stable_ids(&mut self, sampler: &DensitySampler, rate_all: f64) {
        // Stable hair ids: the same roots drawn cell by cell (counts from each
        // cell's arrivals, then each cell's own alias table), against the
        // whole-mesh alias sampler above, same samples, all self.threads.
        let cells = pelage::sample::RootCells::new(&self.blub, sampler);
        let (cells_s, drawn) = median_seconds(self.plan.runs, true, || {
            let counts = cells.counts(1, self.plan.samples as u64);
            let drawn: u64 = (0..cells.len())
                .into_par_iter()
                .map(|c| cells.roots(sampler, 1, c, counts[c]).len() as u64)
                .sum();
            drawn
        });
        assert_eq!(drawn, self.plan.samples as u64, "the cells draw every root");
        let (counts_s, _) = median_seconds(self.plan.runs, true, || {
            cells.counts(1, self.plan.samples as u64)
        });
        let cells_rate = self.plan.samples as f64 / cells_s;
        let stable_ratio = rate_all / cells_rate;
        self.report += &table(
            &format!(
                "Stable hair ids: root cells ({} cells) against the alias sampler, {} threads",
                thousands(cells.len() as u64),
                self.threads
            ),
            &["", "samples/s", "time ratio", "target"],
            &[
                Row {
                    cells: vec![
                        "alias sampler (whole mesh)".into(),
                        mega(rate_all),
                        "1.00".into(),
                        "".into(),
                    ],
                },
                Row {
                    cells: vec![
                        "root cells (counts + per-cell tables)".into(),
                        mega(cells_rate),
                        format!("{stable_ratio:.2}"),
                        "≤ 1.5".into(),
                    ],
                },
                Row {
                    cells: vec![
                        "  of which counting the arrivals".into(),
                        format!("{:.1} ms", counts_s * 1e3),
                        format!("{:.2}", counts_s * rate_all / self.plan.samples as f64),
                        "".into(),
                    ],
                },
            ],
        );
        self.json
            .insert("stable_ids_samples_per_s".into(), cells_rate.round().into());
        self.json
            .insert("stable_ids_time_ratio".into(), stable_ratio.into());
        self.json.insert("root_cells".into(), cells.len().into());
        self.json
            .insert("stable_ids_counting_s".into(), counts_s.into());
    }

    /// The selectors alone against rand_distr's alias table.
    fn selectors(&mut self, sampler: &DensitySampler) {
        // The selectors alone against a peer, rand_distr's WeightedAliasIndex,
        // on the same weights, in plain loops (no prefetching on either side).
        let weights: Vec<f64> = sampler
            .records()
            .iter()
            .map(|r| f64::from(r.probability))
            .collect();
        let selections = self.plan.samples;
        let (ours_build, ours) = median_seconds(self.plan.runs, true, || {
            AliasTable::new(weights.iter().copied())
        });
        // Selections in a plain loop, summed so none is optimised away.
        let time_selections = |select: &dyn Fn(u64) -> usize| {
            median_seconds(self.plan.runs, true, || {
                let mut sum = 0usize;
                for i in 0..selections as u64 {
                    sum = sum.wrapping_add(select(mix64(i)));
                }
                std::hint::black_box(sum)
            })
            .0
        };
        let ours_select = time_selections(&|bits| ours.select(bits));
        let (cdf_build, cdf) = median_seconds(self.plan.runs, true, || {
            CdfGrid::new(weights.iter().copied(), 100)
        });
        let cdf_select = time_selections(&|bits| cdf.select(bits));
        let peer_weights: Vec<f32> = sampler.records().iter().map(|r| r.probability).collect();
        let (peer_build, peer) = median_seconds(self.plan.runs, true, || {
            WeightedAliasIndex::new(peer_weights.clone()).expect("the weights are valid")
        });
        let (peer_select, _) = median_seconds(self.plan.runs, true, || {
            let mut rng = SmallRng::seed_from_u64(1);
            let mut sum = 0usize;
            for _ in 0..selections {
                sum = sum.wrapping_add(peer.sample(&mut rng));
            }
            std::hint::black_box(sum)
        });
        let per_s = |seconds: f64| mega(selections as f64 / seconds);
        let rows = vec![
            Row {
                cells: vec![
                    "pelage AliasTable".into(),
                    format!("{:.1} ms", ours_build * 1e3),
                    per_s(ours_select),
                    mb(ours.memory_bytes()),
                ],
            },
            Row {
                cells: vec![
                    "pelage CdfGrid, grid 100 %".into(),
                    format!("{:.1} ms", cdf_build * 1e3),
                    per_s(cdf_select),
                    mb(cdf.memory_bytes()),
                ],
            },
            // rand_distr keeps an f32 and a u32 per weight (its documentation).
            Row {
                cells: vec![
                    "rand_distr WeightedAliasIndex<f32>".into(),
                    format!("{:.1} ms", peer_build * 1e3),
                    per_s(peer_select),
                    mb(peer_weights.len() * 8),
                ],
            },
        ];
        self.report += &table(
            &format!(
                "Selectors alone on the headline's {} weights, plain loop, 1 thread (peer measured in this run)",
                thousands(weights.len() as u64)
            ),
            &["selector", "build", "selections/s", "memory"],
            &rows,
        );
        self.json.insert(
            "alias_select_per_s".into(),
            (selections as f64 / ours_select).round().into(),
        );
        self.json.insert(
            "rand_distr_alias_select_per_s".into(),
            (selections as f64 / peer_select).round().into(),
        );
        self.json.insert("alias_build_s".into(), ours_build.into());
        self.json
            .insert("rand_distr_alias_build_s".into(), peer_build.into());
    }

    /// Table 1: grid size, uniform density on blub ×1.
    fn table1(&mut self) -> anyhow::Result<()> {
        // Table 1: grid size, uniform density on self.blub ×1.
        let paper_t1 = [
            (0, "2.37 M/s", "0.054 s", "1.33 MB"),
            (13, "5.86 M/s", "0.055 s", "1.47 MB"),
            (25, "5.95 M/s", "0.057 s", "1.60 MB"),
            (50, "5.89 M/s", "0.058 s", "1.86 MB"),
            (100, "6.39 M/s", "0.059 s", "2.39 MB"),
            (200, "6.53 M/s", "0.061 s", "3.45 MB"),
            (400, "6.45 M/s", "0.066 s", "5.57 MB"),
        ];
        let uniform = Map::Constant(1.0);
        let mut rows = Vec::new();
        for &grid in &self.plan.grids {
            let (pre, s) = median_seconds(self.plan.runs, true, || {
                DensitySampler::new(
                    &self.blub,
                    &uniform,
                    options(Selector::CdfGrid { grid_percent: grid }),
                )
            });
            let s = s?;
            let r = rate(&s, self.plan.samples, self.plan.runs, 1)?;
            let paper = paper_t1.iter().find(|p| p.0 == grid);
            rows.push(Row {
                cells: vec![
                    format!("CDF, grid {grid} %"),
                    mega(r),
                    format!("{:.1} ms", pre * 1e3),
                    mb(s.memory_bytes()),
                    paper.map_or("—", |p| p.1).into(),
                    paper.map_or("—", |p| p.2).into(),
                    paper.map_or("—", |p| p.3).into(),
                ],
            });
        }
        let (pre, s) = median_seconds(self.plan.runs, true, || {
            DensitySampler::new(&self.blub, &uniform, options(Selector::Alias))
        });
        let s = s?;
        let alias_uniform = rate(&s, self.plan.samples, self.plan.runs, 1)?;
        rows.push(Row {
            cells: vec![
                "alias".into(),
                mega(alias_uniform),
                format!("{:.1} ms", pre * 1e3),
                mb(s.memory_bytes()),
                "—".into(),
                "—".into(),
                "—".into(),
            ],
        });
        self.report += &table(
            "Table 1: selector and grid size, uniform density, blub ×1, 1 thread",
            &[
                "selector",
                "samples/s",
                "preprocess",
                "memory",
                "paper samples/s",
                "paper CDF",
                "paper memory",
            ],
            &rows,
        );
        Ok(())
    }

    /// Table 2: models, 1024² Perlin.
    fn table2(&mut self) -> anyhow::Result<()> {
        // Table 2: models, 1024² Perlin.
        let paper_t2 = [
            "0.070 s, 2.39 MB (bunny 69k)",
            "0.127 s, 8.68 MB (dragon 202k)",
            "0.25 s, 51.26 MB (Buddha 1087k)",
        ];
        let mut rows = Vec::new();
        for (k, &(name, level)) in self.plan.models.iter().enumerate() {
            let mesh = self.mesh_for(name, level);
            let (pre, s) = median_seconds(self.plan.runs, true, || {
                DensitySampler::new(&mesh, &self.perlin_1024, DensitySamplerOptions::default())
            });
            let s = s?;
            let r = rate(&s, self.plan.samples, self.plan.runs, 1)?;
            rows.push(Row {
                cells: vec![
                    name.into(),
                    thousands(mesh.triangle_count() as u64),
                    thousands(s.records().len() as u64),
                    format!("{:.1} ms", pre * 1e3),
                    mb(s.memory_bytes()),
                    mega(r),
                    paper_t2[k].into(),
                ],
            });
            if name == "spot ×4" {
                self.json.insert("spot4_preprocess_s".into(), pre.into());
            }
        }
        self.report += &table(
            "Table 2: models, 1024² Perlin density, alias, 1 thread",
            &[
                "model",
                "triangles",
                "records",
                "preprocess",
                "memory",
                "samples/s",
                "paper",
            ],
            &rows,
        );
        Ok(())
    }

    /// Table 3: texture resolution, blub ×1.
    fn table3(&mut self) -> anyhow::Result<()> {
        // Table 3: texture resolution, self.blub ×1.
        let paper_t3 = [
            (512, "6.76 M/s, 0.019 s, 4.49 MB"),
            (1024, "6.31 M/s, 0.070 s, 5.33 MB"),
            (2048, "5.00 M/s, 0.253 s, 31.26 MB"),
        ];
        let mut rows = Vec::new();
        for &res in &self.plan.resolutions {
            let map = if res == 1024 {
                self.perlin_1024.clone()
            } else {
                perlin_texture(res, 0.5)
            };
            for selector in [Selector::CdfGrid { grid_percent: 100 }, Selector::Alias] {
                let (pre, s) = median_seconds(self.plan.runs, true, || {
                    DensitySampler::new(&self.blub, &map, options(selector))
                });
                let s = s?;
                let r = rate(&s, self.plan.samples, self.plan.runs, 1)?;
                let label = match selector {
                    Selector::Alias => "alias",
                    _ => "CDF + grid 100 %",
                };
                rows.push(Row {
                    cells: vec![
                        format!("{res}²"),
                        label.into(),
                        thousands(s.records().len() as u64),
                        format!("{:.1} ms", pre * 1e3),
                        mb(s.memory_bytes()),
                        mega(r),
                        paper_t3
                            .iter()
                            .find(|p| p.0 == res)
                            .map_or("—", |p| p.1)
                            .into(),
                    ],
                });
            }
        }
        self.report += &table(
            "Table 3: density texture resolution, blub ×1, 1 thread",
            &[
                "texture",
                "selector",
                "records",
                "preprocess",
                "memory",
                "samples/s",
                "paper",
            ],
            &rows,
        );
        Ok(())
    }

    /// Figs. 8–9: against rejection sampling at several density means.
    fn against_rejection(&mut self) -> anyhow::Result<()> {
        // Figs. 8–9: against rejection sampling at several density means.
        let mut rows = Vec::new();
        for mean in self.plan.means.clone() {
            let map = perlin_texture(self.plan.texture, mean);
            let (cdf_pre, cdf) = median_seconds(self.plan.runs, false, || {
                DensitySampler::new(
                    &self.blub,
                    &map,
                    options(Selector::CdfGrid { grid_percent: 100 }),
                )
            });
            let cdf = cdf?;
            let (alias_pre, alias) = median_seconds(self.plan.runs, false, || {
                DensitySampler::new(&self.blub, &map, options(Selector::Alias))
            });
            let alias = alias?;
            let rejection = RejectionSampler::new(&self.blub, &map)?;
            let cdf_rate = rate(&cdf, self.plan.samples, self.plan.runs, 1)?;
            let alias_rate = rate(&alias, self.plan.samples, self.plan.runs, 1)?;
            let rejection_n = (self.plan.samples / 4).max(self.plan.samples.min(100_000));
            let rejection_rate = rate(&rejection, rejection_n, self.plan.runs, 1)?;
            // Including preprocess, for one million samples (the paper's solid lines).
            let with_pre = |pre: f64, r: f64| 1e6 / (pre + 1e6 / r);
            rows.push(Row {
                cells: vec![
                    format!("{mean}"),
                    mega(cdf_rate),
                    mega(alias_rate),
                    mega(rejection_rate),
                    format!("{:.1}×", alias_rate / rejection_rate),
                    format!(
                        "{} / {}",
                        mega(with_pre(cdf_pre, cdf_rate)),
                        mega(with_pre(alias_pre, alias_rate))
                    ),
                ],
            });
            if mean == 0.1 {
                self.json.insert(
                    "rejection_samples_per_s_1t_mean_0_1".into(),
                    rejection_rate.round().into(),
                );
                self.json.insert(
                    "alias_over_rejection_mean_0_1".into(),
                    (alias_rate / rejection_rate).into(),
                );
            }
        }
        self.report += &table(
            "Figs. 8–9: against rejection sampling, blub ×1, 1024² Perlin, 1 thread (paper: rejection falls linearly with the mean; target ≥ 20× at 0.1)",
            &[
                "mean",
                "CDF + grid",
                "alias",
                "rejection",
                "alias / rejection",
                "1 M samples incl. preprocess (CDF / alias)",
            ],
            &rows,
        );
        Ok(())
    }
}

/// Blender's Poisson Disk distribution measured by Blender itself.
struct BlenderPoisson {
    seconds: f64,
    points: u64,
    version: String,
}

/// Runs `blender_poisson.py` on `mesh` for `count` points at least
/// `distance` apart. An error says why it was not measured.
fn measure_blender_poisson(
    mesh: &Mesh,
    count: u64,
    distance: f32,
    runs: usize,
) -> anyhow::Result<BlenderPoisson> {
    let report = super::run_bpy_case(
        "blender_poisson.py",
        include_str!("blender_poisson.py"),
        |dir| {
            super::write_mesh_case(dir, mesh)?;
            let case = serde_json::json!({
                "count": count,
                "distance": distance,
                "area": mesh.surface_area(),
                "runs": runs,
            });
            std::fs::write(dir.join("case.json"), case.to_string())?;
            Ok(())
        },
    )?;
    let number = |key: &str| report[key].as_f64().context("a number in Blender's report");
    Ok(BlenderPoisson {
        seconds: number("seconds")?,
        points: number("points")? as u64,
        version: report["blender"].as_str().unwrap_or("?").to_string(),
    })
}

/// The smallest distance between two of `points`.
fn closest_pair(mesh: &Mesh, points: &[SurfacePoint]) -> f32 {
    let positions: Vec<glam::Vec3> = points.iter().map(|p| p.position(mesh)).collect();
    let tree = pelage::nearest::NearestPoints::new(positions.clone());
    positions
        .par_iter()
        .map_init(Vec::new, |out, p| {
            tree.nearest(*p, 2, out);
            out.get(1)
                .map_or(f32::INFINITY, |n| n.distance_squared.sqrt())
        })
        .reduce(|| f32::INFINITY, f32::min)
}
