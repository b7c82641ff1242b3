//! The one shape of pelage's file errors: [`Located`], what went wrong
//! (a typed kind) and where, in which source: a line and column, the key
//! written there, or an element by index. Groom, shell-scene, mesh and
//! curves-file errors are each a `Located` of their own kind
//! ([`crate::groom::GroomError`], [`crate::shell::SceneError`],
//! [`crate::mesh::MeshError`], [`crate::io::CurvesReadError`]), and all
//! display as `SOURCE[:LINE[:COLUMN]][: KEY][: ELEMENT N]: what is wrong`.

use std::fmt;
use std::path::PathBuf;

/// Where in its source an error is. Every part is optional: a default
/// value has no place in its file, a mesh built in memory has no lines.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Where {
    /// 1-based line of a text file.
    pub line: Option<usize>,
    /// 1-based column on that line, where known.
    pub column: Option<usize>,
    /// The setting's key, with its table (`roots.count`, `ops[2].clump`).
    pub key: Option<String>,
    /// An element by kind and 0-based index (`vertex 12`, `curve 3`).
    pub element: Option<(&'static str, usize)>,
}

impl Where {
    /// The whole source: no place in it.
    pub fn whole() -> Self {
        Self::default()
    }

    /// A 1-based line.
    pub fn line(line: usize) -> Self {
        Self {
            line: Some(line),
            ..Self::default()
        }
    }

    /// A line and column (both 1-based), if known, and the key there.
    pub fn at(line_column: Option<(usize, usize)>, key: Option<String>) -> Self {
        Self {
            line: line_column.map(|(line, _)| line),
            column: line_column.map(|(_, column)| column),
            key,
            element: None,
        }
    }

    /// An element by kind and 0-based index.
    pub fn element(kind: &'static str, index: usize) -> Self {
        Self {
            element: Some((kind, index)),
            ..Self::default()
        }
    }

    /// Line and column, when both are known.
    pub fn line_column(&self) -> Option<(usize, usize)> {
        Some((self.line?, self.column?))
    }
}

impl fmt::Display for Where {
    /// `:LINE[:COLUMN]`, `: KEY`, `: ELEMENT N`, each where known: what
    /// follows the source's name in a message.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(column) = self.column {
                write!(f, ":{column}")?;
            }
        }
        if let Some(key) = &self.key {
            write!(f, ": {key}")?;
        }
        if let Some((kind, index)) = self.element {
            write!(f, ": {kind} {index}")?;
        }
        Ok(())
    }
}

/// An error of kind `K` at a place in a source (a file, or a name such
/// as `embedded spot`). Displays as `SOURCE WHERE: KIND`.
///
/// Boxed inside, so results stay small on the happy path. It prints its
/// cause in its message and returns none as `source()`: front ends print
/// each cause once by walking the chain; the cause stays typed in the
/// kind for programs that inspect it.
pub struct Located<K>(Box<LocatedError<K>>);

/// What a [`Located`] holds.
#[derive(Debug)]
pub struct LocatedError<K> {
    /// The file (or a name for what was not read from one).
    pub source: PathBuf,
    /// Where in it.
    pub at: Where,
    /// What is wrong.
    pub kind: K,
}

impl<K> Located<K> {
    /// An error of `kind` at `at` in `source`.
    pub fn with(source: impl Into<PathBuf>, at: Where, kind: K) -> Self {
        Self(Box::new(LocatedError {
            source: source.into(),
            at,
            kind,
        }))
    }

    /// What is wrong.
    pub fn kind(&self) -> &K {
        &self.0.kind
    }

    /// The same error with another kind (a layer's error carried up).
    pub fn map_kind<L>(self, f: impl FnOnce(K) -> L) -> Located<L> {
        let LocatedError { source, at, kind } = *self.0;
        Located::with(source, at, f(kind))
    }
}

impl<K> std::ops::Deref for Located<K> {
    type Target = LocatedError<K>;
    fn deref(&self) -> &LocatedError<K> {
        &self.0
    }
}

impl<K: fmt::Debug> fmt::Debug for Located<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl<K: fmt::Display> fmt::Display for Located<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}: {}",
            self.0.source.display(),
            self.0.at,
            self.0.kind
        )
    }
}

impl<K: fmt::Display + fmt::Debug> std::error::Error for Located<K> {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_place_displays_after_the_source() {
        let e = Located::with(
            "fur.toml",
            Where::at(Some((3, 9)), Some("roots.count".into())),
            "too many",
        );
        assert_eq!(e.to_string(), "fur.toml:3:9: roots.count: too many");
        assert_eq!(e.at.line_column(), Some((3, 9)));
        let e = Located::with("a.obj", Where::line(12), "bad face");
        assert_eq!(e.to_string(), "a.obj:12: bad face");
        let e = Located::with("embedded spot", Where::element("vertex", 4), "not finite");
        assert_eq!(e.to_string(), "embedded spot: vertex 4: not finite");
        assert_eq!(Located::with("x", Where::whole(), 1).to_string(), "x: 1");
    }
}
