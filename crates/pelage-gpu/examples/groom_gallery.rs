//! The groom operators' gallery, `docs/gallery/groom-op-*.png`: the same
//! patch of hair (a flat square, guides combed slightly to one side),
//! grown once without operators and once with each operator alone, seen
//! from the same camera; `groom-operators.png` puts them on one sheet in
//! the order none, noise, frizz, clump, clump on two levels, curl, cut,
//! length, strands, width, colour, twist, flyaways. Rendered by the preview renderer (lavapipe serves
//! without a GPU).
//!
//! ```sh
//! cargo run --release -p pelage-gpu --example groom_gallery
//! ```

use glam::Vec3;
use pelage::Mesh;
use pelage::groom::Groom;
use pelage::mesh::Uvs;
use pelage_gpu::{Camera, GpuContext, PreviewScene, PreviewStyle, Renderer};
use std::fmt::Write as _;

#[path = "common/patch.rs"]
mod patch;
use patch::patch;

const WIDTH: u32 = 480;
const HEIGHT: u32 = 360;

/// The base groom on the patch, with `ops` appended.
fn groom_text(hairs: u32, ops: &str) -> String {
    format!(
        r#"[mesh]
path = "patch.obj"
[roots]
count = {hairs}
[guides]
points = 8
generate = {{ count = 49, length = 0.32, comb = [0.25, 0, 0], seed = 3 }}
[finish]
points = 32
width = {{ root = 0.005, tip = 0.0012 }}
{ops}"#
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = tempfile_dir()?;
    let mesh = patch(16);
    write_obj(&mesh, &dir.join("patch.obj"))?;
    let ctx = GpuContext::headless()?;
    let renderer = Renderer::new(&ctx);
    let camera = Camera {
        eye: Vec3::new(0.0, 0.8, 1.45),
        target: Vec3::new(0.0, 0.12, -0.05),
        fov_y_degrees: 36.0,
    };
    let style = PreviewStyle {
        skin: [0.55, 0.47, 0.38],
        hair: [0.32, 0.16, 0.07],
        ..PreviewStyle::default()
    };
    let gallery = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/gallery");
    let cases: [(&str, u32, &str); 13] = [
        ("none", 2500, ""),
        (
            "noise",
            2500,
            "[[ops]]\nnoise = { amplitude = 0.09, frequency = 4 }\n",
        ),
        (
            "frizz",
            2500,
            "[[ops]]\nfrizz = { amplitude = 0.045, frequency = 5, fraction = 0.4 }\n",
        ),
        (
            "clump",
            2500,
            "[[ops]]\nclump = { count = 40, rate = 0.85 }\n",
        ),
        (
            "clump-two-levels",
            2500,
            "[[ops]]\nclump = { count = 8, rate = 0.5 }\n[[ops]]\nclump = { count = 60, rate = 0.85, ramp = 2 }\n",
        ),
        (
            "curl",
            900,
            "[[ops]]\ncurl = { radius = 0.022, turns = 3, ramp = 0.5 }\n",
        ),
        (
            "cut",
            2500,
            "[[ops]]\ncut = { at = \"noise:frequency=3,seed=5,offset=0.55,scale=0.6\" }\n",
        ),
        (
            "length",
            2500,
            "[[ops]]\nlength = { scale = 0.8, jitter = 0.35 }\n",
        ),
        (
            "strands",
            300,
            "[[ops]]\nstrands = { count = 8, root_spread = 0.004, tip_spread = 0.04, twist = 0.6 }\n",
        ),
        (
            "width",
            2500,
            "[[ops]]\nwidth = { root = 0.012, tip = 0.0004, ramp = 0.6, jitter = 0.5 }\n",
        ),
        (
            "color",
            2500,
            "[[ops]]\ncolor = { root = [0.05, 0.03, 0.02], tip = [0.95, 0.8, 0.55], ramp = \"smooth\", jitter = 0.3 }\n",
        ),
        (
            "twist",
            900,
            "[[ops]]\ntwist = { angle = 270, jitter = 0.2 }\n",
        ),
        (
            "flyaways",
            2500,
            "[[ops]]\nclump = { count = 40, rate = 0.85 }\n[[ops]]\nflyaways = { spread = 0.12, fraction = 0.06, length = 1.35, frequency = 3 }\n",
        ),
    ];
    let mut index = String::new();
    // All of them on one sheet, in the order above, four a row.
    let columns = 4u32;
    let rows = (cases.len() as u32).div_ceil(columns);
    let mut sheet =
        image::RgbaImage::from_pixel(columns * WIDTH, rows * HEIGHT, image::Rgba([255; 4]));
    for (k, (name, hairs, ops)) in cases.into_iter().enumerate() {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, groom_text(hairs, ops))?;
        let groom = Groom::load(&path)?;
        let generator = groom.generator(None)?;
        let parts = (0..generator.parts().len())
            .map(|p| generator.part(p))
            .collect::<Result<Vec<_>, _>>()?;
        let curves = pelage::curves::join(parts.iter())?;
        let scene = PreviewScene {
            mesh: Some(groom.mesh()),
            points: &[],
            curves: Some(&curves),
            skin_texture: None,
        };
        let image = renderer.render(&ctx, &scene, &style, Some(camera), WIDTH, HEIGHT)?;
        let out = gallery.join(format!("groom-op-{name}.png"));
        image.save(&out)?;
        let (x, y) = (k as u32 % columns * WIDTH, k as u32 / columns * HEIGHT);
        image::imageops::replace(&mut sheet, &image, i64::from(x), i64::from(y));
        writeln!(
            index,
            "{name}: {} hairs → {}",
            curves.curve_count(),
            out.display()
        )?;
    }
    let out = gallery.join("groom-operators.png");
    sheet.save(&out)?;
    writeln!(index, "all of them → {}", out.display())?;
    print!("{index}");
    println!("rendered on {}", ctx.adapter_name());
    Ok(())
}

/// A fresh folder under the system's temporary folder.
fn tempfile_dir() -> std::io::Result<std::path::PathBuf> {
    let dir = std::env::temp_dir().join(format!("pelage-groom-gallery-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// Writes `mesh` as OBJ with UVs (the groom file names a mesh file).
fn write_obj(mesh: &Mesh, path: &std::path::Path) -> std::io::Result<()> {
    let mut text = String::new();
    for p in mesh.positions() {
        let _ = writeln!(text, "v {} {} {}", p.x, p.y, p.z);
    }
    if let Some(Uvs::PerVertex(uvs)) = mesh.uvs() {
        for uv in uvs {
            let _ = writeln!(text, "vt {} {}", uv.x, uv.y);
        }
    }
    for t in mesh.triangles() {
        let [a, b, c] = t.map(|i| i + 1);
        let _ = writeln!(text, "f {a}/{a} {b}/{b} {c}/{c}");
    }
    std::fs::write(path, text)
}
