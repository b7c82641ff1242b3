//! The groom grown on the GPU (`GpuGroom`, from a `GroomRecipe`) against
//! the CPU groom of the same frame (`Generator::part`,
//! `AnimatedGroom::part`): every operator alone, and a groom with all of
//! them (masks, maps, regions' worth of clumps at two levels); at rest, on
//! a posed Fox (hairs carried by the skin), on a Fox whose guides were
//! simulated, and with the hairs kept out of the skin at rest and posed. Every point of every hair, matched by hair id, must lie
//! within 1e-4 of the groom's size of the CPU's; widths and colours are the
//! CPU operators' own.
//! Needs an adapter (lavapipe serves); `PELAGE_REQUIRE_GPU=1` (CI) makes
//! a missing one a failure.

use glam::Vec3;
use image::RgbaImage;
use pelage::Curves;
use pelage::groom::{Generator, Groom, GroomRecipe};
use pelage::shell::{ShellTextureParams, ShellTextures};
use pelage_gpu::{
    Camera, FurLevel, FurLevelParams, FurLod, GpuContext, GpuGroom, ShellFeatures, ShellParams,
    ShellRenderer, ShellStandIn, ShellTarget, ShellView, StrandLook, StrandParams, StrandRenderer,
};
use std::collections::HashMap;
mod common;

use common::gpu;

const FOX: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../pelage/assets/fox/Fox.gltf");

/// A groom on the embedded Spot: `ops` are its `[[ops]]` tables.
fn spot_groom(ops: &[&str]) -> Groom {
    let mut text = String::from(
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 3000\nseed = 3\n\
         [guides]\npoints = 6\ngenerate = { count = 60, length = 0.08, comb = [0, -0.5, -1.0], gravity = 0.3, seed = 5 }\n\
         [finish]\npoints = 9\nwidth = { root = 0.002, tip = 0.0005, jitter = 0.2 }\n",
    );
    for op in ops {
        text.push_str(&format!("[[ops]]\n{op}\n"));
    }
    Groom::from_text("spot.toml", &text).unwrap_or_else(|e| panic!("{ops:?}: {e}"))
}

/// Every part's roots and ids, in part order.
fn all_roots(generator: &Generator) -> (Vec<pelage::mesh::SurfacePoint>, Vec<u64>) {
    let (mut roots, mut ids) = (Vec::new(), Vec::new());
    for p in 0..generator.parts().len() {
        let (r, i) = generator.part_roots(p);
        roots.extend(r);
        ids.extend(i);
    }
    (roots, ids)
}

/// The largest distance between matching points of `a` and `b`.
fn farthest_apart(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0f32, f32::max)
}

/// The largest distance, over every point of every hair matched by id,
/// between `cpu` and `gpu`, and the largest width difference.
fn farthest(cpu: &[Curves], gpu: &Curves) -> (f32, f32) {
    let index: HashMap<u64, usize> = gpu
        .ids()
        .unwrap()
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect();
    assert_eq!(index.len(), gpu.curve_count(), "every hair id once");
    let (mut far, mut wide, mut hairs) = (0f32, 0f32, 0);
    for part in cpu {
        let ids = part.ids().unwrap();
        for (c, id) in ids.iter().enumerate() {
            let g = *index
                .get(id)
                .unwrap_or_else(|| panic!("hair {id} is missing on the GPU"));
            let (a, b) = (part.range(c), gpu.range(g));
            assert_eq!(a.len(), b.len(), "hair {id}: point counts");
            far = far.max(farthest_apart(
                &part.points()[a.clone()],
                &gpu.points()[b.clone()],
            ));
            for (w, v) in part.widths()[a].iter().zip(&gpu.widths()[b]) {
                wide = wide.max((w - v).abs());
            }
            hairs += 1;
        }
    }
    assert_eq!(hairs, gpu.curve_count(), "as many hairs on both");
    (far, wide)
}

/// The groom's size: its skin's bounding box's largest side.
fn size_of(generator: &Generator) -> f32 {
    let (lo, hi) = generator.mesh().bounds();
    (hi - lo).max_element()
}

