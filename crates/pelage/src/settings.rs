//! TOML settings files (groom files, shell scenes): the text and its path,
//! serde parsing, and turning a place in the text into the line, column and
//! dotted key (`ops[2].clump.rate`) that every error names. Each layer
//! wraps these places in its own error type ([`crate::groom::GroomError`],
//! [`crate::shell::SceneError`]).

use crate::error::Where;
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

impl SettingsSource {
    /// Reads a settings file.
    pub fn read(path: &Path) -> std::io::Result<Self> {
        crate::io::check_input(path, "a settings file (TOML)")?;
        let text = std::fs::read_to_string(path)?;
        Ok(Self {
            path: path.to_path_buf(),
            // A byte-order mark (Windows editors) is not TOML.
            text: match text.strip_prefix('\u{feff}') {
                Some(rest) => rest.to_string(),
                None => text,
            },
        })
    }

    /// The folder relative paths are resolved against.
    pub fn folder(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new(""))
    }

    /// A `[NAME]` header for one of `lists`, the tables written as arrays
    /// (`[[ops]]`, `[[droplets]]`): TOML then reads it as one table and
    /// serde's complaint ("invalid type: map, expected a sequence", or
    /// "duplicate key" for the second) does not say what to write.
    pub fn single_bracket_list(&self, lists: &[&str]) -> Option<(Where, String)> {
        let mut offset = 0;
        for line in self.text.split_inclusive('\n') {
            let code = line.split('#').next().unwrap_or("").trim();
            if let Some(name) = code.strip_prefix('[').and_then(|c| c.strip_suffix(']'))
                && !name.starts_with('[')
                && lists.contains(&name.trim())
            {
                let name = name.trim();
                let start = offset + line.find('[').unwrap_or(0);
                let mut place = self.place(start..start + code.len());
                place.key = Some(format!("[{name}]"));
                return Some((
                    place,
                    format!(
                        "[{name}] holds a list: write [[{name}]] (two brackets) above each entry"
                    ),
                ));
            }
            offset += line.len();
        }
        None
    }

    /// Parses the text with serde; a failure comes with its place (unknown
    /// keys, wrong types, unknown enum values with the accepted ones).
    pub fn deserialize<T: serde::de::DeserializeOwned>(&self) -> Result<T, (Where, String)> {
        toml::from_str(&self.text).map_err(|e| {
            let place = e.span().map(|s| self.place(s)).unwrap_or_default();
            (place, e.message().to_string())
        })
    }

    /// The place of a span of the text; nowhere for a default value (the
    /// empty span at 0).
    pub fn place(&self, span: Range<usize>) -> Where {
        if span == (0..0) {
            return Where::default();
        }
        let start = span.start.min(self.text.len());
        let line_start = self.text[..start].rfind('\n').map_or(0, |i| i + 1);
        Where::at(self.line_of(span), key_at(&self.text, line_start, start))
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

    /// Line and column of table `name`'s `[name]` header (`None` when the
    /// file writes it inline or not at all).
    pub fn line_of_table(&self, name: &str) -> Option<(usize, usize)> {
        let header = format!("[{name}]");
        let line = self
            .text
            .lines()
            .position(|l| l.split('#').next().unwrap_or("").trim() == header)?;
        Some((line + 1, 1))
    }
}

/// `line` with every byte inside a quoted string replaced by `x`: the same
/// length and the same character boundaries outside strings.
fn mask_strings(line: &str) -> String {
    let mut out = Vec::with_capacity(line.len());
    let mut quote = None;
    let mut escaped = false;
    for &b in line.as_bytes() {
        match quote {
            Some(q) => {
                if escaped {
                    escaped = false;
                } else if b == b'\\' && q == b'"' {
                    escaped = true;
                } else if b == q {
                    quote = None;
                    out.push(b);
                    continue;
                }
                out.push(b'x');
            }
            None => {
                if b == b'"' || b == b'\'' {
                    quote = Some(b);
                }
                out.push(b);
            }
        }
    }
    String::from_utf8(out).expect("only ASCII bytes were replaced, and by ASCII")
}

