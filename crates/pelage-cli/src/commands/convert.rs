//! `pelage convert IN OUT`: curves from one format to another, formats by
//! extension (reads .usda/.usdc/.usd/.hair/.ply; writes .usdc/.usd/.usda/
//! .hair/.ply/.rib/.pbrt).

use super::load_mesh;
use anyhow::Context;
use clap::builder::TypedValueParser;
use clap::{Args, ValueEnum};
use pelage::io::{
    CurveBasis, CurvesExport, UpAxis, UsdOptions, UsdWrap, read_curves_and_sample_count,
    write_curves,
};
use std::path::PathBuf;

/// Arguments of `pelage convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Curves to read: .usda, .usdc, .usd, .hair or .ply (vertex + edge).
    pub input: PathBuf,
    /// Where to write: .usdc (or .usd: binary USD), .usda (text USD),
    /// .hair, .ply, .rib or .pbrt.
    pub output: PathBuf,
    /// How the points are interpolated (USD, RIB, pbrt).
    #[arg(
        long,
        default_value_t = CurveBasis::CatmullRom,
        value_parser = clap::builder::PossibleValuesParser::new(CurveBasis::NAMES)
            .try_map(|s: String| s.parse::<CurveBasis>()),
    )]
    pub basis: CurveBasis,
    /// End treatment of Catmull-Rom curves in USD: pinned passes through the
    /// end points (Blender's choice), nonperiodic needs ≥ 4 points a curve.
    #[arg(long, value_enum, default_value_t = WrapArg::Pinned)]
    pub wrap: WrapArg,
    /// USD up axis.
    #[arg(long, value_enum, default_value_t = UpAxisArg::Y)]
    pub up_axis: UpAxisArg,
    /// USD metersPerUnit.
    #[arg(long, default_value_t = 1.0, value_parser = super::args::positive)]
    pub meters_per_unit: f64,
    /// Also write this mesh (or `spot`, the embedded one) into the USD file
    /// as the skin, so it opens complete in usdview or Blender.
    #[arg(long, value_name = "MESH")]
    pub with_mesh: Option<String>,
}

/// `--wrap`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum WrapArg {
    /// Through the end points.
    Pinned,
    /// End points only steer.
    Nonperiodic,
}

/// `--up-axis`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum UpAxisArg {
    /// Y up.
    Y,
    /// Z up (Blender).
    Z,
}

impl ConvertArgs {
    /// The USD options these flags describe.
    pub fn usd_options(&self) -> UsdOptions {
        UsdOptions {
            basis: self.basis,
            wrap: match self.wrap {
                WrapArg::Pinned => UsdWrap::Pinned,
                WrapArg::Nonperiodic => UsdWrap::Nonperiodic,
            },
            up_axis: match self.up_axis {
                UpAxisArg::Y => UpAxis::Y,
                UpAxisArg::Z => UpAxis::Z,
            },
            meters_per_unit: self.meters_per_unit,
            ..UsdOptions::default()
        }
    }
}

pub fn run(args: &ConvertArgs) -> anyhow::Result<()> {
    // An animated file converts at its first sample: said, not silent.
    let (curves, samples) =
        read_curves_and_sample_count(&args.input).context("cannot read the curves")?;
    if samples > 1 {
        eprintln!(
            "note: {} is animated ({samples} time samples): convert writes its first; its skin, if it has one, is not converted (`--with-mesh` writes a still mesh); `pelage render --frames` and Python's read_curves(path, time=) read the others",
            args.input.display()
        );
    }
    let mesh = match args.with_mesh.as_deref() {
        None => None,
        Some("spot") => Some(load_mesh(None)?),
        Some(path) => Some(load_mesh(Some(path.as_ref()))?),
    };
    let export = CurvesExport {
        usd: args.usd_options(),
        mesh: mesh.as_ref(),
        guides: None,
    };
    write_curves(&args.output, [("curves".to_string(), &curves)], &export)?;
    let (lo, hi) = curves.point_count_range();
    println!(
        "wrote {} ({} curves, {} points, {lo}–{hi} points a curve)",
        args.output.display(),
        curves.curve_count(),
        curves.points().len()
    );
    Ok(())
}
