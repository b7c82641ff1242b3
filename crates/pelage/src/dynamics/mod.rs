//! Moving fur: mass-spring systems over the skin that move the shell
//! layers (Banisch & Wüthrich; Silva et al. §3.2.1), and guide strands
//! simulated with collisions (Müller et al. 2012).
//!
//! - [`system`]: the topologies — spring-sticks, separable spring-sticks,
//!   prisms, separable prisms (Banisch) and Silva's strands — built from a
//!   mesh, and the state of their masses.
//! - [`solver`]: forces (springs, Banisch's restoring force Eq. 5, gravity,
//!   gusting turbulent wind, a brush) and the explicit and implicit solvers.
//!
//! - [`strands`]: guide strands simulated on their own (Dynamic
//!   Follow-The-Leader with bending, follow and friction), and
//!   [`skin_sdf`], the posed skin as a signed-distance grid they collide
//!   with; [`guide_sim`]: a groom's guides simulated on an animated skin.
//!
//! The shell renderer reads [`MassSpringSystem::corner_tip_offsets`]: how
//! far each skin corner's strand tip has moved from rest.

pub mod guide_sim;
pub mod skin_sdf;
pub mod solver;
pub mod strands;
pub mod system;

pub use guide_sim::GuideSimulation;
pub use skin_sdf::SkinSdf;
pub use solver::{DynamicsParams, PushBrush, Solver, Wind, WindNow};
pub use strands::{GuideStrandParams, GuideStrands, MAX_STRAND_POINTS, RootFrame, StrandError};
pub use system::{MassSpringSystem, Topology};
