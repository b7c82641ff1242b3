//! Shell fur standing in for a groom far away (the real-time strands'
//! level of detail hands over to it): the shell texture's density matched
//! to the groom's hairs on the skin, its length the guides', its colour
//! the skin texture's or the look's, brightened to meet the strands'. Both
//! GPU hosts draw it: pelage-gpu's `RealtimeFur` and the Bevy plugin's
//! `GroomFur`.
//!
//! [`FurLod`] says when to draw what by a character's height on screen:
//! every strand near; as it gets smaller, fewer strands, the first hairs
//! by arrival (`pelage::groom::roots_by_arrival`: the hairs a preview
//! fraction grows), widths × 1/√F so the coat still covers the skin; at a
//! floor, a cross-fade to the stand-in; the stand-in alone far away. The
//! share follows the character's area on screen (`F = (h / full)²`), so
//! the hairs a pixel holds stay about the same from near to far.

use glam::{Vec2, Vec3};
use pelage::groom::ops::Operator;
use pelage::groom::{Generator, Groom, GroomError};
use pelage::map::MapSite;
use pelage::shell::ShellTextureParams;
use pelage::shell::math::ClumpParams;
use pelage::shell::wetness::{Droplet, WetnessMask, mask_coordinates};

/// How much brighter a stand-in's shells are coloured than its hairs.
const SHELL_GAIN: f32 = 1.8;

/// Shell fur standing in for a groom far away: its texture's density of
/// hairs per texel matched to the groom's on the skin, its length the
/// guides' mean length; its clumps, from the groom's first clump, are
/// [`clump_mask`]'s.
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

/// Each root's colour in the groom's base colour texture (linear RGB,
/// the nearest texel at the root's UV), for strands the groom gives no
/// colour of their own: the texture the stand-in is made of, so strands
/// near and shells far agree. `None` without a texture or UVs.
///
/// # Errors
/// When the texture cannot be read.
pub fn root_colors(
    groom: &Groom,
    mesh: &pelage::Mesh,
    roots: &[pelage::mesh::SurfacePoint],
) -> Result<Option<Vec<Vec3>>, GroomError> {
    let Some(image) = groom.base_color_texture()? else {
        return Ok(None);
    };
    if !mesh.has_uvs() {
        return Ok(None);
    }
    let image = image.to_rgb8();
    let (w, h) = image.dimensions();
    let linear = |x: u8| pelage::groom::srgb_to_linear(f32::from(x) / 255.0);
    Ok(Some(
        roots
            .iter()
            .map(|root| {
                // pelage's UVs start at the bottom left, images at the top.
                let uv = root.uv(mesh).unwrap_or_default();
                let x = ((uv.x.rem_euclid(1.0) * w as f32) as u32).min(w - 1);
                let y = (((1.0 - uv.y).rem_euclid(1.0) * h as f32) as u32).min(h - 1);
                let [r, g, b] = image.get_pixel(x, y).0;
                Vec3::new(linear(r), linear(g), linear(b))
            })
            .collect(),
    ))
}

/// Texels of a stand-in's clump mask a clump covers on average (the
/// mask's side is a power of two between [`LEAST_MASK`] and
/// [`MOST_MASK`]).
const TEXELS_A_CLUMP: f32 = 64.0;
const LEAST_MASK: u32 = 64;
const MOST_MASK: u32 = 1024;

/// The groom's first clump as the stand-in's shells clump it (Banisch's
/// Alg. 2 reading a wetness mask): each texel of a square mask over the
/// skin's UVs belongs to the nearest clump centre's root
/// ([`WetnessMask::of_clumps`]), within twice the distance to the
/// centre's nearest neighbour (a clump alone on a UV island does not
/// cover the square), wet by the clump's rate at the centre; the clump
/// bends the shells in along their length (`w = 1`: roots stay, tips
/// gather). `None` when the groom has no clump or the skin no UVs.
pub fn clump_mask(generator: &Generator) -> Option<(WetnessMask, ClumpParams)> {
    let mesh = generator.mesh();
    if !mesh.has_uvs() {
        return None;
    }
    let clump = generator
        .operators()
        .iter()
        .find_map(|op| match op.unmasked() {
            Operator::Clump(c) if !c.centres().surface_roots().is_empty() => Some(c),
            _ => None,
        })?;
    let roots = clump.centres().surface_roots();
    let centres: Vec<Vec2> = roots
        .iter()
        .map(|r| mask_coordinates(r.uv(mesh).unwrap_or_default()))
        .collect();
    let spread =
        pelage::nearest::NearestPoints::new(centres.iter().map(|c| c.extend(0.0)).collect());
    let mut nearest = Vec::new();
    let clumps: Vec<Droplet> = roots
        .iter()
        .zip(&centres)
        .map(|(&root, &centre)| {
            spread.nearest(centre.extend(0.0), 2, &mut nearest);
            let radius = nearest
                .get(1)
                .map_or(1.0, |n| 2.0 * n.distance_squared.sqrt());
            let site = MapSite::with_position(mesh, root, root.position(mesh));
            Droplet {
                centre,
                radius,
                wetness: clump.rate().at(&site),
            }
        })
        .collect();
    let side = (TEXELS_A_CLUMP * clumps.len() as f32)
        .sqrt()
        .ceil()
        .max(1.0) as u32;
    let side = side.next_power_of_two().clamp(LEAST_MASK, MOST_MASK);
    let params = ClumpParams {
        w: 1.0,
        strength: 1.0,
    };
    Some((WetnessMask::of_clumps(side, side, &clumps), params))
}

