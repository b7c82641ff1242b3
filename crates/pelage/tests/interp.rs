//! Guide interpolation as a groomer relies on it: hairs at guide roots are
//! those guides, weights are a partition of unity, and on a thin part the
//! style mesh keeps each side to its own guides where Shepard mixes them
//! (the Furtility talk's motivation).

use glam::Vec3;
use pelage::guides::{GuideGrowth, Guides};
use pelage::interp::{
    GuideWeight, GuideWeights, HairRoot, HairScratch, InterpolationMethod, Interpolator, Shepard,
    StyleMesh, StyleMeshOptions,
};
use pelage::mesh::TriangleBvh;
use pelage::{Curves, Mesh, SurfacePoint};

fn methods() -> [InterpolationMethod; 2] {
    [
        InterpolationMethod::Shepard {
            k: 6,
            power: 2.0,
            radius: None,
        },
        InterpolationMethod::StyleMesh(StyleMeshOptions::default()),
    ]
}

fn spot_guides() -> (Mesh, Guides) {
    let spot = pelage::assets::spot();
    let growth = GuideGrowth {
        count: 300,
        comb: Vec3::new(0.3, 0.0, 1.0),
        gravity: 0.5,
        ..GuideGrowth::default()
    };
    let guides = Guides::grow(&spot, &growth).unwrap();
    (spot, guides)
}

#[test]
fn a_hair_at_a_guide_root_is_that_guide() {
    let (spot, guides) = spot_guides();
    // On Spot's 2,930 vertices some of 300 random guides share their
    // nearest vertex; the style mesh reports those (they are not used) and
    // with split_shared gives every guide its own vertex.
    let lost: Vec<u32> = StyleMesh::build(&spot, &guides, &StyleMeshOptions::default())
        .lost()
        .iter()
        .map(|l| l.guide)
        .collect();
    assert!(!lost.is_empty() && lost.len() < 30, "{lost:?}");
    let mut methods = methods().to_vec();
    methods.push(InterpolationMethod::StyleMesh(StyleMeshOptions {
        split_shared: true,
    }));
    for method in methods {
        let interp = Interpolator::new(&spot, guides.clone(), &method);
        let (mut scratch, mut hair) = (
            HairScratch::default(),
            vec![Vec3::ZERO; guides.points_per_guide()],
        );
        let skip = |i: usize| {
            method == InterpolationMethod::StyleMesh(StyleMeshOptions::default())
                && lost.contains(&(i as u32))
        };
        for (i, root) in guides.roots().iter().enumerate().filter(|(i, _)| !skip(*i)) {
            interp.hair(&spot, *root, &mut scratch, &mut hair);
            for (a, b) in hair.iter().zip(guides.guide(i)) {
                assert!(
                    (*a - *b).length() <= 1e-5,
                    "{method:?} guide {i}: {a} vs {b}"
                );
            }
        }
    }
}

#[test]
fn weights_are_non_negative_and_sum_to_one() {
    let (spot, guides) = spot_guides();
    let shepard = Shepard::new(&spot, &guides, 8, 2.0, Some(0.3));
    let style = StyleMesh::build(&spot, &guides, &StyleMeshOptions::default());
    assert!(
        style.triangles().len() > guides.len(),
        "a surface of {} guides has more triangles",
        guides.len()
    );
    let mut w: Vec<GuideWeight> = Vec::new();
    for i in 0..2000u32 {
        let root = SurfacePoint::new(i * 7 % spot.triangle_count() as u32, [0.3, 0.4]);
        let on_skin = HairRoot::on(&spot, root);
        let anywhere = HairRoot::at(on_skin.position);
        for (method, root) in [
            (&shepard as &dyn GuideWeights, on_skin),
            (&style, on_skin),
            (&style, anywhere),
        ] {
            method.weights(root, &mut w);
            assert!(!w.is_empty());
            assert!(w.iter().all(|w| w.weight >= 0.0), "{w:?}");
            let sum: f32 = w.iter().map(|w| w.weight).sum();
            assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        }
    }
}

#[test]
fn straight_guides_give_hairs_along_their_own_normal() {
    // Tangent-space interpolation: shapes are turned into the hair's frame,
    // so hairs follow the surface's curvature instead of copying guide
    // directions.
    let spot = pelage::assets::spot();
    let guides = Guides::grow(
        &spot,
        &GuideGrowth {
            count: 200,
            ..GuideGrowth::default()
        },
    )
    .unwrap();
    for method in methods() {
        let interp = Interpolator::new(&spot, guides.clone(), &method);
        let (mut scratch, mut hair) = (HairScratch::default(), vec![Vec3::ZERO; 8]);
        for i in 0..300u32 {
            let root = SurfacePoint::new(i * 13 % spot.triangle_count() as u32, [0.2, 0.5]);
            interp.hair(&spot, root, &mut scratch, &mut hair);
            let along = (hair[7] - hair[0]).normalize();
            assert!(
                along.dot(root.normal(&spot)) > 0.999,
                "{method:?}: {along} vs {}",
                root.normal(&spot)
            );
        }
    }
}

