//! Cem Yuksel's `.hair` format (cemyuksel.com/research/hairmodels), read
//! and written byte for byte.
//!
//! Layout, little-endian: a 128-byte header — `"HAIR"`, hair count, point
//! count, array flags (1 segments, 2 points, 4 thickness, 8 transparency,
//! 16 colours), default segment count, default thickness, default
//! transparency, default colour (3 floats), 88 bytes of info text — then
//! the arrays present, in flag order: segments (`u16` per hair), points
//! (3 `f32` per point), thickness, transparency (`f32` per point), colours
//! (3 `f32` per point). A hair of `s` segments has `s + 1` points; without
//! a segments array every hair has the default count.
//!
//! [`HairFile`] keeps everything the file holds (which arrays, the
//! defaults, the info bytes), so read → write gives the same bytes.
//! Thickness is the hair's width (diameter), transparency is
//! `1 − opacity`.

use super::read_error::{CurvesReadError, CurvesReadErrorKind as Kind};
use super::{WriteError, write_atomically};
use crate::Curves;
use glam::Vec3;
use std::io::Write;
use std::path::Path;

const HEADER: usize = 128;
const FLAG_SEGMENTS: u32 = 1;
const FLAG_POINTS: u32 = 2;
const FLAG_THICKNESS: u32 = 4;
const FLAG_TRANSPARENCY: u32 = 8;
const FLAG_COLORS: u32 = 16;

/// The contents of a `.hair` file.
#[derive(Debug, Clone, PartialEq)]
pub struct HairFile {
    /// Segments per hair, when the file stores them per hair.
    pub segments: Option<Vec<u16>>,
    /// All points.
    pub points: Vec<Vec3>,
    /// Per-point thickness (width), if stored.
    pub thickness: Option<Vec<f32>>,
    /// Per-point transparency, if stored.
    pub transparency: Option<Vec<f32>>,
    /// Per-point colour, if stored.
    pub colors: Option<Vec<Vec3>>,
    /// Number of hairs (needed when there is no segments array).
    pub hair_count: u32,
    /// Segments of every hair without a segments array.
    pub default_segments: u32,
    /// Thickness of points without a thickness array.
    pub default_thickness: f32,
    /// Transparency without a transparency array.
    pub default_transparency: f32,
    /// Colour without a colour array.
    pub default_color: Vec3,
    /// The 88-byte info field (text, zero padded).
    pub info: [u8; 88],
}

impl HairFile {
    /// Parses a `.hair` file's bytes; `path` names the file in errors.
    pub fn parse(bytes: &[u8], path: &Path) -> Result<Self, CurvesReadError> {
        let whole = |kind| CurvesReadError::whole(path, kind);
        if bytes.len() < HEADER {
            return Err(CurvesReadError::whole(
                path,
                Kind::Inconsistent(format!(
                    "the file has {} bytes, fewer than the 128-byte header",
                    bytes.len()
                )),
            ));
        }
        if &bytes[..4] != b"HAIR" {
            return Err(CurvesReadError::whole(
                path,
                Kind::Syntax("not a .hair file: it does not start with \"HAIR\"".into()),
            ));
        }
        let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let f32_at = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let (hair_count, point_count, flags) = (u32_at(4), u32_at(8), u32_at(12));
        if flags & !0x1f != 0 {
            return Err(whole(Kind::Unsupported(format!(
                "header field 'arrays': unknown array flags {:#x}",
                flags & !0x1f
            ))));
        }
        if flags & FLAG_POINTS == 0 {
            return Err(whole(Kind::Unsupported(
                "header field 'arrays': the file stores no points array".into(),
            )));
        }
        let mut file = HairFile {
            segments: None,
            points: Vec::new(),
            thickness: None,
            transparency: None,
            colors: None,
            hair_count,
            default_segments: u32_at(16),
            default_thickness: f32_at(20),
            default_transparency: f32_at(24),
            default_color: Vec3::new(f32_at(28), f32_at(32), f32_at(36)),
            info: bytes[40..128].try_into().unwrap(),
        };
        // Every array's size is known from the header, so check the total
        // before reading any of them.
        let (hairs, points) = (hair_count as usize, point_count as usize);
        let sizes = [
            (FLAG_SEGMENTS, "segments", hairs * 2),
            (FLAG_POINTS, "points", points * 12),
            (FLAG_THICKNESS, "thickness", points * 4),
            (FLAG_TRANSPARENCY, "transparency", points * 4),
            (FLAG_COLORS, "colors", points * 12),
        ];
        let mut at = HEADER;
        for (flag, name, size) in sizes {
            if flags & flag == 0 {
                continue;
            }
            let Some(array) = bytes.get(at..at + size) else {
                return Err(whole(Kind::Inconsistent(format!(
                    "the {name} array needs {size} bytes at offset {at} ({hairs} hairs, {points} points) but the file ends at {}; it is truncated or its counts are wrong",
                    bytes.len()
                ))));
            };
            let floats = || {
                array
                    .chunks_exact(4)
                    .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            };
            let vec3s = || {
                let f: Vec<f32> = floats().collect();
                f.chunks_exact(3).map(Vec3::from_slice).collect::<Vec<_>>()
            };
            match flag {
                FLAG_SEGMENTS => {
                    file.segments = Some(
                        array
                            .chunks_exact(2)
                            .map(|b| u16::from_le_bytes([b[0], b[1]]))
                            .collect(),
                    )
                }
                FLAG_POINTS => file.points = vec3s(),
                FLAG_THICKNESS => file.thickness = Some(floats().collect()),
                FLAG_TRANSPARENCY => file.transparency = Some(floats().collect()),
                _ => file.colors = Some(vec3s()),
            }
            at += size;
        }
        if at != bytes.len() {
            return Err(whole(Kind::Inconsistent(format!(
                "{} bytes follow the last array; the header's counts ({hairs} hairs, {points} points) do not describe the file",
                bytes.len() - at
            ))));
        }
        let implied: u64 = match &file.segments {
            Some(s) => s.iter().map(|&s| s as u64 + 1).sum(),
            None => hair_count as u64 * (file.default_segments as u64 + 1),
        };
        if implied != point_count as u64 {
            let field = if file.segments.is_some() {
                "the segments array"
            } else {
                "the default segment count"
            };
            return Err(whole(Kind::Inconsistent(format!(
                "header field 'point count' says {point_count} points but {field} implies {implied}"
            ))));
        }
        Ok(file)
    }

