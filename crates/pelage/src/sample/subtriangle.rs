//! Sub-triangle positions inside a mesh triangle (Sik §3.1, Fig. 4).
//!
//! Midpoint subdivision splits a triangle into three corner children
//! (j = 0, 1, 2, at corners 0, 1, 2) and an inverted middle child (j = 3).
//! Position indices follow the paper, `i = 4(i_parent + 1) + j`, with the
//! whole triangle as `i = −1` (`u32::MAX`, so the u32 arithmetic wraps to
//! the same formula). Level 1 is 0..4, level 2 is 4..20, level 3 is 20..84:
//! dense, so a table indexed by position holds every sub-triangle once.
//!
//! In the parent's barycentric space `[b1, b2]` every sub-triangle is the
//! reference triangle scaled and moved: corners `o`, `o + (s, 0)`,
//! `o + (0, s)` with `|s| = 2^−level` and `s < 0` for inverted ones. So a
//! position is three floats, and a point `[u, v]` of the reference triangle
//! maps to `o + s·[u, v]` (Sik Fig. 6 step 3).

use glam::Vec2;

/// Position index of the whole (undivided) triangle.
pub const WHOLE_TRIANGLE: u32 = u32::MAX;

/// Deepest level the position table holds (21,844 entries, 256 KiB);
/// deeper positions are decoded from their index on the fly.
const TABLE_LEVELS: u32 = 7;

/// Deepest subdivision level whose indices fit in a u32.
pub const MAX_LEVEL: u32 = 15;

/// A sub-triangle in its parent triangle's barycentric space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubTriangle {
    /// Barycentric coordinates `[b1, b2]` of its corner 0.
    pub origin: Vec2,
    /// Signed edge scale: `±2^−level`, negative for inverted triangles.
    pub scale: f32,
}

impl SubTriangle {
    /// The whole triangle.
    pub const WHOLE: SubTriangle = SubTriangle {
        origin: Vec2::ZERO,
        scale: 1.0,
    };

    /// Child `j` (0–2: at corner j, 3: the inverted middle).
    #[inline]
    pub fn child(self, j: u32) -> SubTriangle {
        let h = 0.5 * self.scale;
        let (offset, scale) = match j {
            0 => (Vec2::ZERO, h),
            1 => (Vec2::new(h, 0.0), h),
            2 => (Vec2::new(0.0, h), h),
            _ => (Vec2::new(h, h), -h),
        };
        SubTriangle {
            origin: self.origin + offset,
            scale,
        }
    }

    /// Barycentric coordinates in the parent of reference point `[u, v]`.
    #[inline]
    pub fn to_parent(self, [u, v]: [f32; 2]) -> Vec2 {
        self.origin + self.scale * Vec2::new(u, v)
    }

    /// Barycentric coordinates of its centroid in the parent.
    #[inline]
    pub fn centroid(self) -> Vec2 {
        self.to_parent([1.0 / 3.0, 1.0 / 3.0])
    }

    /// Its area as a fraction of the parent's: `s²`.
    #[inline]
    pub fn area_fraction(self) -> f32 {
        self.scale * self.scale
    }

    /// Whether parent barycentrics `b` lie in this sub-triangle (with a
    /// tolerance `eps` in reference-triangle units).
    pub fn contains(self, b: Vec2, eps: f32) -> bool {
        let local = (b - self.origin) / self.scale;
        local.x >= -eps && local.y >= -eps && local.x + local.y <= 1.0 + eps
    }
}

/// Position index of child `j` of position `parent` (Sik: `i = 4(i_p + 1) + j`).
#[inline]
pub fn child_index(parent: u32, j: u32) -> u32 {
    parent.wrapping_add(1).wrapping_mul(4) + j
}

/// Subdivision level of a position index (0 for the whole triangle).
pub fn level_of(index: u32) -> u32 {
    let mut level = 0;
    let mut i = index;
    while i != WHOLE_TRIANGLE {
        i = (i / 4).wrapping_sub(1);
        level += 1;
    }
    level
}

