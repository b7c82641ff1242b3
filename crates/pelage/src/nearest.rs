//! The k nearest of a fixed set of points (guide roots for Shepard, clump
//! centres for `clump`), for queries that arrive in spatially coherent
//! order: the generator grows a part's hairs along the skin (root cells
//! along their Morton curve, or by triangle), so each root is close to the
//! one before.
//!
//! A kd-tree answers any query, but most hairs are answered from a short
//! list of candidates kept for the last neighbourhood ([`NeighbourCache`]).
//! The list is exact, not a heuristic. It is filled at a point `q` whose
//! k-th nearest point is `d_k(q)` away, and serves queries `p` within
//! `R = a·d_k(q)` of `q` (`a` = 1/2; 1 when k = 1): `q`'s k nearest are
//! within `d_k(q) + R` of `p`, so `d_k(p) ≤ d_k(q) + R`, and every point
//! `p` could choose lies within `d_k(q) + 2R` of `q` — those are the
//! candidates. A query then costs a dozen or two distances instead of a
//! tree search.
//!
//! The argument holds for any `R`. A list that had to be filled again
//! after a few queries (the roots of a preview fraction are ten times
//! sparser than the whole groom's) reaches twice as far at its next fill,
//! and back after many: fewer tree searches for a few more candidates a
//! query (module constants).
//!
//! It also gives callers a second way to
//! keep lists: a [`QueryRegion`], a ball known to hold the query (the skin
//! triangle under a hair's root). A list is then filled at the ball's
//! centre with `R` at least its radius, and serves every query in the
//! ball, however the roots in it are ordered: clump centres (k = 1, a
//! small `d_1`) needed a fill every six hairs without it.
//!
//! Results are ordered by (squared distance, index), computed here from
//! the points, so they are the same whichever earlier query filled the
//! list: a hair's neighbours never depend on the thread or the order that
//! grew it (docs/design.md, "Deterministic by hair id"), ties included.

use glam::Vec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZeroUsize;
use std::sync::atomic::{AtomicU64, Ordering};

/// Candidates a list may hold before it serves only the point it was
/// filled at (a few large triangles under many guides would otherwise
/// brute-force hundreds of points a hair).
const MOST_CANDIDATES: usize = 64;

/// A list that answered fewer queries than this before it had to be
/// filled again reaches twice as far at its next fill (up to
/// `MOST_WIDENING` times `a`), and one that answered more than
/// `MANY_SERVED` half as far (down to `a`): a sparse walk (a preview
/// fraction's hairs, a farm part's few roots a triangle) then pays for a
/// kd-tree search every few hairs instead of at nearly every hair, and a
/// dense one keeps short lists.
const FEW_SERVED: u32 = 4;
const MANY_SERVED: u32 = 64;
const MOST_WIDENING: f32 = 2.0;

/// Slack on squared radii handed to the kd-tree, so that its rounding of a
/// distance and ours can never leave a point out.
const RADIUS_SLACK: f32 = 1.001;

/// One of the nearest points: its index and squared distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Index into the point set.
    pub index: u32,
    /// Squared distance to the query.
    pub distance_squared: f32,
}

/// A ball that holds a query point and, likely, the next few (see the
/// module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QueryRegion {
    /// Its centre.
    pub centre: Vec3,
    /// Its radius.
    pub radius: f32,
}

impl QueryRegion {
    /// The ball around a triangle from its centroid, through its farthest
    /// corner, a little larger so that rounding cannot leave a point of
    /// the triangle outside.
    pub fn around_triangle(corners: [Vec3; 3]) -> Self {
        let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
        let farthest = corners
            .iter()
            .map(|c| (*c - centre).length_squared())
            .fold(0.0, f32::max)
            .sqrt();
        Self {
            centre,
            radius: farthest * (1.0 + 1e-5) + 1e-9,
        }
    }
}

/// A fixed set of points with a kd-tree over them.
#[derive(Debug)]
pub struct NearestPoints {
    tree: Option<ImmutableKdTree<f32, 3>>,
    points: Vec<Vec3>,
    /// Tells this set's list apart in a shared [`NeighbourCache`].
    id: u64,
}

/// Candidate lists kept between queries, one per point set and k. Keep one
/// per worker and pass it to every query of a run of nearby points.
#[derive(Debug, Default)]
pub struct NeighbourCache {
    lists: Vec<CandidateList>,
}