/// Grows `groom` at rest on the GPU and the CPU and compares them;
/// returns how many hairs grew.
fn compare_at_rest(ctx: &GpuContext, groom: &Groom, what: &str) -> usize {
    let generator = groom.generator(None).unwrap();
    let (roots, ids) = all_roots(&generator);
    let recipe = GroomRecipe::new(&generator, &roots, &ids).unwrap();
    let mut on_gpu =
        GpuGroom::new(ctx, &recipe, &GpuGroom::skin_at_rest(generator.mesh())).unwrap();
    let offsets = GroomRecipe::guide_offsets(generator.guides());
    on_gpu.grow(ctx, &offsets, None).unwrap();
    let gpu_curves = on_gpu.read_curves(ctx).unwrap();
    let cpu: Vec<Curves> = (0..generator.parts().len())
        .map(|p| generator.part(p).unwrap())
        .collect();
    let (far, wide) = farthest(&cpu, &gpu_curves);
    let size = size_of(&generator);
    assert!(
        far <= 1e-4 * size,
        "{what}: a point {far} from the CPU's (size {size})"
    );
    assert!(wide <= 1e-7, "{what}: a width {wide} from the CPU's");
    if let Some(colors) = cpu[0].colors() {
        let gpu_colors = gpu_curves.colors().expect("colours on the GPU too");
        assert_eq!(
            &gpu_colors[..colors.len().min(9)],
            &colors[..colors.len().min(9)]
        );
    }
    gpu_curves.curve_count()
}

#[test]
fn every_operator_alone_grows_as_on_the_cpu() {
    let Some(ctx) = gpu() else { return };
    let ops = [
        "length = { scale = 1.4, jitter = 0.3 }",
        "curl = { radius = 0.004, turns = 2.5 }",
        "twist = { angle = 120, jitter = 0.5, ramp = \"smooth\" }",
        "noise = { amplitude = 0.01, frequency = 20 }",
        "noise = { amplitude = 0.01, frequency = 20, vectors = 4 }",
        "frizz = { amplitude = 0.006, frequency = 5, fraction = 0.5 }",
        "flyaways = { spread = 0.02, fraction = 0.3 }",
        "clump = { count = 80, rate = 0.8, ramp = 1.5 }",
        "clump = { count = 80, rate = 0.8, size = 0.05 }",
        "width = { root = 0.003, tip = 0.001, jitter = 0.3 }",
        "color = { root = [0.5, 0.3, 0.1], tip = [0.9, 0.8, 0.6], jitter = 0.2 }",
        "opacity = { root = 1.0, tip = 0.3 }",
        "cut = { at = 0.6 }",
        "strands = { count = 4, root_spread = 0.001, tip_spread = 0.006, twist = 0.5 }",
    ];
    for op in ops {
        compare_at_rest(ctx, &spot_groom(&[op]), op);
    }
    // Strands before a clump: its centres are their strands' first hairs.
    let split_then_clump = [
        "strands = { count = 3, tip_spread = 0.005 }",
        "clump = { count = 60, rate = 0.6 }",
    ];
    compare_at_rest(ctx, &spot_groom(&split_then_clump), "strands, then clump");
    // Strands of strands: a hair's steps read the numbers of the hair it
    // was at that point of the chain (the cut its first strand's, the
    // noise its own); the second split masked (a root where the mask is 0
    // keeps its first strand whole); centres through both splits.
    let strands_of_strands = [
        "strands = { count = 3, root_spread = 0.001, tip_spread = 0.006 }",
        "cut = { at = \"noise:frequency=4,offset=0.5,scale=1.0\" }",
        "strands = { count = 2, tip_spread = 0.002, twist = 1.0, mask = \"noise:frequency=3,seed=2,offset=0.0,scale=1.0\" }",
        "clump = { count = 60, rate = 0.5 }",
        "noise = { amplitude = 0.004, frequency = 30 }",
    ];
    let hairs = compare_at_rest(ctx, &spot_groom(&strands_of_strands), "strands of strands");
    assert!(
        hairs > 3 * 3000 && hairs < 6 * 3000,
        "{hairs} hairs: some split twice, some once"
    );
    // Some hairs cut away whole (the map below 0 there): gone on both.
    let cut_away = "cut = { at = \"noise:frequency=3,offset=0.1,scale=1.0\" }";
    let hairs = compare_at_rest(ctx, &spot_groom(&[cut_away]), cut_away);
    assert!(hairs > 0 && hairs < 3000, "{hairs} hairs left");
}

