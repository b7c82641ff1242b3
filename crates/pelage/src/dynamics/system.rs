//! Mass-spring topologies over a skin mesh (Banisch & Wüthrich, "Mass–Spring
//! Topologies"; Silva et al. §3.2.1).
//!
//! Every topology is made of *sticks*: a root mass on the skin, moved by the
//! skin and never by forces (Banisch: "attached to the initial surface by
//! setting its mass sufficiently large" — here simply kinematic), and a tip
//! mass at the uppermost shell layer, free. What differs is where the sticks
//! stand and which springs join them:
//!
//! | topology | sticks | springs |
//! | --- | --- | --- |
//! | spring-sticks | one per vertex | root–tip |
//! | separable spring-sticks | one per triangle corner | root–tip |
//! | prisms | one per vertex | root–tip + tip–tip along every mesh edge |
//! | separable prisms | one per triangle corner | root–tip + tip–tip along each triangle's own edges |
//! | Silva strands | one per triangle, at its centroid | tip to its rest position `p0` (zero length) |
//!
//! Separable topologies treat each triangle as its own surface, so the
//! shell layers of neighbouring triangles can part (Banisch Fig. 5b, 12).
//! Silva strands are limited to `|p − p_root| ≤ L0` and the hemisphere above
//! the surface (Eq. 3); every other topology keeps its tips above the skin's
//! tangent plane too, besides Banisch's restoring force (Eq. 5).

use crate::Mesh;
use glam::Vec3;

/// Which masses and springs (see the module table); scene files name them
/// in kebab case (`spring-sticks`, `separable-prisms`, …).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Topology {
    /// One stick per vertex.
    SpringSticks,
    /// One stick per triangle corner: shells can part.
    SeparableSpringSticks,
    /// Sticks per vertex, tips joined along the mesh edges.
    Prisms,
    /// Sticks per corner, tips joined along each triangle's edges.
    SeparablePrisms,
    /// Silva §3.2.1: one mass per triangle, a spring to its rest position.
    SilvaStrands,
}

impl Topology {
    /// Every topology, in the order of the papers.
    pub const ALL: [Topology; 5] = [
        Topology::SpringSticks,
        Topology::SeparableSpringSticks,
        Topology::Prisms,
        Topology::SeparablePrisms,
        Topology::SilvaStrands,
    ];

    /// The name scene files and the benchmark use.
    pub fn name(self) -> &'static str {
        match self {
            Topology::SpringSticks => "spring-sticks",
            Topology::SeparableSpringSticks => "separable-spring-sticks",
            Topology::Prisms => "prisms",
            Topology::SeparablePrisms => "separable-prisms",
            Topology::SilvaStrands => "silva-strands",
        }
    }

    /// The topology called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    /// Whether springs join the tips (the prisms): the implicit step then
    /// solves one system over all of them, not a 3×3 one per tip.
    pub fn joins_tips(self) -> bool {
        matches!(self, Topology::Prisms | Topology::SeparablePrisms)
    }

    /// Whether each triangle has sticks of its own.
    pub fn is_per_corner(self) -> bool {
        matches!(
            self,
            Topology::SeparableSpringSticks | Topology::SeparablePrisms
        )
    }
}

/// A spring between two tips.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipSpring {
    /// One tip.
    pub a: u32,
    /// The other.
    pub b: u32,
    /// Rest length.
    pub rest: f32,
}

/// The masses of a topology and their state.
#[derive(Debug, Clone)]
pub struct MassSpringSystem {
    pub(crate) topology: Topology,
    /// Root positions (kinematic), one per stick.
    pub(crate) roots: Vec<Vec3>,
    /// Root velocities (the skin's motion).
    pub(crate) root_velocities: Vec<Vec3>,
    /// Rest direction of each stick (unit skin normal).
    pub(crate) normals: Vec<Vec3>,
    /// Rest length `L0` of each stick.
    pub(crate) lengths: Vec<f32>,
    /// Tip positions.
    pub(crate) tips: Vec<Vec3>,
    /// Tip velocities.
    pub(crate) velocities: Vec<Vec3>,
    /// Tip-tip springs (prisms).
    pub(crate) springs: Vec<TipSpring>,
    /// For each tip, its springs (indices into `springs`), CSR.
    pub(crate) spring_offsets: Vec<u32>,
    pub(crate) spring_index: Vec<u32>,
    /// The most tip-tip springs any tip has (the explicit solver's
    /// stability bound reads it).
    pub(crate) max_tip_springs: u32,
    /// For each triangle corner (3t + k), the stick it follows.
    corner_sticks: Vec<u32>,
    /// The next state while a step writes it (double buffering).
    pub(crate) scratch_tips: Vec<Vec3>,
    pub(crate) scratch_velocities: Vec<Vec3>,
}

