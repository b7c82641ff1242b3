//! Closest point on a set of triangles: a bounding-volume hierarchy (median
//! split on the longest axis of the centroid bounds, 4 triangles a leaf)
//! and Ericson's closest point on a triangle (Real-Time Collision
//! Detection §5.1.5), which also gives the barycentric coordinates.
//!
//! Used to bind guide roots to the skin and, in the style mesh, to find the
//! three guides a hair interpolates. Degenerate triangles (two or three
//! equal corners) are fine: they act as segments or points.

use glam::Vec3;

/// The closest point found by [`TriangleBvh::closest`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    /// The triangle's index.
    pub triangle: u32,
    /// Barycentric weights of the triangle's three corners (sum 1).
    pub weights: [f32; 3],
    /// The point itself.
    pub point: Vec3,
    /// Squared distance from the query.
    pub distance_squared: f32,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: first triangle slot; inner: index of the second child (the
    /// first child follows this node).
    start_or_right: u32,
    /// Leaf: triangle count; inner: 0.
    count: u32,
}

/// A BVH over triangles given by corner positions.
#[derive(Debug, Clone)]
pub struct TriangleBvh {
    nodes: Vec<Node>,
    /// Triangle indices in leaf order.
    order: Vec<u32>,
    /// Corners of each triangle, in leaf order.
    corners: Vec<[Vec3; 3]>,
}

const LEAF: usize = 4;

impl TriangleBvh {
    /// Builds the hierarchy over `triangles` (indices into `positions`).
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        let tris: Vec<[Vec3; 3]> = triangles
            .iter()
            .map(|t| t.map(|i| positions[i as usize]))
            .collect();
        let centroids: Vec<Vec3> = tris.iter().map(|t| (t[0] + t[1] + t[2]) / 3.0).collect();
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * tris.len() / LEAF + 1);
        if !tris.is_empty() {
            build(&mut nodes, &mut order, 0, &tris, &centroids);
        }
        let corners = order.iter().map(|&i| tris[i as usize]).collect();
        Self {
            nodes,
            order,
            corners,
        }
    }

    /// The closest point to `p` on any triangle, or `None` without
    /// triangles. Ties go to the triangle met first (deterministic).
    pub fn closest(&self, p: Vec3) -> Option<ClosestPoint> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best: Option<ClosestPoint> = None;
        let mut best_d = f32::INFINITY;
        // (node, squared distance to its box), nearest child on top.
        let mut stack = [(0u32, 0.0f32); 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let (current, box_d) = stack[top];
            if box_d > best_d {
                continue;
            }
            let node = self.nodes[current as usize];
            if node.count > 0 {
                let start = node.start_or_right as usize;
                for slot in start..start + node.count as usize {
                    let (point, weights) = closest_on_triangle(p, self.corners[slot]);
                    let d = (point - p).length_squared();
                    if d < best_d {
                        best_d = d;
                        best = Some(ClosestPoint {
                            triangle: self.order[slot],
                            weights,
                            point,
                            distance_squared: d,
                        });
                    }
                }
            } else {
                let (left, right) = (current + 1, node.start_or_right);
                let dl = self.box_distance(left, p);
                let dr = self.box_distance(right, p);
                let (near, far) = if dl <= dr {
                    ((left, dl), (right, dr))
                } else {
                    ((right, dr), (left, dl))
                };
                if far.1 <= best_d {
                    stack[top] = far;
                    top += 1;
                }
                if near.1 <= best_d {
                    stack[top] = near;
                    top += 1;
                }
            }
        }
        best
    }

    fn box_distance(&self, node: u32, p: Vec3) -> f32 {
        let n = &self.nodes[node as usize];
        box_distance_squared(n.lo, n.hi, p)
    }
}