#[test]
fn a_groom_with_every_operator_masked_mapped_and_clumped_twice_grows_as_on_the_cpu() {
    let Some(ctx) = gpu() else { return };
    let mask = "mask = \"noise:frequency=4,seed=9\"";
    let ops = [
        // Before the first clump: some of its centres are cut away whole
        // and grow bare, as the CPU grows them.
        format!("cut = {{ at = \"noise:frequency=5,offset=0.1,scale=1.2\", {mask} }}"),
        "clump = { count = 40, rate = 0.7 }".to_string(),
        "noise = { amplitude = \"noise:frequency=3,scale=0.02\", frequency = 15 }".into(),
        format!("clump = {{ count = 200, rate = 0.5, {mask} }}"),
        format!("curl = {{ radius = 0.003, turns = \"noise:frequency=2,offset=2\", {mask} }}"),
        "twist = { angle = 60 }".into(),
        format!("length = {{ scale = 1.2, jitter = 0.2, {mask} }}"),
        "frizz = { amplitude = 0.004, fraction = 0.3 }".into(),
        "flyaways = { spread = 0.01, fraction = 0.05 }".into(),
        "color = { root = [0.4, 0.3, 0.2], tip = [0.8, 0.7, 0.5] }".into(),
        format!("opacity = {{ root = 1.0, tip = 0.5, {mask} }}"),
        // After the clumps (their centres are strands' first hairs), and
        // masked: where the mask is 0 a root keeps one whole hair.
        format!("strands = {{ count = 3, tip_spread = 0.004, {mask} }}"),
        "width = { root = 0.003, tip = 0.001, jitter = 0.4 }".into(),
    ];
    let ops: Vec<&str> = ops.iter().map(String::as_str).collect();
    compare_at_rest(ctx, &spot_groom(&ops), "every operator");
}

/// The Fox running, with a groom in `mode` (`extra`: more sections).
fn fox_groom(mode: &str, extra: &str) -> Groom {
    fox_groom_kept_out(mode, extra, false)
}

/// [`fox_groom`], its hairs kept out of the skin or not (`outside_skin`,
/// an animated groom's default).
fn fox_groom_kept_out(mode: &str, extra: &str, outside: bool) -> Groom {
    let text = format!(
        "[mesh]\npath = {FOX:?}\n[roots]\ncount = 2000\n\
         [guides]\npoints = 8\ngenerate = {{ count = 120, length = 12.0, comb = [0, -0.2, -0.8] }}\n\
         [[ops]]\nclump = {{ count = 150, rate = 0.5 }}\n\
         [[ops]]\ncurl = {{ radius = 0.6, turns = 2 }}\n\
         [[ops]]\nnoise = {{ amplitude = 0.8, frequency = 0.15 }}\n\
         [finish]\npoints = 10\noutside_skin = {outside}\n\
         [animation]\nframes = \"1-4\"\nclip = \"Run\"\nmode = \"{mode}\"\n{extra}"
    );
    Groom::from_text("fox.toml", &text).unwrap()
}

/// The Fox's groom for Bevy (600 guides over the whole body, 40,000
/// hairs): on its thin ears and paws a hair's skin normal nearly opposes a
/// guide's, where the turn between them must be glam's rotation arc on
/// both sides (a half turn about an arbitrary axis put one hair's tip a
/// quarter unit off).
#[test]
fn the_fox_groom_for_bevy_grows_as_on_the_cpu() {
    let Some(ctx) = gpu() else { return };
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../pelage/assets/fox/fox.groom.toml"
    );
    let groom = Groom::load(std::path::Path::new(path)).unwrap();
    assert_eq!(compare_at_rest(ctx, &groom, "fox.groom.toml"), 40_000);
}