impl MassSpringSystem {
    /// Builds `topology` over `mesh` with sticks `length` long along the
    /// vertex normals (the face normal for Silva strands), at rest.
    pub fn new(mesh: &Mesh, topology: Topology, length: f32) -> Self {
        let tri_count = mesh.triangle_count();
        let (roots, normals) =
            Self::sticks_on(topology, mesh.triangles(), mesh.positions(), mesh.normals());
        let corner_sticks: Vec<u32> = match topology {
            Topology::SpringSticks | Topology::Prisms => {
                mesh.triangles().iter().flatten().copied().collect()
            }
            Topology::SeparableSpringSticks | Topology::SeparablePrisms => {
                (0..3 * tri_count as u32).collect()
            }
            Topology::SilvaStrands => (0..tri_count as u32).flat_map(|t| [t, t, t]).collect(),
        };
        let normals: Vec<Vec3> = normals.iter().map(|n| n.normalize_or(Vec3::Y)).collect();
        let tips: Vec<Vec3> = roots
            .iter()
            .zip(&normals)
            .map(|(&r, &n)| r + length * n)
            .collect();
        let mut springs = Vec::new();
        let spring = |a: u32, b: u32| TipSpring {
            a,
            b,
            rest: tips[a as usize].distance(tips[b as usize]),
        };
        match topology {
            Topology::Prisms => {
                for &[a, b] in &mesh.edges().edges {
                    springs.push(spring(a, b));
                }
            }
            Topology::SeparablePrisms => {
                for t in 0..tri_count as u32 {
                    let [a, b, c] = [3 * t, 3 * t + 1, 3 * t + 2];
                    springs.extend([spring(a, b), spring(b, c), spring(c, a)]);
                }
            }
            _ => {}
        }
        let n = tips.len();
        let mut counts = vec![0u32; n + 1];
        for s in &springs {
            counts[s.a as usize + 1] += 1;
            counts[s.b as usize + 1] += 1;
        }
        for i in 0..n {
            counts[i + 1] += counts[i];
        }
        let mut fill = counts.clone();
        let mut spring_index = vec![0u32; springs.len() * 2];
        for (k, s) in springs.iter().enumerate() {
            for end in [s.a, s.b] {
                spring_index[fill[end as usize] as usize] = k as u32;
                fill[end as usize] += 1;
            }
        }
        let max_tip_springs = counts.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
        Self {
            topology,
            max_tip_springs,
            root_velocities: vec![Vec3::ZERO; n],
            lengths: vec![length; n],
            velocities: vec![Vec3::ZERO; n],
            roots,
            normals,
            tips,
            springs,
            spring_offsets: counts,
            spring_index,
            corner_sticks,
            scratch_tips: Vec::new(),
            scratch_velocities: Vec::new(),
        }
    }

