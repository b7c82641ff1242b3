//! Writing a groom: parts stream to the writer as they are grown (docs/design.md,
//! "Streaming"), and a farm's per-part files are tied together by a small
//! root USD layer ([`write_assembly`]) or, Alembic having no references,
//! joined into one archive ([`write_alembic_assembly`]).

use super::error::GroomError;
use super::generator::{Generator, GroomSummary};
use crate::curves::Curves;
use crate::io::{
    AbcWriter, CurvesExport, CurvesFormat, PrimWriteError, PrimWriter, UpAxis, UsdOptions,
    UsdaWriter, WriteError, read_abc_objects, read_usd_extent, write_atomically,
    write_atomically_with, write_curves, write_streamed,
};
use crate::mesh::Mesh;
use glam::Vec3;
use std::io::{BufRead, Write};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// The parts run `k` of `n` (1-based `k`) grows: a contiguous slice of the
/// layout, so the `n` runs together grow every part exactly once, in order.
pub fn part_slice(k: usize, n: usize, parts: usize) -> Range<usize> {
    debug_assert!((1..=n).contains(&k));
    (k - 1) * parts / n..k * parts / n
}

/// The prim name of part `p` (global index, so files of separate runs
/// never collide).
pub fn part_name(p: usize) -> String {
    format!("part_{p:04}")
}

/// The file run `k` of `n` writes beside `output`: `groom.usda` →
/// `groom.part-3-of-8.usda`.
pub fn part_file(output: &Path, k: usize, n: usize) -> PathBuf {
    let stem = output
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("groom");
    let ext = output
        .extension()
        .and_then(|s| s.to_str())
        .unwrap_or("usda");
    output.with_file_name(format!("{stem}.part-{k}-of-{n}.{ext}"))
}

impl Generator {
    /// Grows `parts` and writes them to `path` (format by extension),
    /// atomically. USD streams: a part is written while the next one grows,
    /// so memory holds about two parts whatever the groom's size. Other
    /// formats need every curve at once and join the parts first.
    /// `on_part(p, curves)` is called as each part is done.
    ///
    /// # Errors
    /// A hair that grew values that are not finite (the file is then not
    /// written), or a file that cannot be written.
    pub fn write(
        &self,
        path: &Path,
        parts: Range<usize>,
        export: &CurvesExport,
        on_part: impl FnMut(usize, &Curves) + Send,
    ) -> Result<GroomSummary, GroomWriteError> {
        self.write_until(path, parts, export, &AtomicBool::new(false), on_part)
    }

    /// [`Self::write`] that stops between parts once `cancel` is set (by
    /// `on_part`, or another thread: a front end's Ctrl-C). The output is
    /// then left as it was before the write, and the error is
    /// [`GroomWriteError::Cancelled`].
    pub fn write_until(
        &self,
        path: &Path,
        parts: Range<usize>,
        export: &CurvesExport,
        cancel: &AtomicBool,
        on_part: impl FnMut(usize, &Curves) + Send,
    ) -> Result<GroomSummary, GroomWriteError> {
        self.write_grown_until(path, parts, export, cancel, &|p| self.part(p), on_part)
    }

    /// [`Self::write_until`] with each part grown by `grow` instead of
    /// [`Self::part`]: another evaluator of this groom (the GPU's, which
    /// hands its hairs to [`Self::part_from_grown`]).
    pub fn write_grown_until(
        &self,
        path: &Path,
        parts: Range<usize>,
        export: &CurvesExport,
        cancel: &AtomicBool,
        grow: PartGrower<'_>,
        mut on_part: impl FnMut(usize, &Curves) + Send,
    ) -> Result<GroomSummary, GroomWriteError> {
        let mut summary = GroomSummary::default();
        let mut count = |c: &Curves| {
            summary.hairs += c.curve_count() as u64;
            summary.points += c.points().len() as u64;
        };
        let format = CurvesFormat::from_path(path);
        let streamed = format.is_some_and(CurvesFormat::streams_parts);
        if !streamed {
            let mut grown = Vec::new();
            for p in parts {
                let curves = grow(p)?;
                on_part(p, &curves);
                if cancel.load(Ordering::Relaxed) {
                    return Err(GroomWriteError::Cancelled);
                }
                count(&curves);
                if curves.curve_count() > 0 {
                    grown.push((part_name(p), curves));
                }
            }
            write_curves(path, grown.iter().map(|(n, c)| (n.clone(), c)), export)?;
            return Ok(summary);
        }
        write_atomically_with(path, |out| {
            let on_part = |p, c: &Curves| {
                on_part(p, c);
                count(c);
            };
            let format = format.expect("a streamed format");
            write_streamed(out, format, &export.usd, |layer| {
                self.stream_parts(layer, parts, export, (cancel, grow), on_part)
            })
        })
        .map_err(|e| e.at(path))?;
        Ok(summary)
    }

