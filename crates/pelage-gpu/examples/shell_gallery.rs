//! Reproduces the shell-fur figures of Silva et al. and Banisch & Wüthrich
//! into `docs/gallery/` (run from the repository root):
//!
//! ```text
//! cargo run --release -p pelage-gpu --example shell_gallery
//! ```
//!
//! Each sheet is a row of panels, left to right as in the paper's figure:
//! - `silva-fig1.png`: straight, curly, dry, wet clumped (spot),
//! - `silva-fig7.png`: straight, wavy, few large curls, many small curls,
//! - `silva-fig9.png`: clumps with w = 0 and w = 1, seen from the side,
//! - `silva-fig11.png`: dry vs wet clumped, the wetness mask inset,
//! - `silva-fig12c.png`: "CGI10" written in water on a furry square, mask
//!   inset,
//! - `banisch-fig2.png`: structure, colour, self-shadow, shading,
//! - `shells-textures.png`: a Banisch layer stack beside Lengyel's random
//!   strands (layers 1, N/2, N).

use glam::{Vec2, Vec3};
use pelage::Mesh;
use pelage::shell::math::{ClumpParams, CurlParams, ShadingMode};
use pelage::shell::wetness::{DropletStyle, droplets_from_image, droplets_on_mesh};
use pelage::shell::{ShellScene, ShellTextureParams, ShellTextures, TextureStyle, WetnessMask};
use pelage_gpu::{
    Camera, GpuContext, ShellFeatures, ShellParams, ShellRenderer, ShellTarget, ShellView,
};
use std::f32::consts::TAU;
use std::path::Path;

#[path = "common/patch.rs"]
mod patch;
use patch::patch;

const WIDTH: u32 = 480;
const HEIGHT: u32 = 360;

struct Panel<'a> {
    mesh: &'a Mesh,
    color: &'a image::RgbaImage,
    textures: &'a ShellTextures,
    mask: &'a WetnessMask,
    params: ShellParams,
    camera: Option<Camera>,
}

fn render(ctx: &GpuContext, panel: &Panel) -> image::RgbaImage {
    let features = ShellFeatures {
        curl: panel.params.curl.radius != 0.0,
        clump: panel.mask.wet_fraction() > 0.0,
        cull_back: false,
    };
    let renderer = ShellRenderer::new(ctx, features);
    let model = renderer
        .upload(
            ctx,
            panel.mesh,
            panel.color,
            panel.textures,
            panel.mask.width(),
        )
        .expect("upload");
    renderer.set_wetness(ctx, &model, panel.mask).expect("mask");
    let target = ShellTarget::new(ctx, &renderer, WIDTH, HEIGHT).expect("target");
    let view = ShellView::new(
        panel.camera,
        panel.mesh.bounds(),
        panel.params.length,
        WIDTH as f32 / HEIGHT as f32,
        None,
    );
    renderer
        .render(ctx, &model, &panel.params, &view, &target)
        .expect("render")
}

/// The mask's picture, `size` pixels wide, in the top-left corner.
fn inset(image: &mut image::RgbaImage, mask: &WetnessMask, size: u32) {
    let small = image::imageops::resize(
        &mask.preview(),
        size,
        size,
        image::imageops::FilterType::Nearest,
    );
    image::imageops::replace(image, &small, 4, 4);
}

fn sheet(path: &Path, panels: &[image::RgbaImage]) {
    let mut sheet = image::RgbaImage::from_pixel(
        WIDTH * panels.len() as u32 + 4 * (panels.len() as u32 - 1),
        HEIGHT,
        image::Rgba([255; 4]),
    );
    for (i, p) in panels.iter().enumerate() {
        image::imageops::replace(&mut sheet, p, i64::from(i as u32 * (WIDTH + 4)), 0);
    }
    sheet.save(path).expect("write the sheet");
    println!("wrote {}", path.display());
}

/// "CGI10" in a 5 × 7 pixel font, as a brightness function over the mask.
fn cgi10(p: Vec2) -> f32 {
    const GLYPHS: [[&str; 7]; 5] = [
        [
            ".###.", "#...#", "#....", "#....", "#....", "#...#", ".###.",
        ],
        [
            ".###.", "#...#", "#....", "#.###", "#...#", "#...#", ".###.",
        ],
        [
            ".###.", "..#..", "..#..", "..#..", "..#..", "..#..", ".###.",
        ],
        [
            "..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###.",
        ],
        [
            ".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###.",
        ],
    ];
    // Five glyphs of 5 columns + 1 gap = 29 columns across 0.08..0.92.
    let (x, y) = ((p.x - 0.08) / 0.84 * 29.0, (p.y - 0.3) / 0.4 * 7.0);
    if !(0.0..29.0).contains(&x) || !(0.0..7.0).contains(&y) {
        return 0.0;
    }
    let (glyph, column) = ((x as usize) / 6, (x as usize) % 6);
    if column == 5 {
        return 0.0;
    }
    let row = GLYPHS[glyph][y as usize].as_bytes();
    f32::from(u8::from(row[column] == b'#'))
}

