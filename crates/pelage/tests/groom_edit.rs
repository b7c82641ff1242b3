//! Grooming by hand: brushes do what a groomer expects of them, undo and
//! redo restore states bit for bit, and incremental regrowth equals a
//! full regrow after random edits of every kind.

use glam::Vec3;
use pelage::groom::brush::{Brush, BrushRefusal, Dab, Falloff, height_above_skin};
use pelage::groom::edit::{Edit, EditableGroom};
use pelage::groom::{
    ClumpParams, GroomErrorKind, GroomOp, GroomSpec, LengthParams, NoiseParams, RootsSpec,
};
use pelage::guides::{GuideGrowth, Guides};
use pelage::map::{Map, VertexMap};
use pelage::mesh::Mesh;
use pelage::{Curves, sample::mix64};
use std::sync::Arc;

/// Spot with a `len` layer, 60 guides, a clump level, a painted length
/// and noise: every kind of dependence a hair can have.
fn spec(hairs: u64) -> GroomSpec {
    let spot = pelage::assets::spot();
    let n = spot.vertex_count();
    let mesh = Arc::new(spot.with_vertex_attribute("len", vec![1.0; n]).unwrap());
    let growth = GuideGrowth {
        count: 60,
        length: Map::Constant(0.08),
        comb: Vec3::new(0.0, -0.3, -0.6),
        points: 8,
        ..Default::default()
    };
    let guides = Guides::grow(&mesh, &growth).unwrap();
    GroomSpec::new(mesh, guides, RootsSpec::new(hairs))
        .with_op(GroomOp::Clump(ClumpParams::new(40)))
        .with_op(GroomOp::Length(LengthParams::new(Map::Vertex(
            VertexMap::new("len"),
        ))))
        .with_op(GroomOp::Noise(NoiseParams::new(Map::Constant(0.002))))
}

fn bits(c: &Curves) -> (Vec<u64>, Vec<[u32; 3]>, Vec<u32>, Vec<u32>) {
    (
        c.ids().unwrap().to_vec(),
        c.points()
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect(),
        c.widths().iter().map(|w| w.to_bits()).collect(),
        c.offsets().to_vec(),
    )
}

/// A guide's root position (its first point).
fn root(groom: &EditableGroom, g: usize) -> Vec3 {
    groom.guides().guide(g)[0]
}

/// Every part `groom` grows.
fn grown_parts(groom: &pelage::groom::Groom) -> Vec<Curves> {
    let g = groom.generator(None).unwrap();
    (0..g.parts().len()).map(|p| g.part(p).unwrap()).collect()
}

/// The hairs of `parts` and the farthest any of their points is from the
/// same point of the hair of the same id in `session`.
fn farthest_by_id(parts: &[Curves], session: &Curves) -> (usize, f32) {
    let by_id = index_by_id(session);
    let (mut hairs, mut worst) = (0, 0.0f32);
    for part in parts {
        for i in 0..part.curve_count() {
            let j = by_id[&part.ids().unwrap()[i]];
            for (a, b) in part.points()[part.range(i)]
                .iter()
                .zip(&session.points()[session.range(j)])
            {
                worst = worst.max(a.distance(*b));
            }
            hairs += 1;
        }
    }
    (hairs, worst)
}

/// Each hair's index in `curves`, by id.
fn index_by_id(curves: &Curves) -> std::collections::HashMap<u64, usize> {
    let ids = curves.ids().unwrap().iter();
    ids.enumerate().map(|(i, id)| (*id, i)).collect()
}

fn lengths(points: &[Vec3]) -> Vec<f32> {
    points.windows(2).map(|s| s[0].distance(s[1])).collect()
}

fn dab(center: Vec3, radius: f32) -> Dab {
    Dab::new(center, radius)
}

#[test]
fn comb_moves_tips_along_the_stroke_and_keeps_segment_lengths() {
    let mut groom = EditableGroom::new(spec(2_000), 1.0).unwrap();
    let before = groom.guides().clone();
    let center = root(&groom, 5);
    let mut d = dab(center, 0.12);
    d.direction = Vec3::new(0.03, 0.0, 0.02);
    d.strength = 1.0;
    groom
        .brush(&Brush::Comb, &d)
        .unwrap()
        .expect("the dab touches guides");
    let after = groom.guides();
    let mut moved = 0;
    for g in 0..after.len() {
        let (a, b) = (before.guide(g), after.guide(g));
        assert_eq!(a[0], b[0], "roots stay");
        for (la, lb) in lengths(a).iter().zip(lengths(b)) {
            assert!((la - lb).abs() <= 1e-4 * la, "segment {la} became {lb}");
        }
        if a != b {
            moved += 1;
            let tip = b[b.len() - 1] - a[a.len() - 1];
            assert!(tip.dot(d.direction) > 0.0, "guide {g}'s tip moved {tip}");
        }
        for p in b {
            assert!(height_above_skin(groom.mesh(), groom.bvh(), *p) > -1e-5);
        }
    }
    assert!(moved > 0);
}