/// A plate `1 × 1` and `thickness` thin, closed, its big faces gridded
/// `n × n` (the sides are single strips joining the two rims).
fn thin_plate(n: usize, thickness: f32) -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let index =
        |side: usize, i: usize, j: usize| (side * (n + 1) * (n + 1) + j * (n + 1) + i) as u32;
    for (side, z) in [(0, 0.5 * thickness), (1, -0.5 * thickness)] {
        for j in 0..=n {
            for i in 0..=n {
                positions.push(Vec3::new(i as f32 / n as f32, j as f32 / n as f32, z));
            }
        }
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (
                    index(side, i, j),
                    index(side, i + 1, j),
                    index(side, i + 1, j + 1),
                    index(side, i, j + 1),
                );
                // Top faces +z, bottom faces −z.
                if side == 0 {
                    triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    triangles.extend([[a, c, b], [a, d, c]]);
                }
            }
        }
    }
    // The rim loop, counter-clockwise seen from +z.
    let mut rim = Vec::new();
    rim.extend((0..n).map(|i| (i, 0)));
    rim.extend((0..n).map(|j| (n, j)));
    rim.extend((0..n).map(|i| (n - i, n)));
    rim.extend((0..n).map(|j| (0, n - j)));
    for k in 0..rim.len() {
        let (p, q) = (rim[k], rim[(k + 1) % rim.len()]);
        let (t0, t1) = (index(0, p.0, p.1), index(0, q.0, q.1));
        let (b0, b1) = (index(1, p.0, p.1), index(1, q.0, q.1));
        triangles.extend([[t0, b0, b1], [t0, b1, t1]]);
    }
    Mesh::new("thin plate", positions, triangles, None, None).unwrap()
}

/// 25 guides on each face of the plate at the same (x, y): combed +x on
/// top, −x underneath.
fn plate_guides(plate: &Mesh, thickness: f32) -> Guides {
    let (mut points, mut offsets) = (Vec::new(), vec![0u32]);
    for (z, normal, comb) in [
        (0.5 * thickness, Vec3::Z, Vec3::X),
        (-0.5 * thickness, Vec3::NEG_Z, Vec3::NEG_X),
    ] {
        for j in 0..5 {
            for i in 0..5 {
                let root = Vec3::new((i as f32 + 0.5) / 5.0, (j as f32 + 0.5) / 5.0, z);
                points.extend((0..4).map(|k| root + k as f32 * (0.02 * normal + 0.05 * comb)));
                offsets.push(points.len() as u32);
            }
        }
    }
    let widths = vec![0.002; points.len()];
    let curves = Curves::new(points, widths, offsets).unwrap();
    let (guides, report) = Guides::bind(plate, &curves, 4, 1e-4);
    assert!(report.dropped.is_empty(), "{:?}", report.dropped);
    guides
}

#[test]
fn on_a_thin_plate_the_style_mesh_keeps_each_side_to_its_guides_and_shepard_does_not() {
    let thickness = 0.02; // a tenth of the guide spacing
    let plate = thin_plate(40, thickness);
    let guides = plate_guides(&plate, thickness);
    let style = StyleMesh::build(&plate, &guides, &StyleMeshOptions::default());
    assert!(style.lost().is_empty(), "{:?}", style.lost());
    let shepard = Shepard::new(&plate, &guides, 8, 2.0, None);
    let interp_style = Interpolator::new(
        &plate,
        guides.clone(),
        &InterpolationMethod::StyleMesh(StyleMeshOptions::default()),
    );
    let interp_shepard = Interpolator::new(
        &plate,
        guides.clone(),
        &InterpolationMethod::Shepard {
            k: 8,
            power: 2.0,
            radius: None,
        },
    );
    let (mut w, mut hair) = (Vec::new(), vec![Vec3::ZERO; 4]);
    let (mut shepard_wrong, mut hairs) = (0.0f32, 0);
    let skin = TriangleBvh::new(plate.positions(), plate.triangles());
    for j in 0..12 {
        for i in 0..12 {
            // Hairs on top, away from the rim.
            let root = Vec3::new(
                0.2 + 0.6 * i as f32 / 11.0,
                0.2 + 0.6 * j as f32 / 11.0,
                0.5 * thickness,
            );
            // On the skin (its own cells) and by position alone (closest
            // point on the whole style mesh): both stay on top.
            let triangle = skin.closest(root).unwrap().triangle;
            for hair_root in [
                HairRoot {
                    position: root,
                    triangle: Some(triangle),
                    region: 0,
                },
                HairRoot::at(root),
            ] {
                style.weights(hair_root, &mut w);
                let wrong: f32 = w.iter().filter(|w| w.guide >= 25).map(|w| w.weight).sum();
                assert_eq!(
                    wrong, 0.0,
                    "style-mesh hair at {hair_root:?} takes weight from the underside: {w:?}"
                );
            }
            interp_style.shape(&w, root, Vec3::Z, &mut hair);
            assert!(
                hair[3].x - root.x > 0.14,
                "style-mesh hair at {root} is not combed +x: {hair:?}"
            );

            shepard.weights(HairRoot::at(root), &mut w);
            shepard_wrong += w
                .iter()
                .filter(|w| w.guide >= 25)
                .map(|w| w.weight)
                .sum::<f32>();
            interp_shepard.shape(&w, root, Vec3::Z, &mut hair);
            hairs += 1;
        }
    }
    // Shepard counts guides through the plate: about half the weight
    // comes from the underside.
    let mean_wrong = shepard_wrong / hairs as f32;
    assert!(
        mean_wrong > 0.3,
        "Shepard took only {mean_wrong} from the underside"
    );
}

