//! Groom craft end to end: hair ids and roots that survive a change of the
//! count or a local density edit, regions that interpolation and clumps
//! never cross, masks, maps on meshes without UVs, blue-noise roots, and
//! clumps that stay on their side of thin parts.

mod support;

use glam::{Vec2, Vec3};
use pelage::Curves;
use pelage::groom::ops::Operator;
use pelage::groom::{
    ClumpParams, Generator, Groom, GroomOp, GroomSpec, LengthParams, NoiseParams, RegionsSpec,
    RootDistribution, RootsSpec,
};
use pelage::guides::{GuideGrowth, Guides};
use pelage::interp::{InterpolationMethod, NearestPoints, StyleMeshOptions};
use pelage::map::{Filter, ImageMap, Map, Wrap};
use pelage::mesh::{Mesh, SurfacePoint, Uvs};
use pelage::sample::{DensitySampler, SurfaceSampler};
use std::collections::HashMap;
use std::sync::Arc;
use support::chi_square::assert_fits;

/// Every part of a groom.
fn grow(generator: &Generator) -> Vec<Curves> {
    (0..generator.parts().len())
        .map(|p| generator.part(p).unwrap())
        .collect()
}

/// Each hair by id: its root and the bits of its points.
fn by_id(parts: &[Curves]) -> HashMap<u64, (SurfacePoint, Vec<u32>)> {
    let mut out = HashMap::new();
    for c in parts {
        let (ids, roots) = (c.ids().unwrap(), c.roots().unwrap());
        for i in 0..c.curve_count() {
            let bits: Vec<u32> = c.points()[c.range(i)]
                .iter()
                .flat_map(|p| p.to_array().map(f32::to_bits))
                .collect();
            assert!(
                out.insert(ids[i], (roots[i], bits)).is_none(),
                "id {} twice",
                ids[i]
            );
        }
    }
    out
}

fn spot_guides(mesh: &Mesh, count: usize) -> Guides {
    let growth = GuideGrowth {
        count,
        length: Map::Constant(0.04),
        comb: Vec3::new(0.0, -0.5, 0.0),
        points: 6,
        ..Default::default()
    };
    Guides::grow(mesh, &growth).unwrap()
}

fn spot_spec(count: u64, density: Map) -> GroomSpec {
    let mesh = Arc::new(pelage::assets::spot());
    let guides = spot_guides(&mesh, 80);
    GroomSpec::new(
        mesh,
        guides,
        RootsSpec::new(count).with_density(density).with_seed(5),
    )
    .with_op(GroomOp::Clump(ClumpParams::new(150)))
    .with_op(GroomOp::Noise(NoiseParams::new(Map::Constant(0.002))))
    .with_op(GroomOp::Length(LengthParams {
        jitter: Map::Constant(0.2),
        ..LengthParams::new(Map::Constant(1.0))
    }))
}

#[test]
fn raising_the_count_keeps_every_hair_bit_for_bit_and_lowering_it_moves_none() {
    let density = Map::parse("noise:frequency=3,offset=0.6,scale=0.4").unwrap();
    let grown = |n| by_id(&grow(&spot_spec(n, density.clone()).generator().unwrap()));
    let (small, large) = (grown(3_000), grown(7_000));
    assert_eq!((small.len(), large.len()), (3_000, 7_000));
    for (id, hair) in &small {
        let Some(same) = large.get(id) else {
            panic!("hair {id} of 3,000 is gone at 7,000");
        };
        assert_eq!(same.0, hair.0, "hair {id}'s root moved");
        assert_eq!(same.1, hair.1, "hair {id}'s shape changed");
    }
    // Parts and threads do not matter either: 11 parts give the same hairs.
    let mut spec = spot_spec(3_000, density.clone());
    spec.roots.parts = Some(11);
    assert_eq!(by_id(&grow(&spec.generator().unwrap())), small);
}