#[test]
fn a_comb_into_the_skin_keeps_every_segment_length() {
    // Combed hard toward the skin: points are lifted back above it, and
    // the points after each lifted one follow at their lengths (lifting a
    // point alone shortened the segment after it by up to 43 %).
    let mut groom = EditableGroom::new(spec(2_000), 1.0).unwrap();
    let before = groom.guides().clone();
    let g = 5;
    let center = root(&groom, g);
    let normal = (before.guide(g)[1] - before.guide(g)[0]).normalize();
    let mut d = dab(center, 0.15);
    d.direction = -0.08 * normal + Vec3::new(0.02, 0.0, 0.0);
    d.strength = 1.0;
    groom
        .brush(&Brush::Comb, &d)
        .unwrap()
        .expect("the dab touches guides");
    let after = groom.guides();
    let mut worst = 0.0f32;
    for g in 0..after.len() {
        for (la, lb) in lengths(before.guide(g)).iter().zip(lengths(after.guide(g))) {
            worst = worst.max((la - lb).abs() / la);
        }
        for p in after.guide(g) {
            assert!(height_above_skin(groom.mesh(), groom.bvh(), *p) > -1e-5);
        }
    }
    assert!(
        worst <= 1e-4,
        "a segment's length changed by {:.2} %",
        worst * 100.0
    );
}

#[test]
fn cut_leaves_no_point_past_the_cut_and_length_grows() {
    let mut groom = EditableGroom::new(spec(1_000), 1.0).unwrap();
    // A sphere through the guides' middles, beside guide 3's root.
    let g3 = groom.guides().guide(3).to_vec();
    let d = dab(g3[5], 0.03);
    groom.brush(&Brush::Cut, &d).unwrap().expect("cuts guide 3");
    for g in 0..groom.guides().len() {
        let guide = groom.guides().guide(g);
        if d.center.distance(guide[0]) >= d.radius {
            for p in guide {
                assert!(
                    p.distance(d.center) >= d.radius * (1.0 - 1e-4),
                    "guide {g} has a point inside the cut"
                );
            }
        }
    }
    let cut_length: f32 = lengths(groom.guides().guide(3)).iter().sum();
    assert!(cut_length < lengths(&g3).iter().sum::<f32>());
    let mut grow = dab(g3[0], 0.05);
    grow.strength = 0.5;
    groom.brush(&Brush::Length, &grow).unwrap().unwrap();
    let grown: f32 = lengths(groom.guides().guide(3)).iter().sum();
    assert!(grown > cut_length * 1.2, "{grown} after {cut_length}");
}

#[test]
fn puff_raises_guides_and_smooth_keeps_lengths() {
    let mut groom = EditableGroom::new(spec(1_000), 1.0).unwrap();
    let angle = |groom: &EditableGroom, g: usize| {
        let guide = groom.guides().guide(g);
        let normal = groom.guides().roots()[g].normal(groom.mesh());
        (guide[guide.len() - 1] - guide[0]).normalize().dot(normal)
    };
    let before = angle(&groom, 7);
    let mut d = dab(root(&groom, 7), 0.2);
    d.strength = 0.8;
    groom.brush(&Brush::Puff, &d).unwrap().unwrap();
    // Closer to the normal by at least a third of the way left.
    let after = angle(&groom, 7);
    assert!(
        after > before + 0.3 * (1.0 - before),
        "{after} after {before}"
    );
    let l0 = lengths(groom.guides().guide(7));
    d.falloff = Falloff::Constant;
    groom.brush(&Brush::Smooth, &d).unwrap();
    for (a, b) in l0.iter().zip(lengths(groom.guides().guide(7))) {
        assert!((a - b).abs() <= 1e-4 * a);
    }
}

#[test]
fn added_guides_are_rooted_on_the_skin_with_their_neighbours_shape() {
    let mut groom = EditableGroom::new(spec(1_000), 1.0).unwrap();
    let before = groom.generator().guides().clone();
    let count = before.len();
    let d = dab(root(&groom, 11), 0.1);
    groom.brush(&Brush::Add { count: 3 }, &d).unwrap().unwrap();
    let after = groom.guides();
    assert_eq!(after.len(), count + 3);
    // What the old guides interpolate at each new root.
    let interpolator = pelage::interp::Interpolator::new(
        groom.mesh(),
        before,
        &pelage::interp::InterpolationMethod::by_name("shepard").unwrap(),
    );
    for g in count..count + 3 {
        let r = after.roots()[g];
        let guide = after.guide(g);
        assert!(guide[0].distance(r.position(groom.mesh())) < 1e-6);
        assert!(guide[0].distance(d.center) < d.radius);
        let mut shape = vec![Vec3::ZERO; guide.len()];
        interpolator.hair(groom.mesh(), r, &mut Default::default(), &mut shape);
        for (a, b) in shape.iter().zip(guide) {
            assert!(
                a.distance(*b) < 1e-3,
                "added guide {g} strays from its neighbours"
            );
        }
    }
}

