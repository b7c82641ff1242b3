//! Ceilings on the counts and sizes pelage reads from files and flags.
//!
//! A number in a groom file, a scene or on the command line decides how
//! much memory and time a run takes. Without a ceiling, a typo such as
//! `count = 1000000000000` or `subdivide = 20` runs until the allocator
//! aborts the process or the machine stops answering. Each ceiling here is
//! checked when the value is read, and the error names the key, the value
//! and the ceiling. docs/limits.md lists them with the memory behind each
//! and how to raise one (change the constant and rebuild).
//!
//! The ceilings are far above what a production asset needs, and are set
//! so that work at the ceiling fits a 64 GB workstation (or, where output
//! streams to disk part by part, the disk: see
//! [`crate::io::check_free_space`]).

/// Hairs in one groom (`[roots] count`, times `strands`). Grooms stream
/// to their output part by part, so this bounds the run time and the file,
/// not the memory: a billion hairs of 16 points is 190 GB of positions.
pub const MAX_HAIRS: u64 = 1_000_000_000;

/// Points in one curve (`[finish] points`, `[guides] points`). Production
/// hair has 4 to 64; a curve of this many points is already a rope.
pub const MAX_CURVE_POINTS: u64 = 4096;

/// Guide curves grown or read (`[guides] generate.count`, `pelage guides
/// -n`). Guides are held in memory with a kd-tree over their roots.
pub const MAX_GUIDES: u64 = 10_000_000;

/// Clumps of one clump operator. Each clump's centre hair is grown and held
/// in memory while the groom grows (10 M centres of 16 points: 2 GB).
pub const MAX_CLUMPS: u64 = 10_000_000;

/// Hairs a `strands` operator makes of each hair.
pub const MAX_STRANDS: u64 = 1024;

/// Parts of a groom (`[roots] parts`): each part is a task and a file.
pub const MAX_PARTS: u64 = 1_000_000;

/// Points `pelage sample` places: they are held in memory (about 60 bytes
/// each with their normals, UVs and triangles: 12 GB at the ceiling).
pub const MAX_SAMPLE_POINTS: u64 = 200_000_000;

/// Points `pelage sample --distribution blue-noise` (and Python's
/// `sample(distribution="blue-noise")`) thins to at once: the whole set is
/// thinned together, two candidates a point, each with its position,
/// radius, cell and order: about 200 bytes a point kept (4 GB at the
/// ceiling).
pub const MAX_BLUE_NOISE_POINTS: u64 = 20_000_000;

/// Triangles of a mesh after `subdivide` (each step makes four of one). A
/// mesh costs about 100 bytes a triangle with its topology and sampler.
pub const MAX_TRIANGLES: u64 = 100_000_000;

/// Midpoint subdivision steps (`[mesh] subdivide`): 12 steps make 16
/// million triangles of each one.
pub const MAX_SUBDIVIDE: u64 = 12;

/// Pixels of an image read as a map or texture: 64 M (8192 × 8192). A map
/// holds 4 bytes a texel and decoding needs up to 16 more.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// Frames of a sequence (`[animation] frames`, `--frames`): over an hour at
/// 24 fps. Each frame is a file.
pub const MAX_FRAMES: u64 = 100_000;

/// Dynamics steps per frame (`steps_per_frame`), explicit substeps per step
/// (`substeps`) and conjugate-gradient iterations (`iterations`): each is
/// a pass over every spring, so each multiplies the frame time.
pub const MAX_DYNAMICS_STEPS: u64 = 1000;

/// Conjugate-gradient iterations of the implicit solver per step.
pub const MAX_SOLVER_ITERATIONS: u64 = 10_000;

/// Random droplets of one `[[droplets]]` table (each is stamped into the
/// mask in turn).
pub const MAX_DROPLETS: u64 = 1_000_000;

/// Texels per side of a generated texture or wetness mask.
pub const MAX_TEXTURE_SIDE: u64 = 4096;

/// Texels of a shell texture, `resolution² × layers` (4 bytes each, on
/// the CPU while it is generated and on the GPU: 1 GB at the ceiling,
/// e.g. 2048² × 64 or 4096² × 16).
pub const MAX_SHELL_TEXELS: u64 = 1 << 28;

/// Pixels per side of a rendered image (further bounded by the GPU's own
/// texture limit, which the renderer checks).
pub const MAX_IMAGE_SIDE: u64 = 16384;