#[test]
fn a_fraction_is_a_subset_of_the_groom_with_wider_hairs_and_fractions_nest() {
    let density = Map::parse("noise:frequency=3,offset=0.6,scale=0.4").unwrap();
    let spec = |fraction: f64| {
        let mut s = spot_spec(8_000, density.clone());
        s.roots.fraction = fraction;
        s
    };
    let grown = |f: f64| grow(&spec(f).generator().unwrap());
    let (full, fifth, tenth) = (grown(1.0), grown(0.2), grown(0.1));
    let (full_ids, fifth_ids, tenth_ids) = (by_id(&full), by_id(&fifth), by_id(&tenth));
    assert_eq!(
        (full_ids.len(), fifth_ids.len(), tenth_ids.len()),
        (8_000, 1_600, 800)
    );
    for (small, large) in [(&tenth_ids, &fifth_ids), (&fifth_ids, &full_ids)] {
        for (id, hair) in small {
            assert_eq!(
                large.get(id),
                Some(hair),
                "hair {id} is not kept bit for bit"
            );
        }
    }
    // Widths: the full groom's times 1/√F.
    let widths = |parts: &[Curves]| -> HashMap<u64, Vec<f32>> {
        parts
            .iter()
            .flat_map(|c| {
                (0..c.curve_count())
                    .map(move |i| (c.ids().unwrap()[i], c.widths()[c.range(i)].to_vec()))
            })
            .collect()
    };
    let (full_w, tenth_w) = (widths(&full), widths(&tenth));
    let scale = (1.0 / 0.1f64.sqrt()) as f32;
    for (id, w) in &tenth_w {
        let expected: Vec<f32> = full_w[id].iter().map(|x| x * scale).collect();
        assert_eq!(w, &expected, "hair {id}'s widths");
    }
    // A fraction of grooms that renumber or thin every root is refused.
    let mut sequential = spec(0.5);
    sequential.roots.ids = pelage::groom::HairIds::Sequential;
    let err = sequential.generator().unwrap_err();
    assert!(
        matches!(err.kind, pelage::groom::GroomErrorKind::Conflict(_)),
        "{err}"
    );
    // Blamed on the setting that rules a fraction out.
    assert_eq!(err.at.key.as_deref(), Some("roots.ids"), "{err}");
    assert!(err.to_string().contains("stable ids"), "{err}");
    assert!(spec(0.0).generator().is_err());
    assert!(spec(1.5).generator().is_err());
}

#[test]
fn a_local_density_edit_leaves_hairs_far_from_it_in_place() {
    // A 32×32 density, then the same with a bright block at UV (0.7–0.85, 0.2–0.35).
    let texels = |edited: bool| {
        let mut t = vec![1.0f32; 32 * 32];
        if edited {
            for y in 21..27 {
                for x in 22..27 {
                    t[y * 32 + x] = 4.0;
                }
            }
        }
        Map::Image(
            ImageMap::from_texels(32, 32, t, Wrap::Clamp)
                .unwrap()
                .with_filter(Filter::Nearest),
        )
    };
    let before = by_id(&grow(&spot_spec(6_000, texels(false)).generator().unwrap()));
    let after = by_id(&grow(&spot_spec(6_000, texels(true)).generator().unwrap()));
    let mesh = pelage::assets::spot();
    let block = |uv: Vec2| (0.6..0.95).contains(&uv.x) && (0.1..0.45).contains(&uv.y);
    let far =
        |hairs: &HashMap<u64, (SurfacePoint, Vec<u32>)>| -> HashMap<u64, (SurfacePoint, Vec<u32>)> {
            hairs
                .iter()
                .filter(|(_, (root, _))| !block(root.uv(&mesh).unwrap()))
                .map(|(id, h)| (*id, h.clone()))
                .collect()
        };
    let (far_before, far_after) = (far(&before), far(&after));
    // With the count fixed, the hairs the brighter block gains are the
    // latest arrivals elsewhere: far hairs are only removed, never moved
    // or added (a cell straddling the block's edge may renew a few).
    let same = far_after
        .iter()
        .filter(|(id, h)| far_before.get(id) == Some(h))
        .count();
    assert!(
        same as f64 >= 0.99 * far_after.len() as f64,
        "{same} of {} far hairs unchanged",
        far_after.len()
    );
    assert!(far_after.len() < far_before.len());
    let gained = after.len() - far_after.len();
    let had = before.len() - far_before.len();
    assert!(
        2 * gained > 3 * had,
        "the block went from {had} to {gained} hairs"
    );
}

