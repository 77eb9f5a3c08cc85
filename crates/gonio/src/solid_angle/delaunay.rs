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
                if orient2d(coord(a), coord(b), coord(point)) < 0.0 {
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
        let pt = |i: u32| coord(self.points[i as usize]);
        if incircle(pt(u), pt(v), pt(p), pt(d)) <= 0.0 {
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
    fn a_point_outside_the_polygon_is_refused() {
        let mut points = square_corners();
        points.push([0.0, 0.0]);
        points.push([20.0, 0.0]);
        assert!(triangulate_in_polygon(&points, 4, [4, 5]).is_none());
    }
}
