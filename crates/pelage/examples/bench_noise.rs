//! Microbenchmark of `NoiseMap::perlin3_vector`, the 3-D vector Perlin
//! lookup that the noise operator and the wind's turbulence call per point
//! or per mass: ns a call over 20 M points along a wandering line.
fn main() {
    let noise = pelage::map::NoiseMap::new(1.0, 1, 1, 0.0, 1.0);
    let n = 20_000_000;
    let t = std::time::Instant::now();
    let mut acc = glam::Vec3::ZERO;
    for i in 0..n {
        let f = i as f32;
        let p = glam::Vec3::new(f * 0.00123, (f * 0.000731).sin() * 40.0, f * 0.0000917);
        acc += noise.perlin3_vector(p);
    }
    let ns = t.elapsed().as_secs_f64() * 1e9 / n as f64;
    eprintln!("{ns:.1} ns a call ({acc})");
}
