//! Statistical tests of the root samplers (Sik §3): chi-square of sample
//! counts per triangle and per texel against exact expected probabilities,
//! for all three methods and four density maps; a deliberately wrong
//! sampler must fail the same test; determinism across threads and ranges;
//! errors for densities that cannot be sampled.
//!
//! Exactness: on the flat test mesh below, every triangle is half of a
//! power-of-two square of texels, so each sub-triangle the sampler makes
//! lies inside one texel, and with nearest filtering the paper's
//! centroid rule is exact. The expected probabilities are computed here
//! independently, by clipping each triangle against each texel.

mod support;
use glam::{Vec2, Vec3};
use pelage::map::{Filter, ImageMap, Map, NoiseMap, Wrap};
use pelage::mesh::{Mesh, SurfacePoint, Uvs};
use pelage::sample::{
    DensitySampler, DensitySamplerOptions, RejectionSampler, SampleError, SampleRng, Selector,
    SurfaceSampler, sample_range,
};
use support::chi_square::{assert_fits, chi_square, chi_square_limit};

const TEXELS: u32 = 32;
const SAMPLES: u64 = 1_000_000;

/// The unit square tiled by squares of 16, 8, 4 and 2 texels (one size
/// per quadrant), each split into two right triangles, diagonals
/// alternating. UV = xy. Triangle areas differ 64-fold.
fn quadtree_square() -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let quadrants = [(0.0, 0.5, 16), (0.5, 0.5, 8), (0.0, 0.0, 4), (0.5, 0.0, 2)];
    let mut flip = false;
    for (qx, qy, size) in quadrants {
        let s = size as f32 / TEXELS as f32;
        let n = 16 / size;
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (qx + i as f32 * s, qy + j as f32 * s);
                let base = positions.len() as u32;
                positions.extend([
                    Vec3::new(x, y, 0.0),
                    Vec3::new(x + s, y, 0.0),
                    Vec3::new(x + s, y + s, 0.0),
                    Vec3::new(x, y + s, 0.0),
                ]);
                if flip {
                    triangles.extend([[base, base + 1, base + 3], [base + 1, base + 2, base + 3]]);
                } else {
                    triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
                }
                flip = !flip;
            }
        }
    }
    let uvs = positions.iter().map(|p| p.truncate()).collect();
    Mesh::new(
        "quadtree square",
        positions,
        triangles,
        None,
        Some(Uvs::PerVertex(uvs)),
    )
    .unwrap()
}

fn texture(values: impl Fn(u32, u32) -> f32) -> ImageMap {
    // Texel (x, y) with y counted from the bottom, as UVs are.
    let mut texels = Vec::with_capacity((TEXELS * TEXELS) as usize);
    for row in 0..TEXELS {
        for x in 0..TEXELS {
            texels.push(values(x, TEXELS - 1 - row));
        }
    }
    ImageMap::from_texels(TEXELS, TEXELS, texels, Wrap::Clamp)
        .unwrap()
        .with_filter(Filter::Nearest)
}

fn test_maps() -> Vec<(&'static str, Map)> {
    let noise = NoiseMap::new(3.0, 3, 11, 0.5, 0.5);
    vec![
        ("constant", Map::Constant(1.0)),
        (
            "gradient",
            Map::Image(texture(|x, _| (x as f32 + 0.5) / TEXELS as f32)),
        ),
        (
            "checkerboard",
            Map::Image(texture(|x, y| ((x / 4 + y / 4) % 2) as f32)),
        ),
        (
            "perlin",
            Map::Image(texture(|x, y| {
                noise.eval(Vec2::new((x as f32 + 0.5) / 32.0, (y as f32 + 0.5) / 32.0))
            })),
        ),
    ]
}

/// Area of the polygon clipped to the axis-aligned box (Sutherland–Hodgman).
fn clipped_area(polygon: &[Vec2], lo: Vec2, hi: Vec2) -> f64 {
    let mut poly = polygon.to_vec();
    let planes: [(Vec2, f32); 4] = [
        (Vec2::X, lo.x),
        (-Vec2::X, -hi.x),
        (Vec2::Y, lo.y),
        (-Vec2::Y, -hi.y),
    ];
    for (normal, offset) in planes {
        let inside = |p: Vec2| normal.dot(p) >= offset;
        let mut next = Vec::new();
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            if inside(a) {
                next.push(a);
            }
            if inside(a) != inside(b) {
                let t = (offset - normal.dot(a)) / normal.dot(b - a);
                next.push(a + t * (b - a));
            }
        }
        poly = next;
        if poly.is_empty() {
            return 0.0;
        }
    }
    let mut twice = 0.0f64;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        twice += f64::from(a.x) * f64::from(b.y) - f64::from(b.x) * f64::from(a.y);
    }
    0.5 * twice.abs()
}

