//! Paint that knows the brush that laid it: the other half of the circle.

/// Paint.
pub struct Paint {
    /// Written by a brush; `crate::Brush` is `brush::Brush` re-exported.
    pub by: Option<Box<crate::Brush>>,
}