/// An `n`×`n` grid of quads on the unit square (z = 0), UVs = xy.
fn plane(n: u32) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push(Vec3::new(i as f32 / n as f32, j as f32 / n as f32, 0.0));
        }
    }
    let mut triangles = Vec::new();
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let uvs = positions.iter().map(|p| p.truncate()).collect();
    Mesh::new(
        "plane",
        positions,
        triangles,
        None,
        Some(Uvs::PerVertex(uvs)),
    )
    .unwrap()
}

/// Guides on a 7×7 lattice of the plane combed away from x = 0.5: left
/// of it toward −X, right of it toward +X (a parting).
fn parted_guides(mesh: &Mesh) -> Guides {
    let (mut points, mut offsets) = (Vec::new(), vec![0u32]);
    for j in 0..7 {
        for i in 0..7 {
            let root = Vec3::new((i as f32 + 0.5) / 7.0, (j as f32 + 0.5) / 7.0, 0.0);
            let side = if root.x < 0.5 { -1.0 } else { 1.0 };
            for k in 0..4 {
                let t = k as f32 / 3.0;
                points.push(root + t * Vec3::new(0.1 * side, 0.0, 0.1));
            }
            offsets.push(points.len() as u32);
        }
    }
    let widths = vec![0.001; points.len()];
    let curves = Curves::new(points, widths, offsets).unwrap();
    Guides::bind(mesh, &curves, 4, 1e-4).0
}

fn halves() -> Map {
    Map::Image(
        ImageMap::from_texels(2, 1, vec![0.0, 1.0], Wrap::Clamp)
            .unwrap()
            .with_filter(Filter::Nearest),
    )
}

#[test]
fn hairs_never_take_their_shape_across_a_parting() {
    let mesh = Arc::new(plane(20));
    let guides = parted_guides(&mesh);
    for method in [
        InterpolationMethod::Shepard {
            k: 12,
            power: 1.0,
            radius: None,
        },
        InterpolationMethod::StyleMesh(StyleMeshOptions::default()),
    ] {
        let spec = |regions: bool| {
            let spec = GroomSpec::new(mesh.clone(), guides.clone(), RootsSpec::new(4_000))
                .with_interpolation(method.clone());
            if regions {
                spec.with_regions(RegionsSpec::from_map(halves(), 1.0))
            } else {
                spec
            }
        };
        // Hairs comb away from the parting: the tip's x moves the way its side does.
        let crossings = |parts: &[Curves]| {
            parts
                .iter()
                .flat_map(|c| (0..c.curve_count()).map(move |i| &c.points()[c.range(i)]))
                .filter(|h| {
                    let (root, tip) = (h[0], h[h.len() - 1]);
                    let away = if root.x < 0.5 {
                        root.x - tip.x
                    } else {
                        tip.x - root.x
                    };
                    away <= 0.0
                })
                .count()
        };
        let parted = grow(&spec(true).generator().unwrap());
        assert_eq!(crossings(&parted), 0, "{method:?}");
        // The test can fail: without regions, hairs by the parting mix both sides.
        let mixed = grow(&spec(false).generator().unwrap());
        if matches!(method, InterpolationMethod::Shepard { .. }) {
            assert!(crossings(&mixed) > 10, "{method:?}: {}", crossings(&mixed));
        }
    }
}