    /// Grows `parts` and streams them as USD text to `out`, one part
    /// written while the next grows (memory: about two parts). A part that
    /// cannot grow ([`Generator::part`]) stops the stream with its
    /// [`GroomError`].
    ///
    /// ```
    /// use pelage::groom::{GroomSpec, RootsSpec};
    /// use pelage::guides::{GuideGrowth, Guides};
    /// use pelage::io::CurvesExport;
    /// use std::sync::Arc;
    ///
    /// let mesh = Arc::new(pelage::assets::spot());
    /// let guides = Guides::grow(&mesh, &GuideGrowth { count: 20, ..Default::default() })?;
    /// let generator = GroomSpec::new(mesh, guides, RootsSpec::new(500)).generator()?;
    /// let mut usda = Vec::new();
    /// let parts = 0..generator.parts().len();
    /// generator.write_usd(&mut usda, parts, &CurvesExport::default(), |_, _| {})?;
    /// let text = String::from_utf8(usda)?;
    /// assert!(text.starts_with("#usda 1.0"));
    /// assert!(text.contains("int[] curveVertexCounts"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn write_usd(
        &self,
        out: impl Write,
        parts: Range<usize>,
        export: &CurvesExport,
        on_part: impl FnMut(usize, &Curves) + Send,
    ) -> Result<(), StreamError> {
        let mut usd = UsdaWriter::new(out, &export.usd)?;
        let never = AtomicBool::new(false);
        self.stream_parts(
            &mut usd,
            parts,
            export,
            (&never, &|p| self.part(p)),
            on_part,
        )?;
        usd.finish()?;
        Ok(())
    }

    /// Writes the skin (if exported), then grows `parts` with `grow` on a
    /// second thread and writes each as it arrives, stopping once `cancel`
    /// is set.
    fn stream_parts(
        &self,
        usd: &mut dyn PrimWriter,
        parts: Range<usize>,
        export: &CurvesExport,
        (cancel, grow): (&AtomicBool, PartGrower<'_>),
        mut on_part: impl FnMut(usize, &Curves) + Send,
    ) -> Result<(), StreamError> {
        if let Some(mesh) = export.mesh {
            usd.write_mesh("skin", mesh)?;
        }
        if let Some(guides) = &export.guides {
            usd.write_guides("guides", guides)?;
        }
        std::thread::scope(|scope| {
            type Grown = (usize, Result<Curves, GroomError>);
            let (send, receive) = std::sync::mpsc::sync_channel::<Grown>(1);
            let grower = scope.spawn(move || {
                for p in parts {
                    let part = grow(p);
                    let failed = part.is_err();
                    if send.send((p, part)).is_err() || failed {
                        break; // the writer failed and hung up, or we did
                    }
                }
            });
            for (p, curves) in receive {
                let curves = curves?;
                // A part that grew no hair (more parts than hairs, or a
                // bald region) is left out: USD has no empty BasisCurves.
                if curves.curve_count() > 0 {
                    usd.write_part(&part_name(p), &curves)?;
                }
                on_part(p, &curves);
                self.recycle(curves);
                if cancel.load(Ordering::Relaxed) {
                    // Hanging up stops the grower at its next part.
                    return Err(StreamError::Cancelled);
                }
            }
            grower.join().expect("the part grower does not panic");
            Ok::<(), StreamError>(())
        })
    }
}

/// Grows part `p` of a groom: [`Generator::part`], or another evaluator
/// of the same groom (the GPU's).
pub type PartGrower<'a> = &'a (dyn Fn(usize) -> Result<Curves, GroomError> + Sync);

