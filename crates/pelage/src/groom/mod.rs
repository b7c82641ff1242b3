//! Groom generation: a mesh, guides and maps in; finished hair curves out,
//! part by part (Sik §4, Stubble's generator; the Furtility talk's chain of
//! groom operators).
//!
//! - [`GroomSpec`] (`spec.rs`): the groom as plain Rust values: mesh,
//!   guides, roots, interpolation, operators, finish. Programs and bindings
//!   build one directly.
//! - [`Groom`] (`load.rs`, the schema in `file.rs`): the TOML groom file, one front end
//!   that produces a `GroomSpec`; every error with file, line and key
//!   ([`GroomError`], `error.rs`; `source.rs` finds lines and keys).
//! - [`Generator`]: a spec prepared for generation (root sampler,
//!   [`PartLayout`], interpolator, operator chain with clump centres);
//!   [`Generator::part`] grows one part's hairs (`grow.rs`; a hair that
//!   overflows is traced to its operator in `diagnose.rs`).
//! - [`ops`]: the operators.
//! - [`parts`]: the part layout; [`Generator::write`] streams parts to a
//!   file; [`FarmRun`] (`K/N`) is one run of a farm and
//!   [`find_part_files`] finds the runs' files, which [`write_assembly`]
//!   ties together in USD ([`Groom::assemble`] does both).
//! - [`HairLook`] (`look.rs`): `[look]`, each hair's values for a
//!   physically based hair shader.
//! - [`GroomReport`] (`report.rs`): what a groom grew and left out, for
//!   every front end.
//!
//! One hair, as Sik's Fig. 14 draws it: a root sampled in its part → shape
//! interpolated from the guides → resampled to the finishing point count →
//! base width/colour/opacity → the operators in order → per-point normals
//! from rotation-minimizing frames. Every random number a hair uses is keyed
//! by (seed, hair id), so the output does not depend on threads, and any
//! part generated alone equals that part of the full run.

pub mod animate;
mod blue_noise;
pub mod brush;
mod clips;
mod diagnose;
pub mod edit;
mod error;
mod farm;
pub(crate) mod file;
mod generator;
mod grow;
mod hair_look;
mod load;
pub mod ops;
mod output;
mod outside_skin;
pub mod parts;
mod ramp;
pub mod regions;
mod report;
mod simulate;
mod source;
mod spec;
mod writing;

pub use animate::{
    AnimatedGroom, AnimationMode, AnimationProgress, AnimationSpec, AxisTurn, FrameOutput,
    GuideMotion,
};
pub use clips::{ClipAssembly, FrameFile, find_frame_files, frames_file, write_clip_assembly};
pub use error::{GroomError, GroomErrorDetails, GroomErrorKind};
pub use farm::{FarmError, FarmRun, find_part_files};
pub use generator::{Generator, GroomSummary, HAIRS_PER_PART};
pub use hair_look::HairLook;
pub use load::{Groom, GroomInputs};
pub use output::{GroomWriteError, StreamError, part_file, part_name, part_slice, write_assembly};
pub use outside_skin::OutsideSkin;
pub use parts::{Part, PartLayout};
pub use ramp::Ramp;
pub use report::{
    GroomReport, GuideNote, GuidesReport, LostGuideNote, PartReport, RegionReport, ReportBuilder,
    Timings,
};
pub use simulate::{
    CacheUse, SIMULATED_GUIDES_NAME, SimulatedGuides, SimulationSettings, cached_simulation,
    simulate_guides, simulation_key,
};
pub use writing::{AssembleError, Assembly, DEFAULT_FPS};

pub use ops::{
    ClumpParams, CurlParams, FlyawaysParams, FrizzParams, GroomOp, LengthParams, NoiseParams,
    StrandsParams, TwistParams,
};
pub use spec::{
    FinishSpec, GroomSpec, HairIds, RegionSource, RegionsSpec, RootDistribution, RootsSpec,
};