#[derive(Debug)]
struct CandidateList {
    set: u64,
    k: usize,
    centre: Vec3,
    reach_squared: f32,
    /// Candidate indices and their coordinates, copied as three columns.
    candidates: Vec<u32>,
    xs: Vec<f32>,
    ys: Vec<f32>,
    zs: Vec<f32>,
    /// The last query's candidates that could be among its k nearest, as
    /// [`key`]s (valid up to the count kept), and its k smallest keys
    /// (kept for the next query).
    keys: Vec<u64>,
    best: Vec<u64>,
    /// Queries answered since the last fill, and the factor on `a` the
    /// next fill uses (module docs: sized to how sparse the queries are).
    served: u32,
    widen: f32,
}

impl NearestPoints {
    /// A set over `points` (finite).
    pub fn new(points: Vec<Vec3>) -> Self {
        static NEXT_ID: AtomicU64 = AtomicU64::new(0);
        let array: Vec<[f32; 3]> = points.iter().map(|p| p.to_array()).collect();
        Self {
            tree: (!array.is_empty())
                .then(|| ImmutableKdTree::new_from_slice(&array).expect("finite points")),
            points,
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
        }
    }

    /// The points.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// Replaces `out` with the `k` points nearest `p` (fewer if the set is
    /// smaller), nearest first, ties by index.
    pub fn nearest(&self, p: Vec3, k: usize, out: &mut Vec<Neighbour>) {
        out.clear();
        let Some(kth) = self.kth_distance_squared(p, k) else {
            return;
        };
        let mut best = vec![u64::MAX; k];
        self.visit_within(p, kth * RADIUS_SLACK, |i| {
            keep_smallest(
                &mut best,
                key((self.points[i as usize] - p).length_squared(), i),
            );
        });
        out.extend(neighbours(&best));
    }

