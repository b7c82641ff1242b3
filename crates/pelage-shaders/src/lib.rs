//! pelage-shaders: what pelage's GPU hosts share, with no GPU API in it.
//!
//! Two hosts draw pelage's fur: `pelage-gpu` on its own wgpu device, and
//! `pelage-bevy` through Bevy's renderer (a different wgpu version). Each
//! builds its own pipelines; the WGSL they run and the data they upload
//! come from here, so the fur is the same in both and moving either host
//! to a new wgpu is a version bump, not a port.
//!
//! - [`groom`]: a groom grown on the GPU every frame: the compute shader
//!   and the arrays a host uploads for it;
//! - [`hair`]: real-time strands' ribbons and hair model in WGSL;
//! - [`shell`]: shell fur's math in WGSL, the strand frame's tangents and
//!   the shell texture's mip chain;
//! - [`stand_in`]: the shell fur that stands in for a groom far away.

pub mod groom;
pub mod hair;
pub mod shell;
pub mod stand_in;

/// Threads a workgroup of every compute shader (their
/// `@workgroup_size(64)`).
pub const WORKGROUP: u32 = 64;

/// Workgroups (x, y) covering `n` invocations of a compute shader: past
/// 65,535 along x, the shaders fold y into the index.
pub fn workgroups(n: u32) -> (u32, u32) {
    let groups = n.div_ceil(WORKGROUP).max(1);
    let x = groups.min(65_535);
    (x, groups.div_ceil(x))
}
