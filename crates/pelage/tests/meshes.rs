//! Loading and subdividing the real meshes the project uses
//! (`tests/data/meshes/`, with their licences) and the small valid files
//! in `tests/data/good/`.

use pelage::Mesh;
use pelage::mesh::Uvs;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

fn test_mesh(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/meshes")
        .join(file)
}

fn good(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/good")
        .join(file)
}

#[test]
fn blub_loads_as_its_licence_file_describes() {
    let blub = Mesh::load(test_mesh("blub_triangulated.obj")).unwrap();
    assert_eq!(blub.triangle_count(), 14_208);
    assert_eq!(blub.vertex_count(), 7_106);
    assert!(blub.has_uvs());
    let r = blub.topology_report();
    assert_eq!((r.boundary_edges, r.non_manifold_edges), (0, 0));
}

/// Number of mesh edges whose two sides carry different UVs: the UV seams.
fn uv_seam_edges(mesh: &Mesh) -> usize {
    let mut sides: HashMap<[u32; 2], Vec<[[u32; 2]; 2]>> = HashMap::new();
    for (t, tri) in mesh.triangles().iter().enumerate() {
        let uvs = mesh.triangle_uvs(t).unwrap();
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let (ua, ub) = (
                uvs[k].to_array().map(f32::to_bits),
                uvs[(k + 1) % 3].to_array().map(f32::to_bits),
            );
            // Store each side's UVs in (lo, hi) vertex order so sides compare.
            let (key, side) = if a < b {
                ([a, b], [ua, ub])
            } else {
                ([b, a], [ub, ua])
            };
            sides.entry(key).or_default().push(side);
        }
    }
    sides
        .values()
        .filter(|s| s.len() == 2 && s[0] != s[1])
        .count()
}

fn check_subdivision(mesh: &Mesh, levels: u32) {
    let fine = mesh.subdivided(levels);
    let factor = 4usize.pow(levels);
    assert_eq!(fine.triangle_count(), mesh.triangle_count() * factor);
    let relative = (fine.surface_area() - mesh.surface_area()).abs() / mesh.surface_area();
    assert!(relative < 1e-5, "area changed by {relative:e} relative");
    let (r0, r1) = (mesh.topology_report(), fine.topology_report());
    assert_eq!(r1.boundary_edges, r0.boundary_edges * 2usize.pow(levels));
    assert_eq!(r1.non_manifold_edges, 0);

    // UV continuity, 1: every child corner has the UV the parent triangle
    // has at that point (the parent of triangle t at level L is t / 4^L).
    for t in (0..fine.triangle_count()).step_by(7) {
        let parent = t / factor;
        let [p0, p1, p2] = mesh.triangle_positions(parent);
        let [t0, t1, t2] = mesh.triangle_uvs(parent).unwrap();
        for (p, uv) in fine
            .triangle_positions(t)
            .iter()
            .zip(fine.triangle_uvs(t).unwrap())
        {
            // Barycentrics of p in the parent by least squares on its plane.
            let (e1, e2, d) = (p1 - p0, p2 - p0, *p - p0);
            let (a, b, c) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
            let det = a * c - b * b;
            let b1 = (c * e1.dot(d) - b * e2.dot(d)) / det;
            let b2 = (a * e2.dot(d) - b * e1.dot(d)) / det;
            let expected = t0 + b1 * (t1 - t0) + b2 * (t2 - t0);
            assert!(
                (uv - expected).length() < 1e-4,
                "triangle {t}: uv {uv} expected {expected}"
            );
        }
    }
    // UV continuity, 2: no new seams, each old seam split into 2^L pieces.
    assert!(
        uv_seam_edges(mesh) > 0,
        "the test needs a mesh with UV seams"
    );
    assert_eq!(
        uv_seam_edges(&fine),
        uv_seam_edges(mesh) * 2usize.pow(levels)
    );
}

#[test]
fn subdivided_blub_keeps_area_and_uvs() {
    let blub = Mesh::load(test_mesh("blub_triangulated.obj")).unwrap();
    check_subdivision(&blub, 1);
    assert_eq!(blub.subdivided(1).triangle_count(), 56_832);
}

#[test]
fn subdivided_spot_keeps_area_and_uvs() {
    let spot = pelage::assets::spot();
    check_subdivision(&spot, 2);
    assert_eq!(spot.subdivided(2).triangle_count(), 93_696);
}

#[test]
fn gltf_cube_is_welded_closed_with_uvs_per_corner() {
    for file in ["cube.gltf", "cube.glb"] {
        let cube = Mesh::load(good(file)).unwrap();
        assert_eq!(cube.vertex_count(), 8, "{file}");
        assert_eq!(cube.triangle_count(), 12);
        // The node scales the unit cube by 2: area 6 × 4.
        assert!((cube.surface_area() - 24.0).abs() < 1e-5);
        assert_eq!(cube.topology_report().boundary_edges, 0);
        assert!(matches!(cube.uvs(), Some(Uvs::PerCorner { .. })));
        // Welded corners average the three face normals: the diagonal.
        for (p, n) in cube.positions().iter().zip(cube.normals()) {
            assert!((p.normalize() - *n).length() < 1e-5, "{p} {n}");
        }
    }
}
