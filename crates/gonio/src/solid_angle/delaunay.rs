//! Delaunay triangulation by incremental insertion in spatial order, for the
//! Voronoi cells of scattered layouts.
//!
//! The points to triangulate all lie strictly inside a convex polygon whose
//! corners are given first (the ghost ring of `voronoi`). That polygon is
//! triangulated as a fan, then every point is inserted in Hilbert-curve
//! order: a visibility walk from the previous point's triangle finds the
//! triangle that holds the new point, the triangle is split in three and
//! Lawson flips restore the Delaunay property. Because every point is inside
//! the polygon, the convex hull never changes and no "outside" case exists.
//!
//! Why not `delaunator`: the real pgII scans are long paths of near-collinear
//! points 0.04° apart. delaunator's sweep adds them in order of distance from
//! a seed, so each path is met side-on and its legalisation cascades. In
//! Hilbert order each insertion is local: a short walk and a few flips.
//!
//! Orientation and in-circle tests are Shewchuk's adaptive exact predicates
//! (crate `robust`), so the result is a true Delaunay triangulation; with
//! exact predicates a visibility walk in a Delaunay triangulation always
//! terminates. The layout of the result mirrors delaunator's: triangle `t`
//! has the counter-clockwise vertices `triangles[3t..3t + 3]`, halfedge `e`
//! runs from `triangles[e]` to `triangles[next(e)]`, and `halfedges[e]` is
//! its twin or [`NONE`] on the hull.

use robust::{Coord, incircle, orient2d};

/// No twin: the halfedge is on the convex hull.
pub(crate) const NONE: u32 = u32::MAX;

/// A triangulation in halfedge form (see the module docs).
pub(crate) struct Triangulation {
    /// Three vertex indices per triangle, counter-clockwise.
    pub triangles: Vec<u32>,
    /// The twin of each halfedge, or [`NONE`].
    pub halfedges: Vec<u32>,
}

/// The halfedge after `e` in its triangle.
#[inline]
pub(crate) fn next(e: u32) -> u32 {
    if e % 3 == 2 { e - 2 } else { e + 1 }
}

/// The halfedge before `e` in its triangle.
#[inline]
fn prev(e: u32) -> u32 {
    if e.is_multiple_of(3) { e + 2 } else { e - 1 }
}

#[inline]
fn coord(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// Positive when a, b, c turn counter-clockwise, negative when clockwise,
/// zero when collinear: the plain determinant when its sign is certain
/// (Shewchuk's first error bound), the exact adaptive one otherwise.
#[inline]
fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    const BOUND: f64 = (3.0 + 16.0 * f64::EPSILON) * f64::EPSILON;
    let left = (a[0] - c[0]) * (b[1] - c[1]);
    let right = (a[1] - c[1]) * (b[0] - c[0]);
    let det = left - right;
    if det.abs() >= BOUND * (left.abs() + right.abs()) {
        det
    } else {
        orient2d(coord(a), coord(b), coord(c))
    }
}