#[test]
fn deleted_guides_weigh_on_no_hair() {
    let mut groom = EditableGroom::new(spec(3_000), 1.0).unwrap();
    let d = dab(root(&groom, 2), 0.15);
    let inside = (0..groom.guides().len())
        .filter(|&g| root(&groom, g).distance(d.center) < d.radius)
        .count();
    assert!(inside >= 1);
    let count = groom.guides().len();
    groom.brush(&Brush::Delete, &d).unwrap().unwrap();
    assert_eq!(groom.guides().len(), count - inside);
    for (_, _, weights) in groom.hair_weights() {
        for w in weights {
            let r = groom.guides().guide(w.guide as usize)[0];
            assert!(
                r.distance(d.center) >= d.radius,
                "a hair still follows a deleted guide"
            );
        }
    }
}

#[test]
fn a_painted_parting_is_never_crossed() {
    let mut groom = EditableGroom::new(spec(4_000), 1.0).unwrap();
    // Part the back of the cow along a long stroke.
    let (lo, hi) = groom.mesh().bounds();
    for i in 0..12 {
        let t = i as f32 / 11.0;
        let center = Vec3::new(lo.x + t * (hi.x - lo.x), hi.y, 0.0);
        let Some(hit) = groom.bvh().closest(center) else {
            continue;
        };
        let mut d = dab(hit.point, 0.35);
        d.falloff = Falloff::Constant;
        groom.brush(&Brush::Part { region: 1 }, &d).unwrap();
    }
    let generator = groom.generator();
    let guide_regions: Vec<u32> = groom
        .guides()
        .roots()
        .iter()
        .map(|r| generator.region_of(*r))
        .collect();
    assert!(guide_regions.contains(&0) && guide_regions.contains(&1));
    let mut hairs_in = [0usize; 2];
    for (_, region, weights) in groom.hair_weights() {
        hairs_in[region.min(1) as usize] += 1;
        for w in weights {
            assert_eq!(
                guide_regions[w.guide as usize], region,
                "a hair crosses the parting"
            );
        }
    }
    assert!(hairs_in[0] > 100 && hairs_in[1] > 100, "{hairs_in:?}");
}

#[test]
fn undo_restores_bit_for_bit_and_redo_reapplies() {
    let mut groom = EditableGroom::new(spec(3_000), 0.5).unwrap();
    let start = bits(&groom.curves());
    let start_guides = groom.guides().curves().points().to_vec();
    let mut d = dab(root(&groom, 9), 0.2);
    d.direction = Vec3::new(0.0, 0.05, 0.0);
    groom.brush(&Brush::Comb, &d).unwrap().unwrap();
    let combed = bits(&groom.curves());
    assert_ne!(combed, start);
    groom
        .brush(
            &Brush::Paint {
                layer: "density".into(),
                value: 0.0,
            },
            &d,
        )
        .unwrap()
        .unwrap();
    let painted = bits(&groom.curves());
    assert_ne!(painted, combed);
    groom.undo().unwrap().unwrap();
    assert_eq!(bits(&groom.curves()), combed);
    groom.undo().unwrap().unwrap();
    assert_eq!(bits(&groom.curves()), start);
    assert_eq!(groom.guides().curves().points(), &start_guides[..]);
    assert!(groom.undo().unwrap().is_none());
    groom.redo().unwrap().unwrap();
    assert_eq!(bits(&groom.curves()), combed);
    groom.redo().unwrap().unwrap();
    assert_eq!(bits(&groom.curves()), painted);
    // The history is bounded: a tiny budget keeps no step.
    groom.set_history_budget(16);
    assert_eq!(groom.history_len(), (0, 0));
}

/// A wavy sheet symmetric across X = 0 (vertex x values exact negatives).
fn symmetric_sheet() -> Mesh {
    let n = 16;
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let x = (i as f32 - (n / 2) as f32) / (n / 2) as f32;
            let z = j as f32 / n as f32;
            positions.push(Vec3::new(x, 0.1 * (x * x) + 0.05 * z, z));
        }
    }
    let mut triangles = Vec::new();
    let w = n as u32 + 1;
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let a = j * w + i;
            // Diagonals mirrored too: left half one way, right half the other.
            if i < n as u32 / 2 {
                triangles.push([a, a + w, a + 1]);
                triangles.push([a + 1, a + w, a + w + 1]);
            } else {
                triangles.push([a, a + w, a + w + 1]);
                triangles.push([a, a + w + 1, a + 1]);
            }
        }
    }
    Mesh::new("sheet", positions, triangles, None, None).unwrap()
}

