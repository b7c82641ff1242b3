//! Real readers as test oracles: Pixar's usd-core (`tools/usdcheck`) and
//! Blender's importers (`tools/blendercheck`), each set up in a cached venv
//! on first use. Where one cannot be set up the tests print SKIPPED; with
//! `PELAGE_REQUIRE_USDCHECK=1` / `PELAGE_REQUIRE_BLENDER=1` (CI) they fail
//! instead. Shared by the library's and the CLI's tests.

#![allow(dead_code)] // each test binary uses its own share

pub mod chi_square;

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A file of the repository.
pub fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// Runs `tools/usdcheck ARGS`: `(passed, output)`, or `None` after
/// printing SKIPPED.
pub fn usdcheck<S: AsRef<OsStr>>(args: &[S]) -> Option<(bool, String)> {
    reader("usdcheck", "PELAGE_REQUIRE_USDCHECK", args)
}

/// Runs `tools/blendercheck ARGS` (Blender imports a USD or Alembic file
/// and says what it made): `(imported, output)`, or `None` after printing
/// SKIPPED.
pub fn blendercheck<S: AsRef<OsStr>>(args: &[S]) -> Option<(bool, String)> {
    reader("blendercheck", "PELAGE_REQUIRE_BLENDER", args)
}

/// Exit 2 from a tool means it could not set itself up.
fn reader<S: AsRef<OsStr>>(tool: &str, require: &str, args: &[S]) -> Option<(bool, String)> {
    let script = repo(&format!("tools/{tool}"));
    let required = std::env::var_os(require).is_some();
    if !script.exists() {
        assert!(
            !required,
            "{require} is set but {} is missing",
            script.display()
        );
        eprintln!("SKIPPED: {} not found", script.display());
        return None;
    }
    let output = Command::new(&script)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{tool} does not start: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    if output.status.code() == Some(2) {
        assert!(!required, "{tool} could not set itself up:\n{text}");
        eprintln!("SKIPPED: {tool} could not set itself up:\n{text}");
        return None;
    }
    Some((output.status.success(), text))
}

/// The numbers after `PREFIX` on the line that starts with it.
pub fn numbers_after(text: &str, prefix: &str) -> Vec<f64> {
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix(prefix))
        .unwrap_or_else(|| panic!("no line starting {prefix:?} in:\n{text}"));
    line.split_whitespace()
        .map_while(|x| x.parse::<f64>().ok())
        .collect()
}
