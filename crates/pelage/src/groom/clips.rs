//! Animated grooms in many files, stitched back into one stage with USD
//! value clips: one file a frame (`--frame-files`, the layout of large
//! caches) or one file a farm task (a run of the parts × a range of
//! frames). The stitching layer is small text USD: each prim of the groom
//! is an `over` that references its first file (for the prim, its
//! topology and everything that does not move) and takes its time samples
//! from the clips, each active from its file's first time code.

use super::output::part_file;
use crate::anim::FrameRange;
use crate::io::asset_path;
use crate::io::{UsdLayerInfo, WriteError, read_usd_layer_info, write_atomically};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The file that holds frames `first..=last` of `output`, written by farm
/// run `run` (`Some((k, n))`) or by one process: `groom.usdc` →
/// `groom.part-2-of-4.f0001-0012.usdc`, `groom.f0007.usdc`.
pub fn frames_file(output: &Path, run: Option<(usize, usize)>, first: i32, last: i32) -> PathBuf {
    let base = match run {
        Some((k, n)) => part_file(output, k, n),
        None => output.to_path_buf(),
    };
    let stem = base
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("groom")
        .to_string();
    let ext = base
        .extension()
        .and_then(|s| s.to_str())
        .unwrap_or("usdc")
        .to_string();
    let frames = if first == last {
        format!("f{first:04}")
    } else {
        format!("f{first:04}-{last:04}")
    };
    base.with_file_name(format!("{stem}.{frames}.{ext}"))
}

/// A file of an animated groom split by frames, as found beside the
/// output.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameFile {
    /// The file.
    pub path: PathBuf,
    /// The farm run that wrote it (1-based) and of how many; `(1, 1)` for
    /// one process.
    pub run: (usize, usize),
    /// The frames it holds.
    pub first: i32,
    /// The last of them.
    pub last: i32,
}

/// Every `STEM[.part-K-of-N].fA[-B].EXT` beside `output` (STEM its file
/// stem), sorted by run and frame.
pub fn find_frame_files(output: &Path) -> std::io::Result<Vec<FrameFile>> {
    let folder = crate::io::folder_of(output);
    let stem = output.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let mut found = Vec::new();
    for entry in std::fs::read_dir(folder)? {
        let name = entry?.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(rest) = name.strip_prefix(stem).and_then(|r| r.strip_prefix('.')) else {
            continue;
        };
        let mut fields: Vec<&str> = rest.split('.').collect();
        // Value clips are USD: Alembic frame files cannot be stitched.
        if fields.len() < 2 || !matches!(fields.pop(), Some("usdc" | "usd")) {
            continue;
        }
        let run = match fields.as_slice() {
            [part, _] => {
                let Some((k, n)) = part
                    .strip_prefix("part-")
                    .and_then(|p| p.split_once("-of-"))
                    .and_then(|(k, n)| Some((k.parse().ok()?, n.parse().ok()?)))
                else {
                    continue;
                };
                (k, n)
            }
            [_] => (1, 1),
            _ => continue,
        };
        let Some(frames) = fields.last().and_then(|f| f.strip_prefix('f')) else {
            continue;
        };
        let Some((first, last)) = frame_span(frames) else {
            continue;
        };
        found.push(FrameFile {
            path: folder.join(name),
            run,
            first,
            last,
        });
    }
    found.sort_by_key(|f| (f.run, f.first));
    Ok(found)
}

/// The frames of a file name's `fA` or `fA-B` field (without the `f`):
/// either may be negative (`f-003`, `f-003-0004`, `f-010--001`), so the
/// range's `-` is the first one after the first character.
fn frame_span(frames: &str) -> Option<(i32, i32)> {
    let split = frames
        .char_indices()
        .skip(1)
        .find(|&(_, c)| c == '-')
        .map(|(i, _)| i);
    match split {
        Some(i) => Some((frames[..i].parse().ok()?, frames[i + 1..].parse().ok()?)),
        None => frames.parse().ok().map(|f| (f, f)),
    }
}

/// What [`write_clip_assembly`] tied together.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipAssembly {
    /// Farm runs (1 for one process).
    pub runs: usize,
    /// Files stitched.
    pub files: usize,
    /// Prims of the groom (parts, and the skin if written).
    pub prims: usize,
    /// The first and last time codes.
    pub time_range: (f64, f64),
}

