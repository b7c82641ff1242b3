//! Reading and writing curves and points. Every writer writes to a
//! temporary name beside the target and renames on success
//! ([`write_atomically`]), so an error or a kill never leaves a truncated
//! file under the real name.
//!
//! - [`read_curves`] / [`write_curves`]: curves by extension (`.usdc` and
//!   `.usd`, `.usda`, `.abc`, `.hair`, `.ply`; `.rib` and `.pbrt` write
//!   only).
//! - USD: [`UsdaWriter`] streams usda and [`UsdcWriter`] binary USD
//!   (BasisCurves per part, time samples, optional skin
//!   mesh); [`read_usd_curves`] reads usda and usdc (Blender's export too).
//! - Alembic: [`AbcWriter`] streams Ogawa curves; [`read_abc_curves`]
//!   reads them back.
//! - [`HairFile`]: Cem Yuksel's `.hair`, byte for byte.
//! - [`write_curves_ply`] / [`read_curves_ply`]: curves as PLY polylines.
//! - [`write_rib`] / [`write_pbrt`]: RenderMan and pbrt-v4 scene text.
//! - [`PointsPly`]: sampled points with normals, UVs and triangle indices.
//! - [`Mesh::load`](crate::Mesh::load) / [`Mesh::from_bytes`](crate::Mesh::from_bytes):
//!   a mesh by format (`mesh_file.rs`), here because USD meshes need the USD reader.

mod abc;
mod atomic;
pub(crate) use atomic::folder_of;
mod curves_file;
mod curves_ply;
mod hair;
mod hair_material;
pub use hair_material::MATERIAL_NAME as HAIR_MATERIAL_NAME;
mod mesh_file;
mod points_ply;
mod read_error;
mod render_text;
mod text;
mod usd_options;
mod usd_read;
mod usd_schema;
mod usda;
mod usdc;

pub use abc::{
    AbcCurvesObject, AbcWriter, abc_curves_from_bytes, read_abc_curves, read_abc_curves_at,
    read_abc_description, read_abc_objects, read_abc_sample_count,
};
pub use atomic::{
    AtomicFile, check_free_space, check_input, check_output, check_writable, note_input,
    protect_inputs, remove_temporary_files, write_atomically, write_atomically_with,
};
pub use curves_file::{
    CurvesExport, CurvesFormat, read_curves, read_curves_and_sample_count, write_curves,
    write_streamed,
};
pub use curves_ply::{read_curves_ply, write_curves_ply};
pub use hair::{HairFile, HairWriteError};
pub(crate) use mesh_file::usd_mesh_error;
pub use points_ply::{
    PointsPly, ply_element_count, ply_has_faces, read_points_ply, write_points_ply,
};
pub use read_error::{CurvesReadError, CurvesReadErrorKind};
pub use render_text::{bezier_control_points, write_pbrt, write_rib};
pub use usd_options::{CurveBasis, PrimWriteError, UpAxis, UsdOptions, UsdWrap};
pub use usd_read::{
    UsdCurvesSequence, UsdLayerInfo, read_usd_curves, read_usd_curves_at, read_usd_extent,
    read_usd_layer_info, usd_curves_from_bytes,
};
pub(crate) use usd_read::{UsdSkin, read_usd_skin, usd_skin_from_bytes};
pub(crate) use usd_schema::curve_extent;
pub use usd_schema::{PrimWriter, SurfacePoints};
pub use usda::UsdaWriter;
pub(crate) use usda::asset_path;
pub use usdc::UsdcWriter;

use std::path::PathBuf;

/// A file could not be written. Names the file and says what went wrong
/// (in its message, so a cause chain does not repeat it).
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {error}", path.display())]
pub struct WriteError {
    /// The file that was being written.
    pub path: PathBuf,
    /// What went wrong.
    pub error: std::io::Error,
}