/// Exact probability of each triangle of the flat mesh under a map that is
/// constant on each texel (nearest filter), or constant.
fn exact_triangle_probabilities(mesh: &Mesh, map: &Map) -> Vec<f64> {
    let texel = 1.0 / TEXELS as f32;
    let mut masses: Vec<f64> = (0..mesh.triangle_count())
        .map(|t| {
            let tri: Vec<Vec2> = mesh
                .triangle_positions(t)
                .iter()
                .map(|p| p.truncate())
                .collect();
            let mut mass = 0.0;
            for x in 0..TEXELS {
                for y in 0..TEXELS {
                    let lo = Vec2::new(x as f32, y as f32) * texel;
                    let area = clipped_area(&tri, lo, lo + Vec2::splat(texel));
                    if area > 0.0 {
                        mass += area * f64::from(map.eval(lo + Vec2::splat(0.5 * texel)));
                    }
                }
            }
            mass
        })
        .collect();
    let total: f64 = masses.iter().sum();
    masses.iter_mut().for_each(|m| *m /= total);
    masses
}

fn exact_texel_probabilities(map: &Map) -> Vec<f64> {
    let values: Vec<f64> = (0..TEXELS * TEXELS)
        .map(|i| {
            let (x, y) = (i % TEXELS, i / TEXELS);
            f64::from(map.eval(Vec2::new((x as f32 + 0.5) / 32.0, (y as f32 + 0.5) / 32.0)))
        })
        .collect();
    let total: f64 = values.iter().sum();
    values.iter().map(|v| v / total).collect()
}

fn counts_per_triangle(mesh: &Mesh, points: &[SurfacePoint]) -> Vec<u64> {
    let mut counts = vec![0u64; mesh.triangle_count()];
    for p in points {
        counts[p.tri as usize] += 1;
    }
    counts
}

/// Counts per texel. A sample within 10⁻⁴ texel of a texel edge lies on
/// it up to f32 rounding (sub-triangle edges coincide with texel edges
/// here); it is counted in the adjacent texel of larger expected
/// probability, as its texel is ambiguous.
fn counts_per_texel(mesh: &Mesh, points: &[SurfacePoint], probabilities: &[f64]) -> Vec<u64> {
    const EPS: f32 = 1e-4;
    let mut counts = vec![0u64; (TEXELS * TEXELS) as usize];
    let cell = |v: f32| (v.floor().max(0.0) as u32).min(TEXELS - 1);
    for p in points {
        let t = p.uv(mesh).unwrap() * TEXELS as f32;
        let xs = [cell(t.x - EPS), cell(t.x + EPS)];
        let ys = [cell(t.y - EPS), cell(t.y + EPS)];
        let best = xs
            .iter()
            .flat_map(|&x| ys.iter().map(move |&y| (y * TEXELS + x) as usize))
            .max_by(|&a, &b| probabilities[a].total_cmp(&probabilities[b]))
            .unwrap();
        counts[best] += 1;
    }
    counts
}

fn subdivision(mesh: &Mesh, map: &Map) -> DensitySampler {
    let options = DensitySamplerOptions {
        selector: Selector::CdfGrid { grid_percent: 100 },
        ..Default::default()
    };
    DensitySampler::new(leak_mesh(mesh), map, options).unwrap()
}

fn alias(mesh: &Mesh, map: &Map) -> DensitySampler {
    let options = DensitySamplerOptions {
        selector: Selector::Alias,
        ..Default::default()
    };
    DensitySampler::new(leak_mesh(mesh), map, options).unwrap()
}

/// The three methods on one mesh and map, by name.
fn all_methods(mesh: &Mesh, map: &'static Map) -> Vec<(&'static str, Box<dyn SurfaceSampler>)> {
    vec![
        ("subdivision+grid", Box::new(subdivision(mesh, map))),
        ("alias", Box::new(alias(mesh, map))),
        (
            "rejection",
            Box::new(RejectionSampler::new(leak_mesh(mesh), map).unwrap()),
        ),
    ]
}