#[test]
fn guides_denser_than_the_mesh_are_reported_and_splitting_gives_each_its_vertex() {
    let spot = pelage::assets::spot();
    // Five guides inside one triangle, plus some elsewhere.
    let mut roots: Vec<SurfacePoint> =
        [[0.1, 0.1], [0.6, 0.2], [0.2, 0.6], [0.3, 0.3], [0.05, 0.8]]
            .into_iter()
            .map(|b| SurfacePoint::new(100, b))
            .collect();
    roots.extend((0..40).map(|i| SurfacePoint::new(i * 131 + 7, [0.3, 0.3])));
    let (mut points, mut offsets) = (Vec::new(), vec![0u32]);
    for r in &roots {
        let (p, n) = (r.position(&spot), r.normal(&spot));
        points.extend([p, p + 0.05 * n, p + 0.1 * n]);
        offsets.push(points.len() as u32);
    }
    let curves = Curves::new(points, vec![0.01; roots.len() * 3], offsets).unwrap();
    let (guides, _) = Guides::bind(&spot, &curves, 3, 1e-4);
    let style = StyleMesh::build(&spot, &guides, &StyleMeshOptions::default());
    // Three corners for five guides: at least two lose their vertex.
    assert!(style.lost().len() >= 2, "{:?}", style.lost());
    assert!(style.lost().iter().all(|l| l.guide < 5 && l.kept_by < 5));
    assert!(style.lost()[0].to_string().contains("is not used: vertex"));

    let split = StyleMesh::build(&spot, &guides, &StyleMeshOptions { split_shared: true });
    assert!(split.lost().is_empty());
    let interp = Interpolator::with_weights(&spot, guides.clone(), Box::new(split));
    let (mut scratch, mut hair) = (HairScratch::default(), vec![Vec3::ZERO; 3]);
    for (i, root) in guides.roots().iter().enumerate() {
        interp.hair(&spot, *root, &mut scratch, &mut hair);
        for (a, b) in hair.iter().zip(guides.guide(i)) {
            assert!((*a - *b).length() <= 1e-5, "guide {i}: {a} vs {b}");
        }
    }
}

#[test]
fn methods_are_found_by_name() {
    assert!(matches!(
        InterpolationMethod::by_name("shepard"),
        Some(InterpolationMethod::Shepard { k: 4, .. })
    ));
    assert!(matches!(
        InterpolationMethod::by_name("style-mesh"),
        Some(InterpolationMethod::StyleMesh(_))
    ));
    assert!(InterpolationMethod::by_name("nearest").is_none());
}