#[test]
fn x_mirror_on_a_symmetric_mesh_gives_mirrored_guides() {
    let mesh = Arc::new(symmetric_sheet());
    // Pairs of guides at ±x, straight up and leaning outward.
    let mut points = Vec::new();
    let mut widths = Vec::new();
    let mut offsets = vec![0u32];
    for k in 0..6 {
        let (x, z) = (0.15 + 0.12 * k as f32, 0.2 + 0.1 * k as f32);
        for side in [1.0f32, -1.0] {
            let base = Vec3::new(side * x, 0.1 * x * x + 0.05 * z, z);
            for s in 0..6 {
                points.push(base + Vec3::new(side * 0.01 * s as f32, 0.02 * s as f32, 0.0));
                widths.push(0.001);
            }
            offsets.push(points.len() as u32);
        }
    }
    let curves = Curves::new(points, widths, offsets).unwrap();
    let (guides, report) = Guides::bind(&mesh, &curves, 6, 1e-3);
    assert_eq!(report.kept, 12);
    let spec = GroomSpec::new(mesh, guides, RootsSpec::new(500));
    let mut groom = EditableGroom::new(spec, 1.0).unwrap();
    let mut d = dab(Vec3::new(0.5, 0.1 * 0.25, 0.5), 0.35);
    d.direction = Vec3::new(0.04, 0.0, 0.03);
    d.mirror_x = true;
    groom.brush(&Brush::Comb, &d).unwrap().unwrap();
    let guides = groom.guides();
    let mut changed = 0;
    for pair in 0..6 {
        let (a, b) = (guides.guide(2 * pair), guides.guide(2 * pair + 1));
        for (p, q) in a.iter().zip(b) {
            let mirrored = Vec3::new(-q.x, q.y, q.z);
            assert!(p.distance(mirrored) < 1e-5, "pair {pair}: {p} and {q}");
        }
        changed += usize::from(a[5].distance(curves.points()[12 * pair + 5]) > 1e-4);
    }
    assert!(changed > 0);
}

/// Random dabs of every brush, with undo and redo between, each followed
/// by a check that the groom equals the same groom grown from nothing.
#[test]
fn incremental_regrowth_equals_a_full_regrow_after_random_edits() {
    let mut groom = EditableGroom::new(spec(6_000), 0.6).unwrap();
    let brushes = [
        Brush::Comb,
        Brush::Length,
        Brush::Cut,
        Brush::Smooth,
        Brush::Puff,
        Brush::Clump,
        Brush::Spread,
        Brush::Add { count: 2 },
        Brush::Delete,
        Brush::Paint {
            layer: "len".into(),
            value: 1.6,
        },
        Brush::Paint {
            layer: "density".into(),
            value: 0.2,
        },
        Brush::Part { region: 1 },
    ];
    let vertices = groom.mesh().positions().to_vec();
    let mut kinds = std::collections::BTreeSet::new();
    let mut regrown = 0usize;
    for step in 0..100u64 {
        let h = mix64(step + 17);
        let r = |k: u64| ((mix64(h ^ k) >> 40) as f32) / (1u64 << 24) as f32;
        let action = h % 16;
        let result = if action == 14 {
            groom.undo().map(|r| r.map(|r| r.regrown_roots))
        } else if action == 15 {
            groom.redo().map(|r| r.map(|r| r.regrown_roots))
        } else {
            let brush = &brushes[(action % brushes.len() as u64) as usize];
            let at = vertices[(mix64(h ^ 99) % vertices.len() as u64) as usize];
            let mut d = dab(at, 0.05 + 0.15 * r(1));
            d.strength = if *brush == Brush::Length {
                r(2) - 0.5
            } else {
                0.3 + 0.7 * r(2)
            };
            d.direction = Vec3::new(r(3) - 0.5, r(4) - 0.5, r(5) - 0.5) * 0.05;
            d.mirror_x = r(6) < 0.3;
            d.falloff = [Falloff::Smooth, Falloff::Linear, Falloff::Constant][(h % 3) as usize];
            kinds.insert(brush.name());
            match groom.brush(brush, &d) {
                // Deleting the last guides is refused: fine.
                Err(e) if e.to_string().contains("every guide") => Ok(None),
                other => other.map(|r| r.map(|r| r.regrown_roots)),
            }
        };
        regrown += result.unwrap().unwrap_or(0);
        if step % 10 == 9 || step == 99 {
            let full = groom.regrown_from_scratch().unwrap();
            assert_eq!(
                bits(&groom.curves()),
                bits(&full.curves()),
                "step {step}: incremental and full regrowth differ"
            );
        }
    }
    assert_eq!(kinds.len(), brushes.len() - 1, "{kinds:?}");
    // Incremental: far fewer hairs regrown than 100 full regrows.
    assert!(regrown < 100 * groom.root_count() / 3, "{regrown}");
}

#[test]
fn hairs_far_from_a_comb_are_untouched_and_few_are_regrown() {
    let mut groom = EditableGroom::new(spec(20_000), 1.0).unwrap();
    let before = groom.curves();
    let guides_before = groom.guides().clone();
    let mut d = dab(root(&groom, 20), 0.08);
    d.direction = Vec3::new(0.0, 0.0, 0.05);
    let regrowth = groom.brush(&Brush::Comb, &d).unwrap().unwrap();
    assert!(regrowth.regrown_roots > 0);
    assert!(
        regrowth.regrown_roots * 4 < regrowth.hairs,
        "{} of {} regrown",
        regrowth.regrown_roots,
        regrowth.hairs
    );
    let after = groom.curves();
    // Hairs rooted far from every moved guide's root are bit-identical.
    let moved: Vec<Vec3> = (0..groom.guides().len())
        .filter(|&g| groom.guides().guide(g) != guides_before.guide(g))
        .map(|g| root(&groom, g))
        .collect();
    assert!(!moved.is_empty());
    let mesh = groom.mesh();
    assert_eq!(before.ids(), after.ids(), "same hairs");
    let mut far = 0;
    for i in 0..before.curve_count() {
        let p = before.roots().unwrap()[i].position(mesh);
        if moved.iter().all(|m| m.distance(p) > 0.8) {
            far += 1;
            let r = before.range(i);
            assert_eq!(&before.points()[r.clone()], &after.points()[r]);
        }
    }
    assert!(far > 1000, "{far}");
}

