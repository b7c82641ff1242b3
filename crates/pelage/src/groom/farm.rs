//! A groom on a render farm: [`FarmRun`] (run `K` of `N`, written `K/N`)
//! and the part files the runs leave beside the output, found again for
//! the assembly ([`find_part_files`]). The CLI's `--part` and `--assemble`,
//! Python's `part=` and `pelage.assemble` are front ends of these
//! (docs/farm.md).

use super::output::{part_file, part_slice};
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Run `k` of `n` of a farm (1-based): a contiguous share of a groom's
/// parts, so the `n` runs together grow every part once. Written `K/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FarmRun {
    /// This run, 1 to `n`.
    pub k: usize,
    /// The number of runs.
    pub n: usize,
}

impl FarmRun {
    /// Run `k` of `n`, when `1 ≤ k ≤ n`.
    pub fn new(k: usize, n: usize) -> Result<Self, FarmError> {
        if n == 0 || k == 0 || k > n {
            return Err(FarmError::Run(format!(
                "{k}/{n}: K must be 1 to N (runs are numbered from 1)"
            )));
        }
        Ok(Self { k, n })
    }

    /// The parts this run grows of a groom of `parts` parts; an error when
    /// there are fewer parts than runs.
    pub fn parts(&self, parts: usize) -> Result<Range<usize>, FarmError> {
        if self.n > parts {
            return Err(FarmError::TooManyRuns { run: *self, parts });
        }
        Ok(part_slice(self.k, self.n, parts))
    }

    /// The file this run writes beside `output` (`groom.part-3-of-8.usdc`).
    pub fn file(&self, output: &Path) -> PathBuf {
        part_file(output, self.k, self.n)
    }
}

impl fmt::Display for FarmRun {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl FromStr for FarmRun {
    type Err = FarmError;

    /// `"3/8"`.
    fn from_str(s: &str) -> Result<Self, FarmError> {
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| FarmError::Run(format!("{s:?}: write the run as K/N, e.g. 3/8")))?;
        let number = |t: &str| {
            t.trim()
                .parse::<usize>()
                .map_err(|_| FarmError::Run(format!("{t:?} is not a whole number")))
        };
        Self::new(number(k)?, number(n)?)
    }
}

/// A farm run or its files that do not fit.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FarmError {
    /// `K/N` that is not a run.
    #[error("{0}")]
    Run(String),
    /// More runs than the groom has parts.
    #[error(
        "run {run}: the groom has {parts} parts, so at most {parts} runs; set [roots] parts for more"
    )]
    TooManyRuns {
        /// The run asked for.
        run: FarmRun,
        /// The groom's parts.
        parts: usize,
    },
    /// The output's folder cannot be listed.
    #[error("cannot list {folder}: {error}")]
    List {
        /// The folder.
        folder: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// No part file beside the output.
    #[error(
        "no part files {stem}.part-K-of-N.* in {folder}; run `pelage groom FILE --part K/N` first"
    )]
    NoParts {
        /// The output's name without extension.
        stem: String,
        /// Its folder.
        folder: PathBuf,
    },
    /// Part files of two farm runs of different sizes.
    #[error("{folder}: part files of two different farm runs (of {a} and of {b}); remove one set")]
    TwoFarms {
        /// The folder.
        folder: PathBuf,
        /// One run count.
        a: usize,
        /// The other.
        b: usize,
    },
    /// Alembic part files assembled into a USD layer: they are joined
    /// into one Alembic file instead (Alembic has no references).
    #[error(
        "{path}: Alembic part files are joined into one Alembic file: assemble with `-o NAME.abc` (a USD layer references USD parts only)"
    )]
    AlembicParts {
        /// One of the Alembic part files.
        path: PathBuf,
    },
    /// A run's file is missing.
    #[error("{path} is missing: run {run} has not finished")]
    Missing {
        /// The file looked for.
        path: PathBuf,
        /// Its run.
        run: FarmRun,
    },
    /// A run's file was grown from another version of the groom than
    /// the others, or than the groom assembling them.
    #[error(
        "{path} was grown from another version of the groom (groom key {found:016x}, {than} {want:016x}): grow run {run} again (`pelage groom FILE --part {run}`)"
    )]
    Stale {
        /// The part file.
        path: PathBuf,
        /// Its run.
        run: FarmRun,
        /// Its key.
        found: u64,
        /// The key it should have.
        want: u64,
        /// Whose key that is: the groom's, or the first part's.
        than: &'static str,
    },
}

/// What a farm run's part file says of the groom that grew it (the USD
/// layer's `documentation`, the Alembic archive's description).
pub fn part_documentation(key: u64, run: FarmRun) -> String {
    format!(
        "pelage {} part {} of {}, groom key {key:016x}",
        env!("CARGO_PKG_VERSION"),
        run.k,
        run.n
    )
}

/// The groom key a part file carries, if it carries one: a file another
/// tool or an older pelage wrote carries none, and one that cannot be
/// read is left to the assembly, which reads it whole and says what is
/// wrong with it.
fn part_key(path: &Path) -> Option<u64> {
    let text = if crate::io::CurvesFormat::from_path(path) == Some(crate::io::CurvesFormat::Abc) {
        crate::io::read_abc_description(path).ok()?
    } else {
        crate::io::read_usd_layer_info(path).ok()?.documentation
    };
    let text = text?;
    let (_, hex) = text.split_once("groom key ")?;
    u64::from_str_radix(hex.trim(), 16).ok()
}

