//! Shell fur standing in for a groom far away (the real-time strands'
//! level of detail hands over to it): the shell texture's density matched
//! to the groom's hairs on the skin, its length the guides', its colour
//! the skin texture's or the look's, brightened to meet the strands'. Both
//! GPU hosts draw it: pelage-gpu's `RealtimeFur` and the Bevy plugin's
//! `GroomFur`.

use glam::Vec3;
use pelage::groom::{Generator, Groom, GroomError};
use pelage::shell::ShellTextureParams;

/// How much brighter a stand-in's shells are coloured than its hairs.
const SHELL_GAIN: f32 = 1.8;

/// Shell fur standing in for a groom far away: its texture's density of
/// hairs per texel matched to the groom's on the skin, its length the
/// guides' mean length, its clumping from the groom's first clump.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellStandIn {
    /// The shell texture to generate.
    pub texture: ShellTextureParams,
    /// Texture repeats across the UV square.
    pub tiles: f32,
    /// The shells' length (world units).
    pub length: f32,
}

impl ShellStandIn {
    /// The stand-in for `generator`'s groom, with `layers` shells.
    pub fn of(generator: &Generator, layers: u32) -> Self {
        let guides = generator.guides();
        let length =
            (0..guides.len()).map(|g| guides.length(g)).sum::<f32>() / guides.len().max(1) as f32;
        let hairs: u64 = generator.parts().iter().map(|p| p.hair_count).sum();
        let mesh = generator.mesh();
        // The UV square's share the skin covers: its triangles' UV area.
        let uv_area: f32 = (0..mesh.triangle_count())
            .filter_map(|t| mesh.triangle_uvs(t))
            .map(|[a, b, c]| 0.5 * (b - a).perp_dot(c - a).abs())
            .sum::<f32>()
            .clamp(1e-3, 1.0);
        let texture = ShellTextureParams {
            layers,
            resolution: 256,
            ..Default::default()
        };
        // Guard hairs per texel as the texture's default, tiled as often
        // as the groom's hairs need over the skin's share of the square.
        let per_tile = texture.density * (texture.resolution as f32).powi(2);
        let tiles = (hairs as f32 / (uv_area * per_tile)).sqrt().max(1.0);
        Self {
            texture,
            tiles,
            length,
        }
    }

    /// The shells' colour for hairs of `color` (linear RGB): brighter, so
    /// that the shells, which lose light to their depth's shadow factor
    /// and have only a diffuse lobe and a faint highlight, are about as
    /// bright as the strands they take over from (the gain measured on
    /// Spot's level-of-detail ladder, `tests/groom.rs`).
    pub fn color(&self, color: Vec3) -> Vec3 {
        (SHELL_GAIN * color).min(Vec3::ONE)
    }
}

impl ShellStandIn {
    /// The stand-in's colour texture (sRGB): the groom's base colour
    /// texture brightened, or, without one, `hair` (linear RGB)
    /// brightened, as one flat texel block.
    pub fn color_texture(&self, groom: &Groom, hair: Vec3) -> Result<image::RgbaImage, GroomError> {
        Ok(match groom.base_color_texture()? {
            Some(image) => {
                let mut out = image.to_rgba8();
                for p in out.pixels_mut() {
                    let linear = Vec3::new(
                        pelage::groom::srgb_to_linear(f32::from(p.0[0]) / 255.0),
                        pelage::groom::srgb_to_linear(f32::from(p.0[1]) / 255.0),
                        pelage::groom::srgb_to_linear(f32::from(p.0[2]) / 255.0),
                    );
                    let [r, g, b, _] = srgb(self.color(linear)).0;
                    p.0[..3].copy_from_slice(&[r, g, b]);
                }
                out
            }
            None => image::RgbaImage::from_pixel(2, 2, srgb(self.color(hair))),
        })
    }
}

/// sRGB bytes of a linear colour.
pub fn srgb(c: Vec3) -> image::Rgba<u8> {
    let [r, g, b] = c
        .to_array()
        .map(|x| (255.0 * pelage::groom::linear_to_srgb(x)).round() as u8);
    image::Rgba([r, g, b, 255])
}