#[test]
fn the_editable_groom_grows_what_the_generator_grows() {
    let spec = spec(5_000);
    let groom = EditableGroom::new(spec.clone(), 1.0).unwrap();
    let generator = spec.generator().unwrap();
    let mut by_id = std::collections::HashMap::new();
    let session = groom.curves();
    for i in 0..session.curve_count() {
        by_id.insert(session.ids().unwrap()[i], i);
    }
    let mut total = 0;
    for p in 0..generator.parts().len() {
        let part = generator.part(p).unwrap();
        for i in 0..part.curve_count() {
            let j = by_id[&part.ids().unwrap()[i]];
            assert_eq!(
                &part.points()[part.range(i)],
                &session.points()[session.range(j)]
            );
            assert_eq!(
                &part.widths()[part.range(i)],
                &session.widths()[session.range(j)]
            );
            total += 1;
        }
    }
    assert_eq!(total, session.curve_count());
    // A preview is a subset of the full groom, hair for hair.
    let preview = EditableGroom::new(groom.spec().clone(), 0.2)
        .unwrap()
        .curves();
    assert!(preview.curve_count() < total / 3);
    for i in 0..preview.curve_count() {
        let j = by_id[&preview.ids().unwrap()[i]];
        assert_eq!(
            &preview.points()[preview.range(i)],
            &session.points()[session.range(j)]
        );
    }
}

#[test]
fn bad_edits_are_refused_and_change_nothing() {
    let mut groom = EditableGroom::new(spec(500), 1.0).unwrap();
    let before = bits(&groom.curves());
    let e = groom
        .apply(Edit::MoveGuides {
            guides: vec![999],
            points: vec![Vec3::ZERO; 8],
        })
        .unwrap_err();
    assert!(e.to_string().contains("guide 999 of 60"), "{e}");
    let e = groom
        .apply(Edit::Paint {
            layer: "nope".into(),
            vertices: vec![0],
            values: vec![1.0],
        })
        .unwrap_err();
    assert!(e.to_string().contains("no paint layer 'nope'"), "{e}");
    let e = groom
        .apply(Edit::Paint {
            layer: "len".into(),
            vertices: vec![0],
            values: vec![f32::NAN],
        })
        .unwrap_err();
    assert!(e.to_string().contains("finite"), "{e}");
    let e = groom
        .brush(
            &Brush::Paint {
                layer: "bad name".into(),
                value: 1.0,
            },
            &dab(Vec3::ZERO, 1.0),
        )
        .unwrap_err();
    assert!(e.to_string().contains("letters, digits"), "{e}");
    // A strength that would make guides no later dab can move, and an
    // add past the guide limit (it hung), are refused, typed.
    let root0 = root(&groom, 0);
    let huge = Dab {
        strength: 1e30,
        ..dab(root0, 0.1)
    };
    let e = groom.brush(&Brush::Length, &huge).unwrap_err();
    assert!(
        matches!(e.kind, GroomErrorKind::Brush(BrushRefusal::Dab(_))),
        "{e}"
    );
    let e = groom
        .brush(&Brush::Add { count: u32::MAX }, &dab(root0, 0.1))
        .unwrap_err();
    assert!(
        matches!(
            e.kind,
            GroomErrorKind::Brush(BrushRefusal::TooManyGuides { have: 60, .. })
        ),
        "{e}"
    );
    let nowhere = dab(Vec3::splat(f32::NAN), 0.1);
    assert!(groom.brush(&Brush::Comb, &nowhere).is_err());
    assert_eq!(bits(&groom.curves()), before);
    assert_eq!(groom.history_len(), (0, 0));
    // The groom still takes a sensible dab.
    let grow = Dab {
        strength: 0.5,
        ..dab(root0, 0.1)
    };
    assert!(groom.brush(&Brush::Length, &grow).unwrap().is_some());
    let sequential = {
        let mut s = spec(100);
        s.roots.ids = pelage::groom::HairIds::Sequential;
        s
    };
    let e = EditableGroom::new(sequential, 1.0).unwrap_err();
    assert!(e.to_string().contains("stable hair ids"), "{e}");
    assert!(EditableGroom::new(spec(100), 0.0).is_err());
}