/// A groom could not be streamed into a layer: a part did not grow, the
/// writer refused a prim, or the file itself failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StreamError {
    /// A hair could not be grown (the error names the groom file's line).
    #[error(transparent)]
    Groom(#[from] GroomError),
    /// The writer refused a prim, or writing it failed.
    #[error(transparent)]
    Prim(#[from] PrimWriteError),
    /// The output file could not be created, synced or renamed.
    #[error(transparent)]
    File(#[from] WriteError),
    /// The write was cancelled between parts.
    #[error("the write was cancelled")]
    Cancelled,
}

impl StreamError {
    /// As a [`GroomWriteError`] of the file at `path`.
    fn at(self, path: &Path) -> GroomWriteError {
        match self {
            StreamError::Groom(e) => GroomWriteError::Groom(e),
            StreamError::File(e) => GroomWriteError::Write(e),
            StreamError::Cancelled => GroomWriteError::Cancelled,
            StreamError::Prim(e) => GroomWriteError::Write(WriteError {
                path: path.to_path_buf(),
                error: e.into(),
            }),
        }
    }
}

/// A groom could not be written.
#[derive(Debug, thiserror::Error)]
pub enum GroomWriteError {
    /// A hair could not be grown (the error names the groom file's line).
    #[error(transparent)]
    Groom(#[from] GroomError),
    /// The output could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The write was cancelled (`write_until`): the output is as it was.
    #[error("the write was cancelled; the output is left as it was")]
    Cancelled,
}

/// Writes a root USD layer at `path` that references every part file (each
/// a stage whose default prim holds that run's parts) with its extent, so a
/// renderer loads the whole groom through USD composition. Extents are read
/// from the part files (pelage writes one per prim); a missing part file is
/// an error naming it.
pub fn write_assembly(
    path: &Path,
    part_files: &[PathBuf],
    options: &UsdOptions,
) -> Result<(Vec3, Vec3), WriteError> {
    // Named after the layer being written, the message after the file at
    // fault (a part file that cannot be read, or the layer's own name).
    let fail = |file: &Path, message: String| WriteError {
        path: path.to_path_buf(),
        error: std::io::Error::other(if file == path {
            message
        } else {
            format!("{}: {message}", file.display())
        }),
    };
    if CurvesFormat::from_path(path) != Some(CurvesFormat::Usda) {
        return Err(fail(
            path,
            "the assembly layer is text USD: name it .usda (its part files may be .usdc)".into(),
        ));
    }
    let mut extents = Vec::with_capacity(part_files.len());
    for file in part_files {
        let binary = std::fs::File::open(file)
            .and_then(|mut f| {
                let mut head = [0u8; 8];
                let n = std::io::Read::read(&mut f, &mut head)?;
                Ok(head[..n] == *b"PXR-USDC")
            })
            .map_err(|e| fail(file, format!("cannot read the part file: {e}")))?;
        if binary {
            // The reader's error names the part file; it travels typed.
            let bounds = read_usd_extent(file).map_err(|e| WriteError {
                path: path.to_path_buf(),
                error: std::io::Error::other(e),
            })?;
            extents.push(bounds);
            continue;
        }
        let reader = std::fs::File::open(file)
            .map(std::io::BufReader::new)
            .map_err(|e| fail(file, format!("cannot read the part file: {e}")))?;
        let mut bounds: Option<(Vec3, Vec3)> = None;
        // A part file cut short (a run killed while copying it, a full
        // disk) or not USD at all must not be referenced as if whole: its
        // extent would be silently missing from the assembly's.
        let (mut header, mut depth, mut lines) = (false, 0i64, 0usize);
        for line in reader.lines() {
            let line = line.map_err(|e| fail(file, format!("cannot read the part file: {e}")))?;
            if lines == 0 {
                header = line.starts_with("#usda ");
            }
            lines += 1;
            let mut quoted = false;
            for c in line.chars() {
                match c {
                    '"' => quoted = !quoted,
                    '{' | '(' if !quoted => depth += 1,
                    '}' | ')' if !quoted => depth -= 1,
                    _ => {}
                }
            }
            let Some(values) = line.trim_start().strip_prefix("float3[] extent = ") else {
                continue;
            };
            let numbers: Vec<f32> = values
                .split(|c: char| !(c.is_ascii_digit() || "-+.eE".contains(c)))
                .filter(|s| !s.is_empty())
                .filter_map(|s| s.parse().ok())
                .collect();
            if let [a, b, c, d, e, f] = numbers[..] {
                let (lo, hi) = (Vec3::new(a, b, c), Vec3::new(d, e, f));
                bounds = Some(match bounds {
                    Some((l, h)) => (l.min(lo), h.max(hi)),
                    None => (lo, hi),
                });
            }
        }
        if !header {
            return Err(fail(
                file,
                "not a USD part file (it does not start with `#usda`); grow its run again".into(),
            ));
        }
        if depth != 0 {
            return Err(fail(
                file,
                format!(
                    "the part file is incomplete (cut short after {lines} lines); grow its run again"
                ),
            ));
        }
        // A run whose parts all grew nothing has no prims and no extent;
        // it is still referenced, so the layer lists every run.
        extents.push(bounds);
    }
    let whole = extents
        .iter()
        .flatten()
        .copied()
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
        .unwrap_or((Vec3::ZERO, Vec3::ZERO));
    let folder = path.parent().unwrap_or(Path::new(""));
    write_atomically(path, |out| {
        let t = |v: Vec3| format!("({}, {}, {})", v.x, v.y, v.z);
        writeln!(
            out,
            "#usda 1.0\n(\n    defaultPrim = \"{root}\"\n    doc = \"Written by pelage {}: the parts of a groom, one reference a part file\"\n    metersPerUnit = {}\n    upAxis = \"{}\"\n)\n\ndef Xform \"{root}\"\n{{\n    float3[] extentsHint = [{}, {}]",
            env!("CARGO_PKG_VERSION"),
            ryu::Buffer::new().format(options.meters_per_unit),
            match options.up_axis {
                UpAxis::Y => "Y",
                UpAxis::Z => "Z",
            },
            t(whole.0),
            t(whole.1),
            root = options.root,
        )?;
        for (k, (file, bounds)) in part_files.iter().zip(&extents).enumerate() {
            // Reference by path relative to the root layer when possible.
            let shown = file
                .strip_prefix(folder)
                .map(|p| format!("./{}", p.display()))
                .unwrap_or_else(|_| file.display().to_string());
            let hint = match bounds {
                Some((lo, hi)) => {
                    format!("\n        float3[] extentsHint = [{}, {}]", t(*lo), t(*hi))
                }
                None => String::new(),
            };
            writeln!(
                out,
                "\n    def Xform \"run_{:04}\" (\n        prepend references = {}\n    )\n    {{{hint}\n    }}",
                k + 1,
                crate::io::asset_path(&shown),
            )?;
        }
        writeln!(out, "}}")
    })?;
    Ok(whole)
}

/// Joins a farm's Alembic part files into one archive at `path`: the skin
/// first when given, then every run's guides (run 1 writes them) and part
/// objects in run order, read back and written again — the archive one
/// run writes, byte for byte.
/// One part file is in memory at a time. Returns the groom's extent.
pub fn write_alembic_assembly(
    path: &Path,
    part_files: &[PathBuf],
    options: &UsdOptions,
    skin: Option<&Mesh>,
) -> Result<(Vec3, Vec3), WriteError> {
    let fail = |message: String| WriteError {
        path: path.to_path_buf(),
        error: std::io::Error::other(message),
    };
    if !CurvesFormat::from_path(path).is_some_and(CurvesFormat::assembly_joins_parts) {
        return Err(fail(
            "Alembic part files are joined into an Alembic file: name it .abc".into(),
        ));
    }
    let mut whole: Option<(Vec3, Vec3)> = None;
    write_atomically(path, |out| {
        let other = |e: PrimWriteError| std::io::Error::other(e);
        let mut abc = AbcWriter::new(out, options).map_err(other)?;
        if let Some(mesh) = skin {
            abc.write_mesh("skin", mesh).map_err(other)?;
        }
        for file in part_files {
            let objects = read_abc_objects(file).map_err(std::io::Error::other)?;
            // Guides (run 1's) first, as one run writes them before its parts.
            let (guides, hairs): (Vec<_>, Vec<_>) = objects.into_iter().partition(|o| o.2);
            for (name, curves, _) in &guides {
                abc.write_guides(name, curves).map_err(other)?;
            }
            for (name, curves, _) in &hairs {
                let (lo, hi) = crate::io::curve_extent(curves);
                whole = Some(whole.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
                abc.write_part(name, curves).map_err(other)?;
            }
        }
        abc.finish().map_err(other)?;
        Ok(())
    })?;
    Ok(whole.unwrap_or((Vec3::ZERO, Vec3::ZERO)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn part_slices_tile_the_layout_for_any_run_count() {
        for parts in [1, 5, 16, 17] {
            for n in 1..=parts {
                let mut next = 0;
                for k in 1..=n {
                    let r = part_slice(k, n, parts);
                    assert_eq!(r.start, next);
                    next = r.end;
                }
                assert_eq!(next, parts);
            }
        }
        assert_eq!(
            part_file(Path::new("out/groom.usda"), 3, 8),
            Path::new("out/groom.part-3-of-8.usda")
        );
    }
}
