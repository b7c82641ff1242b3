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

/// Opens and decodes an image file (PNG, EXR, …, by its contents) as
/// pelage reads every map and texture: the size in its header is checked
/// against [`crate::limits::MAX_IMAGE_PIXELS`] before any pixel memory is
/// allocated, so a small file declaring 20000 × 20000 pixels is an error,
/// not an abort; and under [`crate::io::protect_inputs`] the file is an
/// input no output may replace.
pub fn open_image(path: &Path) -> Result<image::DynamicImage, image::ImageError> {
    crate::io::check_input(path, "an image file")?;
    decode_within_limits(|| image::ImageReader::open(path)?.with_guessed_format())
}

/// Decodes an image from `reader` (made twice: once for the header, once
/// for the pixels), refusing more than [`crate::limits::MAX_IMAGE_PIXELS`]
/// before decoding.
fn decode_within_limits<R: std::io::BufRead + std::io::Seek>(
    reader: impl Fn() -> std::io::Result<image::ImageReader<R>>,
) -> Result<image::DynamicImage, image::ImageError> {
    // A header cut short is a broken image, not a failure to read a file.
    let broken = |e: image::ImageError| match e {
        image::ImageError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            image::ImageError::Decoding(image::error::DecodingError::new(
                image::error::ImageFormatHint::Unknown,
                e,
            ))
        }
        e => e,
    };
    let (width, height) = reader()?.into_dimensions().map_err(broken)?;
    check_image_size(width.into(), height.into()).map_err(|message| {
        image::ImageError::IoError(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            message,
        ))
    })?;
    let mut reader = reader()?;
    // The header was checked above; the decoder's own allocation limit
    // (512 MB by default) would refuse 8192² 16-bit RGBA.
    reader.no_limits();
    reader.decode()
}

/// Refuses an image of more than [`crate::limits::MAX_IMAGE_PIXELS`],
/// from the size in its header.
fn check_image_size(width: u64, height: u64) -> Result<(), String> {
    let pixels = width * height;
    let limit = crate::limits::MAX_IMAGE_PIXELS;
    if pixels <= limit {
        return Ok(());
    }
    Err(format!(
        "the image is {width} × {height} pixels ({:.0} M); pelage reads at most {} M pixels (8192 × 8192): scale it down (docs/limits.md)",
        pixels as f64 / 1e6,
        limit >> 20
    ))
}

/// An image file's width and height from its header alone (no pixel is
/// decoded), for totals over many images (the tiles of a UDIM map).
pub(crate) fn image_size(path: &Path) -> Result<(u64, u64), String> {
    if is_exr(path) {
        use exr::prelude::*;
        let meta = MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
        let header = meta.headers.first().ok_or("the EXR has no layer")?;
        let size = header.layer_size;
        return Ok((size.width() as u64, size.height() as u64));
    }
    let (w, h) = image::ImageReader::open(path)
        .map_err(|e| e.to_string())?
        .with_guessed_format()
        .map_err(|e| e.to_string())?
        .into_dimensions()
        .map_err(|e| e.to_string())?;
    Ok((w.into(), h.into()))
}

/// Whether `path` is an OpenEXR file (by its magic number).
fn is_exr(path: &Path) -> bool {
    let mut magic = [0u8; 4];
    std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic))
        .is_ok_and(|()| magic == [0x76, 0x2f, 0x31, 0x01])
}

