//! Profiling harness for the groom generator (`perf record` it): the
//! `pelage bench groom` groom (spot ×2, 1,000 guides, Shepard k = 4, a
//! clump centre every 100 hairs, noise, 16 points, normals, widths), HAIRS
//! hairs (default 400,000) grown in memory.
//! OPS=none drops the operators, to see interpolation alone; NORMALS=0
//! drops the per-point normals; FRACTION=0.1 grows a preview fraction of
//! them (the bench's `fraction_0_1` row), preparation included;
//! BLUE_NOISE=1 draws blue-noise roots (the `blue_noise_groom` row);
//! OUTSIDE_SKIN=1 keeps the hairs out of the skin (`outside_skin`).
use pelage::groom::Groom;

fn main() {
    let hairs: u64 = std::env::var("HAIRS")
        .ok()
        .and_then(|h| h.parse().ok())
        .unwrap_or(400_000);
    // As `pelage bench groom`: a clump centre for every 100 hairs.
    let ops = if std::env::var("OPS").as_deref() == Ok("none") {
        String::new()
    } else {
        format!(
            "[[ops]]\nclump = {{ count = {}, rate = 0.6 }}\n[[ops]]\nnoise = {{ amplitude = 0.004, frequency = 30 }}\n",
            (hairs / 100).max(1)
        )
    };
    let normals = std::env::var("NORMALS").as_deref() != Ok("0");
    let outside = match std::env::var("OUTSIDE_SKIN").as_deref() {
        Ok("1") => "outside_skin = true\n",
        _ => "",
    };
    let distribution = match std::env::var("BLUE_NOISE").as_deref() {
        Ok("1") => "distribution = \"blue-noise\"\n",
        _ => "",
    };
    let text = format!(
        "[mesh]\npath = \"spot\"\nsubdivide = 2\n[roots]\ncount = {hairs}\n{distribution}density = \"noise:frequency=6,octaves=3,seed=2,offset=0.6,scale=0.4\"\n[guides]\npoints = 8\ngenerate = {{ count = 1000, length = 0.06, comb = [0, -0.5, -1], gravity = 0.3 }}\n[interpolation]\nmethod = \"shepard\"\nk = 4\n{ops}[finish]\npoints = 16\nnormals = {normals}\nwidth = {{ root = 0.0015, tip = 0.0002 }}\n{outside}"
    );
    let mut groom = Groom::from_text("<profile>", text).unwrap();
    if let Some(fraction) = std::env::var("FRACTION").ok().and_then(|f| f.parse().ok()) {
        groom.set_fraction(fraction).unwrap();
    }
    let start = std::time::Instant::now();
    let t = std::time::Instant::now();
    let generator = groom.generator(None).unwrap();
    eprintln!("prepare {:?}", t.elapsed());
    let t = std::time::Instant::now();
    let mut n = 0;
    // A checksum of every point, width and normal, hair by hair and
    // independent of the hairs' order, to tell whether a change altered the
    // output (CHECKSUM=1; it costs a pass over the arrays).
    let checksum = std::env::var("CHECKSUM").as_deref() == Ok("1");
    let mut sum = 0u64;
    for p in 0..generator.parts().len() {
        let part = generator.part(p).expect("the benchmark groom grows");
        n += part.curve_count();
        if checksum {
            // Hair by hair, summed: the same whatever order a part's hairs
            // are grown in.
            let ids = part.ids().expect("stable ids");
            for (c, &id) in ids.iter().enumerate() {
                let range = part.range(c);
                let normals = part.normals().map_or(&[][..], |n| &n[range.clone()]);
                let vectors = part.points()[range.clone()].iter().chain(normals);
                let bits = vectors
                    .flat_map(|v| v.to_array())
                    .chain(part.widths()[range].iter().copied())
                    .map(f32::to_bits);
                let h = bits.fold(id, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
                sum = sum.wrapping_add(h);
            }
        }
        generator.recycle(part);
    }
    let s = t.elapsed().as_secs_f64();
    eprintln!("{n} hairs in {s:.3} s: {:.2} M hairs/s", n as f64 / s / 1e6);
    eprintln!("all of it {:.3} s", start.elapsed().as_secs_f64());
    if checksum {
        eprintln!("checksum {sum:016x}");
    }
}