fn build(
    nodes: &mut Vec<Node>,
    order: &mut [u32],
    start: u32,
    tris: &[[Vec3; 3]],
    centroids: &[Vec3],
) -> u32 {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let (mut clo, mut chi) = (lo, hi);
    for &i in order.iter() {
        for c in tris[i as usize] {
            lo = lo.min(c);
            hi = hi.max(c);
        }
        clo = clo.min(centroids[i as usize]);
        chi = chi.max(centroids[i as usize]);
    }
    let index = nodes.len() as u32;
    nodes.push(Node {
        lo,
        hi,
        start_or_right: start,
        count: order.len() as u32,
    });
    if order.len() <= LEAF {
        return index;
    }
    let extent = chi - clo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis]
            .total_cmp(&centroids[b as usize][axis])
            .then(a.cmp(&b))
    });
    let (left, right) = order.split_at_mut(mid);
    build(nodes, left, start, tris, centroids);
    let right_index = build(nodes, right, start + mid as u32, tris, centroids);
    nodes[index as usize].start_or_right = right_index;
    nodes[index as usize].count = 0;
    index
}

fn box_distance_squared(lo: Vec3, hi: Vec3, p: Vec3) -> f32 {
    let d = (lo - p).max(p - hi).max(Vec3::ZERO);
    d.length_squared()
}

/// Closest point on triangle `t` to `p`, with its barycentric weights
/// (Ericson, Real-Time Collision Detection, §5.1.5). Degenerate triangles
/// fall back to their longest edge.
pub fn closest_on_triangle(p: Vec3, t: [Vec3; 3]) -> (Vec3, [f32; 3]) {
    let [a, b, c] = t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    if ab.cross(ac).length_squared() <= f32::MIN_POSITIVE {
        return closest_on_degenerate(p, t);
    }
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

/// A triangle with no area: the closest point on its three edges.
fn closest_on_degenerate(p: Vec3, t: [Vec3; 3]) -> (Vec3, [f32; 3]) {
    let mut best = (t[0], [1.0, 0.0, 0.0]);
    let mut best_d = (t[0] - p).length_squared();
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let e = t[j] - t[i];
        let len2 = e.length_squared();
        let s = if len2 > 0.0 {
            ((p - t[i]).dot(e) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = t[i] + s * e;
        let d = (q - p).length_squared();
        if d < best_d {
            let mut w = [0.0; 3];
            w[i] += 1.0 - s;
            w[j] += s;
            best = (q, w);
            best_d = d;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bvh_finds_what_brute_force_finds() {
        let spot = crate::assets::spot();
        let bvh = TriangleBvh::new(spot.positions(), spot.triangles());
        for k in 0..200 {
            let f = k as f32;
            let p = Vec3::new(
                (f * 0.37).sin(),
                (f * 0.23).cos() * 1.2,
                (f * 0.11).sin() * 1.3,
            );
            let hit = bvh.closest(p).unwrap();
            let brute = (0..spot.triangle_count())
                .map(|t| {
                    (closest_on_triangle(p, spot.triangle_positions(t)).0 - p).length_squared()
                })
                .fold(f32::INFINITY, f32::min);
            assert!(
                (hit.distance_squared - brute).abs() <= 1e-6 * (1.0 + brute),
                "{p}: {} vs {brute}",
                hit.distance_squared
            );
            let corners = spot.triangle_positions(hit.triangle as usize);
            let from_weights = corners[0] * hit.weights[0]
                + corners[1] * hit.weights[1]
                + corners[2] * hit.weights[2];
            assert!((from_weights - hit.point).length() < 1e-5);
            assert!(
                hit.weights.iter().all(|&w| w >= -1e-6)
                    && (hit.weights.iter().sum::<f32>() - 1.0).abs() < 1e-5
            );
        }
    }

    #[test]
    fn degenerate_triangles_act_as_segments_and_points() {
        let seg = [Vec3::ZERO, Vec3::X, Vec3::X];
        let (q, w) = closest_on_triangle(Vec3::new(0.25, 1.0, 0.0), seg);
        assert!((q - Vec3::new(0.25, 0.0, 0.0)).length() < 1e-6);
        assert!((w[0] - 0.75).abs() < 1e-6 && (w[1] + w[2] - 0.25).abs() < 1e-6);
        let point = [Vec3::ONE; 3];
        assert_eq!(closest_on_triangle(Vec3::ZERO, point).0, Vec3::ONE);
        assert!(TriangleBvh::new(&[], &[]).closest(Vec3::ZERO).is_none());
    }
}