    /// [`Self::nearest`], answered from `cache`'s candidates when `p` is
    /// near the point they were gathered for, and read from the cache (no
    /// buffer of the caller's). The same result as [`Self::nearest`]
    /// whatever the cache holds.
    pub fn nearest_cached<'c>(
        &self,
        p: Vec3,
        k: usize,
        cache: &'c mut NeighbourCache,
    ) -> impl Iterator<Item = Neighbour> + 'c {
        self.nearest_cached_in(p, k, cache, None)
    }

    /// [`Self::nearest_cached`] for a `p` inside `region` (a ball that
    /// likely holds the next queries too): a list filled here serves the
    /// whole ball. The same result as [`Self::nearest`]; a `p` outside its
    /// region is answered, only without the region's help.
    pub fn nearest_cached_in<'c>(
        &self,
        p: Vec3,
        k: usize,
        cache: &'c mut NeighbourCache,
        region: Option<QueryRegion>,
    ) -> impl Iterator<Item = Neighbour> + 'c {
        let k = k.min(self.points.len());
        if k == 0 {
            return neighbours(&[]);
        }
        let list = match cache
            .lists
            .iter()
            .position(|l| l.set == self.id && l.k == k)
        {
            Some(i) => &mut cache.lists[i],
            None => {
                cache.lists.push(CandidateList {
                    set: self.id,
                    k,
                    centre: p,
                    reach_squared: -1.0,
                    candidates: Vec::new(),
                    xs: Vec::new(),
                    ys: Vec::new(),
                    zs: Vec::new(),
                    keys: Vec::new(),
                    best: Vec::new(),
                    served: 0,
                    widen: 1.0,
                });
                cache.lists.last_mut().expect("just pushed")
            }
        };
        if (p - list.centre).length_squared() > list.reach_squared {
            self.refill(list, p, k, region);
        }
        list.served = list.served.saturating_add(1);
        // The same arithmetic as `(q - p).length_squared()`, so cached and
        // uncached answers agree to the bit.
        let distance_squared = |x: f32, y: f32, z: f32| {
            let (dx, dy, dz) = (x - p.x, y - p.y, z - p.z);
            dx * dx + dy * dy + dz * dz
        };
        if k == 1 {
            // The least key of all: one pass, no bound to filter by (it
            // would cost more than it saves for a single point).
            let least = list
                .xs
                .iter()
                .zip(&list.ys)
                .zip(&list.zs)
                .zip(&list.candidates)
                .map(|(((&x, &y), &z), &i)| key(distance_squared(x, y, z), i))
                .fold(u64::MAX, u64::min);
            list.best.clear();
            list.best.push(least);
            return neighbours(&list.best);
        }
        // The last query's answer is mostly this one's too: its k points,
        // measured from `p`, bound the k-th distance, and only candidates
        // within that bound can be among the k nearest. Filtering first
        // leaves a handful to sort in instead of the whole list.
        let answered = list.best.len() == k && !list.best.contains(&u64::MAX);
        let bound = if answered {
            list.best
                .iter()
                .map(|&previous| {
                    let q = self.points[previous as u32 as usize];
                    distance_squared(q.x, q.y, q.z)
                })
                .fold(0.0, f32::max)
        } else {
            f32::INFINITY
        };
        // Kept without branching on the distance (which candidates pass
        // changes from hair to hair, so a branch would mispredict). The
        // key buffer only grows, so it is not cleared for every query.
        if list.keys.len() < list.candidates.len() {
            list.keys.resize(list.candidates.len(), 0);
        }
        let mut kept = 0;
        for (((&x, &y), &z), &i) in list
            .xs
            .iter()
            .zip(&list.ys)
            .zip(&list.zs)
            .zip(&list.candidates)
        {
            let d = distance_squared(x, y, z);
            list.keys[kept] = key(d, i);
            kept += usize::from(d <= bound);
        }
        list.best.clear();
        list.best.resize(k, u64::MAX);
        for &candidate in &list.keys[..kept] {
            keep_smallest(&mut list.best, candidate);
        }
        neighbours(&list.best)
    }

    /// Gathers the candidates for queries near `p`, or in `region` when it
    /// holds `p` (module docs).
    fn refill(&self, list: &mut CandidateList, p: Vec3, k: usize, region: Option<QueryRegion>) {
        list.candidates.clear();
        list.xs.clear();
        list.ys.clear();
        list.zs.clear();
        // The list's centre q and the least reach R: the region's centre
        // and radius, so that R covers all of it (it holds p).
        let (q, least_reach) = match region {
            Some(r) if (p - r.centre).length_squared() <= r.radius * r.radius => {
                (r.centre, r.radius)
            }
            _ => (p, 0.0),
        };
        list.centre = q;
        let Some(kth) = self.kth_distance_squared(q, k) else {
            list.reach_squared = -1.0;
            return;
        };
        // R = a·d_k (at least the region's radius), candidates within
        // d_k + 2R. A single nearest point has few candidates even at
        // a = 1 and would otherwise be refilled every few hairs; for
        // larger k the list grows fast.
        let a: f32 = if k == 1 { 1.0 } else { 0.5 };
        list.widen = match list.served {
            0..FEW_SERVED => (list.widen * 2.0).min(MOST_WIDENING),
            MANY_SERVED.. => (list.widen * 0.5).max(1.0),
            _ => list.widen,
        };
        list.served = 0;
        let d_k = kth.sqrt();
        let fill = |list: &mut CandidateList, widen: f32| {
            let reach = (a * widen * d_k).max(least_reach);
            list.reach_squared = reach * reach;
            let within = d_k + 2.0 * reach;
            list.candidates.clear();
            let candidates = &mut list.candidates;
            self.visit_within(q, within * within * RADIUS_SLACK, |i| candidates.push(i));
        };
        fill(list, list.widen);
        if list.candidates.len() > MOST_CANDIDATES && list.widen > 1.0 {
            // Widened too far for this neighbourhood.
            list.widen = 1.0;
            fill(list, 1.0);
        }
        if list.candidates.len() > MOST_CANDIDATES {
            // Too crowded to brute-force: serve `p` alone.
            list.centre = p;
            list.reach_squared = 0.0;
            list.candidates.clear();
            let kth = if q == p {
                kth
            } else {
                self.kth_distance_squared(p, k)
                    .expect("the set is not empty")
            };
            let candidates = &mut list.candidates;
            self.visit_within(p, kth * RADIUS_SLACK, |i| candidates.push(i));
        }
        for &i in &list.candidates {
            let q = self.points[i as usize];
            list.xs.push(q.x);
            list.ys.push(q.y);
            list.zs.push(q.z);
        }
    }

    /// The kd-tree's squared distance from `p` to its `k`-th nearest point.
    fn kth_distance_squared(&self, p: Vec3, k: usize) -> Option<f32> {
        let tree = self.tree.as_ref()?;
        let k = NonZeroUsize::new(k.min(self.points.len()))?;
        let hits = tree
            .query(&p.to_array())
            .nearest_n::<SquaredEuclidean<f32>>(k)
            .execute();
        hits.last().map(|h| h.distance)
    }

    /// Visits every point within `radius_squared` of `p` (squared distance
    /// at most it), in the tree's order (the same for the same points).
    pub(crate) fn visit_within(&self, p: Vec3, radius_squared: f32, mut visit: impl FnMut(u32)) {
        if let Some(tree) = &self.tree {
            tree.query(&p.to_array())
                .within::<SquaredEuclidean<f32>>(radius_squared)
                .unsorted()
                .visit(|hit| visit(hit.item));
        }
    }
}

