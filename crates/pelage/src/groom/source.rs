//! A groom (or shell scene) file's text and path: parsing it with serde,
//! and turning a place in the text into the line, column and dotted key
//! every error names.

use super::error::{GroomError, GroomErrorKind};
use super::file::{GroomFile, MapText, MapValue};
use crate::map::Map;
use std::path::{Path, PathBuf};

/// A groom file and where it came from, for error messages and relative
/// paths.
#[derive(Debug, Clone)]
pub struct GroomSource {
    /// The file (or a name such as `<demo>`).
    pub path: PathBuf,
    /// Its text.
    pub text: String,
}

impl GroomSource {
    /// Reads a groom file.
    pub fn read(path: &Path) -> Result<Self, GroomError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| GroomError::new(path.to_path_buf(), None, None, GroomErrorKind::Io(e)))?;
        Ok(Self {
            path: path.to_path_buf(),
            text,
        })
    }

    /// The folder relative paths are resolved against.
    pub fn folder(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new(""))
    }

    /// Parses the text.
    pub fn parse(&self) -> Result<GroomFile, GroomError> {
        self.parse_as()
    }

    /// Parses the text as any TOML file pelage reads (groom files, shell
    /// scenes), with errors at their line and key.
    pub fn parse_as<T: serde::de::DeserializeOwned>(&self) -> Result<T, GroomError> {
        toml::from_str(&self.text).map_err(|e| {
            let message = e.message().to_string();
            match e.span() {
                Some(span) => self.error_at(span, GroomErrorKind::Syntax(message)),
                None => GroomError::new(
                    self.path.clone(),
                    None,
                    None,
                    GroomErrorKind::Syntax(message),
                ),
            }
        })
    }

    /// An error at a span of the text: its line and column, and the key
    /// written there (with its table).
    pub fn error_at(&self, span: std::ops::Range<usize>, kind: GroomErrorKind) -> GroomError {
        if span == (0..0) {
            // A default value: no place in the file.
            return GroomError::new(self.path.clone(), None, None, kind);
        }
        let start = span.start.min(self.text.len());
        let line_start = self.text[..start].rfind('\n').map_or(0, |i| i + 1);
        GroomError::new(
            self.path.clone(),
            self.line_of(span),
            key_at(&self.text, line_start, start),
            kind,
        )
    }

    /// Line and column (1-based) of a span of the text; `None` for a
    /// default value (the empty span at 0).
    pub fn line_of(&self, span: std::ops::Range<usize>) -> Option<(usize, usize)> {
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

    /// Line and column of operator `k`'s table: its `[[ops]]` header.
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

    /// Resolves a map value, reporting a bad spec or unreadable image at its
    /// line.
    pub fn map(&self, value: &MapValue) -> Result<Map, GroomError> {
        match value.get_ref() {
            MapText::Number(n) if n.is_finite() => Ok(Map::Constant(*n)),
            MapText::Number(n) => Err(self.error_at(
                value.span(),
                GroomErrorKind::Invalid(format!("{n} is not a finite number")),
            )),
            MapText::Spec(spec) => Map::parse_with_base(spec, Some(self.folder()))
                .map_err(|e| self.error_at(value.span(), GroomErrorKind::Map(e))),
        }
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
