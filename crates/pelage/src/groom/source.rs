//! Groom settings' errors at their place: [`SettingsSource`] read, parsed
//! as any serde type and its spans turned into [`GroomError`]s, and maps
//! resolved against the file's folder. Parsing a whole groom file with its
//! range rules is the file layer's (`file.rs`).

use super::error::{GroomError, GroomErrorKind};
use super::values::{MapText, MapValue};
use crate::map::Map;
use crate::settings::SettingsSource;
use std::path::Path;

impl SettingsSource {
    /// Reads a groom (or other settings) file, the error a [`GroomError`].
    pub fn read_groom(path: &Path) -> Result<Self, GroomError> {
        Self::read(path)
            .map_err(|e| GroomError::new(path.to_path_buf(), None, None, GroomErrorKind::Io(e)))
    }

    /// Parses the text as `T`, the error a [`GroomError`] at its line and
    /// key.
    pub fn parse_as<T: serde::de::DeserializeOwned>(&self) -> Result<T, GroomError> {
        self.deserialize().map_err(|(place, message)| {
            GroomError::with(self.path.clone(), place, GroomErrorKind::Syntax(message))
        })
    }

    /// A [`GroomError`] at a span of the text: its line and column, and the
    /// key written there (with its table).
    pub fn error_at(&self, span: std::ops::Range<usize>, kind: GroomErrorKind) -> GroomError {
        GroomError::with(self.path.clone(), self.place(span), kind)
    }

    /// Resolves a map value, reporting a bad spec or unreadable image at its
    /// line.
    pub(crate) fn map(&self, value: &MapValue) -> Result<Map, GroomError> {
        match value.get_ref() {
            MapText::Number(n) if n.is_finite() => Ok(Map::Constant(*n)),
            MapText::Number(n) => Err(self.error_at(
                value.span(),
                GroomErrorKind::NotFinite(format!("{n} is not a finite number")),
            )),
            MapText::Spec(spec) => Map::parse_with_base(spec, Some(self.folder()))
                .map_err(|e| self.error_at(value.span(), GroomErrorKind::Map(e))),
        }
    }
}
