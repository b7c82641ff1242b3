//! Shell fur: real-time fur drawn as N semi-transparent layers over the
//! skin (Lengyel et al. 2001), with the textures of Banisch & Wüthrich
//! ("Shell Texture Generation") and the curling and wet clumping of Silva
//! et al.
//!
//! - [`textures`]: the shell textures (exponential blades + undercoat, or
//!   Lengyel's random strands), sliced into N RGBA layers.
//! - [`wetness`]: the wetness mask (Silva §3.1): droplets blended by Alg. 1,
//!   random droplets, droplets painted from an image, drying over time.
//! - [`math`]: every formula the shell shaders use (Silva Eqs. 1, 4, 5, 6,
//!   Alg. 2), one function each — the reference `pelage-gpu`'s WGSL mirrors
//!   and is tested against.
//! - [`scene`]: shell scene files (TOML): mesh, textures, curl, clumping,
//!   droplets, light and camera, fins, level of detail
//!   (docs/shells-format.md).
//! - [`ShellAnimation`]: a skinned glTF character playing a clip, posed by
//!   linear-blend skinning for the GPU and the fur's dynamics.

mod error;
pub mod math;
pub mod scene;
mod scene_file;
mod skinned;
pub mod textures;
pub mod wetness;

pub use error::{SceneError, SceneErrorKind};
pub use math::{ClumpParams, Coupling, CurlParams, KajiyaKay, Strand, WetTexel};
pub use scene::{SceneCamera, ShellScene};
pub use skinned::ShellAnimation;
pub use textures::{ShellTextureParams, ShellTextures, TextureStyle};
pub use wetness::{Droplet, DropletStyle, WetnessMask};
