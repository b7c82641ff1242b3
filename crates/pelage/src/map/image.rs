//! Image maps: one channel of a PNG (8 or 16 bit) or EXR (float), stored as
//! f32 texels and filtered bilinearly with texel centres at `(i + ½) / w`.

use super::{MapError, MapErrorKind};
use glam::Vec2;
use std::path::Path;

/// Which channel of an image a scalar map reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Channel {
    /// Rec. 709 luminance of RGB: `0.2126 r + 0.7152 g + 0.0722 b`.
    #[default]
    Luminance,
    /// Red.
    R,
    /// Green.
    G,
    /// Blue.
    B,
    /// Alpha (1 where the image has none).
    A,
}

impl Channel {
    /// Parses `luminance`/`lum`/`l`, `r`, `g`, `b`, `a`.
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s.to_ascii_lowercase().as_str() {
            "luminance" | "lum" | "l" => Self::Luminance,
            "r" | "red" => Self::R,
            "g" | "green" => Self::G,
            "b" | "blue" => Self::B,
            "a" | "alpha" => Self::A,
            _ => return None,
        })
    }

    fn pick(self, [r, g, b, a]: [f32; 4]) -> f32 {
        match self {
            Self::Luminance => 0.2126 * r + 0.7152 * g + 0.0722 * b,
            Self::R => r,
            Self::G => g,
            Self::B => b,
            Self::A => a,
        }
    }
}

/// What happens outside the unit UV square.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Wrap {
    /// The image tiles.
    #[default]
    Repeat,
    /// Edge texels extend outwards.
    Clamp,
}

impl Wrap {
    /// Parses `repeat`/`wrap` or `clamp`.
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "repeat" | "wrap" => Some(Self::Repeat),
            "clamp" => Some(Self::Clamp),
            _ => None,
        }
    }

    /// The texel holding coordinate `c` (in image widths) on an axis of `n`.
    #[inline]
    fn nearest(self, c: f32, n: u32) -> usize {
        let c = match self {
            Self::Repeat => c - floor(c),
            Self::Clamp => c,
        };
        (floor(c * n as f32).max(0.0) as usize).min(n as usize - 1)
    }

    /// The two texels around coordinate `c` (in image widths) on an axis
    /// of `n` texels and the blend between them. No division and no libm
    /// call: this is the density sampler's innermost work.
    #[inline]
    fn bilinear(self, c: f32, n: u32) -> (usize, usize, f32) {
        let last = n as i32 - 1;
        match self {
            Self::Repeat => {
                // Into [0, 1); rounding may give exactly 1, handled below.
                let c = c - floor(c);
                let x = c * n as f32 - 0.5;
                let x0 = floor(x);
                let i = x0 as i32;
                let a = if i < 0 { last } else { i.min(last) };
                let b = if i >= last { 0 } else { i + 1 };
                (a as usize, b as usize, x - x0)
            }
            Self::Clamp => {
                let x = c * n as f32 - 0.5;
                let x0 = floor(x);
                let i = x0 as i32;
                (
                    i.clamp(0, last) as usize,
                    (i + 1).clamp(0, last) as usize,
                    x - x0,
                )
            }
        }
    }
}

/// `x.floor()` without a libm call: Rust's baseline x86-64 target has no
/// SSE4.1 rounding instruction, and texture lookups are the density
/// sampler's hot path. Exact for |x| < 2³¹.
#[inline]
fn floor(x: f32) -> f32 {
    let t = x as i32 as f32;
    if t > x { t - 1.0 } else { t }
}

/// How texels are interpolated between their centres.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Filter {
    /// Bilinear between the four nearest texel centres (smooth).
    #[default]
    Bilinear,
    /// The texel the UV falls in (piecewise constant: a painted zero stays
    /// exactly zero up to the texel's edge).
    Nearest,
}