/// A point's place in the order "nearer first, equally near the lower
/// index first" as one integer: squared distances are never negative, and
/// the bits of non-negative floats order as their values do.
#[inline(always)]
fn key(distance_squared: f32, index: u32) -> u64 {
    (u64::from(distance_squared.to_bits()) << 32) | u64::from(index)
}

/// Merges `key` into `best` (ascending): one compare-exchange per slot and
/// no branch, where inserting into a sorted list mispredicts at every
/// candidate.
#[inline(always)]
fn keep_smallest(best: &mut [u64], key: u64) {
    let mut carried = key;
    for slot in best {
        let (low, high) = ((*slot).min(carried), (*slot).max(carried));
        *slot = low;
        carried = high;
    }
}

/// The neighbours a sorted `best` list holds (unused slots are `MAX`).
fn neighbours(best: &[u64]) -> impl Iterator<Item = Neighbour> + '_ {
    best.iter()
        .take_while(|&&k| k != u64::MAX)
        .map(|&k| Neighbour {
            index: k as u32,
            distance_squared: f32::from_bits((k >> 32) as u32),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::mix64;

    fn scattered(n: usize, seed: u64) -> Vec<Vec3> {
        let unit = |h: u64| (h >> 40) as f32 / (1u64 << 24) as f32;
        (0..n as u64)
            .map(|i| {
                let h = mix64(seed ^ mix64(i));
                Vec3::new(unit(h), unit(mix64(h)), 0.1 * unit(mix64(h ^ 7)))
            })
            .collect()
    }

    fn brute_force(points: &[Vec3], p: Vec3, k: usize) -> Vec<u32> {
        let mut all: Vec<(f32, u32)> = points
            .iter()
            .enumerate()
            .map(|(i, q)| ((*q - p).length_squared(), i as u32))
            .collect();
        all.sort_by(|a, b| a.partial_cmp(b).unwrap());
        all.iter().take(k).map(|a| a.1).collect()
    }

    /// `p` moved in the plane by up to `size / 2` along each axis (from
    /// the random bits `h`), kept in the points' box.
    fn stepped(p: Vec3, h: u64, size: f32) -> Vec3 {
        let d = Vec3::new(
            (h & 0xffff) as f32 / 65536.0 - 0.5,
            (h >> 16 & 0xffff) as f32 / 65536.0 - 0.5,
            0.0,
        );
        (p + d * size).clamp(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.1))
    }

    #[test]
    fn cached_queries_along_a_path_match_brute_force() {
        let points = scattered(500, 1);
        let set = NearestPoints::new(points.clone());
        let mut cache = NeighbourCache::default();
        let mut out = Vec::new();
        for k in [1, 4, 9] {
            // A wandering path of small steps (as sorted hair roots are),
            // with jumps now and then.
            let mut p = Vec3::new(0.5, 0.5, 0.05);
            for step in 0..3000u64 {
                let h = mix64(step ^ (k as u64) << 32);
                let jump = if step % 500 == 0 { 0.4 } else { 0.004 };
                p = stepped(p, h, jump);
                let got: Vec<u32> = set
                    .nearest_cached(p, k, &mut cache)
                    .map(|n| n.index)
                    .collect();
                assert_eq!(got, brute_force(&points, p, k), "k {k} step {step}");
                set.nearest(p, k, &mut out);
                let uncached: Vec<u32> = out.iter().map(|n| n.index).collect();
                assert_eq!(uncached, got);
            }
        }
    }

    #[test]
    fn widened_lists_stay_exact_on_sparse_and_dense_walks() {
        // Stretches of steps about the points' spacing (a preview
        // fraction's roots), where lists widen, then of small steps, where
        // they narrow again; every answer exact.
        let points = scattered(500, 5);
        let set = NearestPoints::new(points.clone());
        for k in [1, 4] {
            let mut cache = NeighbourCache::default();
            let (mut widened, mut narrowed_after) = (false, false);
            let mut p = Vec3::new(0.5, 0.5, 0.05);
            for step in 0..4000u64 {
                let h = mix64(step ^ (k as u64) << 40 ^ 77);
                let sparse = (step / 500) % 2 == 0;
                p = stepped(p, h, if sparse { 0.06 } else { 0.002 });
                let got: Vec<u32> = set
                    .nearest_cached(p, k, &mut cache)
                    .map(|n| n.index)
                    .collect();
                assert_eq!(got, brute_force(&points, p, k), "k {k} step {step}");
                let widen = cache.lists[0].widen;
                widened |= widen > 1.0;
                narrowed_after |= widened && widen == 1.0;
            }
            assert!(
                widened && narrowed_after,
                "k {k}: the lists never widened and narrowed"
            );
        }
    }

    #[test]
    fn queries_in_triangle_regions_match_brute_force() {
        // Roots on small triangles, several a triangle in any order, as
        // the generator asks; now and then a point outside its region (a
        // caller's mistake must cost speed, never a wrong answer).
        let points = scattered(2000, 3);
        let set = NearestPoints::new(points.clone());
        let mut cache = NeighbourCache::default();
        for k in [1, 4] {
            for t in 0..400u64 {
                let h = mix64(t ^ (k as u64) << 40);
                let unit = |s: u64| (mix64(h ^ s) >> 40) as f32 / (1u64 << 24) as f32;
                let a = Vec3::new(unit(1), unit(2), 0.1 * unit(3));
                let size = 0.001 + 0.02 * unit(4);
                let corners = [a, a + Vec3::X * size, a + Vec3::new(0.3, 1.0, 0.2) * size];
                let region = QueryRegion::around_triangle(corners);
                for r in 0..12u64 {
                    let (u, v) = (unit(10 + r), unit(30 + r));
                    let (u, v) = if u + v > 1.0 {
                        (1.0 - u, 1.0 - v)
                    } else {
                        (u, v)
                    };
                    let mut p =
                        corners[0] + u * (corners[1] - corners[0]) + v * (corners[2] - corners[0]);
                    if r == 11 {
                        p += Vec3::X * 0.05;
                    }
                    let got: Vec<u32> = set
                        .nearest_cached_in(p, k, &mut cache, Some(region))
                        .map(|n| n.index)
                        .collect();
                    assert_eq!(
                        got,
                        brute_force(&points, p, k),
                        "k {k} triangle {t} root {r}"
                    );
                }
            }
        }
    }

    #[test]
    fn ties_go_to_the_lower_index_whatever_filled_the_cache() {
        // A square grid: the centre of a cell is equally far from its four
        // corners; with k = 2 the two lowest indices win, from any cache.
        let points: Vec<Vec3> = (0..100)
            .map(|i| Vec3::new((i % 10) as f32, (i / 10) as f32, 0.0))
            .collect();
        let set = NearestPoints::new(points.clone());
        let centre = Vec3::new(4.5, 4.5, 0.0);
        let mut expected = Vec::new();
        set.nearest(centre, 2, &mut expected);
        assert_eq!(
            expected.iter().map(|n| n.index).collect::<Vec<_>>(),
            [44, 45]
        );
        for start in [Vec3::new(4.4, 4.6, 0.0), Vec3::new(4.6, 4.4, 0.0), centre] {
            let mut cache = NeighbourCache::default();
            let _ = set.nearest_cached(start, 2, &mut cache).count();
            let out: Vec<Neighbour> = set.nearest_cached(centre, 2, &mut cache).collect();
            assert_eq!(out, expected, "cache filled at {start}");
        }
    }

    #[test]
    fn crowded_neighbourhoods_and_small_sets_are_still_exact() {
        // Many points piled near one spot and k larger than the set.
        let mut points = vec![Vec3::ZERO; 200];
        for (i, p) in points.iter_mut().enumerate() {
            *p = Vec3::new(1e-3 * (i % 7) as f32, 1e-3 * (i / 7) as f32, 0.0);
        }
        let set = NearestPoints::new(points.clone());
        let mut cache = NeighbourCache::default();
        for i in 0..50 {
            let p = Vec3::new(0.002 + 1e-4 * i as f32, 0.01, 0.0);
            let got: Vec<u32> = set
                .nearest_cached(p, 3, &mut cache)
                .map(|n| n.index)
                .collect();
            assert_eq!(got, brute_force(&points, p, 3));
        }
        let small = NearestPoints::new(vec![Vec3::X, Vec3::Y]);
        assert_eq!(small.nearest_cached(Vec3::ZERO, 5, &mut cache).count(), 2);
        let empty = NearestPoints::new(Vec::new());
        assert_eq!(empty.nearest_cached(Vec3::ZERO, 3, &mut cache).count(), 0);
    }
}
