//! The error of every curve reader: names the file and, where there is one,
//! the line, field or element that is wrong.

use crate::curves::CurvesError;
use crate::error::{Located, Where};
use crate::limits::{DECODED_BYTES_FLOOR, DECODED_BYTES_PER_FILE_BYTE, grouped};
use std::borrow::Cow;
use std::cell::Cell;
use std::path::Path;

/// Bytes of file data (a name, a path) an error message quotes at most.
const EXCERPT_BYTES: usize = 160;

/// `text` as an error quotes it: whole when short, else its start and end
/// around an ellipsis, with its length (a hostile name can be megabytes).
pub(crate) fn excerpt(text: &str) -> Cow<'_, str> {
    if text.len() <= EXCERPT_BYTES {
        return Cow::Borrowed(text);
    }
    let head = text.floor_char_boundary(EXCERPT_BYTES * 2 / 3);
    let tail = text.ceil_char_boundary(text.len() - EXCERPT_BYTES / 4);
    Cow::Owned(format!(
        "{}…{} ({} bytes)",
        &text[..head],
        &text[tail..],
        grouped(text.len() as f64)
    ))
}

/// Bytes of one error message at most, its quotes shortened first.
const MESSAGE_BYTES: usize = 1000;

/// A message that may quote file data, as an error shows it: each run
/// without spaces longer than an excerpt (a path, a name) shortened to
/// its [`excerpt`], and the whole cut to [`MESSAGE_BYTES`], its start and
/// its end (where the problem is said) kept.
pub(crate) fn shortened(message: String) -> String {
    if message.len() <= EXCERPT_BYTES {
        return message;
    }
    let mut out = String::with_capacity(message.len().min(2 * MESSAGE_BYTES));
    for (k, word) in message.split(' ').enumerate() {
        if k > 0 {
            out.push(' ');
        }
        out.push_str(&excerpt(word));
    }
    if out.len() <= MESSAGE_BYTES {
        return out;
    }
    let head = out.floor_char_boundary(MESSAGE_BYTES * 2 / 3);
    let tail = out.ceil_char_boundary(out.len() - MESSAGE_BYTES / 4);
    format!("{} … {}", &out[..head], &out[tail..])
}

/// How many bytes of values one read of a file may still decode (see
/// [`DECODED_BYTES_FLOOR`]): every array, string and path decoded is
/// charged, shared ones each time they are decoded, since each decode is
/// its own allocation.
pub(crate) struct DecodeBudget {
    total: u64,
    left: Cell<u64>,
}

impl DecodeBudget {
    /// The budget of a file of `file_bytes` bytes.
    pub fn for_file(file_bytes: usize) -> Self {
        let total = DECODED_BYTES_FLOOR
            .saturating_add((file_bytes as u64).saturating_mul(DECODED_BYTES_PER_FILE_BYTE));
        Self {
            total,
            left: Cell::new(total),
        }
    }

    /// Takes `bytes` from the budget, or says why not (the caller adds
    /// the file and place).
    pub(crate) fn charge(&self, bytes: u64) -> Result<(), String> {
        match self.left.get().checked_sub(bytes) {
            Some(left) => {
                self.left.set(left);
                Ok(())
            }
            None => Err(format!(
                "decoding {} more bytes would take the file's values past {} bytes, what pelage decodes from a file of this size (1 GiB plus 8 bytes a byte of the file: docs/limits.md); the file claims more data than it holds",
                grouped(bytes as f64),
                grouped(self.total as f64)
            )),
        }
    }
}

/// What is wrong with a curves file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CurvesReadErrorKind {
    /// The file could not be opened or read.
    #[error("cannot read the file: {0}")]
    Io(std::io::Error),
    /// The extension names no format pelage reads curves from.
    #[error(
        "unknown curves format {extension:?}; pelage reads curves from .usda, .usdc, .usd, .abc, .hair and .ply"
    )]
    UnknownFormat {
        /// The extension found (may be empty).
        extension: String,
    },
    /// The text or header could not be parsed.
    #[error("{0}")]
    Syntax(String),
    /// Counts or sizes that do not add up; says which field.
    #[error("{0}")]
    Inconsistent(String),
    /// Something the format allows but pelage cannot use.
    #[error("{0}")]
    Unsupported(String),
    /// The file holds no curves.
    #[error("the file holds no curves{0}")]
    Empty(&'static str),
    /// The arrays read do not make valid curves (NaN, …).
    #[error(transparent)]
    Curves(#[from] CurvesError),
    /// The arrays of one object (a prim, an Alembic object) do not make
    /// valid curves.
    #[error("{object}: {error}")]
    CurvesOf {
        /// The object's path in the file.
        object: String,
        /// Why.
        error: CurvesError,
    },
}

/// A curves file could not be read. Displays as
/// `FILE[:LINE | : ELEMENT N]: what is wrong` ([`Located`]).
pub type CurvesReadError = Located<CurvesReadErrorKind>;

impl Located<CurvesReadErrorKind> {
    /// An error at `location` of the file at `path`. A message that
    /// quotes the file is shortened to excerpts: a hostile name can be
    /// megabytes.
    pub fn new(path: &Path, location: Where, kind: CurvesReadErrorKind) -> Self {
        use CurvesReadErrorKind as K;
        let kind = match kind {
            K::Syntax(m) => K::Syntax(shortened(m)),
            K::Inconsistent(m) => K::Inconsistent(shortened(m)),
            K::Unsupported(m) => K::Unsupported(shortened(m)),
            K::CurvesOf { object, error } => K::CurvesOf {
                object: excerpt(&object).into_owned(),
                error,
            },
            other => other,
        };
        Located::with(path, location, kind)
    }

    /// An error about the whole file.
    pub fn whole(path: &Path, kind: CurvesReadErrorKind) -> Self {
        Self::new(path, Where::whole(), kind)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_quotes_in_messages_are_cut_to_excerpts() {
        assert_eq!(shortened("short: fine".into()), "short: fine");
        let name = "x".repeat(300_000);
        let message = shortened(format!("/{name}/{name}: a group past the end"));
        assert!(message.len() < 400, "{}", message.len());
        assert!(
            message.ends_with(": (600,003 bytes) a group past the end"),
            "{message}"
        );
        // Spaces in the quote: the whole is cut, start and end kept.
        let spaced = "ab ".repeat(100_000);
        let message = shortened(format!("/{spaced}: the end"));
        assert!(message.len() <= MESSAGE_BYTES + 8, "{}", message.len());
        assert!(message.ends_with(": the end"), "{message}");
        // Multi-byte characters are cut at their boundaries.
        let message = excerpt(&"é".repeat(1000)).into_owned();
        assert!(message.contains('…'), "{message}");
        let budget = DecodeBudget::for_file(0);
        assert!(budget.charge(DECODED_BYTES_FLOOR).is_ok());
        assert!(budget.charge(1).unwrap_err().contains("docs/limits.md"));
    }
}