/// The dotted key at `offset` on the line starting at `line_start`, with
/// its table: `roots.count`, `ops[2].clump.rate`.
fn key_at(text: &str, line_start: usize, offset: usize) -> Option<String> {
    let line_end = text[line_start..]
        .find('\n')
        .map_or(text.len(), |i| line_start + i);
    // Strings' contents masked: a `=` or `{` inside a value such as
    // "noise:frequency=6" is not TOML's.
    let masked = mask_strings(&text[line_start..line_end]);
    let line = masked.as_str();
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

/// What a numeric setting must be: a range, each end open or closed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bound {
    /// `min ≤ value ≤ max`.
    Within(f64, f64),
    /// `min < value ≤ max`.
    Above(f64, f64),
}

impl Bound {
    /// `value ≥ min`, no ceiling.
    pub const fn at_least(min: f64) -> Self {
        Self::Within(min, f64::INFINITY)
    }

    /// `value > min`, no ceiling.
    pub const fn more_than(min: f64) -> Self {
        Self::Above(min, f64::INFINITY)
    }

    fn admits(self, v: f64) -> bool {
        match self {
            Self::Within(lo, hi) => v >= lo && v <= hi,
            Self::Above(lo, hi) => v > lo && v <= hi,
        }
    }
}

impl std::fmt::Display for Bound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let number = |v: f64| crate::limits::grouped(v);
        match *self {
            Self::Within(lo, hi) if hi.is_infinite() => write!(f, "use at least {}", number(lo)),
            Self::Above(lo, hi) if hi.is_infinite() => write!(f, "use more than {}", number(lo)),
            Self::Within(lo, hi) => write!(f, "use {} to {}", number(lo), number(hi)),
            Self::Above(lo, hi) => {
                write!(f, "use more than {} and at most {}", number(lo), number(hi))
            }
        }
    }
}

/// A documented range of a numeric setting: `key` is its dotted path with
/// array indices left out (`ops.clump.count` holds for every clump
/// operator; an array value such as `gravity = [0, -9.8, 0]` holds for each
/// element), and `why` is said when the value is refused.
#[derive(Debug, Clone)]
pub struct Rule {
    /// Dotted key without indices.
    pub key: std::borrow::Cow<'static, str>,
    /// The values allowed.
    pub bound: Bound,
    /// What the bound protects, said after it ("" for nothing).
    pub why: &'static str,
}

impl Rule {
    /// A rule for `key`.
    pub const fn new(key: &'static str, bound: Bound, why: &'static str) -> Self {
        Self {
            key: std::borrow::Cow::Borrowed(key),
            bound,
            why,
        }
    }

    /// Why `value` (written `shown`) breaks the rule, or `None` when it
    /// keeps it: `"1.5: use 0 to 1 (a fraction)"`. A file's check and a
    /// value built in a program say the same.
    pub fn refusal(&self, value: f64, shown: &str) -> Option<String> {
        if self.bound.admits(value) {
            return None;
        }
        let why = match self.why {
            "" => String::new(),
            why => format!(" ({why})"),
        };
        Some(format!("{shown}: {}{why}", self.bound))
    }

    /// A rule for a key made at run time (an operator's settings under
    /// `ops.NAME`).
    pub fn owned(key: String, bound: Bound, why: &'static str) -> Self {
        Self {
            key: std::borrow::Cow::Owned(key),
            bound,
            why,
        }
    }
}

