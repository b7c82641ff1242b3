//! `pelage info [MESH]`: what a mesh is made of, and what is wrong with it.

use super::load_mesh;
use crate::format::{short, thousands};
use clap::Args;
use pelage::Mesh;
use pelage::mesh::Uvs;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `pelage info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Mesh file (.obj, .ply, .gltf, .glb). Without it, the embedded Spot.
    pub mesh: Option<PathBuf>,
    /// Midpoint-subdivide the mesh this many times first (×4 triangles each).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=6))]
    pub subdivide: u32,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    let mesh = load_mesh(args.mesh.as_deref())?.subdivided(args.subdivide);
    let summary = MeshSummary::of(&mesh, args.subdivide);
    if args.json {
        println!("{}", summary.json());
    } else {
        print!("{}", summary.table());
    }
    Ok(())
}

/// Everything `info` reports, gathered once so the table and the JSON
/// always agree.
pub struct MeshSummary {
    pub name: String,
    pub subdivisions: u32,
    pub vertices: usize,
    pub triangles: usize,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub surface_area: f64,
    pub uvs: Option<&'static str>,
    pub degenerate_triangles: usize,
    pub edges: usize,
    pub boundary_edges: usize,
    pub non_manifold_edges: usize,
    pub isolated_vertices: usize,
}

impl MeshSummary {
    pub fn of(mesh: &Mesh, subdivisions: u32) -> Self {
        let (lo, hi) = mesh.bounds();
        let topology = mesh.topology_report();
        Self {
            name: mesh.name().to_string(),
            subdivisions,
            vertices: mesh.vertex_count(),
            triangles: mesh.triangle_count(),
            bounds_min: lo.to_array(),
            bounds_max: hi.to_array(),
            surface_area: mesh.surface_area(),
            uvs: mesh.uvs().map(|uvs| match uvs {
                Uvs::PerVertex(_) => "per vertex",
                Uvs::PerCorner { .. } => "per corner",
            }),
            degenerate_triangles: mesh.degenerate_triangle_count(),
            edges: topology.edges,
            boundary_edges: topology.boundary_edges,
            non_manifold_edges: topology.non_manifold_edges,
            isolated_vertices: topology.isolated_vertices,
        }
    }

    pub fn table(&self) -> String {
        let n = |x: usize| thousands(x as u64);
        let v3 = |v: [f32; 3]| {
            format!(
                "({}, {}, {})",
                short(f64::from(v[0])),
                short(f64::from(v[1])),
                short(f64::from(v[2]))
            )
        };
        let size: Vec<f32> = (0..3)
            .map(|k| self.bounds_max[k] - self.bounds_min[k])
            .collect();
        let mut out = String::new();
        let mut row = |label: &str, value: String| {
            let _ = writeln!(out, "{label:<20}{value}");
        };
        let subdivided = match self.subdivisions {
            0 => String::new(),
            k => format!(" (subdivided ×{k})"),
        };
        row("mesh", format!("{}{subdivided}", self.name));
        row("vertices", n(self.vertices));
        row("triangles", n(self.triangles));
        row(
            "bounds",
            format!("{} to {}", v3(self.bounds_min), v3(self.bounds_max)),
        );
        row("size", v3([size[0], size[1], size[2]]));
        row("surface area", short(self.surface_area));
        row(
            "UVs",
            match self.uvs {
                Some(kind) => format!("yes ({kind})"),
                None => "no (image and noise maps cannot be used on this mesh)".into(),
            },
        );
        row(
            "degenerate",
            format!(
                "{} triangles (kept, zero area)",
                n(self.degenerate_triangles)
            ),
        );
        row("edges", n(self.edges));
        row("boundary edges", n(self.boundary_edges));
        row("non-manifold edges", n(self.non_manifold_edges));
        row("isolated vertices", n(self.isolated_vertices));
        out
    }

    pub fn json(&self) -> String {
        serde_json::json!({
            "mesh": self.name,
            "subdivisions": self.subdivisions,
            "vertices": self.vertices,
            "triangles": self.triangles,
            "bounds_min": self.bounds_min,
            "bounds_max": self.bounds_max,
            "surface_area": self.surface_area,
            "uvs": self.uvs.map(|kind| kind.to_string()),
            "degenerate_triangles": self.degenerate_triangles,
            "edges": self.edges,
            "boundary_edges": self.boundary_edges,
            "non_manifold_edges": self.non_manifold_edges,
            "isolated_vertices": self.isolated_vertices,
        })
        .to_string()
    }
}
