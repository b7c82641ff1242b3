//! pelage: a fur toolkit.
//!
//! This crate is the library: everything that is not GPU, window or command
//! line. It is organised by concept, one folder a layer:
//!
//! - [`mesh`]: the surface hair grows on: [`Mesh`], [`SurfacePoint`], loaders
//!   (OBJ, PLY, glTF), topology and midpoint subdivision.
//! - [`map`]: [`Map`], a scalar field over UV (constant, image, noise). Every
//!   groom parameter is a map (Sik, section 4: "every user parameter … is
//!   also specified by a texture").
//! - [`sample`]: hair roots: points distributed by a density map (Sik §3),
//!   deterministic by `(seed, index)`.
//! - [`nearest`]: the k nearest of a fixed point set (kd-tree plus exact
//!   candidate lists for coherent queries): guide roots, clump centres.
//! - [`curves`]: [`Curves`], hair curves as structure of arrays with an
//!   offsets array (Blender's `CurvesGeometry`, USD `BasisCurves`).
//! - [`guides`]: [`guides::Guides`], artist guide curves bound to the mesh
//!   (from a file, with a report of what was left out, or grown).
//! - [`interp`]: guide interpolation — Shepard over a kd-tree (Sik §4.2.2)
//!   and the style mesh (Furtility).
//! - [`groom`]: the groom generator: groom files (TOML), operators
//!   (one module each: noise, frizz, clump, curl, cut, length, strands,
//!   width, colour, opacity, twist, flyaways), parts, deterministic
//!   generation (Sik §4), animated grooms and farm output.
//! - [`anim`]: animated skins (USD time samples, OBJ/PLY sequences, glTF
//!   clips through [`anim::SkinRig`]) and hairs bound to them at rest.
//! - [`dynamics`]: mass-spring systems for shell fur (Banisch, Silva):
//!   four topologies, explicit and implicit solvers, wind and brushes.
//! - [`shell`]: shell fur — shell textures (Banisch), the wetness mask and
//!   the curl / clump / Kajiya-Kay reference math (Silva) that the GPU
//!   shaders mirror, and shell scene files.
//! - [`io`]: curves and points in and out (USD usda and usdc, Alembic,
//!   .hair, PLY, RIB, pbrt), every writer atomic (temporary file, then
//!   rename).
//! - [`settings`]: TOML settings files read with every error at its line
//!   and key, and numbers checked against documented ranges.
//! - [`limits`]: every ceiling on a count or size read from a file.
//! - [`assets`]: the embedded demo mesh (Spot), so every command works with
//!   no files at hand.
//!
//! The library never prints. Every fallible call returns a typed error that
//! names the file (or mesh) and, where there is one, the line or element.
#![warn(missing_docs)]

pub mod anim;
pub mod assets;
pub mod curves;
#[cfg(test)]
mod docs_tests;
pub mod dynamics;
pub mod error;
pub mod groom;
pub mod guides;
pub mod interp;
pub mod io;
pub mod limits;
pub mod map;
pub mod mesh;
pub mod nearest;
pub mod sample;
pub mod settings;
pub mod shell;

pub use curves::Curves;
pub use map::{Map, MapError};
pub use mesh::{Mesh, MeshError, SurfacePoint, TangentFrame};