#[test]
fn a_guide_alone_on_an_island_still_shapes_the_hairs_there() {
    // Two plates far apart, one guide on the small one: its cell touches
    // no other, so the style mesh holds it as a point, and hairs on that
    // plate take it alone (a degenerate style mesh still has a closest
    // point).
    let big = thin_plate(20, 0.02);
    let small = thin_plate(4, 0.02);
    let offset = Vec3::new(5.0, 0.0, 0.0);
    let mut positions = big.positions().to_vec();
    let base = positions.len() as u32;
    positions.extend(small.positions().iter().map(|p| *p + offset));
    let mut triangles = big.triangles().to_vec();
    triangles.extend(small.triangles().iter().map(|t| t.map(|v| v + base)));
    let mesh = Mesh::new("two plates", positions, triangles, None, None).unwrap();
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for root in [
        Vec3::new(0.3, 0.3, 0.01),
        Vec3::new(0.7, 0.6, 0.01),
        Vec3::new(0.5, 0.5, 0.01) + offset,
    ] {
        points.extend([root, root + Vec3::new(0.0, 0.0, 0.1)]);
        offsets.push(points.len() as u32);
    }
    let curves = Curves::new(points, vec![0.01; 6], offsets).unwrap();
    let (guides, report) = Guides::bind(&mesh, &curves, 2, 1e-4);
    assert_eq!(report.kept, 3);
    let style = StyleMesh::build(&mesh, &guides, &StyleMeshOptions::default());
    assert!(
        style.closest_point_set().contains(&[2, 2, 2]),
        "{:?}",
        style.closest_point_set()
    );
    let mut w = Vec::new();
    style.weights(HairRoot::at(Vec3::new(0.9, 0.1, 0.01) + offset), &mut w);
    assert_eq!(
        w,
        vec![GuideWeight {
            guide: 2,
            weight: 1.0
        }]
    );
    // The two guides on the big plate share a border: a segment, no
    // triangle; a hair between them mixes just those two.
    assert!(style.triangles().is_empty());
    style.weights(HairRoot::at(Vec3::new(0.5, 0.45, 0.01)), &mut w);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w.iter().all(|w| w.guide < 2));
}

#[test]
fn hairs_on_the_skin_mostly_pick_the_same_style_triangle_as_the_global_closest_point() {
    // The cell-local search looks only at the hair's own cells; the closest
    // point on the whole style mesh may lie elsewhere only near cell
    // borders. Count how often the two agree on the guides.
    let (spot, guides) = spot_guides();
    let style = StyleMesh::build(&spot, &guides, &StyleMeshOptions::default());
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let mut same = 0;
    let n = 5000u32;
    for i in 0..n {
        let root = SurfacePoint::new(i * 7919 % spot.triangle_count() as u32, [0.25, 0.35]);
        let on_skin = HairRoot::on(&spot, root);
        style.weights(on_skin, &mut a);
        style.weights(HairRoot::at(on_skin.position), &mut b);
        let guides = |w: &[GuideWeight]| {
            let mut g: Vec<u32> = w.iter().map(|w| w.guide).collect();
            g.sort_unstable();
            g
        };
        same += (guides(&a) == guides(&b)) as u32;
    }
    let agreement = same as f32 / n as f32;
    eprintln!(
        "cell-local and global closest points agree on {:.1} % of hairs",
        100.0 * agreement
    );
    assert!(agreement > 0.9, "{agreement}");
}

/// Reference colouring: one multi-source Dijkstra with a binary heap, as
/// the talk describes it (a colour passes on while it is the closest seen).
fn reference_colours(mesh: &Mesh, style: &StyleMesh) -> Vec<u32> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let adjacency = mesh.vertex_adjacency();
    let p = mesh.positions();
    let mut best = vec![(f32::INFINITY, u32::MAX); p.len()];
    let mut heap = BinaryHeap::new();
    for (g, root) in style.positions().iter().enumerate() {
        // The seed: the vertex of colour g nearest the guide's root (the
        // marked vertex, the nearest corner of the root's triangle).
        let seed = style
            .colours()
            .iter()
            .enumerate()
            .filter(|&(_, &c)| c == g as u32)
            .min_by(|a, b| {
                (p[a.0] - *root)
                    .length_squared()
                    .total_cmp(&(p[b.0] - *root).length_squared())
            })
            .map(|(v, _)| v);
        if let Some(v) = seed {
            best[v] = (0.0, g as u32);
            heap.push(Reverse((0u32, g as u32, v as u32)));
        }
    }
    while let Some(Reverse((d, g, v))) = heap.pop() {
        let d = f32::from_bits(d);
        if best[v as usize] != (d, g) {
            continue;
        }
        for &n in adjacency.neighbors(v as usize) {
            let nd = d + (p[n as usize] - p[v as usize]).length();
            let (cd, cg) = best[n as usize];
            if nd < cd || (nd == cd && g < cg) {
                best[n as usize] = (nd, g);
                heap.push(Reverse((nd.to_bits(), g, n)));
            }
        }
    }
    best.into_iter().map(|(_, g)| g).collect()
}

#[test]
fn the_parallel_colouring_equals_one_dijkstra_on_any_number_of_threads() {
    let spot = pelage::assets::spot().subdivided(1);
    let guides = Guides::grow(
        &spot,
        &GuideGrowth {
            count: 150,
            ..GuideGrowth::default()
        },
    )
    .unwrap();
    let build = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| StyleMesh::build(&spot, &guides, &StyleMeshOptions::default()))
    };
    let (one, two) = (build(1), build(2));
    assert_eq!(one.colours(), two.colours());
    assert_eq!(one.triangles(), two.triangles());
    assert!(one.lost().is_empty(), "{:?}", one.lost());
    assert_eq!(one.colours(), reference_colours(&spot, &one).as_slice());
}