    /// Reads a `.hair` file.
    pub fn read(path: &Path) -> Result<Self, CurvesReadError> {
        let bytes = std::fs::read(path).map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
        Self::parse(&bytes, path)
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut flags = FLAG_POINTS;
        for (present, flag) in [
            (self.segments.is_some(), FLAG_SEGMENTS),
            (self.thickness.is_some(), FLAG_THICKNESS),
            (self.transparency.is_some(), FLAG_TRANSPARENCY),
            (self.colors.is_some(), FLAG_COLORS),
        ] {
            if present {
                flags |= flag;
            }
        }
        let mut out = Vec::with_capacity(HEADER + self.points.len() * 32);
        out.extend_from_slice(b"HAIR");
        let hair_count = self
            .segments
            .as_ref()
            .map_or(self.hair_count, |s| s.len() as u32);
        for v in [
            hair_count,
            self.points.len() as u32,
            flags,
            self.default_segments,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let defaults = [self.default_thickness, self.default_transparency];
        for v in defaults.into_iter().chain(self.default_color.to_array()) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.info);
        if let Some(segments) = &self.segments {
            segments
                .iter()
                .for_each(|s| out.extend_from_slice(&s.to_le_bytes()));
        }
        let put = |out: &mut Vec<u8>, v: f32| out.extend_from_slice(&v.to_le_bytes());
        self.points
            .iter()
            .flat_map(|p| p.to_array())
            .for_each(|v| put(&mut out, v));
        for array in [&self.thickness, &self.transparency].into_iter().flatten() {
            array.iter().for_each(|&v| put(&mut out, v));
        }
        if let Some(colors) = &self.colors {
            colors
                .iter()
                .flat_map(|c| c.to_array())
                .for_each(|v| put(&mut out, v));
        }
        out
    }

    /// Writes the file atomically.
    pub fn write(&self, path: &Path) -> Result<(), WriteError> {
        write_atomically(path, |w| w.write_all(&self.to_bytes()))
    }

    /// The hairs as [`Curves`]: thickness becomes width, `1 − transparency`
    /// opacity, colours are kept.
    pub fn to_curves(&self, path: &Path) -> Result<Curves, CurvesReadError> {
        let n = self.points.len();
        let mut offsets = vec![0u32];
        match &self.segments {
            Some(segments) => segments
                .iter()
                .for_each(|&s| offsets.push(offsets.last().unwrap() + s as u32 + 1)),
            None => (0..self.hair_count)
                .for_each(|_| offsets.push(offsets.last().unwrap() + self.default_segments + 1)),
        }
        let widths = self
            .thickness
            .clone()
            .unwrap_or_else(|| vec![self.default_thickness; n]);
        let fail = |e: crate::curves::CurvesError| CurvesReadError::whole(path, e.into());
        let mut curves = Curves::new(self.points.clone(), widths, offsets).map_err(fail)?;
        if let Some(t) = &self.transparency {
            curves = curves
                .with_opacities(t.iter().map(|t| 1.0 - t).collect())
                .map_err(fail)?;
        }
        if let Some(colors) = &self.colors {
            curves = curves.with_colors(colors.clone()).map_err(fail)?;
        }
        Ok(curves)
    }

    /// A `.hair` file holding `curves`: segments, points and thickness
    /// always, transparency and colours when the curves have them.
    /// Curves of more than 65,536 points do not fit the format.
    pub fn from_curves(curves: &Curves) -> Result<Self, HairWriteError> {
        let segments = (0..curves.curve_count())
            .map(|i| {
                let n = curves.range(i).len();
                u16::try_from(n.saturating_sub(1)).map_err(|_| HairWriteError::TooLong {
                    curve: i,
                    points: n,
                })
            })
            .collect::<Result<Vec<u16>, _>>()?;
        if let Some(curve) = (0..curves.curve_count()).find(|&i| curves.range(i).is_empty()) {
            return Err(HairWriteError::Empty { curve });
        }
        let mut info = [0u8; 88];
        let text = b"pelage";
        info[..text.len()].copy_from_slice(text);
        Ok(Self {
            hair_count: segments.len() as u32,
            segments: Some(segments),
            points: curves.points().to_vec(),
            thickness: Some(curves.widths().to_vec()),
            transparency: curves
                .opacities()
                .map(|o| o.iter().map(|o| 1.0 - o).collect()),
            colors: curves.colors().map(<[Vec3]>::to_vec),
            default_segments: 0,
            default_thickness: 1.0,
            default_transparency: 0.0,
            default_color: Vec3::ONE,
            info,
        })
    }
}

/// Curves that the `.hair` format cannot hold.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum HairWriteError {
    /// More points than a 16-bit segment count allows.
    #[error(".hair stores at most 65,535 segments per hair; curve {curve} has {points} points")]
    TooLong {
        /// The curve.
        curve: usize,
        /// Its point count.
        points: usize,
    },
    /// A curve without points.
    #[error(".hair cannot store curve {curve}: it has no points")]
    Empty {
        /// The curve.
        curve: usize,
    },
}