/// Frame `time` of `groom` on the GPU against the CPU's.
fn compare_posed(ctx: &GpuContext, groom: &Groom, time: f64, what: &str) {
    let animated = groom.animated(None).unwrap().expect("an animated groom");
    let rest = animated.generator();
    let (roots, ids) = all_roots(rest);
    let recipe = GroomRecipe::new(rest, &roots, &ids).unwrap();
    let mut on_gpu = GpuGroom::new(ctx, &recipe, animated.binding()).unwrap();
    let pose = animated.pose(time).unwrap();
    let guides = match animated.animation().mode.regrows() {
        true => animated
            .regrown_generator(time, &pose)
            .unwrap()
            .guides()
            .clone(),
        false => rest.guides().clone(),
    };
    on_gpu
        .grow(ctx, &GroomRecipe::guide_offsets(&guides), Some(&pose))
        .unwrap();
    let gpu_curves = on_gpu.read_curves(ctx).unwrap();
    let cpu: Vec<Curves> = (0..rest.parts().len())
        .map(|p| animated.part(p, time).unwrap())
        .collect();
    let (far, _) = farthest(&cpu, &gpu_curves);
    let size = size_of(rest);
    assert!(
        far <= 1e-4 * size,
        "{what}: a point {far} from the CPU's (size {size})"
    );
}

#[test]
fn a_posed_and_a_simulated_fox_grow_as_on_the_cpu() {
    let Some(ctx) = gpu() else { return };
    compare_posed(ctx, &fox_groom("deform", ""), 3.0, "deformed");
    let simulation = "[simulation]\ngravity = [0, -500, 0]\nfollow = 0\npreroll = 2\n";
    compare_posed(ctx, &fox_groom("simulate", simulation), 3.0, "simulated");
    // Kept out of the skin at rest and on the pose (an animated groom's
    // default `outside_skin`): the same grids' queries, the same pushes.
    let kept_out = fox_groom_kept_out("simulate", simulation, true);
    compare_posed(ctx, &kept_out, 1.0, "kept out, at rest");
    compare_posed(ctx, &kept_out, 3.0, "kept out, simulated");
}

/// Spot's groom drawn by the strand renderer over its skin, `size`²
/// pixels on pure blue, lit from `light` (toward the light) as the camera
/// at `eye` sees it; `shadows` turns the shadow map on.
fn draw_spot(ctx: &GpuContext, light: Vec3, eye: Vec3, shadows: bool) -> RgbaImage {
    const SIZE: u32 = 256;
    let groom = spot_groom(&["clump = { count = 300, rate = 0.3 }"]);
    // Thick enough to cover their pixels at this distance.
    let text = groom
        .source()
        .text
        .replace("count = 3000", "count = 20000")
        .replace("root = 0.002, tip = 0.0005", "root = 0.008, tip = 0.003");
    let groom = Groom::from_text("spot.toml", &text).unwrap();
    let generator = groom.generator(None).unwrap();
    let (roots, ids) = all_roots(&generator);
    let recipe = GroomRecipe::new(&generator, &roots, &ids).unwrap();
    let mut on_gpu =
        GpuGroom::new(ctx, &recipe, &GpuGroom::skin_at_rest(generator.mesh())).unwrap();
    let offsets = GroomRecipe::guide_offsets(generator.guides());
    on_gpu.grow(ctx, &offsets, None).unwrap();
    let shells = ShellRenderer::new(ctx, ShellFeatures::default());
    let strands = StrandRenderer::new(ctx, shells.target_formats());
    let mesh = generator.mesh();
    let textures = ShellTextures::generate(&ShellTextureParams {
        resolution: 16,
        layers: 1,
        ..Default::default()
    });
    let grey = RgbaImage::from_pixel(4, 4, image::Rgba([90, 80, 70, 255]));
    let model = shells.upload(ctx, mesh, &grey, &textures, 16).unwrap();
    let skin = ShellParams {
        background: [0.0, 0.0, 1.0],
        ..ShellParams::plain(0, 0.08)
    };
    let (lo, hi) = mesh.bounds();
    let camera = Camera {
        eye,
        target: 0.5 * (lo + hi),
        fov_y_degrees: 30.0,
    };
    let view = ShellView::new(Some(camera), (lo, hi), 0.1, 1.0, Some(light));
    let target = ShellTarget::new(ctx, &shells, SIZE, SIZE).unwrap();
    // Blond: light hair lets light through (TT), as blond fur glows
    // against the sun.
    let params = StrandParams {
        shadow_layer: shadows.then_some(0.02),
        look: StrandLook::from_melanin(0.15, 0.2, 0.3),
        ..StrandParams::for_length(0.08)
    };
    let grown = (lo - Vec3::splat(0.1), hi + Vec3::splat(0.1));
    let binding = strands.bind(ctx, &on_gpu);
    strands
        .render(
            ctx,
            &binding,
            &params,
            &view,
            grown,
            Some((&shells, &model, &skin)),
            &target,
        )
        .unwrap()
}