impl Filter {
    /// Parses `bilinear`/`linear` or `nearest`.
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "bilinear" | "linear" => Some(Self::Bilinear),
            "nearest" => Some(Self::Nearest),
            _ => None,
        }
    }
}

/// One channel of an image as f32 texels, rows from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageMap {
    width: u32,
    height: u32,
    texels: Vec<f32>,
    wrap: Wrap,
    filter: Filter,
}

impl ImageMap {
    /// Loads `channel` of a PNG or EXR file. 8- and 16-bit values are
    /// normalised to [0, 1]; float values are kept as they are.
    pub fn load(path: impl AsRef<Path>, channel: Channel, wrap: Wrap) -> Result<Self, MapError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let reader = image::ImageReader::open(path)
            .map_err(|e| MapError::new(&name, MapErrorKind::Io(e)))?
            .with_guessed_format()
            .map_err(|e| MapError::new(&name, MapErrorKind::Io(e)))?;
        let decoded = reader
            .decode()
            .map_err(|e| MapError::new(&name, MapErrorKind::Decode(e.to_string())))?;
        Self::from_image(&name, &decoded, channel, wrap)
    }

    /// Decodes a PNG or EXR already in memory; `name` is what errors call it.
    pub fn from_bytes(
        name: &str,
        bytes: &[u8],
        channel: Channel,
        wrap: Wrap,
    ) -> Result<Self, MapError> {
        let decoded = image::load_from_memory(bytes)
            .map_err(|e| MapError::new(name, MapErrorKind::Decode(e.to_string())))?;
        Self::from_image(name, &decoded, channel, wrap)
    }

    fn from_image(
        name: &str,
        decoded: &image::DynamicImage,
        channel: Channel,
        wrap: Wrap,
    ) -> Result<Self, MapError> {
        let rgba = decoded.to_rgba32f();
        let (width, height) = rgba.dimensions();
        let texels: Vec<f32> = rgba.pixels().map(|p| channel.pick(p.0)).collect();
        if let Some(i) = texels.iter().position(|t| !t.is_finite()) {
            let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
            return Err(MapError::new(name, MapErrorKind::NonFiniteTexel { x, y }));
        }
        Self::from_texels(width, height, texels, wrap).map_err(|kind| MapError::new(name, kind))
    }

    /// A map from texel values, `width × height`, rows from the top.
    pub fn from_texels(
        width: u32,
        height: u32,
        texels: Vec<f32>,
        wrap: Wrap,
    ) -> Result<Self, MapErrorKind> {
        if width == 0 || height == 0 {
            return Err(MapErrorKind::EmptyImage { width, height });
        }
        if texels.len() != width as usize * height as usize {
            return Err(MapErrorKind::Spec(format!(
                "{} texel values for a {width}×{height} image",
                texels.len()
            )));
        }
        Ok(Self {
            width,
            height,
            texels,
            wrap,
            filter: Filter::Bilinear,
        })
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texels, row-major, rows from the top of the image.
    pub fn texels(&self) -> &[f32] {
        &self.texels
    }

    /// The wrap mode.
    pub fn wrap(&self) -> Wrap {
        self.wrap
    }

    /// The filter.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// The same map with another filter.
    pub fn with_filter(mut self, filter: Filter) -> Self {
        self.filter = filter;
        self
    }

    /// The largest texel value (an upper bound of the filtered map).
    pub fn max_texel(&self) -> f32 {
        self.texels
            .iter()
            .copied()
            .fold(f32::NEG_INFINITY, f32::max)
    }

    /// The texel at column `x`, row `y` (from the top).
    pub fn texel(&self, x: u32, y: u32) -> f32 {
        self.texels[y as usize * self.width as usize + x as usize]
    }

    /// Filtered value at `uv`; v = 0 is the bottom row.
    pub fn eval(&self, uv: Vec2) -> f32 {
        match self.filter {
            Filter::Bilinear => self.eval_bilinear(uv),
            Filter::Nearest => self.eval_nearest(uv),
        }
    }

    fn eval_nearest(&self, uv: Vec2) -> f32 {
        let x = self.wrap.nearest(uv.x, self.width);
        let y = self.wrap.nearest(1.0 - uv.y, self.height);
        self.texels[y * self.width as usize + x]
    }

    fn eval_bilinear(&self, uv: Vec2) -> f32 {
        let (x0, x1, fx) = self.wrap.bilinear(uv.x, self.width);
        let (y0, y1, fy) = self.wrap.bilinear(1.0 - uv.y, self.height);
        let row = self.width as usize;
        let (r0, r1) = (&self.texels[y0 * row..], &self.texels[y1 * row..]);
        let top = r0[x0] + fx * (r0[x1] - r0[x0]);
        let bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
        top + fy * (bottom - top)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_centres_return_texel_values() {
        // 2×2: top row 1, 2; bottom row 3, 4.
        let m = ImageMap::from_texels(2, 2, vec![1.0, 2.0, 3.0, 4.0], Wrap::Clamp).unwrap();
        assert_eq!(m.eval(Vec2::new(0.25, 0.75)), 1.0); // top-left
        assert_eq!(m.eval(Vec2::new(0.75, 0.75)), 2.0);
        assert_eq!(m.eval(Vec2::new(0.25, 0.25)), 3.0); // bottom-left
        assert_eq!(m.eval(Vec2::new(0.5, 0.5)), 2.5); // bilinear centre
    }

    #[test]
    fn nearest_is_constant_over_each_texel() {
        let m = ImageMap::from_texels(2, 2, vec![1.0, 2.0, 3.0, 4.0], Wrap::Clamp)
            .unwrap()
            .with_filter(Filter::Nearest);
        assert_eq!(m.eval(Vec2::new(0.01, 0.99)), 1.0);
        assert_eq!(m.eval(Vec2::new(0.49, 0.51)), 1.0);
        assert_eq!(m.eval(Vec2::new(0.51, 0.51)), 2.0);
        assert_eq!(m.eval(Vec2::new(0.49, 0.49)), 3.0);
        assert_eq!(m.max_texel(), 4.0);
    }

    #[test]
    fn repeat_tiles_and_clamp_extends() {
        let r = ImageMap::from_texels(2, 1, vec![0.0, 1.0], Wrap::Repeat).unwrap();
        let c = ImageMap::from_texels(2, 1, vec![0.0, 1.0], Wrap::Clamp).unwrap();
        assert_eq!(r.eval(Vec2::new(1.25, 0.5)), r.eval(Vec2::new(0.25, 0.5)));
        // At u = 0 the repeat map blends the last and first texels.
        assert_eq!(r.eval(Vec2::new(0.0, 0.5)), 0.5);
        assert_eq!(c.eval(Vec2::new(0.0, 0.5)), 0.0);
        assert_eq!(c.eval(Vec2::new(7.0, 0.5)), 1.0);
    }

    #[test]
    fn sixteen_bit_png_keeps_its_precision() {
        let img =
            image::ImageBuffer::<image::Luma<u16>, _>::from_raw(2, 1, vec![0u16, 257]).unwrap();
        let mut bytes = Vec::new();
        img.write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
        let m = ImageMap::from_bytes("g16.png", &bytes, Channel::R, Wrap::Clamp).unwrap();
        assert!((m.texel(1, 0) - 257.0 / 65535.0).abs() < 1e-7);
    }

    #[test]
    fn exr_float_values_are_kept_unnormalised() {
        let img = image::Rgba32FImage::from_raw(1, 1, vec![3.5, 0.0, 0.0, 1.0]).unwrap();
        let mut bytes = Vec::new();
        image::DynamicImage::ImageRgba32F(img)
            .write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::OpenExr,
            )
            .unwrap();
        let m = ImageMap::from_bytes("f.exr", &bytes, Channel::R, Wrap::Clamp).unwrap();
        assert_eq!(m.texel(0, 0), 3.5);
    }
}