/// sRGB bytes of a linear colour.
pub fn srgb(c: Vec3) -> image::Rgba<u8> {
    let [r, g, b] = c
        .to_array()
        .map(|x| (255.0 * pelage::groom::linear_to_srgb(x)).round() as u8);
    image::Rgba([r, g, b, 255])
}

/// When to draw what, by a character's height on screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FurLod {
    /// At this height in pixels and above, every strand is drawn.
    pub full_px: f32,
    /// The smallest share of the strands drawn; below the height it is
    /// reached at, strands hand over to shells.
    pub floor: f32,
    /// The hand-over's length, a share of the height it starts at: the
    /// strands fade out and the shells in from that height down to
    /// `(1 − fade)` of it.
    pub fade: f32,
}

impl Default for FurLod {
    /// Every strand at 800 pixels (a character three quarters of a 1080p
    /// screen), down to a tenth of them at 253 pixels, shells alone below
    /// 177 pixels.
    fn default() -> Self {
        Self {
            full_px: 800.0,
            floor: 0.1,
            fade: 0.5,
        }
    }
}

/// What one level draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FurLevel {
    /// The share of the strands drawn (the first by arrival).
    pub fraction: f32,
    /// The strands' opacity (0: none drawn).
    pub strand_opacity: f32,
    /// The shells' opacity (0: none drawn).
    pub shell_opacity: f32,
}

impl FurLod {
    /// The level for a character `height_px` pixels high on screen.
    pub fn level(&self, height_px: f32) -> FurLevel {
        let floor = self.floor.clamp(1e-6, 1.0);
        let full = self.full_px.max(1e-3);
        let fraction = (height_px / full).powi(2).clamp(floor, 1.0);
        // The height the floor is reached at, and how far below it.
        let handover = full * floor.sqrt();
        let fade = self.fade.clamp(1e-3, 1.0);
        let t = ((handover - height_px) / (fade * handover)).clamp(0.0, 1.0);
        FurLevel {
            fraction,
            strand_opacity: 1.0 - t,
            shell_opacity: t,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn generator(ops: &str) -> Generator {
        let text = format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 2000\n\
             [guides]\ngenerate = {{ count = 40, length = 0.05 }}\n{ops}"
        );
        Groom::from_text("<stand-in>", text)
            .and_then(|g| g.generator(None))
            .expect("the test groom grows")
    }

    #[test]
    fn the_stand_in_clumps_where_the_grooms_first_clump_does() {
        let clumped = generator(
            "[[ops]]\nclump = { count = 50, rate = 0.6 }\n[[ops]]\nclump = { count = 400, rate = 0.3 }\n",
        );
        let (mask, params) = clump_mask(&clumped).expect("a clumped groom's stand-in clumps");
        assert_eq!(params.w, 1.0, "roots stay, tips gather");
        assert!(params.strength > 0.0);
        // 50 clumps of about 64 texels: the smallest mask.
        assert_eq!((mask.width(), mask.height()), (LEAST_MASK, LEAST_MASK));
        let Operator::Clump(first) = clumped.operators()[0].unmasked() else {
            panic!("the first operator is the clump");
        };
        // Every centre's own texel is its clump's, wet by the first
        // clump's rate (the second clump's 0.3 is not read).
        let mesh = clumped.mesh();
        let mut own = 0;
        for root in first.centres().surface_roots() {
            let centre = mask_coordinates(root.uv(mesh).unwrap());
            let texel = mask.at(centre);
            assert_eq!(texel.wetness, 0.6);
            own += usize::from(texel.centre == centre);
        }
        // A texel is a 64th of the square: two centres may share one.
        assert!(own >= 45, "{own} of 50 centres hold their own texel");
        assert!(mask.wet_fraction() > 0.2, "{}", mask.wet_fraction());
        assert!(clump_mask(&generator("")).is_none(), "no clump, no clumps");
    }
}