#[test]
fn clumps_never_take_a_centre_across_a_region_or_face_groups() {
    // Regions from OBJ groups: the left half of the plane is group "left".
    let mesh = plane(20);
    let triangles = mesh.triangles().to_vec();
    let of_triangle = triangles
        .iter()
        .map(|t| {
            let x = t
                .iter()
                .map(|&v| mesh.positions()[v as usize].x)
                .sum::<f32>()
                / 3.0;
            u32::from(x > 0.5)
        })
        .collect();
    let mesh = mesh
        .with_face_groups(pelage::mesh::FaceGroups {
            kind: "groups".into(),
            names: vec!["left".into(), "right".into()],
            of_triangle,
        })
        .unwrap();
    let mesh = Arc::new(mesh);
    let guides = parted_guides(&mesh);
    let mut clump = ClumpParams::new(6);
    clump.rate = Map::Constant(1.0);
    let spec = GroomSpec::new(mesh.clone(), guides, RootsSpec::new(3_000))
        .with_regions(RegionsSpec::from_faces("groups"))
        .with_op(GroomOp::Clump(clump));
    let generator = spec.generator().unwrap();
    let Operator::Clump(op) = &generator.operators()[0] else {
        panic!()
    };
    let centres = op.centres();
    for c in grow(&generator) {
        for (i, root) in c.roots().unwrap().iter().enumerate() {
            // Rate 1: the tip is the centre's tip; find which centre it is.
            let tip = &c.points()[c.range(i)][&c.points()[c.range(i)].len() - 1];
            let centre = (0..centres.len())
                .min_by(|&a, &b| {
                    let d =
                        |k: usize| (centres.shape(k)[centres.shape(k).len() - 1] - tip).length();
                    d(a).total_cmp(&d(b))
                })
                .unwrap();
            let region = generator.region_of(*root);
            let centre_side = u32::from(centres.roots()[centre].x > 0.5);
            assert_eq!(region, centre_side, "hair at {:?}", root.position(&mesh));
        }
    }
}

#[test]
fn clumps_stay_on_their_side_of_spots_ears_and_a_thin_fin() {
    // A thin fin: two faces 0.002 apart, facing away from each other.
    let mut positions = Vec::new();
    for z in [0.001f32, -0.001] {
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            positions.push(Vec3::new(x, y, z));
        }
    }
    let fin = Mesh::new(
        "fin",
        positions,
        vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]],
        None,
        None,
    )
    .unwrap()
    .subdivided(5);
    // Spot subdivided so that paths along its edges come close to
    // geodesics.
    for mesh in [
        Arc::new(fin),
        Arc::new(pelage::assets::spot().subdivided(2)),
    ] {
        let hop = 4.0 * mesh.edge_graph().mean_edge_length();
        let growth = GuideGrowth {
            count: 200,
            length: Map::Constant(0.03),
            points: 4,
            ..Default::default()
        };
        let guides = Guides::grow(&mesh, &growth).unwrap();
        let mut clump = ClumpParams::new(300);
        clump.rate = Map::Constant(1.0);
        let spec = GroomSpec::new(mesh.clone(), guides, RootsSpec::new(3_000))
            .with_op(GroomOp::Clump(clump));
        let generator = spec.generator().unwrap();
        let Operator::Clump(op) = &generator.operators()[0] else {
            panic!()
        };
        let centres = op.centres();
        // The centre each hair follows (rate 1: its tip is the centre's).
        let followed = |tip: Vec3| {
            (0..centres.len())
                .find(|&k| (centres.shape(k)[centres.shape(k).len() - 1] - tip).length() < 1e-5)
        };
        let mut crossed = 0;
        for c in grow(&generator) {
            for (i, root) in c.roots().unwrap().iter().enumerate() {
                let h = &c.points()[c.range(i)];
                let Some(centre) = followed(h[h.len() - 1]) else {
                    panic!("{}: a hair follows no centre", mesh.name());
                };
                let centre = centres.roots()[centre];
                let p = root.position(&mesh);
                // Across a thin part the way over the surface is far longer
                // than the straight line.
                if surface_distance(&mesh, p, centre) > 3.0 * (centre - p).length() + hop {
                    crossed += 1;
                }
            }
        }
        assert_eq!(crossed, 0, "{}", mesh.name());
    }
}