fn main() {
    let out = Path::new("docs/gallery");
    std::fs::create_dir_all(out).expect("docs/gallery");
    let ctx = GpuContext::headless().expect("a GPU adapter (lavapipe will do)");
    println!("rendering on {}", ctx.adapter_name());
    let scene = ShellScene::spot();
    let spot = &scene.mesh;
    let textures = ShellTextures::generate(&ShellTextureParams {
        layers: 32,
        ..scene.texture
    });
    let base = ShellParams {
        layers: 32,
        ..ShellParams::from_scene(&scene)
    };
    let length = base.length;
    let curly = CurlParams {
        radius: 0.5 * length,
        frequency: 2.0 * TAU,
    };
    let straight = CurlParams {
        radius: 0.0,
        frequency: 0.0,
    };
    let dry = WetnessMask::dry_mask(256, 256);
    let mut wet = dry.clone();
    let drops = DropletStyle {
        radius_min: 0.02,
        radius_max: 0.04,
        wetness: 1.0,
    };
    for d in droplets_on_mesh(spot, 260, drops, 5).expect("droplets") {
        wet.add_droplet(d);
    }
    // A closer camera on spot's flank.
    let (lo, hi) = spot.bounds();
    let centre = 0.5 * (lo + hi);
    let close = Some(Camera {
        eye: centre + Vec3::new(1.6, 0.5, 1.2),
        target: centre + Vec3::new(0.0, 0.05, 0.0),
        fov_y_degrees: 30.0,
    });
    let panel = |params: ShellParams, mask: &WetnessMask| {
        render(
            &ctx,
            &Panel {
                mesh: spot,
                color: &scene.color,
                textures: &textures,
                mask,
                params,
                camera: close,
            },
        )
    };

    // Fig. 1: straight, curly, dry, wet clumped.
    sheet(
        &out.join("silva-fig1.png"),
        &[
            panel(
                ShellParams {
                    curl: straight,
                    ..base
                },
                &dry,
            ),
            panel(
                ShellParams {
                    curl: curly,
                    ..base
                },
                &dry,
            ),
            panel(
                ShellParams {
                    curl: curly,
                    ..base
                },
                &dry,
            ),
            panel(
                ShellParams {
                    curl: curly,
                    ..base
                },
                &wet,
            ),
        ],
    );

    // Fig. 7 on a furry square: straight, wavy, few large curls, many small.
    let square = patch(32);
    let brown = image::RgbaImage::from_pixel(1, 1, image::Rgba([150, 105, 60, 255]));
    let square_length = 0.1;
    let square_textures = ShellTextures::generate(&ShellTextureParams {
        layers: 64,
        density: 0.012,
        thickness: 2.2,
        lean: 0.003,
        undercoat_ratio: 1.0,
        ..scene.texture
    });
    let side = Some(Camera {
        eye: Vec3::new(0.0, 0.62, 0.45),
        target: Vec3::new(0.0, 0.0, 0.02),
        fov_y_degrees: 40.0,
    });
    let square_base = ShellParams {
        layers: 64,
        length: square_length,
        tiles: 2.5,
        ..base
    };
    let square_panel = |params: ShellParams, mask: &WetnessMask| {
        render(
            &ctx,
            &Panel {
                mesh: &square,
                color: &brown,
                textures: &square_textures,
                mask,
                params,
                camera: side,
            },
        )
    };
    let curl = |radius: f32, turns: f32| CurlParams {
        radius: radius * square_length,
        frequency: turns * TAU,
    };
    sheet(
        &out.join("silva-fig7.png"),
        &[
            square_panel(
                ShellParams {
                    curl: straight,
                    ..square_base
                },
                &dry,
            ),
            square_panel(
                ShellParams {
                    curl: curl(0.12, 1.0),
                    ..square_base
                },
                &dry,
            ),
            square_panel(
                ShellParams {
                    curl: curl(0.35, 1.25),
                    ..square_base
                },
                &dry,
            ),
            square_panel(
                ShellParams {
                    curl: curl(0.1, 4.0),
                    ..square_base
                },
                &dry,
            ),
        ],
    );

    // Fig. 9: w = 0 and w = 1, sparse straight guard hair in big clumps,
    // seen from above at an angle.
    let mut square_wet = WetnessMask::dry_mask(256, 256);
    let big = DropletStyle {
        radius_min: 0.085,
        radius_max: 0.09,
        wetness: 1.0,
    };
    for d in droplets_from_image(|_| 1.0, 0.2, big, 9) {
        square_wet.add_droplet(d);
    }
    let sparse = ShellTextures::generate(&ShellTextureParams {
        layers: 64,
        density: 0.012,
        thickness: 1.8,
        lean: 0.004,
        undercoat_ratio: 0.0,
        ..scene.texture
    });
    let pale = image::RgbaImage::from_pixel(1, 1, image::Rgba([225, 200, 160, 255]));
    let low = Some(Camera {
        eye: Vec3::new(0.0, 0.62, 0.45),
        target: Vec3::new(0.0, 0.0, 0.02),
        fov_y_degrees: 40.0,
    });
    let clump_panel = |w: f32| {
        render(
            &ctx,
            &Panel {
                mesh: &square,
                color: &pale,
                textures: &sparse,
                mask: &square_wet,
                params: ShellParams {
                    layers: 64,
                    length: 0.1,
                    tiles: 4.0,
                    curl: straight,
                    clump: ClumpParams { w, strength: 4.0 },
                    ..base
                },
                camera: low,
            },
        )
    };
    sheet(
        &out.join("silva-fig9.png"),
        &[clump_panel(0.0), clump_panel(1.0)],
    );

    // Fig. 11: dry vs wet clumped, with the mask.
    let mut wet_panel = panel(
        ShellParams {
            curl: straight,
            ..base
        },
        &wet,
    );
    inset(&mut wet_panel, &wet, 110);
    let mut dry_panel = panel(
        ShellParams {
            curl: straight,
            ..base
        },
        &dry,
    );
    inset(&mut dry_panel, &dry, 110);
    sheet(&out.join("silva-fig11.png"), &[dry_panel, wet_panel]);

    // Fig. 12c: a word written in water, seen from above.
    let mut word = WetnessMask::dry_mask(256, 256);
    let small = DropletStyle {
        radius_min: 0.012,
        radius_max: 0.016,
        wetness: 1.0,
    };
    for d in droplets_from_image(cgi10, 0.012, small, 3) {
        word.add_droplet(d);
    }
    let above = Some(Camera {
        eye: Vec3::new(0.0, 1.5, 0.6),
        target: Vec3::new(0.0, 0.0, 0.02),
        fov_y_degrees: 36.0,
    });
    let light_fur = image::RgbaImage::from_pixel(1, 1, image::Rgba([215, 190, 150, 255]));
    let mut word_panel = render(
        &ctx,
        &Panel {
            mesh: &square,
            color: &light_fur,
            textures: &square_textures,
            mask: &word,
            params: ShellParams {
                length: 0.06,
                tiles: 4.0,
                clump: ClumpParams {
                    w: 0.6,
                    strength: 6.0,
                },
                ..square_base
            },
            camera: above,
        },
    );
    inset(&mut word_panel, &word, 110);
    sheet(&out.join("silva-fig12c.png"), &[word_panel]);

    // Banisch Fig. 2: structure, colour, self-shadow, shading.
    let stage = |mode: ShadingMode| {
        panel(
            ShellParams {
                curl: straight,
                mode,
                ..base
            },
            &dry,
        )
    };
    sheet(
        &out.join("banisch-fig2.png"),
        &[
            stage(ShadingMode::Structure),
            stage(ShadingMode::Color),
            stage(ShadingMode::Shadow),
            stage(ShadingMode::Lambert),
        ],
    );

    // The textures themselves: Banisch blades vs Lengyel strands, layers
    // 1, N/2 and N of 16.
    let params = ShellTextureParams {
        layers: 16,
        ..scene.texture
    };
    let banisch = ShellTextures::generate(&params);
    let lengyel = ShellTextures::generate(&ShellTextureParams {
        style: TextureStyle::RandomStrands,
        ..params
    });
    let r = params.resolution;
    let mut stack = image::GrayImage::from_pixel(r * 3 + 8, r * 2 + 4, image::Luma([255]));
    for (row, t) in [&banisch, &lengyel].iter().enumerate() {
        for (col, n) in [0, 7, 15].iter().enumerate() {
            image::imageops::replace(
                &mut stack,
                &t.layer_image(*n),
                i64::from(col as u32 * (r + 4)),
                i64::from(row as u32 * (r + 4)),
            );
        }
    }
    let path = out.join("shells-textures.png");
    stack.save(&path).expect("write");
    println!("wrote {}", path.display());
}
