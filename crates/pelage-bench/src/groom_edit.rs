//! `pelage bench groom --edit`: grooming by hand on the Stubble figure.
//! One comb dab touching about 1 % of the 1,000 guides, regrown
//! incrementally ([`pelage::groom::edit::EditableGroom`]), beside a full
//! regrow of the same groom in the same run; the same dab at the viewer's
//! preview density (50,000 hairs) against a 60 Hz frame; and, as the peer,
//! Blender 5 re-evaluating its Interpolate Curves node after one guide
//! point moves, beside pelage's answer to the same edit, on the same
//! surface, guides and hair count.

use super::groom::{GroomBenchArgs, Peer, blender_case_text, groom_text, grow_all};
use super::median_seconds;
use crate::format::thousands;
use anyhow::Context;
use glam::Vec3;
use pelage::groom::Groom;
use pelage::groom::brush::{Brush, Dab, dab_edit};
use pelage::groom::edit::{Edit, EditableGroom};
use std::time::Instant;

/// Hairs the viewer grooms at.
const PREVIEW_HAIRS: f64 = 50_000.0;
/// Guides one dab should reach: 1 % of the figure's 1,000.
const DAB_GUIDES: usize = 10;
/// A frame at 60 Hz.
const FRAME_S: f64 = 1.0 / 60.0;

/// Blender's answer to one guide edit, measured in this run.
#[derive(Debug)]
struct BlenderEdit {
    seconds: f64,
    hairs: u64,
    version: String,
}

/// Everything `--edit` measures.
struct EditFigures {
    hairs: usize,
    guides: usize,
    open_s: f64,
    full_regrow_s: f64,
    edit_regrow_s: f64,
    edited_guides: usize,
    regrown_hairs: usize,
    dabs: usize,
    preview_hairs: usize,
    preview_edit_s: f64,
    peer_hairs: usize,
    one_guide_s: f64,
    peer: Result<BlenderEdit, String>,
    threads: usize,
}

/// Runs `pelage bench groom --edit` and prints its table or JSON.
pub fn run(args: &GroomBenchArgs) -> anyhow::Result<()> {
    let figures = measure(args)?;
    if args.json {
        println!("{}", figures.to_json());
    } else {
        figures.print();
    }
    Ok(())
}

/// Comb dabs centred on guide roots spread over the body, each with a
/// radius reaching about [`DAB_GUIDES`] guides.
fn dabs(groom: &EditableGroom, count: usize) -> Vec<Dab> {
    let guides = groom.guides();
    let roots: Vec<Vec3> = (0..guides.len()).map(|g| guides.guide(g)[0]).collect();
    (0..count)
        .map(|i| {
            let center = roots[(i * 97 + 13) % roots.len()];
            let mut d: Vec<f32> = roots.iter().map(|r| r.distance(center)).collect();
            d.sort_by(f32::total_cmp);
            let mut dab = Dab::new(center, d[DAB_GUIDES.min(d.len() - 1)] * 0.8);
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            dab.direction = Vec3::new(0.0, 0.01, 0.01) * sign;
            dab.strength = 1.0;
            dab
        })
        .collect()
}

