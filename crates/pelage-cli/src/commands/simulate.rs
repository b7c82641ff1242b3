//! `pelage simulate`: simulates an animated groom's guides
//! (`[animation] mode = "simulate"`) and writes them, time-sampled: for
//! other tools (Houdini, Unreal, Blender read them as guide curves), or as
//! the `[simulation] cache` a farm's tasks then read instead of each
//! simulating again (docs/farm.md).

use anyhow::bail;
use clap::Args;
use pelage::anim::FrameRange;
use pelage::groom::{AnimationMode, CacheUse, Groom};
use pelage::io::CurvesFormat;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `pelage simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// The groom file (TOML, with `[animation] mode = "simulate"`).
    pub file: PathBuf,
    /// Where the guides go (.usdc, .usd or .abc), with a time sample a
    /// frame. Default: the file's `[simulation] cache`, refreshed only
    /// when stale.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Frames to write beyond the file's `[animation] frames` (the whole
    /// range is always simulated, from its first frame).
    #[arg(long, value_name = "RANGE", allow_hyphen_values = true)]
    pub frames: Option<FrameRange>,
}

pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let groom = Groom::load_with_frames(&args.file, args.frames.clone())?;
    if groom.animation().map(|a| a.mode) != Some(AnimationMode::Simulate) {
        bail!(
            "{}: only an animated groom with mode = \"simulate\" in [animation] simulates its guides",
            args.file.display()
        );
    }
    if args.output.is_none() && groom.simulation_cache().is_none() {
        bail!(
            "{}: name the output (-o guides.usdc), or a cache in the groom file ([simulation] cache = \"guides.usdc\")",
            args.file.display()
        );
    }
    // Refused before the simulation, not after it.
    if let Some(output) = &args.output
        && !CurvesFormat::from_path(output).is_some_and(CurvesFormat::writes_time_samples)
    {
        bail!(
            "{}: simulated guides are {}",
            output.display(),
            CurvesFormat::NO_TIME_SAMPLES
        );
    }
    if let Some(output) = &args.output {
        pelage::io::check_writable(output)?;
    }
    let (guides, cache) = groom.simulated_guides()?;
    let frames = guides.frames();
    let count = guides.at(*frames.start()).map_or(0, |g| g.curve_count());
    let what = format!(
        "{count} guides over frames {}-{}",
        frames.start(),
        frames.end()
    );
    let seconds = start.elapsed().as_secs_f64();
    match (&args.output, cache.zip(groom.simulation_cache())) {
        (Some(output), _) => {
            guides.write(output, &groom.usd_options())?;
            println!("simulated {what} in {seconds:.2} s → {}", output.display());
        }
        (None, Some((used, path))) => {
            let done = match used {
                CacheUse::Read => "up to date",
                CacheUse::Written => "written",
                CacheUse::Replaced => "was stale: simulated again",
            };
            println!("cache {} ({what}): {done}, {seconds:.2} s", path.display());
        }
        (None, None) => bail!("{}: no output and no cache", args.file.display()),
    }
    Ok(())
}