/// The shortest way along the mesh's edges between the vertices nearest
/// `a` and `b` (plus the hops to them): a stand-in for the geodesic
/// distance. The fin's two faces share no edge: infinite between them.
fn surface_distance(mesh: &Mesh, a: Vec3, b: Vec3) -> f32 {
    let nearest = |p: Vec3| {
        (0..mesh.vertex_count())
            .min_by(|&i, &j| {
                (mesh.positions()[i] - p)
                    .length()
                    .total_cmp(&(mesh.positions()[j] - p).length())
            })
            .unwrap()
    };
    let (from, to) = (nearest(a), nearest(b));
    let graph = mesh.edge_graph();
    let (source, target) = (graph.rank(from as u32), graph.rank(to as u32));
    let mut best = vec![f32::INFINITY; graph.vertex_count()];
    let mut heap = std::collections::BinaryHeap::new();
    best[source as usize] = 0.0;
    heap.push(std::cmp::Reverse((0u32, source)));
    while let Some(std::cmp::Reverse((d, u))) = heap.pop() {
        let d = f32::from_bits(d);
        if u == target {
            break;
        }
        if d > best[u as usize] {
            continue;
        }
        let (next, lengths) = graph.edges_of(u);
        for (&v, &l) in next.iter().zip(lengths) {
            if d + l < best[v as usize] {
                best[v as usize] = d + l;
                heap.push(std::cmp::Reverse(((d + l).to_bits(), v)));
            }
        }
    }
    best[target as usize]
        + (mesh.positions()[from] - a).length()
        + (mesh.positions()[to] - b).length()
}

#[test]
fn masks_fade_operators_and_parse_in_groom_files() {
    let text = |mask: &str| {
        format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 500\n[guides]\ngenerate = {{ count = 40, length = 0.04 }}\n[[ops]]\nlength = {{ scale = 2.0{mask} }}\n"
        )
    };
    let grown = |mask: &str| {
        let g = Groom::from_text("m.toml", text(mask)).unwrap();
        grow(&g.generator(None).unwrap())
    };
    let (none, zero, half) = (grown(""), grown(", mask = 0"), grown(", mask = 0.5"));
    let length = |parts: &[Curves]| -> f32 {
        parts
            .iter()
            .flat_map(|c| (0..c.curve_count()).map(move |i| &c.points()[c.range(i)]))
            .map(|h| (h[h.len() - 1] - h[0]).length())
            .sum()
    };
    let plain = grown(", mask = 1");
    assert_eq!(length(&none), length(&plain));
    // Mask 0 is no operator (hairs as grown), 0.5 half the lengthening.
    let base = length(&zero);
    assert!(
        (length(&half) - 1.5 * base).abs() < 1e-3 * base,
        "{} {}",
        length(&half),
        base
    );
    assert!((length(&none) - 2.0 * base).abs() < 1e-3 * base);
    let err = Groom::from_text(
        "m.toml",
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 5\n[guides]\ngenerate = { count = 4, length = 0.04 }\n[finish]\nwidth = { root = 0.1, tip = 0.1, mask = 0.5 }\n",
    )
    .and_then(|g| g.generator(None))
    .unwrap_err()
    .to_string();
    assert!(err.starts_with("m.toml:8:"), "{err}");
}

/// Spot without its UVs.
fn uvless_spot() -> Mesh {
    let spot = pelage::assets::spot();
    Mesh::new(
        "spot without UVs",
        spot.positions().to_vec(),
        spot.triangles().to_vec(),
        Some(spot.normals().to_vec()),
        None,
    )
    .unwrap()
}