// The samplers borrow their mesh; the tests keep both for the whole run.
fn leak_mesh(mesh: &Mesh) -> &'static Mesh {
    Box::leak(Box::new(mesh.clone()))
}

#[test]
fn all_methods_match_exact_probabilities_per_triangle_and_per_texel() {
    let mesh = quadtree_square();
    for (name, map) in test_maps() {
        let map: &'static Map = Box::leak(Box::new(map));
        let per_triangle = exact_triangle_probabilities(&mesh, map);
        let per_texel = exact_texel_probabilities(map);
        let samplers = all_methods(&mesh, map);
        for (method, sampler) in samplers {
            let points: Vec<SurfacePoint> = (0..SAMPLES).map(|i| sampler.sample(42, i)).collect();
            assert_fits(
                &format!("{method}, {name}, per triangle"),
                &counts_per_triangle(&mesh, &points),
                &per_triangle,
            );
            assert_fits(
                &format!("{method}, {name}, per texel"),
                &counts_per_texel(&mesh, &points, &per_texel),
                &per_texel,
            );
        }
    }
}

/// The test of the test: a sampler that picks triangles by density alone,
/// ignoring their areas, must fail the same chi-square.
#[test]
fn a_sampler_that_ignores_area_fails_the_test() {
    struct IgnoresArea {
        weights: Vec<f64>,
        areas: Vec<f64>,
    }
    impl SurfaceSampler for IgnoresArea {
        fn sample(&self, seed: u64, index: u64) -> SurfacePoint {
            let mut rng = SampleRng::new(seed, index);
            let total: f64 = self.weights.iter().sum();
            let mut x = rng.uniform_f32() as f64 * total;
            let mut t = 0;
            while t + 1 < self.weights.len() && x >= self.weights[t] {
                x -= self.weights[t];
                t += 1;
            }
            let bary = pelage::sample::warp::sample_uniform_triangle(rng.uniform_f32_pair());
            SurfacePoint {
                tri: t as u32,
                bary,
            }
        }
        /// Its own (wrong) density: triangle weight over the total, spread
        /// uniformly over the triangle.
        fn pdf(&self, p: SurfacePoint) -> f64 {
            let total: f64 = self.weights.iter().sum();
            self.weights[p.tri as usize] / total / self.areas[p.tri as usize]
        }
    }
    let mesh = quadtree_square();
    for (name, map) in test_maps() {
        let exact = exact_triangle_probabilities(&mesh, &map);
        // Mean density per triangle: the right mass divided by the area.
        let weights = exact
            .iter()
            .zip(mesh.triangle_areas())
            .map(|(p, a)| p / f64::from(*a))
            .collect();
        let areas = mesh
            .triangle_areas()
            .iter()
            .map(|&a| f64::from(a))
            .collect();
        let wrong = IgnoresArea { weights, areas };
        let points: Vec<SurfacePoint> = (0..SAMPLES).map(|i| wrong.sample(7, i)).collect();
        let (chi2, dof) = chi_square(&counts_per_triangle(&mesh, &points), &exact);
        assert!(
            chi2 > 10.0 * chi_square_limit(dof),
            "{name}: the wrong sampler passed (chi-square {chi2:.1})"
        );
    }
}

#[test]
fn spot_with_constant_density_is_uniform_by_area_for_all_methods() {
    let spot = pelage::assets::spot();
    let map: &'static Map = Box::leak(Box::new(Map::Constant(1.0)));
    let total = spot.surface_area();
    let expected: Vec<f64> = spot
        .triangle_areas()
        .iter()
        .map(|a| f64::from(*a) / total)
        .collect();
    let samplers = all_methods(&spot, map);
    for (method, sampler) in samplers {
        let points = sample_range(sampler.as_ref(), 3, 0..SAMPLES);
        assert_fits(
            &format!("{method} on spot"),
            &counts_per_triangle(&spot, &points),
            &expected,
        );
    }
}

