//! Fur on animated characters: skins that move over frames
//! ([`AnimatedSkin`]: USD time samples, OBJ sequences, glTF skinning),
//! hairs bound at rest and carried with the skin ([`SkinBinding`]), and
//! frame ranges ([`FrameRange`]). The groom side — growing once and
//! deforming, or regrowing every frame from animated guides — is
//! `groom::animate`.

mod binding;
mod frames;
mod gltf_skin;
mod rig;
mod skin;

pub use binding::{RestFrames, SkinBinding, SkinPose};
pub use frames::{FrameRange, FrameRangeError, MAX_FRAMES};
pub use rig::{Influence, PosedFrames, SkinRig};
pub use skin::{AnimatedSkin, SkinOptions, sequence_file};
