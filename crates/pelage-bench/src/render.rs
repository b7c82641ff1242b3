//! `pelage bench render`: frame time of the preview renderer at 1280×720
//! for the skin alone and with 100 k / 1 M hair curves (8 points each,
//! grown along the normal from roots on spot ×1), on whatever adapter is
//! present. A frame is draw + resolve + read-back of the image; uploading
//! the geometry is timed separately.

use super::median_seconds;
use crate::format::thousands;
use clap::Args;
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use pelage::{Curves, Map};
use pelage_gpu::{GpuContext, PreviewScene, PreviewStyle, Renderer};

/// Arguments of `pelage bench render`.
#[derive(Debug, Args)]
pub struct RenderBenchArgs {
    /// A reduced run (100 k curves only, 3 frames each).
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

impl RenderBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &RenderBenchArgs) -> anyhow::Result<()> {
    let ctx = GpuContext::headless()?;
    let renderer = Renderer::new(&ctx);
    let spot = pelage::assets::spot();
    let scale = args.scale();
    let (width, height) = scale.pick((1280, 720), (1280, 720), (320, 180));
    let runs = scale.pick(5, 3, 1);
    let style = PreviewStyle::default();
    let sampler =
        DensitySampler::new(&spot, &Map::Constant(1.0), DensitySamplerOptions::default())?;

    let frame = |scene: &PreviewScene| -> anyhow::Result<(f64, f64)> {
        let (upload_s, uploaded) = median_seconds(1, false, || renderer.upload(&ctx, scene));
        let (frame_s, image) = median_seconds(runs, true, || {
            renderer.render_uploaded(&ctx, &uploaded, &style, None, width, height)
        });
        image?;
        Ok((upload_s, frame_s))
    };
    let skin_scene = PreviewScene {
        mesh: Some(&spot),
        points: &[],
        curves: None,
        skin_texture: None,
    };
    let (_, skin_s) = frame(&skin_scene)?;
    let counts: &[u64] = if scale.reduced() {
        &[100_000]
    } else {
        &[100_000, 1_000_000]
    };
    let mut rows = Vec::new();
    let mut json = serde_json::Map::new();
    json.insert("adapter".into(), ctx.adapter_name().into());
    json.insert("software_adapter".into(), ctx.is_software().into());
    json.insert("skin_ms".into(), (skin_s * 1e3).into());
    for &count in counts {
        let roots = sample_range(&sampler, 5, 0..count);
        let curves = Curves::along_normals(&spot, &roots, 0.05, 8, 0.0015, 0.0003);
        let scene = PreviewScene {
            mesh: Some(&spot),
            points: &[],
            curves: Some(&curves),
            skin_texture: None,
        };
        let (upload_s, frame_s) = frame(&scene)?;
        rows.push((count, curves.segment_count(), upload_s, frame_s));
        let key = if count == 1_000_000 {
            "curves_1m_ms".to_string()
        } else {
            format!("curves_{}k_ms", count / 1000)
        };
        json.insert(key, (frame_s * 1e3).into());
    }
    if args.json {
        println!("{}", serde_json::Value::Object(json));
        return Ok(());
    }
    println!(
        "pelage bench render — {width}×{height}, median of {runs} frames, on {}",
        ctx.adapter_name()
    );
    println!("frame = draw + MSAA resolve + read-back; upload timed once, separately\n");
    println!(
        "{:>12}  {:>11}  {:>10}  {:>10}  {:>9}",
        "scene", "segments", "upload", "frame", "÷ skin"
    );
    println!(
        "{:>12}  {:>11}  {:>10}  {:>7.1} ms  {:>9}",
        "skin",
        "—",
        "—",
        skin_s * 1e3,
        "1.0×"
    );
    for (count, segments, upload_s, frame_s) in rows {
        println!(
            "{:>12}  {:>11}  {:>7.1} ms  {:>7.1} ms  {:>8.1}×",
            format!("+{} curves", thousands(count)),
            thousands(segments as u64),
            upload_s * 1e3,
            frame_s * 1e3,
            frame_s / skin_s
        );
    }
    Ok(())
}