/// Positive when d lies inside the circle through the counter-clockwise
/// a, b, c, negative outside, zero on it: filtered like [`orient`].
#[inline]
fn in_circle(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> f64 {
    const BOUND: f64 = (10.0 + 96.0 * f64::EPSILON) * f64::EPSILON;
    let (adx, ady) = (a[0] - d[0], a[1] - d[1]);
    let (bdx, bdy) = (b[0] - d[0], b[1] - d[1]);
    let (cdx, cdy) = (c[0] - d[0], c[1] - d[1]);
    let (bdxcdy, cdxbdy) = (bdx * cdy, cdx * bdy);
    let (cdxady, adxcdy) = (cdx * ady, adx * cdy);
    let (adxbdy, bdxady) = (adx * bdy, bdx * ady);
    let alift = adx * adx + ady * ady;
    let blift = bdx * bdx + bdy * bdy;
    let clift = cdx * cdx + cdy * cdy;
    let det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * alift
        + (cdxady.abs() + adxcdy.abs()) * blift
        + (adxbdy.abs() + bdxady.abs()) * clift;
    if det.abs() > BOUND * permanent {
        det
    } else {
        incircle(coord(a), coord(b), coord(c), coord(d))
    }
}

/// Delaunay triangulation of `points`, whose first `corners` entries are the
/// counter-clockwise corners of a convex polygon that strictly contains all
/// the others, given in `order` (the insertion order of the other points,
/// which must be distinct). Returns `None` if the input breaks these
/// promises badly enough to be noticed (a point outside the polygon, a walk
/// that does not end), so that the caller can fall back to another method.
pub(crate) fn triangulate_in_polygon(
    points: &[[f64; 2]],
    corners: usize,
    order: impl IntoIterator<Item = u32>,
) -> Option<Triangulation> {
    if corners < 3 || points.len() < corners || points.len() >= (NONE / 2) as usize {
        return None;
    }
    let capacity = 3 * (2 * points.len());
    let mut tri = Triangulation {
        triangles: Vec::with_capacity(capacity),
        halfedges: Vec::with_capacity(capacity),
    };
    // Fan from corner 0: triangle k - 1 is (0, k, k + 1).
    let fan = corners as u32 - 2;
    for k in 1..=fan {
        tri.triangles.extend([0, k, k + 1]);
        let t = k - 1;
        let into_previous = if k == 1 { NONE } else { 3 * (t - 1) + 2 };
        let into_next = if k == fan { NONE } else { 3 * (t + 1) };
        tri.halfedges.extend([into_previous, NONE, into_next]);
    }
    let mut inserter = Inserter {
        points,
        tri,
        stack: Vec::with_capacity(64),
        last: 0,
        walk_budget: 0,
    };
    for p in order {
        inserter.insert(p)?;
    }
    Some(inserter.tri)
}

/// A biased randomised insertion order (BRIO) of `count` points given in
/// spatial (Hilbert) order: a pseudo-random half of the points go in the
/// last round, half of the rest in the round before, and so on; each round
/// keeps the spatial order. Pure spatial order is slow on the real scans:
/// a point added at the end of a path that is being laid down sees the whole
/// neighbouring path and links to it, and those long edges are flipped
/// away again and again (11 flips per point on golden_paper). The random
/// rounds keep the expected work per point constant (about 3 flips), and
/// the spatial order within a round keeps the walks short. The order is a
/// fixed function of `count`, so the result stays deterministic.
pub(crate) fn brio_order(count: usize) -> Vec<u32> {
    // Rounds until the first one has at most ~64 points.
    let mut rounds = 1u32;
    while (count >> rounds) > 64 && rounds < 24 {
        rounds += 1;
    }
    let round_of = |i: usize| -> u32 {
        // splitmix64 of the position: a fixed, well-mixed hash.
        let mut z = (i as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        // Half the points (no trailing zero) in the last round, etc.
        let level = z.trailing_zeros().min(rounds - 1);
        rounds - 1 - level
    };
    // A counting sort by round keeps the spatial order inside each round.
    let mut starts = vec![0usize; rounds as usize + 1];
    for i in 0..count {
        starts[round_of(i) as usize + 1] += 1;
    }
    for r in 0..rounds as usize {
        starts[r + 1] += starts[r];
    }
    let mut order = vec![0u32; count];
    for i in 0..count {
        let r = round_of(i) as usize;
        order[starts[r]] = i as u32;
        starts[r] += 1;
    }
    order
}

struct Inserter<'a> {
    points: &'a [[f64; 2]],
    tri: Triangulation,
    /// Halfedges waiting for the in-circle test.
    stack: Vec<u32>,
    /// A triangle touching the previously inserted point: the walk's start.
    last: u32,
    walk_budget: usize,
}

impl Inserter<'_> {
    fn insert(&mut self, p: u32) -> Option<()> {
        let t = self.locate(self.points[p as usize])?;
        self.split(t, p);
        while let Some(e) = self.stack.pop() {
            self.legalize(e);
        }
        self.last = t;
        Some(())
    }

    /// The triangle containing `point` (inside or on its boundary), by a
    /// visibility walk from `self.last` that crosses any edge `point` lies
    /// strictly beyond, trying the edges in turn after the one it came in by.
    fn locate(&mut self, point: [f64; 2]) -> Option<u32> {
        let tri = &self.tri;
        let mut t = self.last;
        let mut entry = 0u32;
        // A Delaunay walk visits each triangle at most once.
        self.walk_budget = tri.triangles.len() / 3 + 1;
        'walk: loop {
            if self.walk_budget == 0 {
                return None;
            }
            self.walk_budget -= 1;
            for k in 0..3 {
                let e = 3 * t + (entry + k) % 3;
                let a = self.points[tri.triangles[e as usize] as usize];
                let b = self.points[tri.triangles[next(e) as usize] as usize];
                if orient(a, b, point) < 0.0 {
                    let twin = tri.halfedges[e as usize];
                    if twin == NONE {
                        return None; // outside the polygon
                    }
                    t = twin / 3;
                    entry = twin % 3 + 1;
                    continue 'walk;
                }
            }
            return Some(t);
        }
    }

    fn link(&mut self, a: u32, b: u32) {
        self.tri.halfedges[a as usize] = b;
        if b != NONE {
            self.tri.halfedges[b as usize] = a;
        }
    }

    /// Splits triangle `t` = (a, b, c) into (a, b, p), (b, c, p), (c, a, p)
    /// and queues their outer edges. A point on an edge leaves one of them
    /// flat; the in-circle test of that edge always flips it away.
    fn split(&mut self, t: u32, p: u32) {
        let base = 3 * t as usize;
        let [a, b, c] = [
            self.tri.triangles[base],
            self.tri.triangles[base + 1],
            self.tri.triangles[base + 2],
        ];
        let twin_bc = self.tri.halfedges[base + 1];
        let twin_ca = self.tri.halfedges[base + 2];
        let t1 = (self.tri.triangles.len() / 3) as u32;
        let t2 = t1 + 1;
        self.tri.triangles[base + 2] = p;
        self.tri.triangles.extend([b, c, p, c, a, p]);
        self.tri.halfedges.extend([NONE; 6]);
        // (a, b, p): a→b keeps its twin.
        self.link(3 * t + 1, 3 * t1 + 2); // b→p with p→b
        self.link(3 * t + 2, 3 * t2 + 1); // p→a with a→p
        self.link(3 * t1 + 1, 3 * t2 + 2); // c→p with p→c
        self.link(3 * t1, twin_bc);
        self.link(3 * t2, twin_ca);
        self.stack.extend([3 * t, 3 * t1, 3 * t2]);
    }

    /// Halfedge `e` = u→v lies in the triangle (u, v, p) of the newest point
    /// p. If the vertex d across it lies inside that triangle's circumcircle,
    /// flips u–v to p–d and queues the two edges now facing p.
    fn legalize(&mut self, e: u32) {
        let twin = self.tri.halfedges[e as usize];
        if twin == NONE {
            return;
        }
        let tris = &self.tri.triangles;
        let u = tris[e as usize];
        let v = tris[next(e) as usize];
        let p = tris[prev(e) as usize];
        let d = tris[prev(twin) as usize];
        let pt = |i: u32| self.points[i as usize];
        if in_circle(pt(u), pt(v), pt(p), pt(d)) <= 0.0 {
            return;
        }
        // (u, v, p) and (v, u, d) become (u, d, p) and (v, p, d), keeping
        // the positions of their halfedges.
        let (a0, a1) = (e, next(e));
        let (b0, b1, b2) = (twin, next(twin), prev(twin));
        let twin_a1 = self.tri.halfedges[a1 as usize];
        let twin_b1 = self.tri.halfedges[b1 as usize];
        self.tri.triangles[a1 as usize] = d;
        self.tri.triangles[b1 as usize] = p;
        self.link(a0, twin_b1); // u→d
        self.link(b0, twin_a1); // v→p
        self.link(a1, b1); // d→p with p→d
        self.stack.extend([a0, b2]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_corners() -> Vec<[f64; 2]> {
        vec![[-10.0, -10.0], [10.0, -10.0], [10.0, 10.0], [-10.0, 10.0]]
    }

    fn check_delaunay(points: &[[f64; 2]], tri: &Triangulation) {
        for (t, v) in tri.triangles.chunks_exact(3).enumerate() {
            let [a, b, c] = [v[0], v[1], v[2]].map(|i| coord(points[i as usize]));
            assert!(
                orient2d(a, b, c) > 0.0,
                "triangle {t} not counter-clockwise"
            );
        }
        for (e, &twin) in tri.halfedges.iter().enumerate() {
            if twin == NONE {
                continue;
            }
            assert_eq!(tri.halfedges[twin as usize] as usize, e);
            let e = e as u32;
            assert_eq!(
                tri.triangles[e as usize],
                tri.triangles[next(twin) as usize]
            );
            let [u, v, w] =
                [e, next(e), prev(e)].map(|i| points[tri.triangles[i as usize] as usize]);
            let d = points[tri.triangles[prev(twin) as usize] as usize];
            assert!(
                incircle(coord(u), coord(v), coord(w), coord(d)) <= 0.0,
                "edge {e} not Delaunay"
            );
        }
    }

    #[test]
    fn random_points_give_a_delaunay_triangulation() {
        let mut points = square_corners();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..2000 {
            let mut r = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 * 18.0 - 9.0
            };
            points.push([r(), r()]);
        }
        let tri = triangulate_in_polygon(&points, 4, 4..points.len() as u32).unwrap();
        assert_eq!(tri.triangles.len() / 3, 2 * points.len() - 2 - 4);
        check_delaunay(&points, &tri);
    }

    #[test]
    fn grid_points_with_collinear_and_cocircular_sets() {
        let mut points = square_corners();
        for i in 0..30 {
            for j in 0..30 {
                points.push([i as f64 * 0.25 - 3.0, j as f64 * 0.25 - 3.0]);
            }
        }
        let tri = triangulate_in_polygon(&points, 4, 4..points.len() as u32).unwrap();
        assert_eq!(tri.triangles.len() / 3, 2 * points.len() - 2 - 4);
        check_delaunay(&points, &tri);
    }

    #[test]
    fn filtered_predicates_agree_with_the_exact_ones() {
        // Nearly collinear and nearly cocircular points on a fine grid,
        // where the plain determinants are all rounding.
        let g = 1.0 / (1u64 << 30) as f64;
        let mut state = 0x1234_5678u64;
        let mut step = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            ((state >> 33) % 7) as f64 - 3.0
        };
        for k in 0..20_000 {
            let t = 0.3 + 1e-3 * k as f64;
            let a = [0.5, 0.25];
            let b = [0.5 + t, 0.25 + 0.5 * t];
            let c = [0.5 + 2.0 * t + step() * g, 0.25 + t + step() * g];
            assert_eq!(
                orient(a, b, c).signum(),
                orient2d(coord(a), coord(b), coord(c)).signum()
            );
            let r = 0.7;
            let mut on = |angle: f64| [r * angle.cos() + step() * g, r * angle.sin() + step() * g];
            let (p, q, s, d) = (on(0.1), on(1.3 + t), on(2.9), on(4.0 - t));
            assert_eq!(
                in_circle(p, q, s, d).signum(),
                incircle(coord(p), coord(q), coord(s), coord(d)).signum()
            );
        }
    }

    #[test]
    fn a_point_outside_the_polygon_is_refused() {
        let mut points = square_corners();
        points.push([0.0, 0.0]);
        points.push([20.0, 0.0]);
        assert!(triangulate_in_polygon(&points, 4, [4, 5]).is_none());
    }
}