/// Writes `path` (text USD): the groom of `files` over `frames`, every
/// prim stitched from its files with value clips. Every frame must be in
/// exactly one file of each run, and the runs must be all `N` of one farm.
pub fn write_clip_assembly(
    path: &Path,
    files: &[FrameFile],
    frames: &FrameRange,
) -> Result<ClipAssembly, WriteError> {
    let fail = |file: &Path, message: String| WriteError {
        path: file.to_path_buf(),
        error: std::io::Error::other(message),
    };
    if path.extension().and_then(|e| e.to_str()) != Some("usda") {
        return Err(fail(
            path,
            "the stitching layer is text USD: name it .usda (its frame files are .usdc)".into(),
        ));
    }
    let Some(first) = files.first() else {
        return Err(fail(path, "no frame files to stitch".into()));
    };
    let n = first.run.1;
    if let Some(other) = files.iter().find(|f| f.run.1 != n) {
        return Err(fail(
            &other.path,
            format!(
                "frame files of two different farms (of {n} runs and of {})",
                other.run.1
            ),
        ));
    }
    // Per run: its files in frame order, covering every frame once.
    let mut runs: Vec<Vec<(&FrameFile, UsdLayerInfo)>> = Vec::with_capacity(n);
    for k in 1..=n {
        runs.push(run_files(path, files, frames, (k, n))?);
    }
    let head = &runs[0][0].1;
    let (mut start, mut end) = (f64::INFINITY, f64::NEG_INFINITY);
    for (f, info) in runs.iter().flatten() {
        let (a, b) = info.time_range.ok_or_else(|| {
            fail(
                &f.path,
                "it has no startTimeCode/endTimeCode: not an animated groom file".into(),
            )
        })?;
        start = start.min(a);
        end = end.max(b);
    }
    let (text, prims) = clip_layer(&runs, head, (start, end));
    write_atomically(path, |out| std::io::Write::write_all(out, text.as_bytes()))?;
    Ok(ClipAssembly {
        runs: n,
        files: runs.iter().map(Vec::len).sum(),
        prims,
        time_range: (start, end),
    })
}

/// Run `k` of `n`'s frame files in frame order with what each layer
/// holds: each frame asked for in exactly one file, none reaching past
/// them, every file with the same prims. Errors name the file (or, for a
/// frame missing or twice, the layer being written, `path`).
fn run_files<'f>(
    path: &Path,
    files: &'f [FrameFile],
    frames: &FrameRange,
    (k, n): (usize, usize),
) -> Result<Vec<(&'f FrameFile, UsdLayerInfo)>, WriteError> {
    let fail = |file: &Path, message: String| WriteError {
        path: file.to_path_buf(),
        error: std::io::Error::other(message),
    };
    let mine: Vec<&FrameFile> = files.iter().filter(|f| f.run.0 == k).collect();
    for &frame in frames.frames() {
        let holding = mine
            .iter()
            .filter(|f| (f.first..=f.last).contains(&frame))
            .count();
        if holding != 1 {
            let what = if n == 1 {
                String::new()
            } else {
                format!(" of run {k} of {n}")
            };
            return Err(fail(
                path,
                format!(
                    "frame {frame}{what} is in {holding} files; every frame must be in exactly one (has that task finished?)"
                ),
            ));
        }
    }
    let mut infos = Vec::with_capacity(mine.len());
    for f in mine {
        if !frames
            .frames()
            .iter()
            .any(|&x| (f.first..=f.last).contains(&x))
        {
            continue; // frames outside the range asked for
        }
        // A file reaching past the frames asked for would carry its
        // other frames into the stage (and move its end time code).
        if f.first < frames.first() || f.last > frames.last() {
            return Err(fail(
                &f.path,
                format!(
                    "it holds frames {} to {}, past the frames asked for ({frames}): assemble those frames, or remove the file",
                    f.first, f.last
                ),
            ));
        }
        let info = read_usd_layer_info(&f.path).map_err(|e| fail(&f.path, e.to_string()))?;
        infos.push((f, info));
    }
    if let Some((f, info)) = infos
        .iter()
        .find(|(_, i)| i.children != infos[0].1.children)
    {
        return Err(fail(
            &f.path,
            format!(
                "its prims ({}) differ from those of {} of the same run",
                info.children.join(", "),
                infos[0].0.path.display()
            ),
        ));
    }
    Ok(infos)
}