/// Roots per spatial bin (cells of a 4×4×4 grid over the mesh's box) and
/// each bin's probability, from a per-triangle probability.
fn spatial_bins(
    mesh: &Mesh,
    roots: &[SurfacePoint],
    triangle_p: impl Fn(usize) -> f64,
) -> (Vec<u64>, Vec<f64>) {
    let (lo, hi) = mesh.bounds();
    let bin = |p: Vec3| {
        let q = ((p - lo) / (hi - lo) * 4.0).clamp(Vec3::ZERO, Vec3::splat(3.999));
        (q.x as usize) * 16 + (q.y as usize) * 4 + q.z as usize
    };
    let mut probabilities = vec![0.0; 64];
    for t in 0..mesh.triangle_count() {
        let [a, b, c] = mesh.triangle_positions(t);
        probabilities[bin((a + b + c) / 3.0)] += triangle_p(t);
    }
    let mut counts = vec![0u64; 64];
    for r in roots {
        let [a, b, c] = mesh.triangle_positions(r.tri as usize);
        counts[bin((a + b + c) / 3.0)] += 1;
    }
    (counts, probabilities)
}

#[test]
fn noise_and_per_vertex_maps_work_on_a_mesh_without_uvs() {
    let mesh = uvless_spot();
    // Object-space noise: roots follow ∫ noise over each triangle.
    let noise = Map::parse("noise:frequency=2,offset=0.5,scale=0.45").unwrap();
    let sampler = DensitySampler::new(&mesh, &noise, Default::default()).unwrap();
    let roots = pelage::sample::sample_range(&sampler, 9, 0..40_000);
    let Map::Noise(field) = &noise else { panic!() };
    let expected = |t: usize| {
        // 15 interior points of the triangle, its area.
        let [a, b, c] = mesh.triangle_positions(t);
        let mut sum = 0.0;
        for i in 0..5 {
            for j in 0..5 - i {
                let (u, v) = ((i as f32 + 1.0 / 3.0) / 5.0, (j as f32 + 1.0 / 3.0) / 5.0);
                sum += f64::from(field.eval3(a + u * (b - a) + v * (c - a)));
            }
        }
        sum / 15.0 * f64::from(mesh.triangle_areas()[t])
    };
    let total: f64 = (0..mesh.triangle_count()).map(expected).sum();
    let (counts, p) = spatial_bins(&mesh, &roots, |t| expected(t) / total);
    assert_fits("object-space noise", &counts, &p);
    // Per-vertex density: a painted attribute, linear inside triangles.
    let painted: Vec<f32> = mesh
        .positions()
        .iter()
        .map(|p| if p.y > 0.0 { 1.0 } else { 0.2 })
        .collect();
    let mesh = mesh
        .with_vertex_attribute("density", painted.clone())
        .unwrap();
    let density = Map::parse("vertex:density").unwrap();
    let sampler = DensitySampler::new(&mesh, &density, Default::default()).unwrap();
    let roots = pelage::sample::sample_range(&sampler, 9, 0..40_000);
    let exact = |t: usize| {
        let mean = mesh.triangles()[t]
            .iter()
            .map(|&v| f64::from(painted[v as usize]))
            .sum::<f64>()
            / 3.0;
        mean * f64::from(mesh.triangle_areas()[t])
    };
    let total: f64 = (0..mesh.triangle_count()).map(exact).sum();
    let (counts, p) = spatial_bins(&mesh, &roots, |t| exact(t) / total);
    assert_fits("per-vertex density", &counts, &p);
    // A whole groom grows on it with noise and vertex maps; an image map
    // is refused with the alternatives named.
    let mesh = Arc::new(mesh);
    let guides = Guides::grow(
        &mesh,
        &GuideGrowth {
            count: 30,
            length: Map::Constant(0.03),
            ..Default::default()
        },
    )
    .unwrap();
    let spec = GroomSpec::new(
        mesh.clone(),
        guides.clone(),
        RootsSpec::new(2_000).with_density(density),
    )
    .with_op(GroomOp::Length(LengthParams::new(
        Map::parse("noise:offset=1,scale=0.5").unwrap(),
    )));
    assert_eq!(
        grow(&spec.generator().unwrap())
            .iter()
            .map(Curves::curve_count)
            .sum::<usize>(),
        2_000
    );
    let image = Map::Image(ImageMap::from_texels(1, 1, vec![1.0], Wrap::Repeat).unwrap());
    let err = GroomSpec::new(mesh, guides, RootsSpec::new(10).with_density(image))
        .generator()
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("noise") && err.contains("vertex:NAME") && err.contains("density"),
        "{err}"
    );
}

