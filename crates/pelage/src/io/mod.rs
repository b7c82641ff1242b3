//! Writing what pelage makes: files are written to a temporary name beside
//! the target and renamed on success ([`write_atomically`]), so an error or
//! a kill never leaves a truncated file under the real name.
//!
//! Writers so far: [`PointsPly`] (sampled points with normals, UVs and
//! triangle indices).

mod atomic;
mod points_ply;

pub use atomic::write_atomically;
pub use points_ply::{PointsPly, ply_has_faces, read_points_ply, write_points_ply};

use std::path::PathBuf;

/// A file could not be written. Names the file.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {source}", path.display())]
pub struct WriteError {
    /// The file that was being written.
    pub path: PathBuf,
    /// What went wrong.
    #[source]
    pub source: std::io::Error,
}