/// Decodes a position index by walking its parents.
pub fn decode(index: u32) -> SubTriangle {
    if index == WHOLE_TRIANGLE {
        return SubTriangle::WHOLE;
    }
    let mut path = [0u32; MAX_LEVEL as usize + 1];
    let mut depth = 0;
    let mut i = index;
    while i != WHOLE_TRIANGLE {
        path[depth] = i % 4;
        i = (i / 4).wrapping_sub(1);
        depth += 1;
    }
    path[..depth]
        .iter()
        .rev()
        .fold(SubTriangle::WHOLE, |sub, &j| sub.child(j))
}

/// The shared table of sub-triangle positions (Sik: "store barycentric
/// coordinates of these sub-triangle positions in a separate data
/// structure, where they can be easily accessed by the position index").
#[derive(Debug, Clone)]
pub struct PositionTable {
    entries: Vec<SubTriangle>,
}

impl Default for PositionTable {
    fn default() -> Self {
        Self::new()
    }
}

impl PositionTable {
    /// Builds the table for levels 1 to 7.
    pub fn new() -> Self {
        let count = ((4u32.pow(TABLE_LEVELS + 1) - 4) / 3) as usize;
        let mut entries = vec![SubTriangle::WHOLE; count];
        for i in 0..count as u32 {
            let parent = (i / 4).wrapping_sub(1);
            let parent_sub = if parent == WHOLE_TRIANGLE {
                SubTriangle::WHOLE
            } else {
                entries[parent as usize]
            };
            entries[i as usize] = parent_sub.child(i % 4);
        }
        Self { entries }
    }

    /// The sub-triangle at position `index`.
    #[inline]
    pub fn get(&self, index: u32) -> SubTriangle {
        match self.entries.get(index as usize) {
            Some(sub) => *sub,
            None if index == WHOLE_TRIANGLE => SubTriangle::WHOLE,
            None => decode(index),
        }
    }

    /// Bytes the table occupies.
    pub fn memory_bytes(&self) -> usize {
        self.entries.len() * std::mem::size_of::<SubTriangle>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_follow_the_paper_and_are_dense() {
        assert_eq!(
            (0..4)
                .map(|j| child_index(WHOLE_TRIANGLE, j))
                .collect::<Vec<_>>(),
            [0, 1, 2, 3]
        );
        assert_eq!(child_index(0, 0), 4);
        assert_eq!(child_index(3, 3), 19);
        assert_eq!(child_index(4, 0), 20);
        assert_eq!(
            (
                level_of(WHOLE_TRIANGLE),
                level_of(3),
                level_of(19),
                level_of(20)
            ),
            (0, 1, 2, 3)
        );
    }

    #[test]
    fn children_tile_the_parent() {
        // The four children's areas sum to the parent's, and their
        // centroids lie inside the parent and in exactly one child.
        for parent in [
            SubTriangle::WHOLE,
            SubTriangle::WHOLE.child(3),
            decode(child_index(3, 1)),
        ] {
            let area: f32 = (0..4).map(|j| parent.child(j).area_fraction()).sum();
            assert!((area - parent.area_fraction()).abs() < 1e-7);
            for j in 0..4 {
                let c = parent.child(j).centroid();
                assert!(parent.contains(c, 0.0));
                let inside = (0..4).filter(|&k| parent.child(k).contains(c, 0.0)).count();
                assert_eq!(inside, 1);
            }
        }
    }

    #[test]
    fn middle_child_has_the_edge_midpoints_as_corners() {
        let m = SubTriangle::WHOLE.child(3);
        let corners = [
            m.to_parent([0.0, 0.0]),
            m.to_parent([1.0, 0.0]),
            m.to_parent([0.0, 1.0]),
        ];
        for expected in [
            Vec2::new(0.5, 0.0),
            Vec2::new(0.5, 0.5),
            Vec2::new(0.0, 0.5),
        ] {
            assert!(corners.iter().any(|c| (*c - expected).length() < 1e-7));
        }
    }

    #[test]
    fn table_agrees_with_decoding() {
        let table = PositionTable::new();
        for i in (0..21_844)
            .step_by(37)
            .chain([21_843, 21_844, 100_000, 1_000_000])
        {
            assert_eq!(table.get(i), decode(i), "index {i}");
        }
    }
}
