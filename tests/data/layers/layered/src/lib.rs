//! The same two parts in one direction: `brush` uses `paint`, and only a
//! test of `paint` names `brush` (tests may use any layer). CI runs
//! `tools/layers-check` here and expects it to pass.

pub mod brush;
pub mod paint;

pub use brush::Brush;
