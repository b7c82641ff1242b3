//! TOML settings files (groom files, shell scenes): the text and its path,
//! serde parsing, and turning a place in the text into the line, column and
//! dotted key (`ops[2].clump.rate`) that every error names. Each layer
//! wraps these places in its own error type ([`crate::groom::GroomError`],
//! [`crate::shell::SceneError`]).

use std::ops::Range;
use std::path::{Path, PathBuf};

/// A settings file's path and text, for error messages and relative paths.
#[derive(Debug, Clone)]
pub struct SettingsSource {
    /// The file (or a name such as `<demo>`).
    pub path: PathBuf,
    /// Its text.
    pub text: String,
}

/// Where in a settings file something is: line and column (1-based) and
/// the dotted key written there, with its table. Both `None` for a
/// default value, which has no place in the file.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Place {
    /// Line and column.
    pub line: Option<(usize, usize)>,
    /// The key, with its table (`roots.count`).
    pub key: Option<String>,
}

impl SettingsSource {
    /// Reads a settings file.
    pub fn read(path: &Path) -> std::io::Result<Self> {
        Ok(Self {
            path: path.to_path_buf(),
            text: std::fs::read_to_string(path)?,
        })
    }

    /// The folder relative paths are resolved against.
    pub fn folder(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new(""))
    }

    /// Parses the text with serde; a failure comes with its place (unknown
    /// keys, wrong types, unknown enum values with the accepted ones).
    pub fn deserialize<T: serde::de::DeserializeOwned>(&self) -> Result<T, (Place, String)> {
        toml::from_str(&self.text).map_err(|e| {
            let place = e.span().map(|s| self.place(s)).unwrap_or_default();
            (place, e.message().to_string())
        })
    }

    /// The place of a span of the text; nowhere for a default value (the
    /// empty span at 0).
    pub fn place(&self, span: Range<usize>) -> Place {
        if span == (0..0) {
            return Place::default();
        }
        let start = span.start.min(self.text.len());
        let line_start = self.text[..start].rfind('\n').map_or(0, |i| i + 1);
        Place {
            line: self.line_of(span),
            key: key_at(&self.text, line_start, start),
        }
    }

    /// Line and column (1-based) of a span of the text; `None` for a
    /// default value (the empty span at 0).
    pub fn line_of(&self, span: Range<usize>) -> Option<(usize, usize)> {
        if span == (0..0) {
            return None;
        }
        let start = span.start.min(self.text.len());
        let before = &self.text[..start];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Some((
            before.matches('\n').count() + 1,
            before[line_start..].chars().count() + 1,
        ))
    }

    /// Line and column of operator `k`'s table in a groom file: its
    /// `[[ops]]` header.
    pub fn line_of_op(&self, k: usize) -> Option<(usize, usize)> {
        let line = self
            .text
            .lines()
            .enumerate()
            .filter(|(_, l)| l.trim_start().starts_with("[[ops]]"))
            .nth(k)?
            .0;
        Some((line + 1, 1))
    }
}

/// The dotted key at `offset` on the line starting at `line_start`, with
/// its table: `roots.count`, `ops[2].clump.rate`.
fn key_at(text: &str, line_start: usize, offset: usize) -> Option<String> {
    let line_end = text[line_start..]
        .find('\n')
        .map_or(text.len(), |i| line_start + i);
    let line = &text[line_start..line_end];
    let in_line = offset - line_start;
    let trimmed = line.trim_start();
    if trimmed.starts_with('[') {
        return Some(trimmed.trim().to_string());
    }
    // The key is what precedes the last `=` before the offset, or the bare
    // word at the offset (an unknown key is reported at the key itself).
    let head = &line[..in_line.min(line.len())];
    let rest = &line[in_line.min(line.len())..];
    let word_end = rest
        .find(|c: char| c == '=' || c == ',' || c == '}' || c.is_whitespace())
        .unwrap_or(rest.len());
    let at_key = rest[word_end..].trim_start().starts_with('=') && word_end > 0;
    // The key owning the inline table that is open at `pos`.
    let owner_of = |pos: usize| {
        let brace = line[..pos].rfind('{')?;
        let before = line[..brace].trim_end().strip_suffix('=')?.trim_end();
        let start = before.rfind(['{', ',']).map_or(0, |i| i + 1);
        Some(before[start..].trim().to_string())
    };
    let key = match head.rfind('=') {
        // An unknown key is reported at the key itself.
        _ if at_key => {
            let key = rest[..word_end].to_string();
            match owner_of(head.len()) {
                Some(owner) => format!("{owner}.{key}"),
                None => key,
            }
        }
        Some(eq) => {
            let left = &head[..eq];
            // Inside an inline table: the key after the last `{` or `,`.
            let start = left.rfind(['{', ',']).map_or(0, |i| i + 1);
            let inline_owner = owner_of(start);
            let key = left[start..].trim().to_string();
            match inline_owner {
                Some(owner) if start > 0 => format!("{owner}.{key}"),
                _ => key,
            }
        }
        None => rest[..word_end].to_string(),
    };
    if key.is_empty() {
        return None;
    }
    // The table the line is in: the last header above it.
    let mut table = None;
    let mut ops_seen = 0usize;
    for l in text[..line_start].lines() {
        let l = l.trim();
        if l.starts_with("[[ops]]") {
            ops_seen += 1;
            table = Some(format!("ops[{}]", ops_seen - 1));
        } else if let Some(name) = l.strip_prefix('[').and_then(|l| l.split(']').next()) {
            let name = name.trim_start_matches('[').trim();
            table = Some(match name.strip_prefix("ops.") {
                Some(rest) if ops_seen > 0 => format!("ops[{}].{rest}", ops_seen - 1),
                _ => name.to_string(),
            });
        }
    }
    Some(match table {
        Some(t) => format!("{t}.{key}"),
        None => key,
    })
}
