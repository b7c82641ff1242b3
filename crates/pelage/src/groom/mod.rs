//! Groom generation: a mesh, guides and maps in; finished hair curves out,
//! part by part (Sik §4, Stubble's generator; the Furtility talk's chain of
//! groom operators).
//!
//! - [`mod@file`]: the TOML groom file ([`GroomFile`]), every error with file,
//!   line and key.
//! - [`Groom`]: a groom file loaded: its mesh, guides and resolved maps.
//! - [`Generator`]: everything prepared for generation (root sampler,
//!   [`PartLayout`], interpolator, operator chain with clump centres);
//!   [`Generator::part`] grows one part's hairs.
//! - [`ops`]: the operators.
//! - [`parts`]: the part layout; [`Generator::write`] streams parts to a
//!   file, [`write_assembly`] ties a farm's part files together in USD.
//!
//! One hair, as Sik's Fig. 14 draws it: a root sampled in its part → shape
//! interpolated from the guides → resampled to the finishing point count →
//! base width/colour/opacity → the operators in order → per-point normals
//! from rotation-minimizing frames. Every random number a hair uses is keyed
//! by (seed, hair id), so the output does not depend on threads, and any
//! part generated alone equals that part of the full run.

pub mod file;
mod generator;
pub mod ops;
mod output;
pub mod parts;

pub use file::{GroomError, GroomErrorKind, GroomFile, GroomSource, Ramp};
pub(crate) use generator::load_mesh_section;
pub use generator::{Generator, Groom, GroomSummary};
pub use output::{GroomWriteError, part_file, part_name, part_slice, write_assembly};
pub use parts::{Part, PartLayout};