/// The stitching layer's text: the stage metadata of the first file
/// (`head`) over `time_range`, and for each run's prims an `over` with
/// value clips over the run's files. Returns it and the prims stitched.
fn clip_layer(
    runs: &[Vec<(&FrameFile, UsdLayerInfo)>],
    head: &UsdLayerInfo,
    (start, end): (f64, f64),
) -> (String, usize) {
    let root = &head.default_prim;
    let mut text = String::new();
    let fps = head.time_codes_per_second;
    let _ = write!(
        text,
        "#usda 1.0\n(\n    defaultPrim = \"{root}\"\n    doc = \"Written by pelage {}: frame files stitched with value clips\"\n    endTimeCode = {end}\n    framesPerSecond = {fps}\n    metersPerUnit = {}\n    startTimeCode = {start}\n    timeCodesPerSecond = {fps}\n    upAxis = \"{}\"\n)\n\ndef Xform \"{root}\"\n{{\n",
        env!("CARGO_PKG_VERSION"),
        head.meters_per_unit,
        head.up_axis,
    );
    let relative = |file: &Path| {
        let name = file.file_name().map(|n| n.to_string_lossy().into_owned());
        format!("./{}", name.unwrap_or_default())
    };
    let mut prims = 0;
    let mut material_stitched = false;
    for run in runs {
        let Some((first_file, info)) = run.first() else {
            continue;
        };
        // A reference keeps only targets inside the prim it references:
        // the parts' binding to the file's hair material is authored here
        // again, to the material the layer references too.
        let material = crate::io::HAIR_MATERIAL_NAME;
        let bound = info.children.iter().any(|c| c == material);
        for prim in &info.children {
            // Every run's files hold the same material: it is stitched
            // once, from the first run's.
            if prim == material && material_stitched {
                continue;
            }
            material_stitched |= prim == material;
            prims += 1;
            let binding = if bound && prim.starts_with("part_") {
                format!("        rel material:binding = </{root}/{material}>\n")
            } else {
                String::new()
            };
            let assets: Vec<String> = run
                .iter()
                .map(|(f, _)| asset_path(&relative(&f.path)))
                .collect();
            let active: Vec<String> = run
                .iter()
                .enumerate()
                .map(|(i, (_, info))| {
                    let from = info.time_range.map_or(f64::NEG_INFINITY, |r| r.0);
                    format!("({from}, {i})")
                })
                .collect();
            let _ = write!(
                text,
                "    over \"{prim}\" (\n        clips = {{\n            dictionary default = {{\n                double2[] active = [{}]\n                asset[] assetPaths = [{}]\n                string primPath = \"/{root}/{prim}\"\n            }}\n        }}\n        prepend references = {}</{root}/{prim}>\n    )\n    {{\n{binding}    }}\n",
                active.join(", "),
                assets.join(", "),
                asset_path(&relative(&first_file.path)),
            );
        }
    }
    text.push_str("}\n");
    (text, prims)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Negative frames name files that are found again: the range's `-`
    /// is told from a sign.
    #[test]
    fn frame_files_of_negative_frames_are_found_by_their_names() {
        assert_eq!(frame_span("0007"), Some((7, 7)));
        assert_eq!(frame_span("0001-0012"), Some((1, 12)));
        assert_eq!(frame_span("-003"), Some((-3, -3)));
        assert_eq!(frame_span("-003-0002"), Some((-3, 2)));
        assert_eq!(frame_span("-010--001"), Some((-10, -1)));
        assert_eq!(frame_span("x-1"), None);
        let dir = tempfile::tempdir().unwrap();
        let output = dir.path().join("g.usdc");
        for (run, first, last) in [(Some((1, 2)), -3, 2), (Some((2, 2)), -3, 2), (None, -1, -1)] {
            std::fs::write(frames_file(&output, run, first, last), b"").unwrap();
        }
        let found = find_frame_files(&output).unwrap();
        let spans: Vec<_> = found.iter().map(|f| (f.run, f.first, f.last)).collect();
        assert_eq!(spans, [((1, 1), -1, -1), ((1, 2), -3, 2), ((2, 2), -3, 2)]);
    }
}