#[test]
fn a_saved_session_grows_again_as_the_session_showed() {
    let dir = tempfile::tempdir().unwrap();
    let groom_file = dir.path().join("fur.toml");
    std::fs::write(
        &groom_file,
        r#"
[mesh]
path = "spot"

[roots]
count = 4000
seed = 3

[guides]
points = 8
generate = { count = 50, length = 0.06, comb = [0, -0.5, -1.0], gravity = 0.4, seed = 2 }

[[ops]]
clump = { count = 30, rate = 0.5 }

[[ops]]
noise = { amplitude = 0.002 }

[output]
path = "fur.usdc"
"#,
    )
    .unwrap();
    let loaded = pelage::groom::Groom::load(&groom_file).unwrap();
    let mut groom = EditableGroom::new(loaded.spec().unwrap(), 1.0).unwrap();
    let mut d = dab(root(&groom, 4), 0.25);
    d.direction = Vec3::new(0.0, 0.04, 0.02);
    groom.brush(&Brush::Comb, &d).unwrap().unwrap();
    // And one into the skin, whose lifted points the guides' file keeps
    // (a guide whose segments changed length was resampled when bound
    // again, and its hairs moved by 0.4 % of Spot's size).
    let guide = groom.guides().guide(12).to_vec();
    let mut d = dab(guide[0], 0.2);
    d.direction = -0.06 * (guide[1] - guide[0]).normalize();
    groom.brush(&Brush::Comb, &d).unwrap().unwrap();
    // Added guides take the shape the guides interpolate at their roots,
    // laid out evenly by arc length as a bound guide is (uneven ones were
    // resampled when bound again, and their hairs moved by 0.1 %).
    groom
        .brush(&Brush::Add { count: 12 }, &dab(root(&groom, 30), 0.3))
        .unwrap()
        .unwrap();
    groom
        .brush(
            &Brush::Paint {
                layer: "density".into(),
                value: 0.0,
            },
            &dab(root(&groom, 9), 0.3),
        )
        .unwrap()
        .unwrap();
    groom
        .brush(&Brush::Part { region: 1 }, &dab(root(&groom, 20), 0.4))
        .unwrap();
    let saved_path = dir.path().join("fur_groomed.toml");
    let saved = groom.save(&saved_path, Some(loaded.source())).unwrap();
    assert!(saved.guides.exists() && saved.layers.as_ref().unwrap().exists());
    let text = std::fs::read_to_string(&saved.groom).unwrap();
    assert!(
        text.contains("vertex:density") && text.contains("vertex:region"),
        "{text}"
    );

    let again = pelage::groom::Groom::load(&saved.groom).unwrap();
    let session = groom.curves();
    let (total, worst) = farthest_by_id(&grown_parts(&again), &session);
    assert_eq!(total, session.curve_count(), "the same hairs");
    // The guides went through a file and were bound again: float
    // rounding, not a visible change.
    assert!(worst < 1e-4, "hairs moved by {worst}");
}

#[test]
fn a_session_saved_to_another_folder_still_finds_its_image_maps() {
    let dir = tempfile::tempdir().unwrap();
    let (first, elsewhere) = (dir.path().join("first"), dir.path().join("elsewhere"));
    std::fs::create_dir_all(&first).unwrap();
    std::fs::create_dir_all(&elsewhere).unwrap();
    std::fs::write(first.join("tex.png"), pelage::assets::SPOT_TEXTURE_PNG).unwrap();
    let groom_file = first.join("fur.toml");
    std::fs::write(
        &groom_file,
        "[mesh]\npath = \"spot\"\n[roots]\ncount = 500\ndensity = \"tex.png:r\"\n\
         [guides]\ngenerate = { count = 20, length = 0.05 }\n\
         [[ops]]\nlength = { scale = \"tex.png:g:clamp\" }\n",
    )
    .unwrap();
    let loaded = pelage::groom::Groom::load(&groom_file).unwrap();
    let groom = EditableGroom::new(loaded.spec().unwrap(), 1.0).unwrap();
    let saved = groom
        .save(&elsewhere.join("fur.toml"), Some(loaded.source()))
        .unwrap();
    let text = std::fs::read_to_string(&saved.groom).unwrap();
    let absolute = first.canonicalize().unwrap().join("tex.png");
    for suffix in [":r", ":g:clamp"] {
        let named = format!("{}{suffix}", absolute.display());
        assert!(text.contains(&named), "{named} in:\n{text}");
    }
    let again = pelage::groom::Groom::load(&saved.groom).unwrap();
    assert_eq!(
        again.generator(None).unwrap().parts().len(),
        loaded.generator(None).unwrap().parts().len()
    );
}

#[test]
fn a_stroke_joined_into_one_step_is_undone_at_once() {
    let mut groom = EditableGroom::new(spec(1_000), 1.0).unwrap();
    let start = bits(&groom.curves());
    for k in 0..4 {
        let mut d = dab(root(&groom, 3 + k), 0.15);
        d.direction = Vec3::new(0.0, 0.02, 0.0);
        groom.brush(&Brush::Comb, &d).unwrap();
    }
    let combed = bits(&groom.curves());
    let (steps, _) = groom.history_len();
    groom.join_last_steps(steps);
    assert_eq!(groom.history_len(), (1, 0));
    groom.undo().unwrap().unwrap();
    assert_eq!(bits(&groom.curves()), start);
    groom.redo().unwrap().unwrap();
    assert_eq!(bits(&groom.curves()), combed);
}

