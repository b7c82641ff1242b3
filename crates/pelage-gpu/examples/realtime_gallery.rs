//! The gallery of real-time strands, `docs/gallery/`:
//!
//! - `realtime-fox.png`: the Fox mid-run, its groom grown on the GPU from
//!   the frame's pose and drawn as shaded strands with self-shadowing;
//! - `realtime-lobes.png`: the same coat lit from the front and from
//!   behind (the back-lit rim is the light through the hairs, TT);
//! - `target/realtime-reference/fox8.usdc`: the same groom at the same
//!   frame, grown on the CPU and written with its skin, for Cycles to
//!   render beside the still (`realtime-vs-cycles.png`):
//!
//! ```sh
//! cargo run --release -p pelage-gpu --example realtime_gallery
//! tools/bpy-python blender/render_realtime_reference.py target/realtime-reference/fox8.usdc docs/gallery/realtime-fox.png docs/gallery/realtime-vs-cycles.png
//! ```

use glam::Vec3;
use image::{GenericImage, RgbaImage};
use pelage::groom::{AnimatedGroom, Groom, GroomRecipe};
use pelage::shell::{ShellTextureParams, ShellTextures};
use pelage_gpu::{
    Camera, GpuContext, GpuGroom, ShellFeatures, ShellParams, ShellRenderer, ShellTarget,
    ShellView, StrandParams, StrandRenderer,
};
use std::path::Path;

/// The Fox's groom: long fur, clumped and waved, coloured by its skin's
/// texture (a glTF's base colour, the default of `[finish] color`).
fn fox_groom(assets: &Path, hairs: u32, frames: &str) -> Result<Groom, Box<dyn std::error::Error>> {
    let fox = assets.join("Fox.gltf");
    let text = format!(
        "[mesh]\npath = {fox:?}\n\
         [roots]\ncount = {hairs}\nseed = 1\n\
         [guides]\npoints = 12\ngenerate = {{ count = 600, length = 9, comb = [0, -0.2, -0.8], gravity = 0.3, seed = 7 }}\n\
         [[ops]]\nclump = {{ count = 3000, rate = 0.35 }}\n\
         [[ops]]\nnoise = {{ amplitude = 0.4, frequency = 0.15 }}\n\
         [finish]\npoints = 12\noutside_skin = false\n\
         width = {{ root = 0.9, tip = 0.25 }}\n\
         [animation]\nframes = \"{frames}\"\nrest_frame = 1\nfps = 24\nclip = \"Run\"\nmode = \"deform\"\n"
    );
    Ok(Groom::from_text("fox.toml", &text)?)
}

/// Draws the Fox at `time` with its strands, seen by `view`.
struct FoxFrame<'a> {
    animated: &'a AnimatedGroom,
    gpu_groom: &'a mut GpuGroom,
    shells: &'a ShellRenderer,
    strands: &'a StrandRenderer,
    skin_color: RgbaImage,
    textures: ShellTextures,
}

impl FoxFrame<'_> {
    fn draw(
        &mut self,
        ctx: &GpuContext,
        time: f64,
        view: &ShellView,
        size: (u32, u32),
    ) -> Result<RgbaImage, Box<dyn std::error::Error>> {
        let animated = self.animated;
        let pose = animated.pose(time)?;
        let offsets = GroomRecipe::guide_offsets(animated.generator().guides());
        self.gpu_groom.grow(ctx, &offsets, Some(&pose))?;
        let mesh = animated.posed_mesh(&pose)?;
        let model = self
            .shells
            .upload(ctx, &mesh, &self.skin_color, &self.textures, 64)?;
        let shell_params = ShellParams::plain(0, 9.0);
        let target = ShellTarget::new(ctx, self.shells, size.0, size.1)?;
        let binding = self.strands.bind(ctx, self.gpu_groom);
        let (lo, hi) = mesh.bounds();
        let grown = (lo - Vec3::splat(9.0), hi + Vec3::splat(9.0));
        let params = StrandParams::for_length(9.0);
        Ok(self.strands.render(
            ctx,
            &binding,
            &params,
            view,
            grown,
            Some((self.shells, &model, &shell_params)),
            &target,
        )?)
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = GpuContext::headless()?;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let gallery = root.join("docs/gallery");
    let assets = root.join("crates/pelage/assets/fox");
    let groom = fox_groom(&assets, 100_000, "1-28")?;
    let animated = groom.animated(None)?.expect("an animated groom");
    let rest = animated.generator();
    let (mut roots, mut ids) = (Vec::new(), Vec::new());
    for p in 0..rest.parts().len() {
        let (r, i) = rest.part_roots(p);
        roots.extend(r);
        ids.extend(i);
    }
    let recipe = GroomRecipe::new(rest, &roots, &ids)?;
    let mut gpu_groom = GpuGroom::new(&ctx, &recipe, animated.binding())?;
    let shells = ShellRenderer::new(&ctx, ShellFeatures::default());
    let strands = StrandRenderer::new(&ctx, shells.target_formats());
    let mut frame = FoxFrame {
        animated: &animated,
        gpu_groom: &mut gpu_groom,
        shells: &shells,
        strands: &strands,
        skin_color: image::load_from_memory(pelage::assets::FOX_TEXTURE_PNG)?.to_rgba8(),
        textures: ShellTextures::generate(&ShellTextureParams {
            resolution: 16,
            layers: 1,
            ..Default::default()
        }),
    };
    let (w, h) = (800, 520);
    let camera = Camera {
        eye: Vec3::new(190.0, 85.0, 140.0),
        target: Vec3::new(0.0, 40.0, -10.0),
        fov_y_degrees: 32.0,
    };
    let view = ShellView::new(
        Some(camera),
        rest.mesh().bounds(),
        9.0,
        w as f32 / h as f32,
        None,
    );
    let still = frame.draw(&ctx, 8.0, &view, (w, h))?;
    still.save(gallery.join("realtime-fox.png"))?;
    println!("wrote realtime-fox.png");

    // Front and back light, the camera on the Fox's side.
    let (w, h) = (480, 360);
    let side = Camera {
        eye: Vec3::new(330.0, 70.0, 30.0),
        target: Vec3::new(0.0, 45.0, 0.0),
        fov_y_degrees: 34.0,
    };
    let toward_camera = (side.eye - side.target).normalize();
    let mut pair = RgbaImage::new(2 * w, h);
    for (i, light) in [toward_camera, -toward_camera + 0.25 * Vec3::Y]
        .into_iter()
        .enumerate()
    {
        let view = ShellView::new(
            Some(side),
            rest.mesh().bounds(),
            9.0,
            w as f32 / h as f32,
            Some(light.normalize()),
        );
        pair.copy_from(&frame.draw(&ctx, 1.0, &view, (w, h))?, i as u32 * w, 0)?;
    }
    pair.save(gallery.join("realtime-lobes.png"))?;
    println!("wrote realtime-lobes.png");

    // The still's groom and frame for Cycles: grown at rest on the CPU,
    // carried to frame 8, written with the posed skin.
    let reference = root.join("target/realtime-reference");
    std::fs::create_dir_all(&reference)?;
    let one_frame = fox_groom(&assets, 100_000, "8")?;
    let animated = one_frame.animated(None)?.expect("an animated groom");
    let parts = 0..animated.generator().parts().len();
    let usd = reference.join("fox8.usdc");
    animated.write(&usd, parts, &one_frame.usd_options(), true, |_| {})?;
    println!("wrote {}", usd.display());
    Ok(())
}
