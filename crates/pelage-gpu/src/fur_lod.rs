//! A groom's level of detail in real time: every strand near; as the
//! character gets smaller on screen, fewer strands, the first hairs by
//! arrival (`pelage::groom::roots_by_arrival`: the hairs a preview
//! fraction grows, so each level's hairs are hairs of every larger one),
//! widths × 1/√F so the coat covers the skin as the whole groom does; at a
//! floor, a cross-fade to shell fur made from the same groom
//! ([`ShellStandIn`]); shells alone in the distance.
//!
//! The share of the hairs follows the character's area on screen
//! (`F = (h / full)²`, `h` its height in pixels): the hairs a pixel holds
//! stay about the same from near to far.

use crate::{ShellParams, StrandParams};
pub use pelage_shaders::stand_in::{FurLevel, FurLod, ShellStandIn};

/// What a [`FurLevel`] means for each renderer's parameters.
pub trait FurLevelParams {
    /// `base` at this level for a groom of `hairs` render hairs (ordered
    /// by arrival), or `None` when no strand is drawn.
    fn strands(&self, base: StrandParams, hairs: u32) -> Option<StrandParams>;
    /// `base` (the shells) at this level.
    fn shells(&self, base: ShellParams) -> ShellParams;
}

impl FurLevelParams for FurLevel {
    /// `base` at this level for a groom of `hairs` render hairs (ordered
    /// by arrival), or `None` when no strand is drawn. In the hand-over
    /// the strands thin out hair by hair, the latest arrivals first, as
    /// they fade: dense fur fades poorly by opacity alone (overlapping
    /// hairs through alpha-to-coverage stay opaque until they vanish).
    fn strands(&self, base: StrandParams, hairs: u32) -> Option<StrandParams> {
        let drawn = (hairs as f32 * self.fraction * self.strand_opacity).round() as u32;
        (self.strand_opacity > 0.0 && drawn > 0).then(|| StrandParams {
            hairs: Some(drawn.min(hairs)),
            width_scale: base.width_scale / self.fraction.sqrt(),
            opacity: base.opacity * self.strand_opacity,
            ..base
        })
    }

    /// `base` (the shells) at this level, or `None` when they are not
    /// drawn; with 0 layers (the skin alone) when the strands cover it.
    fn shells(&self, base: ShellParams) -> ShellParams {
        if self.shell_opacity > 0.0 {
            ShellParams {
                opacity: base.opacity * self.shell_opacity,
                ..base
            }
        } else {
            ShellParams { layers: 0, ..base }
        }
    }
}

impl ShellParams {
    /// These parameters' shading, drawing `stand_in`'s layers, length and
    /// tiles.
    pub fn for_stand_in(self, stand_in: &ShellStandIn) -> Self {
        ShellParams {
            layers: stand_in.texture.layers,
            length: stand_in.length,
            tiles: stand_in.tiles,
            ..self
        }
    }
}
