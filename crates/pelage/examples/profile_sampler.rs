//! A harness for profiling the density sampler with `perf record`: blub ×1
//! with a 1024² Perlin density (the benchmark's headline case).
//!
//! ```sh
//! cargo build --release -p pelage --example profile_sampler
//! perf record -g target/release/examples/profile_sampler preprocess   # 20 builds
//! perf record -g target/release/examples/profile_sampler sample       # 5 × 10 M samples, alias
//! perf record -g target/release/examples/profile_sampler sample cdf   # the same with CDF + grid
//! ```
//!
//! It reads blub from the repository's `tests/data/meshes/`.

use pelage::map::{ImageMap, Map, NoiseMap, Wrap};
use pelage::mesh::SurfacePoint;
use pelage::sample::{DensitySampler, DensitySamplerOptions, Selector, SurfaceSampler};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let blub = pelage::Mesh::load(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/data/meshes/blub_triangulated.obj"),
    )
    .expect("blub is in tests/data/meshes")
    .subdivided(1);
    let noise = NoiseMap::new(8.0, 4, 1, 0.5, 0.5);
    let size = 1024u32;
    let texels: Vec<f32> = (0..size * size)
        .map(|i| {
            let (x, y) = (i % size, i / size);
            let uv = glam::Vec2::new(
                (x as f32 + 0.5) / size as f32,
                1.0 - (y as f32 + 0.5) / size as f32,
            );
            noise.eval(uv)
        })
        .collect();
    let map = Map::Image(ImageMap::from_texels(size, size, texels, Wrap::Repeat).unwrap());
    let selector = if args.iter().any(|a| a == "cdf") {
        Selector::CdfGrid { grid_percent: 100 }
    } else {
        Selector::Alias
    };
    let options = DensitySamplerOptions {
        selector,
        ..Default::default()
    };

    if args.iter().any(|a| a == "sample") {
        let sampler = DensitySampler::new(&blub, &map, options).unwrap();
        let mut out = vec![SurfacePoint::default(); 10_000_000];
        let n = out.len();
        for round in 0..5 {
            let start = Instant::now();
            for (c, chunk) in out.chunks_mut(64).enumerate() {
                sampler.sample_block(1, (round * n + c * 64) as u64, chunk);
            }
            let rate = n as f64 / start.elapsed().as_secs_f64() / 1e6;
            println!("{rate:.1} M samples/s");
        }
    } else {
        let start = Instant::now();
        for _ in 0..20 {
            let sampler = DensitySampler::new(&blub, &map, options).unwrap();
            std::hint::black_box(sampler.records().len());
        }
        let ms = start.elapsed().as_secs_f64() * 1e3 / 20.0;
        println!("{ms:.1} ms per build");
    }
}