#[test]
fn spot_with_perlin_noise_matches_each_samplers_own_density() {
    // Bilinear procedural noise: the subdivision samplers realise the
    // centroid-rule distribution their records define; rejection realises
    // the continuous map. Each is checked against its own probabilities,
    // and pdf() is checked to integrate to them.
    let spot = pelage::assets::spot();
    let map: &'static Map = Box::leak(Box::new(Map::Noise(NoiseMap::new(6.0, 3, 5, 0.5, 0.5))));
    let sampler = alias(&spot, map);
    let own: Vec<f64> = (0..spot.triangle_count())
        .map(|t| sampler.triangle_probability(t))
        .collect();
    let points = sample_range(&sampler, 9, 0..SAMPLES);
    assert_fits(
        "alias on spot, perlin",
        &counts_per_triangle(&spot, &points),
        &own,
    );

    let rejection = RejectionSampler::new(leak_mesh(&spot), map).unwrap();
    let integrated = integrate_pdf(&spot, &rejection);
    let total: f64 = integrated.iter().sum();
    assert!(
        (total - 1.0).abs() < 2e-3,
        "rejection pdf integrates to {total}"
    );
    let expected: Vec<f64> = integrated.iter().map(|p| p / total).collect();
    let points = sample_range(&rejection, 9, 0..SAMPLES);
    assert_fits(
        "rejection on spot, perlin",
        &counts_per_triangle(&spot, &points),
        &expected,
    );

    // The subdivision sampler's pdf integrates, triangle by triangle, to
    // the probability its records give.
    let integrated = integrate_pdf(&spot, &sampler);
    for t in (0..spot.triangle_count()).step_by(13) {
        let (a, b) = (integrated[t], own[t]);
        assert!(
            (a - b).abs() <= 1e-3 * b + 1e-9,
            "triangle {t}: ∫pdf {a} vs {b}"
        );
    }
}

/// ∫ pdf dA over each triangle, by the centroid rule on 4⁴ sub-triangles.
fn integrate_pdf(mesh: &Mesh, sampler: &impl SurfaceSampler) -> Vec<f64> {
    use pelage::sample::subtriangle::decode;
    let level4: Vec<_> = (84..340).map(decode).collect();
    (0..mesh.triangle_count())
        .map(|t| {
            let area = f64::from(mesh.triangle_areas()[t]);
            level4
                .iter()
                .map(|sub| {
                    let c = sub.centroid();
                    let p = SurfacePoint {
                        tri: t as u32,
                        bary: [c.x, c.y],
                    };
                    sampler.pdf(p) * area * f64::from(sub.area_fraction())
                })
                .sum()
        })
        .collect()
}

#[test]
fn zero_density_regions_and_degenerate_triangles_get_no_samples() {
    // A strip: two proper triangles in the density's zero half, two in its
    // one half, and two degenerate triangles (repeated vertex, collinear).
    let positions = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(0.5, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.75, 0.0, 0.0),
    ];
    let uvs: Vec<Vec2> = positions.iter().map(|p| p.truncate()).collect();
    let triangles = vec![
        [0, 1, 2],
        [0, 2, 3],
        [1, 4, 5],
        [1, 5, 2],
        [1, 1, 5],
        [1, 6, 4],
    ];
    let mesh = Mesh::new(
        "strip",
        positions,
        triangles,
        None,
        Some(Uvs::PerVertex(uvs)),
    )
    .unwrap();
    assert_eq!(mesh.degenerate_triangle_count(), 2);
    let half = ImageMap::from_texels(2, 1, vec![0.0, 1.0], Wrap::Clamp)
        .unwrap()
        .with_filter(Filter::Nearest);
    let map: &'static Map = Box::leak(Box::new(Map::Image(half)));
    let samplers = all_methods(&mesh, map);
    for (method, sampler) in samplers {
        let counts = counts_per_triangle(&mesh, &sample_range(sampler.as_ref(), 1, 0..200_000));
        assert_eq!(
            &counts[0..2],
            &[0, 0],
            "{method}: samples in the zero-density half"
        );
        assert_eq!(
            &counts[4..6],
            &[0, 0],
            "{method}: samples on degenerate triangles"
        );
        assert!(counts[2] > 0 && counts[3] > 0);
        assert_eq!(
            sampler.pdf(SurfacePoint {
                tri: 0,
                bary: [0.3, 0.3]
            }),
            0.0
        );
    }
}

#[test]
fn same_seed_same_samples_on_one_and_two_threads_and_in_ranges() {
    let spot = pelage::assets::spot();
    let map = Map::Noise(NoiseMap::default());
    for selector in [Selector::Alias, Selector::CdfGrid { grid_percent: 100 }] {
        let options = DensitySamplerOptions {
            selector,
            ..Default::default()
        };
        let build = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let sampler = DensitySampler::new(&spot, &map, options).unwrap();
                (
                    sampler.records().to_vec(),
                    sample_range(&sampler, 77, 0..300_000),
                )
            })
        };
        let (records_1, points_1) = build(1);
        let (records_2, points_2) = build(2);
        assert_eq!(
            records_1, records_2,
            "records differ between 1 and 2 threads"
        );
        assert_eq!(points_1, points_2, "samples differ between 1 and 2 threads");

        let sampler = DensitySampler::new(&spot, &map, options).unwrap();
        let middle = sample_range(&sampler, 77, 123_457..200_001);
        assert_eq!(middle.as_slice(), &points_1[123_457..200_001]);
        assert_ne!(sample_range(&sampler, 78, 0..1000), points_1[..1000]);
    }
}