    /// Each stick's root and rest direction on a skin with `positions` and
    /// unit `normals` (one a vertex) over `triangles`: a vertex's
    /// (spring-sticks, prisms), a triangle corner's (the separable
    /// topologies) or a triangle's centre and face normal (Silva strands).
    /// What [`Self::move_roots`] takes when the skin deforms.
    pub fn sticks_on(
        topology: Topology,
        triangles: &[[u32; 3]],
        positions: &[Vec3],
        normals: &[Vec3],
    ) -> (Vec<Vec3>, Vec<Vec3>) {
        match topology {
            Topology::SpringSticks | Topology::Prisms => (positions.to_vec(), normals.to_vec()),
            Topology::SeparableSpringSticks | Topology::SeparablePrisms => triangles
                .iter()
                .flatten()
                .map(|&v| (positions[v as usize], normals[v as usize]))
                .unzip(),
            Topology::SilvaStrands => triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|v| positions[v as usize]);
                    let n = (b - a).cross(c - a).normalize_or_zero();
                    ((a + b + c) / 3.0, if n == Vec3::ZERO { Vec3::Y } else { n })
                })
                .unzip(),
        }
    }

    /// The topology.
    pub fn topology(&self) -> Topology {
        self.topology
    }

    /// Number of free masses (tips). Roots move with the skin.
    pub fn mass_count(&self) -> usize {
        self.tips.len()
    }

    /// Number of springs: one per stick, plus the tip-tip ones.
    pub fn spring_count(&self) -> usize {
        self.tips.len() + self.springs.len()
    }

    /// Tip positions.
    pub fn tips(&self) -> &[Vec3] {
        &self.tips
    }

    /// Tip velocities.
    pub fn velocities(&self) -> &[Vec3] {
        &self.velocities
    }

    /// Root positions.
    pub fn roots(&self) -> &[Vec3] {
        &self.roots
    }

    /// Rest direction of each stick.
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Root velocities (the skin's motion, from [`move_roots`](Self::move_roots)).
    pub fn root_velocities(&self) -> &[Vec3] {
        &self.root_velocities
    }

    /// Rest length `L0` of each stick.
    pub fn lengths(&self) -> &[f32] {
        &self.lengths
    }

    /// The tip-tip springs (prisms; empty otherwise).
    pub fn tip_tip_springs(&self) -> &[TipSpring] {
        &self.springs
    }

    /// Whether springs join the tips: then the implicit step solves one
    /// system over all of them (conjugate gradients), else a 3×3 one per
    /// tip — on the CPU or the GPU. [`Topology::joins_tips`] says the same
    /// before a system is built.
    pub fn joins_tips(&self) -> bool {
        !self.springs.is_empty()
    }

    /// For each tip `i`, its tip-tip springs are
    /// `spring_index[spring_offsets[i]..spring_offsets[i + 1]]`, indices
    /// into [`tip_tip_springs`](Self::tip_tip_springs): `(spring_offsets, spring_index)`.
    pub fn tip_spring_adjacency(&self) -> (&[u32], &[u32]) {
        (&self.spring_offsets, &self.spring_index)
    }

    /// Replaces the tips' state (positions and velocities, one per tip), e.g.
    /// with a state stepped elsewhere (the GPU).
    pub fn set_state(&mut self, tips: &[Vec3], velocities: &[Vec3]) {
        assert_eq!(tips.len(), self.tips.len(), "one position a tip");
        assert_eq!(velocities.len(), self.tips.len(), "one velocity a tip");
        self.tips.copy_from_slice(tips);
        self.velocities.copy_from_slice(velocities);
    }

    /// The rest position `p0` of tip `i`.
    pub fn rest_tip(&self, i: usize) -> Vec3 {
        self.roots[i] + self.lengths[i] * self.normals[i]
    }

    /// Moves tip `i` (and sets its velocity): for tests and user pokes.
    pub fn set_tip(&mut self, i: usize, position: Vec3, velocity: Vec3) {
        self.tips[i] = position;
        self.velocities[i] = velocity;
    }

    /// Moves the skin: new root positions and rest directions (one per
    /// stick, in the order [`roots`](Self::roots) has them), after `dt`
    /// seconds — the roots' velocities are taken from the move, so the
    /// tips lag by inertia.
    pub fn move_roots(&mut self, roots: &[Vec3], normals: &[Vec3], dt: f32) {
        for i in 0..self.roots.len().min(roots.len()) {
            self.root_velocities[i] = (roots[i] - self.roots[i]) / dt.max(1e-9);
            self.roots[i] = roots[i];
            self.normals[i] = normals[i].normalize_or(self.normals[i]);
        }
    }

    /// For each triangle corner `3t + k`, how far its stick's tip has moved
    /// from rest: `p − p0`, what the shell renderer reads.
    pub fn corner_tip_offsets(&self) -> Vec<Vec3> {
        self.corner_sticks
            .iter()
            .map(|&s| self.tips[s as usize] - self.rest_tip(s as usize))
            .collect()
    }

    /// For each triangle corner, the stick it follows.
    pub fn corner_sticks(&self) -> &[u32] {
        &self.corner_sticks
    }
}
