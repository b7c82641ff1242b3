//! UDIM image maps: one image a unit square of UV space, as Mari,
//! Substance and Blender paint them past the 0–1 square. Tile
//! `1001 + u + 10 v` (`u` 0 to 9, `v` from 0) covers UVs
//! `[u, u + 1) × [v, v + 1)`; a file `fur_density.<UDIM>.png` stands for
//! every `fur_density.1001.png`, `fur_density.1002.png`, … in its folder.
//! A UV on a tile with no file reads 0 (no hair where nothing was
//! painted).

use super::{Channel, Filter, ImageMap, MapError, MapErrorKind, Wrap};
use glam::Vec2;
use std::path::Path;

/// The token standing for the tile number in a UDIM path.
pub const UDIM_TOKEN: &str = "<UDIM>";

/// Images by UDIM tile, each read with clamped edges.
#[derive(Debug, Clone, PartialEq)]
pub struct UdimMap {
    /// `(tile, image)`, ascending by tile.
    tiles: Vec<(u32, ImageMap)>,
}

impl UdimMap {
    /// Loads every tile of `pattern` (a path holding `<UDIM>`). Fails,
    /// naming the pattern, when no tile exists.
    pub fn load(pattern: &Path, channel: Channel, filter: Filter) -> Result<Self, MapError> {
        let text = pattern.to_string_lossy().to_string();
        let fail = |msg: String| MapError::new(&text, MapErrorKind::Spec(msg));
        let file = pattern
            .file_name()
            .map(|f| f.to_string_lossy().to_string())
            .unwrap_or_default();
        let Some((prefix, suffix)) = file.split_once(UDIM_TOKEN) else {
            return Err(fail(format!("a UDIM map's file name holds {UDIM_TOKEN}")));
        };
        let folder = match pattern.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => std::path::PathBuf::from("."),
        };
        let entries = std::fs::read_dir(&folder)
            .map_err(|e| MapError::new(folder.display().to_string(), MapErrorKind::Io(e)))?;
        let mut found = Vec::new();
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().to_string();
            let Some(number) = name
                .strip_prefix(prefix)
                .and_then(|rest| rest.strip_suffix(suffix))
            else {
                continue;
            };
            let Ok(tile) = number.parse::<u32>() else {
                continue;
            };
            if number.len() != 4 || !(1001..=9999).contains(&tile) {
                continue;
            }
            found.push((tile, entry.path()));
        }
        if found.is_empty() {
            return Err(fail(format!(
                "no tile of this UDIM map in {}: expected files such as {prefix}1001{suffix}",
                folder.display()
            )));
        }
        // Each tile is within the one-image ceiling when loaded; the
        // tiles together are bounded here, from their headers, before any
        // is decoded.
        let mut pixels = 0u64;
        for (_, path) in &found {
            let (w, h) = super::image::image_size(path)
                .map_err(|e| MapError::new(path.display().to_string(), MapErrorKind::Spec(e)))?;
            pixels = pixels.saturating_add(w.saturating_mul(h));
        }
        let limit = crate::limits::MAX_UDIM_PIXELS;
        if pixels > limit {
            return Err(fail(format!(
                "its {} tiles hold {} M pixels together; pelage reads at most {} M pixels of one UDIM map (docs/limits.md): scale the tiles down",
                found.len(),
                pixels >> 20,
                limit >> 20
            )));
        }
        let mut tiles = Vec::with_capacity(found.len());
        for (tile, path) in found {
            let image = ImageMap::load(path, channel, Wrap::Clamp)?.with_filter(filter);
            tiles.push((tile, image));
        }
        tiles.sort_by_key(|(tile, _)| *tile);
        Ok(Self { tiles })
    }

    /// A UDIM map of given tiles.
    pub fn from_tiles(mut tiles: Vec<(u32, ImageMap)>) -> Self {
        tiles.sort_by_key(|(tile, _)| *tile);
        Self { tiles }
    }

    /// The tiles, ascending.
    pub fn tiles(&self) -> &[(u32, ImageMap)] {
        &self.tiles
    }

    /// The UDIM tile of `uv` (`None` left of 0, right of 10 or below 0).
    pub fn tile_of(uv: Vec2) -> Option<u32> {
        let (u, v) = (uv.x.floor(), uv.y.floor());
        ((0.0..10.0).contains(&u) && (0.0..899.0).contains(&v))
            .then(|| 1001 + u as u32 + 10 * v as u32)
    }

    /// The value at `uv`: its tile's image at the UV within the tile.
    pub fn eval(&self, uv: Vec2) -> f32 {
        let Some(tile) = Self::tile_of(uv) else {
            return 0.0;
        };
        match self.tiles.binary_search_by_key(&tile, |(t, _)| *t) {
            Ok(i) => self.tiles[i].1.eval(uv - uv.floor()),
            Err(_) => 0.0,
        }
    }

    /// The largest texel of any tile.
    pub fn max_texel(&self) -> f32 {
        self.tiles
            .iter()
            .map(|(_, image)| image.max_texel())
            .fold(0.0, f32::max)
    }

    /// The largest tile size, texels a UV unit.
    pub fn resolution(&self) -> (u32, u32) {
        self.tiles.iter().fold((1, 1), |(w, h), (_, image)| {
            (w.max(image.width()), h.max(image.height()))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_their_unit_squares_and_missing_tiles_read_zero() {
        let dir = tempfile::tempdir().unwrap();
        for (tile, value) in [(1001, 64u8), (1002, 255), (1012, 128)] {
            image::GrayImage::from_raw(1, 1, vec![value])
                .unwrap()
                .save(dir.path().join(format!("fur.{tile}.png")))
                .unwrap();
        }
        // Not tiles: another prefix, a five-digit number.
        std::fs::write(dir.path().join("other.1003.png"), b"").unwrap();
        let map = UdimMap::load(
            &dir.path().join("fur.<UDIM>.png"),
            Channel::Luminance,
            Filter::Nearest,
        )
        .unwrap();
        assert_eq!(map.tiles().len(), 3);
        assert!((map.eval(Vec2::new(0.5, 0.5)) - 64.0 / 255.0).abs() < 1e-6);
        assert_eq!(map.eval(Vec2::new(1.5, 0.2)), 1.0);
        assert!((map.eval(Vec2::new(1.5, 1.7)) - 128.0 / 255.0).abs() < 1e-6);
        assert_eq!(map.eval(Vec2::new(2.5, 0.5)), 0.0, "tile 1003 has no file");
        assert_eq!(map.eval(Vec2::new(-0.5, 0.5)), 0.0);
        let err = UdimMap::load(
            &dir.path().join("none.<UDIM>.png"),
            Channel::Luminance,
            Filter::Bilinear,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("none.1001.png"), "{err}");
    }
}