/// One channel of an EXR's first layer, for files the image crate does
/// not decode (no R, G and B): `Y` stands in for each colour channel and
/// luminance, `A` is 1 where absent. Width, height, texels.
fn exr_channel(path: &Path, channel: Channel) -> Result<(u32, u32, Vec<f32>), String> {
    use exr::prelude::*;
    let meta = MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
    let header = meta.headers.first().ok_or("the EXR has no layer")?;
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    check_image_size(w as u64, h as u64)?;
    let image = read_first_flat_layer_from_file(path).map_err(|e| e.to_string())?;
    let channels = &image.layer_data.channel_data.list;
    let named = |wanted: &str| {
        channels.iter().find(|c| {
            let name = c.name.to_string();
            let last = name.rsplit('.').next().unwrap_or(&name).to_string();
            last.eq_ignore_ascii_case(wanted)
        })
    };
    let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
    let source = match channel {
        Channel::A => named("A"),
        Channel::R => named("R").or_else(|| named("Y")),
        Channel::G => named("G").or_else(|| named("Y")),
        Channel::B => named("B").or_else(|| named("Y")),
        Channel::Luminance => named("Y"),
    };
    let texels: Vec<f32> = match source {
        Some(c) => (0..w * h)
            .map(|i| c.sample_data.value_by_flat_index(i).to_f32())
            .collect(),
        None if channel == Channel::A => vec![1.0; w * h],
        None => {
            return Err(format!(
                "the EXR has channels {}: no {channel:?} and no Y to read",
                names.join(", ")
            ));
        }
    };
    Ok((w as u32, h as u32, texels))
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
        let decoded = match open_image(path) {
            Ok(decoded) => decoded,
            // Masks are often single-channel EXRs (Y, or A alone), which
            // the image crate does not decode.
            Err(image::ImageError::Decoding(_) | image::ImageError::Unsupported(_))
                if is_exr(path) =>
            {
                let (width, height, texels) = exr_channel(path, channel)
                    .map_err(|e| MapError::new(&name, MapErrorKind::Decode(e)))?;
                return Self::checked(&name, width, height, texels, wrap);
            }
            Err(image::ImageError::IoError(e)) => {
                return Err(MapError::new(&name, MapErrorKind::Io(e)));
            }
            Err(e) => return Err(MapError::new(&name, MapErrorKind::Decode(e.to_string()))),
        };
        Self::from_image(&name, &decoded, channel, wrap)
    }

    /// Decodes a PNG or EXR already in memory; `name` is what errors call it.
    pub fn from_bytes(
        name: &str,
        bytes: &[u8],
        channel: Channel,
        wrap: Wrap,
    ) -> Result<Self, MapError> {
        let decoded = decode_within_limits(|| {
            image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format()
        })
        .map_err(|e| MapError::new(name, MapErrorKind::Decode(e.to_string())))?;
        Self::from_image(name, &decoded, channel, wrap)
    }

    pub(crate) fn from_image(
        name: &str,
        decoded: &image::DynamicImage,
        channel: Channel,
        wrap: Wrap,
    ) -> Result<Self, MapError> {
        let rgba = decoded.to_rgba32f();
        let (width, height) = rgba.dimensions();
        let texels: Vec<f32> = rgba.pixels().map(|p| channel.pick(p.0)).collect();
        Self::checked(name, width, height, texels, wrap)
    }

    /// A map of decoded texels, refused where one is not finite.
    fn checked(
        name: &str,
        width: u32,
        height: u32,
        texels: Vec<f32>,
        wrap: Wrap,
    ) -> Result<Self, MapError> {
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

    /// Writes a one-channel EXR (`name` is the channel) to `path`.
    fn one_channel_exr(path: &Path, name: &str, values: Vec<f32>, width: usize) {
        use exr::prelude::*;
        let height = values.len() / width;
        let channels = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
            name,
            FlatSamples::F32(values),
        )]));
        Image::from_channels((width, height), channels)
            .write()
            .to_file(path)
            .unwrap();
    }

    #[test]
    fn single_channel_exr_masks_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let y = dir.path().join("mask_y.exr");
        one_channel_exr(&y, "Y", vec![0.25, 0.75], 2);
        for channel in [Channel::Luminance, Channel::R, Channel::G] {
            let m = ImageMap::load(&y, channel, Wrap::Clamp).unwrap();
            assert_eq!((m.texel(0, 0), m.texel(1, 0)), (0.25, 0.75), "{channel:?}");
        }
        // No A channel: opaque.
        assert_eq!(
            ImageMap::load(&y, Channel::A, Wrap::Clamp)
                .unwrap()
                .texel(1, 0),
            1.0
        );
        let a = dir.path().join("mask_a.exr");
        one_channel_exr(&a, "A", vec![0.5, 1.0, 0.0, 0.125], 2);
        let m = ImageMap::load(&a, Channel::A, Wrap::Clamp).unwrap();
        assert_eq!((m.width(), m.height(), m.texel(1, 1)), (2, 2, 0.125));
        // An alpha-only mask has no colour to read.
        let err = ImageMap::load(&a, Channel::R, Wrap::Clamp)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("mask_a.exr") && err.contains("channels A"),
            "{err}"
        );
    }
}
