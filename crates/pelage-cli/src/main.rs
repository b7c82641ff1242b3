//! `pelage`: the command-line tool over the pelage library.
//!
//! A thin binary: it parses arguments (clap), calls the library, and owns
//! everything the library must not do: printing, progress, exit codes.
//! Errors print as `error: …` followed by their causes, and exit with 2.

mod commands;
use pelage_bench::format;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// pelage: a fur toolkit. Grooming (hair roots, guides, operators, USD out)
/// and real-time shell fur, from published methods.
#[derive(Debug, Parser)]
#[command(name = "pelage", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print what a mesh is made of: counts, bounds, area, UVs, defects.
    Info(commands::info::InfoArgs),
    /// Place points (hair roots) on a mesh with a density map; write a PLY.
    Sample(commands::sample::SampleArgs),
    /// Render a mesh, a point cloud or curves to a PNG (headless GPU).
    Render(commands::render::RenderArgs),
    /// Grow a groom file's hairs (guides, operators, parts) and write them.
    Groom(commands::groom::GroomArgs),
    /// Simulate an animated groom's guides (gravity, wind, collisions) and
    /// write them with a time sample a frame.
    Simulate(commands::simulate::SimulateArgs),
    /// Grow guide curves on a mesh, or bind guides from a file to it.
    Guides(commands::guides::GuidesArgs),
    /// Convert curves between formats (USD, .hair, PLY, RIB, pbrt).
    Convert(commands::convert::ConvertArgs),
    /// Draw shell fur (curl, wet clumps, drying) to a PNG or a sequence.
    Shells(commands::shells::ShellsArgs),
    /// Look at shell fur in a window: sliders, drop water, push, shake
    /// (needs the `viewer` feature).
    View(commands::view::ViewArgs),
    /// Run the demo on the embedded Spot mesh.
    Demo(commands::demo::DemoArgs),
    /// Measure a capability against its paper's figures.
    Bench(commands::bench::BenchArgs),
}

fn main() -> ExitCode {
    quiet_vulkan_device_select();
    remove_temporary_files_on_signals();
    let cli = Cli::parse();
    // A run's outputs never replace its inputs (`sample -o in.ply`, a
    // groom's `[output] path` naming its mesh). The benchmarks write and
    // read back their own scratch files, over and over.
    if !matches!(cli.command, Command::Bench(_)) {
        pelage::io::protect_inputs();
    }
    let result = match cli.command {
        Command::Info(args) => commands::info::run(&args),
        Command::Sample(args) => commands::sample::run(&args),
        Command::Render(args) => commands::render::run(&args),
        Command::Convert(args) => commands::convert::run(&args),
        Command::Guides(args) => commands::guides::run(&args),
        Command::Groom(args) => commands::groom::run(&args),
        Command::Simulate(args) => commands::simulate::run(&args),
        Command::Shells(args) => commands::shells::run(&args),
        Command::View(args) => commands::view::run(&args),
        Command::Demo(args) => commands::demo::run(&args),
        Command::Bench(args) => commands::bench::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {}", one_line(&err));
            ExitCode::from(2)
        }
    }
}

/// On Ctrl-C (SIGINT), SIGTERM or SIGHUP: removes the temporary files of
/// the outputs being written, so an interrupted run leaves every target as
/// it was (absent, or its earlier complete version), then exits with the
/// shell's code for the signal (128 + its number). Runs on a thread of its
/// own (signal-hook's self-pipe), where removing files is safe.
fn remove_temporary_files_on_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            pelage::io::remove_temporary_files();
            eprintln!(
                "\ninterrupted: the files being written were removed; finished ones are complete"
            );
            std::process::exit(128 + signal);
        }
    });
}

/// The error and its causes on one line, "a: b: c": each error prints
/// its cause or returns it as its `source`, never both, so every cause is
/// said once.
pub(crate) fn one_line(err: &anyhow::Error) -> String {
    format!("{err:#}")
}

/// Mesa's `VK_LAYER_MESA_device_select` (an implicit Vulkan layer, there
/// whenever Mesa's drivers are) connects to Wayland while the GPUs are
/// listed, to put the display's GPU first. Without a usable
/// `XDG_RUNTIME_DIR` (ssh, `su`, containers, CI) libwayland then prints
/// "error: XDG_RUNTIME_DIR is invalid or not set in the environment." twice
/// on a render that succeeds, which reads as pelage failing. With no such
/// directory there is no Wayland display for the layer to find, so its own
/// off switch (`NODEVICE_SELECT=1`) loses nothing: wgpu still chooses the
/// adapter (`WGPU_ADAPTER_NAME`, `WGPU_POWER_PREF`). A value the user set
/// is left alone.
fn quiet_vulkan_device_select() {
    // libwayland's own test: unset, or not an absolute path.
    let runtime_dir = std::env::var_os("XDG_RUNTIME_DIR");
    let usable = runtime_dir.is_some_and(|d| d.to_string_lossy().starts_with('/'));
    if cfg!(target_os = "linux") && !usable && std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: the first thing `main` does; no other thread exists yet
        // to read the environment while it changes.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}