/// The median seconds of `dabs` combed one after another, with the median
/// guides moved and hairs regrown.
fn comb(groom: &mut EditableGroom, dabs: &[Dab]) -> anyhow::Result<(f64, usize, usize)> {
    let (mut times, mut guides, mut hairs) = (Vec::new(), Vec::new(), Vec::new());
    for dab in dabs {
        if let Some(Edit::MoveGuides { guides: moved, .. }) =
            dab_edit(groom, &Brush::Comb, dab).map_err(anyhow::Error::msg)?
        {
            guides.push(moved.len());
        }
        let start = Instant::now();
        let regrowth = groom.brush(&Brush::Comb, dab)?;
        times.push(start.elapsed().as_secs_f64());
        hairs.push(regrowth.map_or(0, |r| r.regrown_roots));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let median_count = |v: &mut Vec<usize>| {
        v.sort_unstable();
        v.get(v.len() / 2).copied().unwrap_or(0)
    };
    Ok((
        median(&mut times),
        median_count(&mut guides),
        median_count(&mut hairs),
    ))
}

fn measure(args: &GroomBenchArgs) -> anyhow::Result<EditFigures> {
    let (hairs, peer_hairs, runs, dab_count) = args.scale().pick(
        (1_600_000u64, 1_000_000u64, 3, 25),
        (200_000, 200_000, 3, 7),
        (5_000, 5_000, 1, 3),
    );
    let groom = Groom::from_text("<bench>", groom_text(hairs, "shepard"))?;
    eprintln!("growing {} hairs to groom…", thousands(hairs));
    let start = Instant::now();
    let mut editable = EditableGroom::new(groom.spec()?, 1.0)?;
    let open_s = start.elapsed().as_secs_f64();
    let (full_regrow_s, counted) = median_seconds(runs, false, || grow_all(&groom));
    counted?;
    let strokes = dabs(&editable, dab_count);
    let (edit_regrow_s, edited_guides, regrown_hairs) = comb(&mut editable, &strokes)?;
    let total = editable.hair_count();
    let guides = editable.guides().len();
    drop(editable);

    let fraction = (PREVIEW_HAIRS / hairs as f64).min(1.0);
    let mut preview = EditableGroom::new(groom.spec()?, fraction)?;
    let preview_strokes = dabs(&preview, 15);
    let (preview_edit_s, _, _) = comb(&mut preview, &preview_strokes)?;
    let preview_hairs = preview.hair_count();
    drop(preview);

    // The peer's case: distribution and interpolation, 8 points, no
    // operators; one guide's tip moves.
    let case = Groom::from_text("<bench>", blender_case_text(peer_hairs))?;
    let mut one = EditableGroom::new(case.spec()?, 1.0)?;
    let n = one.guides().points_per_guide();
    let guide = one.guides().len() / 3;
    let offset = 0.01f32;
    let mut times = Vec::new();
    for run in 0..5 {
        let mut points = one.guides().guide(guide).to_vec();
        let sign = if run % 2 == 0 { 1.0 } else { -1.0 };
        points[n - 1].y += sign * offset;
        let start = Instant::now();
        one.apply(Edit::MoveGuides {
            guides: vec![guide as u32],
            points,
        })?;
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let one_guide_s = times[times.len() / 2];
    let peer = match args.peer {
        Some(Peer::Blender) => {
            eprintln!("measuring Blender's answer to a guide edit with bpy (tools/bpy-python)…");
            measure_blender(&case, peer_hairs, guide, offset, runs).map_err(|e| format!("{e:#}"))
        }
        None => Err("run with --peer blender".to_string()),
    };
    Ok(EditFigures {
        hairs: total,
        guides,
        open_s,
        full_regrow_s,
        edit_regrow_s,
        edited_guides,
        regrown_hairs,
        dabs: dab_count,
        preview_hairs,
        preview_edit_s,
        peer_hairs: one.hair_count(),
        one_guide_s,
        peer,
        threads: rayon::current_num_threads(),
    })
}

fn measure_blender(
    groom: &Groom,
    hairs: u64,
    guide: usize,
    offset: f32,
    runs: usize,
) -> anyhow::Result<BlenderEdit> {
    let report = super::run_bpy_case("blender_edit.py", include_str!("blender_edit.py"), |dir| {
        super::groom::write_groom_case(dir, groom)?;
        let (mesh, guides) = (groom.mesh(), groom.guides());
        let case = serde_json::json!({
            "hairs": hairs,
            "area": mesh.surface_area(),
            "guides": guides.len(),
            "points_per_guide": guides.points_per_guide(),
            "neighbours": 4,
            "runs": runs.max(5),
            "guide": guide,
            "offset": offset,
        });
        std::fs::write(dir.join("case.json"), case.to_string())?;
        Ok(())
    })?;
    let number = |key: &str| report[key].as_f64().context("a number in Blender's report");
    Ok(BlenderEdit {
        seconds: number("seconds")?,
        hairs: number("hairs")? as u64,
        version: report["blender"].as_str().unwrap_or("?").to_string(),
    })
}

impl EditFigures {
    fn ratio(&self) -> f64 {
        self.full_regrow_s / self.edit_regrow_s
    }

    fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "hairs": self.hairs,
            "guides": self.guides,
            "threads": self.threads,
            "open_s": self.open_s,
            "full_regrow_s": self.full_regrow_s,
            "edit_regrow_s": self.edit_regrow_s,
            "edit_speedup": self.ratio(),
            "edited_guides": self.edited_guides,
            "regrown_hairs": self.regrown_hairs,
            "dabs": self.dabs,
            "preview_hairs": self.preview_hairs,
            "preview_edit_s": self.preview_edit_s,
            "frame_s": FRAME_S,
            "peer_hairs": self.peer_hairs,
            "one_guide_edit_s": self.one_guide_s,
            "blender": match &self.peer {
                Ok(b) => serde_json::json!({
                    "version": b.version,
                    "hairs": b.hairs,
                    "edit_s": b.seconds,
                    "pelage_speedup": b.seconds / self.one_guide_s,
                }),
                Err(why) => serde_json::json!({ "not_measured": why }),
            },
        })
    }

    fn print(&self) {
        println!(
            "pelage bench groom --edit — the Stubble figure ({} hairs × 16 points, {} guides, clump + noise); {} threads\n",
            thousands(self.hairs as u64),
            thousands(self.guides as u64),
            self.threads
        );
        println!("{:<46} {:>10} {:>22}", "", "seconds", "against");
        println!(
            "{:<46} {:>10.3}",
            "open for grooming (grow all, keep recipes)", self.open_s
        );
        println!(
            "{:<46} {:>10.3} {:>22}",
            "full regrow (pelage groom, in memory)", self.full_regrow_s, ""
        );
        println!(
            "{:<46} {:>10.4} {:>22}",
            format!(
                "comb dab: {} guides, {} hairs regrown",
                self.edited_guides,
                thousands(self.regrown_hairs as u64)
            ),
            self.edit_regrow_s,
            format!("{:.0}× faster (≥ 30)", self.ratio())
        );
        println!(
            "{:<46} {:>10.4} {:>22}",
            format!(
                "  at preview density ({} hairs)",
                thousands(self.preview_hairs as u64)
            ),
            self.preview_edit_s,
            format!("{:.1} frames at 60 Hz", self.preview_edit_s / FRAME_S)
        );
        println!(
            "{:<46} {:>10.4}",
            format!(
                "one guide tip moved, {} hairs × 8 points",
                thousands(self.peer_hairs as u64)
            ),
            self.one_guide_s
        );
        match &self.peer {
            Ok(b) => println!(
                "{:<46} {:>10.4} {:>22}",
                format!(
                    "  peer: Blender {} Interpolate Curves ({})",
                    b.version,
                    thousands(b.hairs)
                ),
                b.seconds,
                format!("pelage {:.0}× faster (≥ 20)", b.seconds / self.one_guide_s)
            ),
            Err(why) => println!("{:<46} not measured: {why}", "  peer: Blender"),
        }
        println!(
            "\nmedians of {} dabs ({} at preview density); the full regrow is the median of 3.",
            self.dabs, 15
        );
    }
}
