//! Profiling harness for the style mesh (`perf record` it): build on spot
//! ×4 with 5,000 guides, then weigh a million hairs on the skin and by
//! position alone.
use pelage::interp::{GuideWeights, HairRoot, StyleMesh};

fn main() {
    let mesh = pelage::assets::spot().subdivided(4);
    let growth = pelage::guides::GuideGrowth {
        count: 5000,
        ..Default::default()
    };
    let guides = pelage::guides::Guides::grow(&mesh, &growth).unwrap();
    let t = std::time::Instant::now();
    let _ = mesh.edges();
    let edges = t.elapsed();
    let t = std::time::Instant::now();
    let _ = mesh.edge_graph();
    eprintln!("mesh edges {edges:?}, edge graph {:?}", t.elapsed());
    let t = std::time::Instant::now();
    let style = StyleMesh::build(&mesh, &guides, &Default::default());
    eprintln!(
        "build {:?}, {} triangles",
        t.elapsed(),
        style.triangles().len()
    );
    let sampler =
        pelage::sample::DensitySampler::new(&mesh, &pelage::Map::Constant(1.0), Default::default())
            .unwrap();
    let mut samples = pelage::sample::sample_range(&sampler, 3, 0..1_000_000);
    // SORTED=1: hairs in skin-triangle order, as a generator working part
    // by part over the mesh would meet them.
    if std::env::var_os("SORTED").is_some() {
        samples.sort_by_key(|s| s.tri);
    }
    let on_skin: Vec<HairRoot> = samples.iter().map(|r| HairRoot::on(&mesh, *r)).collect();
    let anywhere: Vec<HairRoot> = on_skin.iter().map(|r| HairRoot::at(r.position)).collect();
    for (label, roots) in [("on the skin", &on_skin), ("by position", &anywhere)] {
        let mut w = Vec::new();
        let t = std::time::Instant::now();
        let mut sum = 0.0;
        for r in roots {
            style.weights(*r, &mut w);
            sum += w[0].weight;
        }
        let ns = t.elapsed().as_secs_f64() * 1e9 / roots.len() as f64;
        eprintln!("weights {label}: {ns:.1} ns/hair ({sum})");
    }
}
