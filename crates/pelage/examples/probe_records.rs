//! Profiling harness for the density sampler's preprocess (blub ×1, 1024²
//! Perlin, 20 builds). Run with `perf record`.
use pelage::map::{ImageMap, Map, NoiseMap, Wrap};
use pelage::sample::{DensitySampler, DensitySamplerOptions};
use std::time::Instant;
fn main() {
    let blub = pelage::Mesh::load("../shared/data/meshes/blub_triangulated.obj")
        .unwrap()
        .subdivided(1);
    let noise = NoiseMap::new(8.0, 4, 1, 0.5, 0.5);
    let size = 1024;
    let texels: Vec<f32> = (0..size * size)
        .map(|i| {
            let (x, y) = (i % size, i / size);
            noise.eval(glam::Vec2::new(
                (x as f32 + 0.5) / size as f32,
                1.0 - (y as f32 + 0.5) / size as f32,
            ))
        })
        .collect();
    let map = Map::Image(ImageMap::from_texels(size, size, texels, Wrap::Repeat).unwrap());
    let t = Instant::now();
    for _ in 0..20 {
        let s = DensitySampler::new(&blub, &map, DensitySamplerOptions::default()).unwrap();
        std::hint::black_box(s.records().len());
    }
    println!("{:.1} ms per build", t.elapsed().as_secs_f64() * 1e3 / 20.0);
}
