//! A brush that knows the paint it lays down.

use crate::paint::Paint;

/// A brush.
pub struct Brush {
    /// What it lays down.
    pub paint: Paint,
}