/// Refuses files of a farm's runs (each with the run that wrote it)
/// grown from different versions of a groom: every key must be `groom`'s
/// when it is known, else the first file's. Files without a key are let
/// through.
pub fn check_part_keys(files: &[(PathBuf, FarmRun)], groom: Option<u64>) -> Result<(), FarmError> {
    let mut want = groom.map(|k| (k, "the groom's is"));
    for (path, run) in files {
        let Some(found) = part_key(path) else {
            continue;
        };
        match want {
            None => want = Some((found, "the first part's is")),
            Some((want, than)) if want != found => {
                return Err(FarmError::Stale {
                    path: path.clone(),
                    run: *run,
                    found,
                    want,
                    than,
                });
            }
            Some(_) => {}
        }
    }
    Ok(())
}

/// The part files of one farm run of `output` (`NAME.part-K-of-N.EXT`
/// beside it, every `K` of one `N`), in run order. A run's file may be
/// text or binary USD whatever the output's extension; an Alembic output's
/// are Alembic.
///
/// # Errors
/// No part file, files of two farms of different sizes, a run's file
/// missing, or a folder that cannot be listed.
pub fn find_part_files(output: &Path) -> Result<Vec<PathBuf>, FarmError> {
    let folder = crate::io::folder_of(output).to_path_buf();
    let stem = output
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("groom")
        .to_string();
    let list = |error| FarmError::List {
        folder: folder.clone(),
        error,
    };
    let mut runs: Option<usize> = None;
    for entry in std::fs::read_dir(&folder).map_err(list)? {
        let name = entry.map_err(list)?.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(rest) = name.strip_prefix(&format!("{stem}.part-")) else {
            continue;
        };
        let Some((_, n)) = rest.split_once("-of-") else {
            continue;
        };
        let Some(n) = n.split('.').next().and_then(|n| n.parse::<usize>().ok()) else {
            continue;
        };
        match runs {
            Some(a) if a != n => {
                return Err(FarmError::TwoFarms {
                    folder: folder.clone(),
                    a,
                    b: n,
                });
            }
            _ => runs = Some(n),
        }
    }
    let alembic_output = crate::io::CurvesFormat::from_path(output)
        .is_some_and(crate::io::CurvesFormat::assembly_joins_parts);
    let n = runs.ok_or_else(|| FarmError::NoParts {
        stem: stem.clone(),
        folder: folder.clone(),
    })?;
    (1..=n)
        .map(|k| {
            let named = part_file(output, k, n);
            let extensions: &[&str] = if alembic_output {
                &["abc"]
            } else {
                &["usda", "usdc", "usd"]
            };
            let found = extensions
                .iter()
                .map(|ext| named.with_extension(ext))
                .find(|f| f.exists());
            let alembic = named.with_extension("abc");
            match found {
                Some(f) => Ok(f),
                None if !alembic_output && alembic.exists() => {
                    Err(FarmError::AlembicParts { path: alembic })
                }
                None => Err(FarmError::Missing {
                    path: named,
                    run: FarmRun { k, n },
                }),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_read_and_print_as_k_of_n() {
        let run: FarmRun = "3/8".parse().unwrap();
        assert_eq!(run, FarmRun { k: 3, n: 8 });
        assert_eq!(run.to_string(), "3/8");
        assert_eq!(run.parts(16).unwrap(), 4..6);
        for bad in ["0/3", "4/3", "3", "a/3", "1/0"] {
            assert!(bad.parse::<FarmRun>().is_err(), "{bad}");
        }
        let err = FarmRun::new(5, 8).unwrap().parts(4).unwrap_err();
        assert!(err.to_string().contains("at most 4 runs"), "{err}");
    }

    #[test]
    fn part_files_are_found_in_run_order_and_gaps_named() {
        let dir = tempfile::tempdir().unwrap();
        let output = dir.path().join("fur.usda");
        for k in [2, 1, 3] {
            std::fs::write(dir.path().join(format!("fur.part-{k}-of-3.usdc")), b"").unwrap();
        }
        let found = find_part_files(&output).unwrap();
        let names: Vec<_> = found
            .iter()
            .map(|p| p.file_name().unwrap().to_str().unwrap().to_string())
            .collect();
        assert_eq!(
            names,
            [
                "fur.part-1-of-3.usdc",
                "fur.part-2-of-3.usdc",
                "fur.part-3-of-3.usdc"
            ]
        );
        std::fs::remove_file(dir.path().join("fur.part-2-of-3.usdc")).unwrap();
        let err = find_part_files(&output).unwrap_err().to_string();
        assert!(
            err.contains("fur.part-2-of-3.usda is missing: run 2/3"),
            "{err}"
        );
        std::fs::write(dir.path().join("fur.part-1-of-2.usda"), b"").unwrap();
        let err = find_part_files(&output).unwrap_err().to_string();
        assert!(err.contains("two different farm runs"), "{err}");
    }
}