#[test]
fn guide_curves_from_a_dcc_move_only_the_guides_whose_points_moved() {
    // A DCC's guide curves, with more points than pelage keeps (any count
    // is resampled), bound as the groom's guides.
    let dense = |g: &Guides, tip: Option<(usize, Vec3)>| {
        let mut points = Vec::new();
        for i in 0..g.len() {
            let guide = g.guide(i);
            for k in 0..=28 {
                let t = k as f32 / 28.0 * (guide.len() - 1) as f32;
                let (j, f) = (t.floor() as usize, t.fract());
                let mut p = guide[j].lerp(guide[(j + 1).min(guide.len() - 1)], f);
                if let Some((moved, by)) = tip
                    && moved == i
                {
                    p += by * (k as f32 / 28.0);
                }
                points.push(p);
            }
        }
        let offsets = (0..=g.len() as u32).map(|i| i * 29).collect();
        Curves::new(points, vec![0.001; g.len() * 29], offsets).unwrap()
    };
    let mut spec = spec(10_000);
    let grown = spec.guides.clone();
    let (bound, report) = Guides::bind(&spec.mesh, &dense(&grown, None), 8, 1e-4);
    assert_eq!(report.kept, grown.len());
    spec.guides = Arc::new(bound);
    let mut groom = EditableGroom::new(spec, 1.0).unwrap();
    let before = groom.curves();
    // Handed back unchanged, nothing regrows.
    assert!(
        groom
            .set_guide_curves(&dense(&grown, None), 1e-4)
            .unwrap()
            .is_none()
    );
    // Guide 20's tip pulled sideways: its neighbours' hairs regrow, far
    // hairs keep every bit.
    let pulled = dense(&grown, Some((20, Vec3::new(0.0, 0.0, 0.04))));
    let regrowth = groom
        .set_guide_curves(&pulled, 1e-4)
        .unwrap()
        .expect("a guide moved");
    assert!(regrowth.regrown_roots > 0 && regrowth.regrown_roots * 4 < regrowth.hairs);
    let after = groom.curves();
    let moved = root(&groom, 20);
    let mesh = groom.mesh();
    let mut far = 0;
    for i in 0..before.curve_count() {
        if before.roots().unwrap()[i].position(mesh).distance(moved) > 0.8 {
            far += 1;
            let r = before.range(i);
            assert_eq!(&before.points()[r.clone()], &after.points()[r]);
        }
    }
    assert!(far > 500, "{far}");
    // A guide left out: the guides are replaced (one fewer).
    let all = dense(&grown, None);
    let points = all.points()[29..].to_vec();
    let offsets = (0..grown.len() as u32).map(|i| i * 29).collect();
    let fewer = Curves::new(points, vec![0.001; (grown.len() - 1) * 29], offsets).unwrap();
    groom
        .set_guide_curves(&fewer, 1e-4)
        .unwrap()
        .expect("guides replaced");
    assert_eq!(groom.guides().len(), grown.len() - 1);
}

#[test]
fn saving_to_a_path_that_is_no_file_writes_nothing() {
    let groom = EditableGroom::new(spec(200), 1.0).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let listing = || {
        let mut names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        names.sort();
        names
    };
    // A folder, and paths that name no file: refused before the guides
    // are written beside them.
    let folder = dir.path().join("sub");
    std::fs::create_dir(&folder).unwrap();
    for path in [folder.clone(), folder.join(".."), "".into()] {
        assert!(groom.save(&path, None).is_err(), "{}", path.display());
    }
    // (The folder's save wrote `sub.guides.usdc` beside it before.)
    assert_eq!(listing(), ["sub"], "{:?}", listing());
    // A pipe (as a device would be) is not renamed over.
    let pipe = dir.path().join("fur.toml");
    let made = std::process::Command::new("mkfifo").arg(&pipe).status();
    if made.is_ok_and(|s| s.success()) {
        let e = groom.save(&pipe, None).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        assert!(!std::fs::metadata(&pipe).unwrap().is_file());
        assert_eq!(listing().len(), 2, "{:?}", listing());
    }
}

#[test]
fn a_groom_of_a_mesh_given_as_values_saves_a_file_that_grows_again() {
    // A mesh from arrays (a DCC's, Python's) has no file for `[mesh]
    // path` to name: it is written beside the groom file, and the saved
    // groom grows the session's hairs.
    let spot = pelage::assets::spot();
    let values = Mesh::new(
        "<python mesh>",
        spot.positions().to_vec(),
        spot.triangles().to_vec(),
        Some(spot.normals().to_vec()),
        spot.uvs().cloned(),
    )
    .unwrap();
    let mesh = Arc::new(values);
    let growth = GuideGrowth {
        count: 40,
        length: Map::Constant(0.08),
        points: 6,
        ..Default::default()
    };
    let guides = Guides::grow(&mesh, &growth).unwrap();
    // (Without the file it came from, a save keeps the settings groom
    // files hold beside the guides: no operators.)
    let spec = GroomSpec::new(mesh, guides, RootsSpec::new(600));
    let groom = EditableGroom::new(spec, 1.0).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let saved = groom.save(&dir.path().join("fur.toml"), None).unwrap();
    let mesh_file = saved.mesh.clone().expect("the mesh is written beside");
    let text = std::fs::read_to_string(&saved.groom).unwrap();
    assert!(text.contains("path = \"fur.mesh.obj\""), "{text}");
    let again = pelage::groom::Groom::load(&saved.groom).unwrap();
    assert_eq!(again.mesh().triangle_count(), spot.triangle_count());
    assert!(mesh_file.exists());
    let session = groom.curves();
    let (hairs, worst) = farthest_by_id(&grown_parts(&again), &session);
    assert_eq!(hairs, session.curve_count());
    assert!(
        worst < 1e-4,
        "the saved groom's hairs are {worst} from the session's"
    );
    // The embedded spot is named as `spot`, not by its display name.
    let on_spot = EditableGroom::new(spec_on_spot(), 1.0).unwrap();
    let saved = on_spot.save(&dir.path().join("spot.toml"), None).unwrap();
    assert!(saved.mesh.is_none());
    let text = std::fs::read_to_string(&saved.groom).unwrap();
    assert!(text.contains("path = \"spot\""), "{text}");
    pelage::groom::Groom::load(&saved.groom).unwrap();
}