#[test]
fn constant_density_merges_every_triangle_into_one_record() {
    let spot = pelage::assets::spot();
    let sampler = DensitySampler::new(&spot, &Map::Constant(0.3), Default::default()).unwrap();
    assert_eq!(sampler.records().len(), spot.triangle_count());
    // A checkerboard of 4×4-texel cells on the flat mesh: the 16-texel
    // squares subdivide to level 4 (256 leaves each) and merge back to
    // 4×4-texel blocks wherever a block is uniform.
    let mesh = quadtree_square();
    let checker = Map::Image(texture(|x, y| 1.0 + ((x / 4 + y / 4) % 2) as f32));
    let sampler = DensitySampler::new(&mesh, &checker, Default::default()).unwrap();
    let leaves: usize = mesh
        .triangle_areas()
        .iter()
        .map(|a| (a * (TEXELS * TEXELS) as f32 * 2.0).round() as usize)
        .sum();
    assert!(
        sampler.records().len() * 4 < leaves,
        "{} records for {leaves} leaves",
        sampler.records().len()
    );
}

#[test]
fn unusable_densities_are_errors_naming_the_mesh() {
    let spot = pelage::assets::spot();
    let zero = Map::Constant(0.0);
    let err = DensitySampler::new(&spot, &zero, Default::default()).unwrap_err();
    assert!(matches!(err, SampleError::ZeroDensity { .. }));
    assert!(
        err.to_string()
            .starts_with("embedded spot: the density is zero everywhere")
    );
    assert!(RejectionSampler::new(&spot, &zero).is_err());

    let negative = Map::Image(ImageMap::from_texels(1, 1, vec![-0.5], Wrap::Repeat).unwrap());
    let err = DensitySampler::new(&spot, &negative, Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("embedded spot: triangle 0 at UV ("),
        "{err}"
    );
    assert!(
        err.contains("the density is -0.5; densities must be finite and not negative"),
        "{err}"
    );

    let nan = Map::Image(ImageMap::from_texels(1, 1, vec![f32::NAN], Wrap::Repeat).unwrap());
    assert!(matches!(
        DensitySampler::new(&spot, &nan, Default::default()),
        Err(SampleError::BadDensity { .. })
    ));

    let no_uvs = Mesh::new(
        "plain triangle",
        vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        vec![[0, 1, 2]],
        None,
        None,
    )
    .unwrap();
    let image = Map::Image(ImageMap::from_texels(1, 1, vec![1.0], Wrap::Repeat).unwrap());
    let err = DensitySampler::new(&no_uvs, &image, Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("plain triangle: this map is evaluated at UVs, and the mesh has no UVs"),
        "{err}"
    );
    assert!(DensitySampler::new(&no_uvs, &Map::Constant(1.0), Default::default()).is_ok());
    // Noise needs no UVs: it is read at the position instead.
    let noise = Map::Noise(NoiseMap::default());
    assert!(DensitySampler::new(&no_uvs, &noise, Default::default()).is_ok());
}

#[test]
fn block_pipeline_gives_exactly_the_points_of_single_samples() {
    let spot = pelage::assets::spot();
    let map = Map::Noise(NoiseMap::default());
    for selector in [
        Selector::Alias,
        Selector::CdfGrid { grid_percent: 50 },
        Selector::CdfGrid { grid_percent: 0 },
    ] {
        let options = DensitySamplerOptions {
            selector,
            ..Default::default()
        };
        let sampler = DensitySampler::new(&spot, &map, options).unwrap();
        // An odd length and an odd start, so partial blocks are covered.
        let mut block = vec![SurfacePoint::default(); 1_003];
        sampler.sample_block(11, 517, &mut block);
        for (k, p) in block.iter().enumerate() {
            assert_eq!(
                *p,
                sampler.sample(11, 517 + k as u64),
                "{selector:?}, sample {}",
                517 + k
            );
        }
    }
}