/// Whether pixel `p` is the background (pure blue).
fn background(p: &image::Rgba<u8>) -> bool {
    p.0[0] < 3 && p.0[1] < 3 && p.0[2] > 250
}

/// The mean red + green of the picture's fur pixels within `reach`
/// pixels of the background (the rim), and of all the others.
fn rim_and_inside(image: &RgbaImage, reach: i64) -> (f64, f64) {
    let (w, h) = (image.width() as i64, image.height() as i64);
    let (mut rim, mut rims, mut inside, mut insides) = (0.0, 0, 0.0, 0);
    for y in 0..h {
        for x in 0..w {
            let p = image.get_pixel(x as u32, y as u32);
            if background(p) {
                continue;
            }
            let near_background = (-reach..=reach).any(|dy| {
                (-reach..=reach).any(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..w).contains(&u)
                        && (0..h).contains(&v)
                        && background(image.get_pixel(u as u32, v as u32))
                })
            });
            let value = f64::from(p.0[0]) + f64::from(p.0[1]);
            if near_background {
                rim += value;
                rims += 1;
            } else {
                inside += value;
                insides += 1;
            }
        }
    }
    assert!(
        rims > 100 && insides > 100,
        "{rims} rim and {insides} inner pixels"
    );
    (rim / rims as f64, inside / insides as f64)
}

#[test]
fn strands_lit_from_behind_glow_at_the_rim_and_shadows_darken_the_hairs_below() {
    let Some(ctx) = gpu() else { return };
    let toward_eye = Vec3::new(1.0, 0.2, 0.15).normalize();
    let eye = 3.6 * toward_eye;
    let front = draw_spot(ctx, toward_eye, eye, true);
    let behind = draw_spot(ctx, -toward_eye, eye, true);
    let above = (Vec3::Y + 0.3 * toward_eye).normalize();
    let lit = draw_spot(ctx, above, eye, false);
    let shadowed = draw_spot(ctx, above, eye, true);
    if std::env::var_os("PELAGE_KEEP_PICTURES").is_some() {
        let pictures = [
            ("front", &front),
            ("behind", &behind),
            ("lit", &lit),
            ("shadowed", &shadowed),
        ];
        for (name, image) in pictures {
            image.save(format!("/tmp/strands-{name}.png")).unwrap();
        }
    }
    let (front_rim, _) = rim_and_inside(&front, 2);
    let (behind_rim, behind_inside) = rim_and_inside(&behind, 2);
    // The light through the hairs (TT) makes the back-lit rim the
    // brightest fur of either picture.
    assert!(
        behind_rim > 1.05 * front_rim && behind_rim > 2.0 * behind_inside,
        "rim lit from behind {behind_rim:.1}, from the front {front_rim:.1}; inside lit from behind {behind_inside:.1}"
    );
    // Light from above: the coat's top hairs keep their light, the ones
    // below them lose some.
    let fur = |image: &RgbaImage| {
        let mut values: Vec<f64> = image
            .pixels()
            .filter(|p| !background(p))
            .map(|p| f64::from(p.0[0]) + f64::from(p.0[1]))
            .collect();
        values.sort_by(f64::total_cmp);
        (values[values.len() / 2], values[values.len() * 19 / 20])
    };
    let ((lit_median, lit_top), (shadowed_median, shadowed_top)) = (fur(&lit), fur(&shadowed));
    assert!(
        shadowed_median < 0.85 * lit_median && shadowed_top > 0.8 * lit_top,
        "median {lit_median} → {shadowed_median}, brightest 5 % {lit_top} → {shadowed_top}"
    );
}

/// sRGB bytes of a linear colour.
fn srgb(c: Vec3) -> image::Rgba<u8> {
    let [r, g, b] = c
        .to_array()
        .map(|x| (255.0 * pelage::groom::linear_to_srgb(x)).round() as u8);
    image::Rgba([r, g, b, 255])
}

