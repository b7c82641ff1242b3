//! Microbenchmark of `NoiseMap::perlin3_vector`, the 3-D vector Perlin
//! lookup that the noise operator and the wind's turbulence call per point
//! or per mass: ns a point over 20 M points along a wandering line, one at
//! a time and in batches (`perlin3_vectors`).
fn main() {
    let noise = pelage::map::NoiseMap::new(1.0, 1, 1, 0.0, 1.0);
    let n = 20_000_000;
    let points: Vec<glam::Vec3> = (0..n)
        .map(|i| {
            let f = i as f32;
            glam::Vec3::new(f * 0.00123, (f * 0.000731).sin() * 40.0, f * 0.0000917)
        })
        .collect();
    let mut out = vec![glam::Vec3::ZERO; 1024];
    for _ in 0..2 {
        let t = std::time::Instant::now();
        let mut acc = glam::Vec3::ZERO;
        for chunk in points.chunks(1024) {
            for (o, p) in out.iter_mut().zip(chunk) {
                *o = noise.perlin3_vector(*p);
            }
            acc += out[..chunk.len()].iter().copied().sum::<glam::Vec3>();
        }
        let ns = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        eprintln!("one at a time: {ns:.1} ns a point ({acc})");
        let t = std::time::Instant::now();
        let mut acc = glam::Vec3::ZERO;
        for chunk in points.chunks(1024) {
            noise.perlin3_vectors(chunk, &mut out[..chunk.len()]);
            acc += out[..chunk.len()].iter().copied().sum::<glam::Vec3>();
        }
        let ns = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        eprintln!("in batches:    {ns:.1} ns a point ({acc})");
    }
}
