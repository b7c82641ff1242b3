//! A crate whose two parts use each other: `paint` names `Brush` through
//! the crate root's re-export, which `tools/layers-check` must follow to
//! `brush` to see the circle. CI runs the check here and expects it to fail.

pub mod brush;
pub mod paint;

pub use brush::Brush;