/// The share of `a`'s and `b`'s fur or skin pixels (not background in
/// either) that differ by more than 40/255 in a channel, and how many such
/// pixels there are.
fn changed(a: &RgbaImage, b: &RgbaImage) -> (f64, usize) {
    let (mut changed, mut object) = (0usize, 0usize);
    for (p, q) in a.pixels().zip(b.pixels()) {
        if background(p) && background(q) {
            continue;
        }
        object += 1;
        changed += usize::from((0..3).any(|c| p.0[c].abs_diff(q.0[c]) > 40));
    }
    (changed as f64 / object.max(1) as f64, object)
}

#[test]
fn the_level_of_detail_hands_over_from_strands_to_shells_without_a_pop() {
    let Some(ctx) = gpu() else { return };
    const SIZE: u32 = 192;
    let groom = spot_groom(&["clump = { count = 300, rate = 0.3 }"]);
    let text = groom
        .source()
        .text
        .replace("count = 3000", "count = 30000")
        .replace("root = 0.002, tip = 0.0005", "root = 0.004, tip = 0.0015");
    let groom = Groom::from_text("spot.toml", &text).unwrap();
    let generator = groom.generator(None).unwrap();
    let (roots, ids) = pelage::groom::roots_by_arrival(&generator);
    let recipe = GroomRecipe::new(&generator, &roots, &ids).unwrap();
    let mut on_gpu =
        GpuGroom::new(ctx, &recipe, &GpuGroom::skin_at_rest(generator.mesh())).unwrap();
    on_gpu
        .grow(ctx, &GroomRecipe::guide_offsets(generator.guides()), None)
        .unwrap();
    let shells = ShellRenderer::new(ctx, ShellFeatures::default());
    let strands = StrandRenderer::new(ctx, shells.target_formats());
    let binding = strands.bind(ctx, &on_gpu);
    let look = StrandLook::default();
    let stand_in = ShellStandIn::of(&generator, 16);
    let mesh = generator.mesh();
    let model = shells
        .upload(
            ctx,
            mesh,
            &RgbaImage::from_pixel(2, 2, srgb(stand_in.color(look.color))),
            &ShellTextures::generate(&stand_in.texture),
            16,
        )
        .unwrap();
    let base_shells = ShellParams {
        background: [0.0, 0.0, 1.0],
        ..ShellParams::plain(0, 0.08)
    }
    .for_stand_in(&stand_in);
    let base_strands = StrandParams {
        shadow_layer: None,
        ..StrandParams::for_length(0.08)
    };
    let (lo, hi) = mesh.bounds();
    let centre = 0.5 * (lo + hi);
    let height = (hi - lo).y;
    let lod = FurLod {
        full_px: 140.0,
        ..FurLod::default()
    };
    let target = ShellTarget::new(ctx, &shells, SIZE, SIZE).unwrap();
    let grown = (lo - Vec3::splat(0.1), hi + Vec3::splat(0.1));
    let hairs = recipe.render_hairs().len() as u32;
    let draw = |view: &ShellView, level: Option<&FurLevel>| {
        let (strand_params, shell_params) = match level {
            Some(level) => (
                level.strands(base_strands, hairs).unwrap_or(StrandParams {
                    hairs: Some(0),
                    ..base_strands
                }),
                level.shells(base_shells),
            ),
            // The skin alone.
            None => (
                StrandParams {
                    hairs: Some(0),
                    ..base_strands
                },
                ShellParams {
                    layers: 0,
                    ..base_shells
                },
            ),
        };
        strands
            .render(
                ctx,
                &binding,
                &strand_params,
                view,
                grown,
                Some((&shells, &model, &shell_params)),
                &target,
            )
            .unwrap()
    };
    let toward_eye = Vec3::new(1.0, 0.25, 0.3).normalize();
    let (mut worst_pop, mut least_fur) = (0.0f64, 1.0f64);
    let mut kinds = std::collections::BTreeSet::new();
    for rung in 0..17 {
        let eye = centre + 2.4 * 1.18f32.powi(rung) * toward_eye;
        let camera = Camera {
            eye,
            target: centre,
            fov_y_degrees: 30.0,
        };
        let view = ShellView::new(Some(camera), (lo, hi), 0.1, 1.0, None);
        let px = view.projected_length(centre, height, SIZE as f32);
        let here = lod.level(px);
        let next = lod.level(px / 1.18);
        kinds.insert((here.strand_opacity > 0.0, here.shell_opacity > 0.0));
        let now = draw(&view, Some(&here));
        let after = draw(&view, Some(&next));
        let bare = draw(&view, None);
        let (pop, _) = changed(&now, &after);
        let (fur, object) = changed(&now, &bare);
        assert!(
            object > 30,
            "rung {rung}: Spot is on screen ({object} pixels)"
        );
        worst_pop = worst_pop.max(pop);
        least_fur = least_fur.min(fur);
        if std::env::var_os("PELAGE_KEEP_PICTURES").is_some() {
            now.save(format!("/tmp/lod-{rung}.png")).unwrap();
        }
        assert!(
            pop <= 0.12 && fur >= 0.15,
            "rung {rung} ({px:.0} px, {here:?} → {next:?}): {:.0} % of the pixels change, fur on {:.0} %",
            100.0 * pop,
            100.0 * fur
        );
    }
    // The ladder went through strands alone, both, and shells alone.
    assert_eq!(kinds.len(), 3, "{kinds:?}");
    eprintln!(
        "worst hand-over {:.1} %, least fur {:.1} %",
        100.0 * worst_pop,
        100.0 * least_fur
    );
}