impl SettingsSource {
    /// Checks every number in the file: each must be finite and fit an
    /// `f32` where it is a float (settings are single precision, and a NaN
    /// would otherwise surface far away, blamed on another setting), and
    /// those `rules` name must lie in their bounds. Call after
    /// [`Self::deserialize`] succeeded; the error is the first offending
    /// value's place and what is wrong with it.
    pub fn check(&self, rules: &[Rule]) -> Result<(), (Where, String)> {
        use toml::de::{DeTable, DeValue};
        let Ok(table) = DeTable::parse(&self.text) else {
            // Serde parsed the same text: nothing to check here.
            return Ok(());
        };
        fn walk(
            source: &SettingsSource,
            rules: &[Rule],
            path: &str,
            value: &toml::Spanned<DeValue<'_>>,
        ) -> Result<(), (Where, String)> {
            let refuse = |message: String| Err((source.place(value.span()), message));
            let number = match value.get_ref() {
                DeValue::Table(table) => {
                    for (key, value) in table {
                        let path = match path {
                            "" => key.get_ref().to_string(),
                            _ => format!("{path}.{}", key.get_ref()),
                        };
                        walk(source, rules, &path, value)?;
                    }
                    return Ok(());
                }
                DeValue::Array(items) => {
                    for item in items.iter() {
                        walk(source, rules, path, item)?;
                    }
                    return Ok(());
                }
                DeValue::Float(f) => {
                    let text = f.as_str();
                    let v: f64 = text.replace('_', "").parse().unwrap_or(f64::NAN);
                    if !v.is_finite() {
                        return refuse(format!("{text} is not a finite number"));
                    }
                    if v.abs() > f32::MAX as f64 {
                        return refuse(format!(
                            "{text} is too large: settings are 32-bit floats, at most ±3.4e38"
                        ));
                    }
                    v
                }
                DeValue::Integer(i) => {
                    let digits = i.as_str().replace('_', "");
                    match i128::from_str_radix(&digits, i.radix()) {
                        Ok(v) => v as f64,
                        Err(_) => return Ok(()),
                    }
                }
                _ => return Ok(()),
            };
            for rule in rules.iter().filter(|r| r.key == path) {
                if let Some(message) = rule.refusal(number, source.text[value.span()].trim()) {
                    return refuse(message);
                }
            }
            Ok(())
        }
        let root = toml::Spanned::new(table.span(), DeValue::Table(table.into_inner()));
        walk(self, rules, "", &root)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(text: &str) -> SettingsSource {
        SettingsSource {
            path: "s.toml".into(),
            text: text.into(),
        }
    }

    const RULES: &[Rule] = &[
        Rule::new("roots.count", Bound::Within(1.0, 100.0), "a test ceiling"),
        Rule::new("ops.clump.rate", Bound::Within(0.0, 1.0), ""),
    ];

    #[test]
    fn numbers_outside_their_rule_are_refused_at_their_place() {
        let (place, message) = source("[roots]\ncount = 101\n").check(RULES).unwrap_err();
        assert_eq!(place.line_column(), Some((2, 9)));
        assert_eq!(place.key.as_deref(), Some("roots.count"));
        assert_eq!(message, "101: use 1 to 100 (a test ceiling)");
        // Array tables: the rule holds for every entry.
        let text = "[[ops]]\nclump = { rate = 0.5 }\n[[ops]]\nclump = { rate = 1.5 }\n";
        let (place, message) = source(text).check(RULES).unwrap_err();
        assert_eq!(place.key.as_deref(), Some("ops[1].clump.rate"));
        assert_eq!(message, "1.5: use 0 to 1");
        source("[roots]\ncount = 100\n").check(RULES).unwrap();
    }

    #[test]
    fn every_float_must_be_finite_and_fit_f32() {
        for (text, expected) in [
            ("a = nan\n", "nan is not a finite number"),
            ("[t]\nv = [1.0, -inf]\n", "-inf is not a finite number"),
            ("b = 1e39\n", "1e39 is too large"),
        ] {
            let (_, message) = source(text).check(&[]).unwrap_err();
            assert!(message.starts_with(expected), "{text}: {message}");
        }
        source("a = 3.0e38\nb = 1_000.5\n").check(&[]).unwrap();
    }

    #[test]
    fn a_key_is_found_outside_the_strings_of_its_line() {
        let text = "[roots]\ndensity = \"noise:frequency=6,octaves=3\"\n";
        let start = text.find("noise").unwrap();
        let place = source(text).place(start..start + 5);
        assert_eq!(place.key.as_deref(), Some("roots.density"));
    }

    #[test]
    fn a_list_written_as_one_table_says_how_to_write_it() {
        let text = "[mesh]\npath = \"spot\"\n[ops]  # operators\nclump = {}\n";
        let (place, message) = source(text).single_bracket_list(&["ops"]).unwrap();
        assert_eq!(place.line_column(), Some((3, 1)));
        assert!(message.contains("write [[ops]]"), "{message}");
        assert!(source("[[ops]]\n").single_bracket_list(&["ops"]).is_none());
    }
}
