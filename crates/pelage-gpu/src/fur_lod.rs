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
pub use pelage_shaders::stand_in::ShellStandIn;

/// When to draw what, by a character's height on screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FurLod {
    /// At this height in pixels and above, every strand is drawn.
    pub full_px: f32,
    /// The smallest share of the strands drawn; below the height it is
    /// reached at, strands hand over to shells.
    pub floor: f32,
    /// The hand-over's length, a share of the height it starts at: the
    /// strands fade out and the shells in from that height down to
    /// `(1 − fade)` of it.
    pub fade: f32,
}

impl Default for FurLod {
    /// Every strand at 800 pixels (a character three quarters of a 1080p
    /// screen), down to a tenth of them at 253 pixels, shells alone below
    /// 177 pixels.
    fn default() -> Self {
        Self {
            full_px: 800.0,
            floor: 0.1,
            fade: 0.5,
        }
    }
}

/// What one level draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FurLevel {
    /// The share of the strands drawn (the first by arrival).
    pub fraction: f32,
    /// The strands' opacity (0: none drawn).
    pub strand_opacity: f32,
    /// The shells' opacity (0: none drawn).
    pub shell_opacity: f32,
}

impl FurLod {
    /// The level for a character `height_px` pixels high on screen.
    pub fn level(&self, height_px: f32) -> FurLevel {
        let floor = self.floor.clamp(1e-6, 1.0);
        let full = self.full_px.max(1e-3);
        let fraction = (height_px / full).powi(2).clamp(floor, 1.0);
        // The height the floor is reached at, and how far below it.
        let handover = full * floor.sqrt();
        let fade = self.fade.clamp(1e-3, 1.0);
        let t = ((handover - height_px) / (fade * handover)).clamp(0.0, 1.0);
        FurLevel {
            fraction,
            strand_opacity: 1.0 - t,
            shell_opacity: t,
        }
    }
}

impl FurLevel {
    /// `base` at this level for a groom of `hairs` render hairs (ordered
    /// by arrival), or `None` when no strand is drawn. In the hand-over
    /// the strands thin out hair by hair, the latest arrivals first, as
    /// they fade: dense fur fades poorly by opacity alone (overlapping
    /// hairs through alpha-to-coverage stay opaque until they vanish).
    pub fn strands(&self, base: StrandParams, hairs: u32) -> Option<StrandParams> {
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
    pub fn shells(&self, base: ShellParams) -> ShellParams {
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
