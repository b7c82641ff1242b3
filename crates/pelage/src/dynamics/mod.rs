//! Moving fur: mass-spring systems over the skin that move the shell
//! layers (Banisch & Wüthrich; Silva et al. §3.2.1).
//!
//! - [`system`]: the topologies — spring-sticks, separable spring-sticks,
//!   prisms, separable prisms (Banisch) and Silva's strands — built from a
//!   mesh, and the state of their masses.
//! - [`solver`]: forces (springs, Banisch's restoring force Eq. 5, gravity,
//!   gusting turbulent wind, a brush) and the explicit and implicit solvers.
//!
//! The shell renderer reads [`MassSpringSystem::corner_tip_offsets`]: how
//! far each skin corner's strand tip has moved from rest.

pub mod solver;
pub mod system;

pub use solver::{Brush, DynamicsParams, Solver, Wind, WindNow};
pub use system::{MassSpringSystem, Topology};