fn spec_on_spot() -> GroomSpec {
    let mesh = Arc::new(pelage::assets::spot());
    let guides = Guides::grow(&mesh, &GuideGrowth::default()).unwrap();
    GroomSpec::new(mesh, guides, RootsSpec::new(300))
}

#[test]
fn the_first_density_dab_moves_only_the_hairs_under_it() {
    // Painting density adds a layer that scales the groom's density map,
    // starting at 1: the noise density stays, and only the cells under
    // the dab (and a few at the margin) are sampled again. Painting the
    // map read at the vertices instead moved every root. (The layer is
    // added and painted as one step, whose regrowth is counted once:
    // 101,774 of 100,000 were reported when the two were summed.)
    let noise = Map::parse("noise:frequency=6,octaves=3,seed=2,offset=0.6,scale=0.4").unwrap();
    let mut s = spec(20_000);
    s.roots = s.roots.clone().with_density(noise);
    let mut groom = EditableGroom::new(s, 1.0).unwrap();
    let before = groom.curves();
    let at = root(&groom, 3);
    let r = groom
        .brush(
            &Brush::Paint {
                layer: "density".into(),
                value: 0.0,
            },
            &dab(at, 0.15),
        )
        .unwrap()
        .expect("the dab paints");
    assert!(
        r.regrown_roots * 10 < r.hairs,
        "{} of {} regrown",
        r.regrown_roots,
        r.hairs
    );
    // Hairs rooted away from the dab kept their ids and every bit.
    let after = groom.curves();
    let kept = index_by_id(&after);
    let (mut far, mut moved) = (0, 0);
    for (i, id) in before.ids().unwrap().iter().enumerate() {
        let points = &before.points()[before.range(i)];
        if points[0].distance(at) < 0.4 {
            continue;
        }
        far += 1;
        match kept.get(id) {
            Some(&j) if after.points()[after.range(j)] == *points => {}
            _ => moved += 1,
        }
    }
    assert!(
        far > 5_000 && moved * 100 < far,
        "{moved} of {far} far hairs moved"
    );
    // And it is what the painted groom grows from nothing.
    assert_eq!(
        bits(&groom.regrown_from_scratch().unwrap().curves()),
        bits(&after)
    );
    let scale = &groom.spec().roots.density_scale;
    assert!(
        matches!(scale, Map::Vertex(v) if v.name == "density"),
        "{scale:?}"
    );
    // The first part dab likewise regrows the hairs its parting reaches.
    let r = groom
        .brush(&Brush::Part { region: 1 }, &dab(root(&groom, 50), 0.15))
        .unwrap()
        .expect("the dab parts");
    assert!(
        r.regrown_roots * 4 < r.hairs,
        "{} of {} regrown",
        r.regrown_roots,
        r.hairs
    );
}

#[test]
fn a_painted_animated_groom_saves_a_file_that_grows_and_simulates_again() {
    let dir = tempfile::tempdir().unwrap();
    let fox = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/fox/Fox.gltf");
    for mode in ["deform", "simulate"] {
        let groom_file = dir.path().join(format!("{mode}.toml"));
        std::fs::write(
            &groom_file,
            format!(
                "[mesh]\npath = {fox:?}\n[roots]\ncount = 400\n\
                 [guides]\ngenerate = {{ count = 30, length = 5.0 }}\n\
                 [animation]\nframes = \"1-3\"\nclip = \"Run\"\nmode = \"{mode}\"\n"
            ),
        )
        .unwrap();
        let loaded = pelage::groom::Groom::load(&groom_file).unwrap();
        let mut groom = EditableGroom::new(loaded.spec().unwrap(), 1.0).unwrap();
        groom
            .brush(
                &Brush::Paint {
                    layer: "density".into(),
                    value: 0.0,
                },
                &dab(root(&groom, 3), 8.0),
            )
            .unwrap()
            .unwrap();
        let saved = groom
            .save(
                &dir.path().join(format!("{mode}_groomed.toml")),
                Some(loaded.source()),
            )
            .unwrap();
        let again = pelage::groom::Groom::load(&saved.groom).unwrap();
        let animated = again.animated(None).unwrap().expect("still animated");
        let frame = animated.part(0, 2.0).unwrap();
        assert!(frame.curve_count() > 0, "{mode}");
        if mode == "simulate" {
            again.simulated_guides().unwrap();
        }
    }
}