#[test]
fn blue_noise_roots_keep_twice_the_distance_and_still_follow_the_density() {
    let mesh = Arc::new(pelage::assets::spot());
    let density = Map::Image(pelage::assets::spot_texture(pelage::map::Channel::R));
    let guides = spot_guides(&mesh, 40);
    let roots = |distribution| {
        let spec = GroomSpec::new(
            mesh.clone(),
            guides.clone(),
            RootsSpec::new(20_000)
                .with_density(density.clone())
                .with_distribution(distribution)
                .with_parts(2),
        );
        let g = spec.generator().unwrap();
        let roots: Vec<SurfacePoint> = grow(&g)
            .iter()
            .flat_map(|c| c.roots().unwrap().to_vec())
            .collect();
        (roots, g)
    };
    let (random, g) = roots(RootDistribution::Random);
    let (blue, _) = roots(RootDistribution::BlueNoise);
    assert_eq!(blue.len(), 20_000);
    // Nearest-neighbour distance over the spacing the density asks for there.
    let sampler = g.sampler();
    let spacing = |r: &SurfacePoint| (1.0 / (20_000.0 * sampler.pdf(*r))).sqrt() as f32;
    let normalised = |set: &[SurfacePoint]| -> Vec<f32> {
        let tree = NearestPoints::new(set.iter().map(|r| r.position(&mesh)).collect());
        let mut out = Vec::new();
        let mut d: Vec<f32> = set
            .iter()
            .map(|r| {
                tree.nearest(r.position(&mesh), 2, &mut out);
                out[1].distance_squared.sqrt() / spacing(r)
            })
            .collect();
        d.sort_by(f32::total_cmp);
        d
    };
    let (r, b) = (normalised(&random), normalised(&blue));
    let percentile = |d: &[f32], q: f64| d[(q * d.len() as f64) as usize];
    // The closest pairs (1st percentile, robust where the minimum is one
    // unlucky pair) at least twice as far apart, and the spread narrower.
    assert!(
        percentile(&b, 0.01) >= 2.0 * percentile(&r, 0.01),
        "{} {}",
        percentile(&b, 0.01),
        percentile(&r, 0.01)
    );
    let spread = |d: &[f32]| percentile(d, 0.9) - percentile(d, 0.1);
    assert!(spread(&b) < spread(&r), "{} {}", spread(&b), spread(&r));
    // No seams: the two parts are thinned together, so even the closest
    // pair of all (which a border between parts thinned apart would
    // bring as close as random roots) keeps most of the spacing.
    assert!(b[0] > 0.4, "closest pair {} of the spacing", b[0]);
    // The density still matches the map.
    let (counts, p) = spatial_bins(&mesh, &blue, |t| sampler.triangle_probability(t));
    assert_fits("blue-noise roots", &counts, &p);
    // Thinned all at once, so a count past the ceiling is refused at once,
    // naming the setting, before anything is placed.
    let too_many = pelage::limits::MAX_BLUE_NOISE_POINTS + 1;
    let err = GroomSpec::new(
        mesh.clone(),
        guides.clone(),
        RootsSpec::new(too_many).with_distribution(RootDistribution::BlueNoise),
    )
    .generator()
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("roots.count") && err.contains("20,000,000") && err.contains("random"),
        "{err}"
    );
}