/// Bytes of one name read from a file (a USD token used as a path
/// element, an Alembic object or property name). Real names are tens of
/// bytes; a path is built of them level by level.
pub const MAX_NAME_BYTES: usize = 4096;

/// Bytes of one object or prim path read from a file. Without it, a
/// chain of long names nested deep builds a path per level, each longer
/// than the last (quadratic memory: a 60,000-deep chain under a 2 KB name
/// is 3.6 TB of path text).
pub const MAX_PATH_BYTES: usize = 65_536;

/// Values decoded from one USD or Alembic file, in all: this floor plus
/// [`DECODED_BYTES_PER_FILE_BYTE`] times the file's size. A file's
/// counts are each checked against the bytes that remain, but compressed
/// integers (two bits a value, then LZ4) and arrays that many fields share
/// decode to far more than the file holds; past this budget the read is an
/// error instead of an allocation the machine cannot make.
pub const DECODED_BYTES_FLOOR: u64 = 1 << 30;

/// See [`DECODED_BYTES_FLOOR`]: plain arrays decode to about their own
/// size, so a file's real values stay well inside eight times its size.
pub const DECODED_BYTES_PER_FILE_BYTE: u64 = 8;

/// Pixels of all the tiles of one UDIM map together (each tile is
/// further bounded by [`MAX_IMAGE_PIXELS`]): 256 M, 1 GB of texels.
pub const MAX_UDIM_PIXELS: u64 = 1 << 28;

/// The largest collision thickness of simulated guides, as a share of
/// the skin's size (its bounding box's longest side): the skin's distance
/// grid reaches that far past the surface, so a thickness of many sizes
/// asks for a grid of billions of cells. The default is 0.2 %.
pub const MAX_THICKNESS_OF_SKIN: f32 = 0.1;

/// Frame files a run keeps open at once while it writes an animation as
/// one file a frame; the rest wait, so a long range stays under the usual
/// limit of 1,024 open files.
pub const MAX_OPEN_FRAME_FILES: usize = 64;

/// A count refused by [`check_count`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CountError {
    /// Zero where at least one is needed.
    #[error("0 {what}: use at least 1")]
    Zero {
        /// What is counted.
        what: String,
    },
    /// More than pelage's limit.
    #[error(
        "{} {what} is more than pelage's limit of {} (docs/limits.md says why and how to raise it)",
        grouped(*value as f64),
        grouped(*max as f64)
    )]
    OverLimit {
        /// The count.
        value: u64,
        /// The limit.
        max: u64,
        /// What is counted.
        what: String,
    },
}

/// A count that must lie in `1..=max` (or `0..=max` when `zero_ok`);
/// the error says what is wrong without naming the setting, which the
/// caller adds ("roots.count: …").
pub fn check_count(value: u64, max: u64, zero_ok: bool, what: &str) -> Result<(), CountError> {
    if value == 0 && !zero_ok {
        return Err(CountError::Zero { what: what.into() });
    }
    if value > max {
        return Err(CountError::OverLimit {
            value,
            max,
            what: what.into(),
        });
    }
    Ok(())
}

/// A number for messages: integers with thousands separators
/// (`1,000,000`), other values as Rust prints them.
pub fn grouped(v: f64) -> String {
    if v.fract() != 0.0 || !v.is_finite() || v.abs() >= 1e21 {
        return v.to_string();
    }
    let digits = format!("{}", v.abs() as u128);
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    if v < 0.0 {
        out.insert(0, '-');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_over_the_ceiling_name_it() {
        assert!(check_count(10, 10, false, "hairs").is_ok());
        let err = check_count(11, 10, false, "hairs").unwrap_err();
        assert!(
            matches!(
                err,
                CountError::OverLimit {
                    value: 11,
                    max: 10,
                    ..
                }
            ),
            "{err}"
        );
        assert!(
            err.to_string()
                .starts_with("11 hairs is more than pelage's limit of 10"),
            "{err}"
        );
        let zero = check_count(0, 10, false, "hairs").unwrap_err();
        assert!(matches!(zero, CountError::Zero { .. }));
        assert_eq!(zero.to_string(), "0 hairs: use at least 1");
        assert!(check_count(0, 10, true, "steps").is_ok());
    }

    #[test]
    fn numbers_are_grouped_by_thousands() {
        assert_eq!(grouped(1e9), "1,000,000,000");
        assert_eq!(grouped(-1234.0), "-1,234");
        assert_eq!(grouped(12.0), "12");
        assert_eq!(grouped(0.5), "0.5");
    }
}
