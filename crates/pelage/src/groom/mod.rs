//! Groom generation: a mesh, guides and maps in; finished hair curves out,
//! part by part (Sik §4, Stubble's generator; the Furtility talk's chain of
//! groom operators).
//!
//! The parts stand in layers, lowest first; each uses only parts of its
//! own layer listed before it, or of lower layers (`tools/layers-check`
//! fails on an import circle; ARCHITECTURE.md has the table):
//!
//! 1. **Values.** `error.rs` ([`GroomError`]: file, line, key and a typed
//!    kind), `source.rs` (settings' spans as errors, maps resolved against
//!    the file's folder), [`Ramp`], `values.rs` (a map as written,
//!    `MapValue`, and the root-to-tip and colour specs),
//!    [`regions`], [`HairLook`] (`hair_look.rs`: `[look]`, each hair's
//!    values for a physically based hair shader), [`OutsideSkin`].
//! 2. **Operators**: [`ops`], one module an operator, which see the chain
//!    they are prepared in only through a trait, never the generator.
//! 3. **Spec**: [`GroomSpec`] (`spec.rs`), the groom as plain Rust values
//!    (mesh, guides, roots, interpolation, operators, finish), which
//!    programs and bindings build directly; [`parts`], the part layout.
//! 4. **Generate**: [`Generator`] (`generator.rs`: what a prepared groom
//!    holds), `blue_noise.rs` (a part's roots thinned), `grow.rs`
//!    ([`Generator::part`]: a part's hairs grown; a hair that overflows
//!    traced to its operator), `build.rs` (a spec made a generator; a
//!    clump's centres grown through the operators before it),
//!    [`GroomRecipe`] (`recipe.rs`: the groom flattened for an evaluator
//!    that grows every hair again each frame, the GPU's).
//! 5. **Write**: `output.rs` ([`Generator::write`] streams parts to a file,
//!    [`write_assembly`]), [`FarmRun`] (`farm.rs`, `K/N`, with
//!    [`find_part_files`]), `clips.rs` (frame files stitched with USD value
//!    clips).
//! 6. **Animate**: [`animate`] (a groom carried or regrown over frames),
//!    `simulate.rs` (guides simulated on the animated skin).
//! 7. **File**: `file.rs` (the TOML schema and its range rules), [`Groom`]
//!    (`load.rs`: a file with its mesh and guides, producing a `GroomSpec`
//!    that keeps where each setting was written), [`GroomReport`]
//!    (`report.rs`), `export.rs` (what every front end writes with:
//!    [`Groom::export`], [`Groom::assemble`]).
//! 8. **Edit**: [`edit`] (the editable groom, its undo stack, regrowing
//!    only what an edit changed, saving) and [`brush`].
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
mod build;
mod clips;

pub mod edit;
mod error;
mod export;
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
mod recipe;
pub mod regions;
mod report;
mod simulate;
mod source;
mod spec;
mod values;

pub use animate::{
    AnimatedFiles, AnimatedGroom, AnimationMode, AnimationProgress, AnimationSpec, AxisTurn,
    FrameOutput, GeneratorGrower, GuideMotion,
};
pub use clips::{ClipAssembly, FrameFile, find_frame_files, frames_file, write_clip_assembly};
pub use error::{GroomError, GroomErrorKind};
pub use export::{
    AnimatedPlan, AnimatedPlanError, AssembleError, Assembly, DEFAULT_FPS, PreflightError,
    Stitching,
};
pub use farm::{FarmError, FarmRun, find_part_files};
pub use generator::{Generator, GroomSummary};
pub use hair_look::{HairLook, color_of_melanin, melanin_of_color};
pub use load::{Groom, GroomInputs};
pub use load::{linear_to_srgb, srgb_to_linear};
pub use output::{
    GroomWriteError, PartGrower, StreamError, part_file, part_name, part_slice, write_assembly,
};
pub use outside_skin::OutsideSkin;
pub use parts::{HAIRS_PER_PART, Part, PartLayout};
pub use ramp::Ramp;
pub use recipe::{
    GroomRecipe, MAX_RECIPE_WEIGHTS, RecipePass, RecipeStep, StepKind, roots_by_arrival,
};
pub use report::{
    GroomReport, GuideNote, GuidesReport, LostGuideNote, PartReport, RegionReport, ReportBuilder,
    Timings,
};
pub use simulate::{
    CacheUse, SIMULATED_GUIDES_NAME, SimulatedGuides, SimulationSettings, cached_simulation,
    cached_simulation_until, simulate_guides, simulate_guides_until, simulation_key,
};

pub use ops::{
    ClumpParams, CurlParams, FlyawaysParams, FrizzParams, GroomOp, LengthParams, NoiseParams,
    StrandsParams, TwistParams,
};
pub use spec::{
    FinishSpec, GroomSpec, HairIds, RegionSource, RegionsSpec, RootDistribution, RootsSpec,
};