#[test]
fn guides_simulated_on_the_gpu_feed_the_hairs_without_a_read_back() {
    let Some(ctx) = gpu() else { return };
    use pelage::dynamics::{GuideSimulation, GuideStrandParams};
    let groom = fox_groom("deform", "");
    let animated = groom.animated(None).unwrap().unwrap();
    let rest = animated.generator();
    let (roots, ids) = all_roots(rest);
    let recipe = GroomRecipe::new(rest, &roots, &ids).unwrap();
    let triangles = animated.binding().triangles().to_vec();
    let size = size_of(rest);
    let params = GuideStrandParams {
        substeps: 2,
        gravity: Vec3::new(0.0, -9.81 * size / 1.4, 0.0),
        thickness: 0.004 * size,
        ..Default::default()
    };
    let first = animated.pose(1.0).unwrap();
    let mut sim =
        GuideSimulation::new(rest.guides(), &triangles, &first, params.clone(), true).unwrap();
    let mut strands = pelage_gpu::GpuStrands::new(ctx, sim.strands()).unwrap();
    let pose = animated.pose(3.0).unwrap();
    let (frames, grids) = (sim.root_frames(&pose), sim.substep_grids(&pose));
    strands
        .step(ctx, &params, 1.0 / 24.0, 0.1, &frames, &grids)
        .unwrap();
    sim.note_pose(&pose);
    // Read back and turned to rest on the CPU…
    let posed = strands.read_positions(ctx).unwrap();
    let n = rest.guides().points_per_guide();
    let mut points = vec![Vec3::ZERO; posed.len()];
    for (i, (&root, out)) in rest
        .guides()
        .roots()
        .iter()
        .zip(points.chunks_mut(n))
        .enumerate()
    {
        animated
            .binding()
            .to_rest(&posed[i * n..(i + 1) * n], root, &pose, out);
    }
    let frame_guides = rest.guides().with_points(points).unwrap();
    let mut read_back = GpuGroom::new(ctx, &recipe, animated.binding()).unwrap();
    read_back
        .grow(ctx, &GroomRecipe::guide_offsets(&frame_guides), Some(&pose))
        .unwrap();
    let a = read_back.read_curves(ctx).unwrap();
    // …and on the GPU, straight from the strands.
    let mut direct = GpuGroom::new(ctx, &recipe, animated.binding()).unwrap();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    direct
        .record_from_strands(ctx, &mut encoder, &strands, &pose)
        .unwrap();
    ctx.queue.submit([encoder.finish()]);
    let b = direct.read_curves(ctx).unwrap();
    let far = farthest_apart(a.points(), b.points());
    assert_eq!(a.ids(), b.ids());
    assert!(far <= 1e-4 * size, "a point {far} apart (size {size})");
    // The guides did move: the frame is not the rest groom.
    let mut at_rest = GpuGroom::new(ctx, &recipe, animated.binding()).unwrap();
    at_rest
        .grow(ctx, &GroomRecipe::guide_offsets(rest.guides()), Some(&pose))
        .unwrap();
    let c = at_rest.read_curves(ctx).unwrap();
    let moved = farthest_apart(c.points(), b.points());
    assert!(
        moved > 1e-3 * size,
        "the simulated guides moved the hairs ({moved})"
    );
}
