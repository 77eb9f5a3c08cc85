//! Delaunay triangulation by incremental insertion in spatial order, for the
//! Voronoi cells of scattered layouts.
//!
//! The points to triangulate all lie strictly inside a convex polygon whose
//! corners are given first (the ghost ring of `voronoi`). That polygon is
//! triangulated as a fan, then every point is inserted in Hilbert-curve
//! order: a visibility walk finds the triangle that holds the new point
//! (starting, when the point's neighbour on the curve is already in, from
//! the triangle about that neighbour that faces the point, found by turning
//! about it with one orientation test per triangle; otherwise from the
//! previous point's triangle), the triangle is split in three and Lawson
//! flips restore the
//! Delaunay property. Because every point is inside the polygon, the convex
//! hull never changes and no "outside" case exists.
//!
//! The walk tests each edge once (not the one it came in by) and the
//! triangles are held during insertion as one 32-byte record each (three
//! vertices and three twins), so a walk step or a flip reads one cache
//! line per triangle. The cells are summed straight from these records;
//! the flat layout below is made only for the seam's small triangulation
//! and for the tests.
//!
//! With two threads the caller's two halves (points left and right of a
//! vertical line, each in spatial order) are triangulated in parallel and
//! the seam between them is triangulated again, with a checked certificate
//! ([`triangulate_in_polygon_split`]). Every triangle's halfedges are
//! handed to an [`EdgeVisitor`] with the circumcentres on both sides, on
//! the thread that made them: the Voronoi cells are summed there, straight
//! from the halves' records. The merged flat triangulation is only built
//! when asked for (the tests check it): the solid angles need only the
//! sums, and skipping it saves a pass and 6 MB of fresh memory on a
//! 127k-point scan.
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
    /// Three vertex indices per triangle, counter-clockwise; all three
    /// [`NONE`] for an unused slot (left by [`triangulate_in_polygon_split`]).
    pub triangles: Vec<u32>,
    /// The twin of each halfedge, or [`NONE`].
    pub halfedges: Vec<u32>,
}

/// Receives each inner halfedge of the final triangulation exactly once
/// (both directions of every edge but the polygon's sides), into one of the
/// accumulators, as the vertex it starts `from` with the circumcentres of
/// the triangle on its left (the one holding it) and on its right: its
/// share of the dual Voronoi edge. A circumcentre is what [`circumcentre`]
/// gives from the triangle's vertices in their stored rotation. (Halfedges
/// rather than edges: no "each edge once" test, a branch no predictor
/// gets right, in the hot loop.)
pub(crate) trait EdgeVisitor: Sync {
    /// What the halfedges are accumulated into (one per thread).
    type Sum: Send;
    /// A fresh accumulator.
    fn start(&self) -> Self::Sum;
    /// Adds the halfedge from vertex `from` to `sum`.
    fn visit(&self, sum: &mut Self::Sum, from: u32, left: [f64; 2], right: [f64; 2]);
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
    order: &[u32],
) -> Option<Triangulation> {
    let mesh = triangulate_mesh(points, corners, order)?;
    let (triangles, halfedges) = flat_layout(&mesh, 0, |_| true);
    Some(Triangulation {
        triangles,
        halfedges,
    })
}

/// Triangles of `inner` points strictly inside a convex polygon with
/// `corners` corners (Euler's formula).
fn triangle_count(corners: usize, inner: usize) -> usize {
    corners.saturating_sub(2) + 2 * inner
}

/// A twin in the inserter's numbering (4t + k) as a halfedge of the flat
/// layout (3t + k) numbered from `offset`, [`NONE`] kept.
#[inline]
fn flat_halfedge(twin: u32, offset: u32) -> u32 {
    if twin == NONE {
        NONE
    } else {
        3 * (twin >> 2) + (twin & 3) + offset
    }
}

/// The inserter's records in the flat layout (triangles and halfedges),
/// halfedges numbered from `offset`; the triangles for which `kept` is
/// false become unused slots ([`NONE`] vertices).
fn flat_layout(
    mesh: &[[u32; 8]],
    offset: u32,
    kept: impl Fn(usize) -> bool,
) -> (Vec<u32>, Vec<u32>) {
    let mut triangles = Vec::with_capacity(3 * mesh.len());
    let mut halfedges = Vec::with_capacity(3 * mesh.len());
    for (t, record) in mesh.iter().enumerate() {
        if kept(t) {
            triangles.extend_from_slice(&record[..3]);
        } else {
            triangles.extend_from_slice(&[NONE; 3]);
        }
        halfedges.extend((0..3).map(|k| flat_halfedge(record[4 + k], offset)));
    }
    (triangles, halfedges)
}

/// The circumcentre of an inserter record's triangle.
fn record_centre(points: &[[f64; 2]], record: &[u32; 8]) -> [f64; 2] {
    circumcentre(
        points[record[0] as usize],
        points[record[1] as usize],
        points[record[2] as usize],
    )
}

/// The triangulation of [`triangulate_in_polygon`] in the inserter's
/// records (see [`Inserter`]): `triangle_count(corners, order.len())` of
/// them, the polygon's fan first.
fn triangulate_mesh(points: &[[f64; 2]], corners: usize, order: &[u32]) -> Option<Vec<[u32; 8]>> {
    if corners < 3 || points.len() < corners || points.len() >= (NONE / 8) as usize {
        return None;
    }
    // Fan from corner 0: triangle k - 1 is (0, k, k + 1).
    let fan = corners as u32 - 2;
    let mut mesh = Vec::with_capacity(triangle_count(corners, order.len()));
    let mut triangle_of = vec![NONE; points.len()];
    triangle_of[0] = 0;
    for k in 1..=fan {
        let t = k - 1;
        let into_previous = if k == 1 { NONE } else { 4 * (t - 1) + 2 };
        let into_next = if k == fan { NONE } else { 4 * (t + 1) };
        mesh.push([0, k, k + 1, 0, into_previous, NONE, into_next, 0]);
        triangle_of[k as usize] = t;
        triangle_of[k as usize + 1] = t;
    }
    let mut inserter = Inserter {
        points,
        mesh,
        stack: Vec::with_capacity(64),
        last: 0,
        triangle_of,
    };
    for &p in order {
        inserter.insert(p)?;
    }
    Some(inserter.mesh)
}

/// Below this many points (besides the corners) one thread triangulates
/// them all: splitting costs a seam triangulation and a merge.
pub(crate) const SPLIT_MIN_POINTS: usize = 4096;

/// Delaunay triangulation of `points`, whose first `corners` entries are the
/// counter-clockwise corners of a convex polygon that strictly contains all
/// the others, which must be distinct and in spatial (Hilbert) order. Each
/// point is inserted in [`brio_order`]. With `halves` = `Some((left, x))`
/// the other points are instead the `left` points with abscissa below `x`,
/// in spatial order, then those at or beyond `x`, in spatial order; with
/// two or more threads and enough points, the halves are triangulated in
/// parallel and merged ([`triangulate_in_polygon_split`]), and the result
/// may contain unused triangle slots. Every halfedge is handed to
/// `visitor` once, on the thread that made it; the accumulators are
/// returned in a fixed order (so their combination does not depend on
/// scheduling). `None` as for [`triangulate_in_polygon`].
pub(crate) fn triangulate_spatially_ordered<V: EdgeVisitor>(
    points: &[[f64; 2]],
    corners: usize,
    halves: Option<(usize, f64)>,
    visitor: &V,
) -> Option<Vec<V::Sum>> {
    let inner = points.len().saturating_sub(corners);
    if let Some((left, split)) = halves
        && inner >= SPLIT_MIN_POINTS
        && rayon::current_num_threads() >= 2
        && let Some((_, sums)) =
            triangulate_in_polygon_split(points, corners, left, split, false, visitor)
    {
        return Some(sums);
    }
    let order: Vec<u32> = brio_order(inner)
        .into_iter()
        .map(|k| k + corners as u32)
        .collect();
    let mesh = triangulate_mesh(points, corners, &order)?;
    let centres: Vec<[f64; 2]> = mesh.iter().map(|r| record_centre(points, r)).collect();
    let mut sum = visitor.start();
    for (t, record) in mesh.iter().enumerate() {
        for k in 0..3 {
            let twin = record[4 + k];
            if twin != NONE {
                let (left, right) = (centres[t], centres[(twin >> 2) as usize]);
                visitor.visit(&mut sum, record[k], left, right);
            }
        }
    }
    Some(vec![sum])
}

/// What the merge needs from one half's Delaunay triangulation (made with
/// the polygon's corners).
struct Half {
    /// Kept triangles: their circumcircle lies strictly on the half's side
    /// of the split line, so no point of the other half is inside it and
    /// the triangle is one of the whole set's Delaunay triangles.
    kept: usize,
    /// The non-corner vertices of the triangles not kept.
    seam: Vec<u32>,
    /// The halfedges of kept triangles whose twin is a triangle not kept:
    /// the edges between the kept part and the seam region.
    boundary: Vec<BoundaryEdge>,
    /// The half's triangulation in the flat layout, its halfedges numbered
    /// from the half's offset and the triangles not kept marked unused:
    /// only when the merged triangulation is asked for.
    flat: Option<(Vec<u32>, Vec<u32>)>,
}

/// A halfedge `from` → `to` of a kept triangle (`from`, `to`, `apex`)
/// whose twin lies in the seam region.
struct BoundaryEdge {
    /// Its number in the merged triangulation's flat layout.
    merged: u32,
    from: u32,
    to: u32,
    apex: u32,
    /// The kept triangle's circumcentre.
    centre: [f64; 2],
}

/// Triangulates the polygon's corners and `members` (one half's points,
/// in spatial order) and keeps the triangles whose vertices and
/// circumcircle lie strictly left (`left`) or right of the line
/// x = `split`, handing the edges between two kept triangles to
/// `visitor`. The halfedges are numbered from `offset` in the merged
/// flat layout; with `flat`, the half's triangles are also returned in
/// that layout.
#[allow(clippy::too_many_arguments)]
fn triangulate_half<V: EdgeVisitor>(
    points: &[[f64; 2]],
    corners: usize,
    members: std::ops::Range<u32>,
    split: f64,
    left: bool,
    offset: u32,
    flat: bool,
    visitor: &V,
    sum: &mut V::Sum,
) -> Option<Half> {
    // Signed distance beyond the line, positive on this half's side.
    let beyond = |x: f64| if left { split - x } else { x - split };
    let on_side = |p: &[f64; 2]| if left { p[0] < split } else { p[0] >= split };
    if !points[members.start as usize..members.end as usize]
        .iter()
        .all(on_side)
    {
        return None;
    }
    let order: Vec<u32> = brio_order(members.len())
        .into_iter()
        .map(|k| members.start + k)
        .collect();
    let mesh = triangulate_mesh(points, corners, &order)?;
    // The circumcentre of each kept triangle, NaN for the others.
    let centres: Vec<[f64; 2]> = mesh
        .iter()
        .map(|record| {
            let [a, b, c] = [record[0], record[1], record[2]].map(|i| points[i as usize]);
            if !(beyond(a[0]) > 0.0 && beyond(b[0]) > 0.0 && beyond(c[0]) > 0.0) {
                return [f64::NAN; 2];
            }
            // The circle clear of the line, with a margin for rounding (a
            // wrong call here is caught by the merge's checks, and the
            // visitor's sums are then thrown away).
            let centre = circumcentre(a, b, c);
            let radius2 = (centre[0] - a[0]).powi(2) + (centre[1] - a[1]).powi(2);
            let gap = beyond(centre[0]);
            if gap > 0.0 && gap * gap > radius2 * (1.0 + 1e-9) {
                centre
            } else {
                [f64::NAN; 2]
            }
        })
        .collect();
    let is_kept = |t: usize| !centres[t][0].is_nan();
    let mut kept = 0;
    let mut seen = vec![false; points.len()];
    let mut seam = Vec::new();
    let mut boundary = Vec::new();
    for (t, record) in mesh.iter().enumerate() {
        if is_kept(t) {
            kept += 1;
            for k in 0..3 {
                let twin = record[4 + k];
                if twin == NONE {
                    continue;
                }
                let from = record[k];
                if !is_kept((twin >> 2) as usize) {
                    boundary.push(BoundaryEdge {
                        merged: 3 * t as u32 + k as u32 + offset,
                        from,
                        to: record[(k + 1) % 3],
                        apex: record[(k + 2) % 3],
                        centre: centres[t],
                    });
                } else {
                    visitor.visit(sum, from, centres[t], centres[(twin >> 2) as usize]);
                }
            }
        } else {
            for &v in &record[..3] {
                let i = v as usize;
                if i >= corners && !seen[i] {
                    seen[i] = true;
                    seam.push(v);
                }
            }
        }
    }
    let flat = flat.then(|| flat_layout(&mesh, offset, is_kept));
    Some(Half {
        kept,
        seam,
        boundary,
        flat,
    })
}

/// The circumcentre of the triangle a, b, c (not finite when it is flat).
pub(crate) fn circumcentre(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> [f64; 2] {
    let (bx, by) = (b[0] - a[0], b[1] - a[1]);
    let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
    let b2 = bx * bx + by * by;
    let c2 = cx * cx + cy * cy;
    let d = 2.0 * (bx * cy - by * cx);
    [
        a[0] + (cy * b2 - by * c2) / d,
        a[1] + (bx * c2 - cx * b2) / d,
    ]
}

/// The Delaunay triangulation of [`triangulate_spatially_ordered`], built
/// on two threads:
///
/// 1. The inner points come as two halves: the first `left_count` have
///    x < `split`, the others x ≥ `split`, each half in spatial order
///    (checked). Each half is triangulated with the polygon's corners, in
///    parallel.
/// 2. A triangle of one half whose vertices and circumcircle lie strictly
///    on its side is *kept*: no point of the other half can be in its
///    circle, so it is a Delaunay triangle of the whole set.
/// 3. The rest of the polygon, the seam region, is covered by the
///    triangulation of the points of the triangles not kept (plus the
///    corners): every Delaunay triangle of the whole set there is one of
///    theirs, and its boundary edges are Delaunay edges of the whole set,
///    so are edges of that small triangulation too. Its triangles inside
///    the seam region are found by a flood fill from the boundary edges.
///
/// Nothing is taken on trust: `None` (and the caller falls back to one
/// thread) unless every boundary edge is found in the seam triangulation
/// exactly once, the triangle count is Euler's for the whole set (so the
/// pieces tile the polygon), and every boundary edge passes the in-circle
/// test with the triangles on both sides. With the edges inside each piece
/// Delaunay by construction, the result is then locally Delaunay
/// everywhere, hence a Delaunay triangulation of all the points.
///
/// The triangulation itself is only made with `build` (the tests check
/// it; the solid angles need only the visitor's sums): the halves' slots,
/// those not kept unused ([`NONE`] vertices), then the seam's triangles.
/// The visitor gets the halfedges of the kept triangles from the halves'
/// threads (accumulators 0 and 1) and those of the seam's triangles from
/// this one (into accumulator 0); its sums are only returned with a
/// triangulation that passed the checks.
pub(crate) fn triangulate_in_polygon_split<V: EdgeVisitor>(
    points: &[[f64; 2]],
    corners: usize,
    left_count: usize,
    split: f64,
    build: bool,
    visitor: &V,
) -> Option<(Option<Triangulation>, Vec<V::Sum>)> {
    if corners < 3 || points.len() < corners + 2 || points.len() >= (NONE / 8) as usize {
        return None;
    }
    let inner = points.len() - corners;
    if left_count == 0 || left_count >= inner {
        return None;
    }
    let left = corners as u32..(corners + left_count) as u32;
    let right = left.end..points.len() as u32;

    // The merged numbering: half a's slots, half b's, then the seam's.
    let slots_a = 3 * triangle_count(corners, left.len());
    let slots_b = 3 * triangle_count(corners, right.len());
    let ((a, mut sum_a), (b, sum_b)) = rayon::join(
        || {
            let mut sum = visitor.start();
            let half = triangulate_half(
                points, corners, left, split, true, 0, build, visitor, &mut sum,
            );
            (half, sum)
        },
        || {
            let mut sum = visitor.start();
            let offset = slots_a as u32;
            let half = triangulate_half(
                points, corners, right, split, false, offset, build, visitor, &mut sum,
            );
            (half, sum)
        },
    );
    let (a, b) = (a?, b?);

    // The seam region's triangulation (its vertices in spatial order).
    let mut seam: Vec<u32> = a.seam.iter().chain(&b.seam).copied().collect();
    seam.sort_unstable();
    let order: Vec<u32> = brio_order(seam.len())
        .into_iter()
        .map(|k| seam[k as usize])
        .collect();
    let gap = triangulate_in_polygon(points, corners, &order)?;
    // One halfedge of the seam triangulation out of each of its vertices:
    // the halfedge between two given vertices is found by turning about
    // the first (a few steps) rather than by sorting all of them.
    let mut out_of = vec![NONE; points.len()];
    for (g, &v) in gap.triangles.iter().enumerate() {
        out_of[v as usize] = g as u32;
    }
    let find = |from: u32, to: u32| -> Option<u32> {
        let start = out_of[from as usize];
        if start == NONE {
            return None;
        }
        // Counter-clockwise about `from`, then clockwise if the polygon's
        // side stops the turn.
        let mut g = start;
        for _ in 0..gap.triangles.len() {
            if gap.triangles[next(g) as usize] == to {
                return Some(g);
            }
            let twin = gap.halfedges[prev(g) as usize];
            if twin == NONE {
                break;
            }
            g = twin;
            if g == start {
                return None;
            }
        }
        let mut g = start;
        for _ in 0..gap.triangles.len() {
            let twin = gap.halfedges[g as usize];
            if twin == NONE {
                return None;
            }
            g = next(twin);
            if gap.triangles[next(g) as usize] == to {
                return Some(g);
            }
            if g == start {
                return None;
            }
        }
        None
    };

    // Pair each boundary halfedge with its twin in the seam triangulation
    // (`partner`, merged numbering), checking the in-circle test.
    let mut partner = vec![NONE; gap.triangles.len()];
    let mut paired = Vec::with_capacity(a.boundary.len() + b.boundary.len());
    let pt = |i: u32| points[i as usize];
    for edge in a.boundary.iter().chain(&b.boundary) {
        let g = find(edge.to, edge.from)?;
        if partner[g as usize] != NONE {
            return None;
        }
        partner[g as usize] = edge.merged;
        paired.push(g);
        let d = gap.triangles[prev(g) as usize];
        if in_circle(pt(edge.from), pt(edge.to), pt(edge.apex), pt(d)) > 0.0 {
            return None;
        }
    }

    // The seam triangles: flood fill from the boundary, not across it.
    let mut new_index = vec![NONE; gap.triangles.len() / 3];
    let mut inside: Vec<u32> = Vec::new();
    let mut stack: Vec<u32> = Vec::new();
    for (g, &p) in partner.iter().enumerate() {
        let t = g as u32 / 3;
        if p != NONE && new_index[t as usize] == NONE {
            new_index[t as usize] = inside.len() as u32;
            inside.push(t);
            stack.push(t);
        }
    }
    while let Some(t) = stack.pop() {
        for g in 3 * t..3 * t + 3 {
            let twin = gap.halfedges[g as usize];
            if partner[g as usize] != NONE || twin == NONE {
                continue;
            }
            let u = twin / 3;
            if new_index[u as usize] == NONE {
                new_index[u as usize] = inside.len() as u32;
                inside.push(u);
                stack.push(u);
            }
        }
    }

    // The pieces tile the polygon only if they have Euler's count.
    if a.kept + b.kept + inside.len() != triangle_count(corners, points.len() - corners) {
        return None;
    }

    // The dual Voronoi edges of the seam's edges: those shared with a kept
    // triangle, then those between two seam triangles.
    let seam_centres: Vec<[f64; 2]> = inside
        .iter()
        .map(|&t| {
            let v = &gap.triangles[3 * t as usize..3 * t as usize + 3];
            circumcentre(pt(v[0]), pt(v[1]), pt(v[2]))
        })
        .collect();
    let centre_of = |g: u32| seam_centres[new_index[g as usize / 3] as usize];
    for (edge, &g) in a.boundary.iter().chain(&b.boundary).zip(&paired) {
        let seam = centre_of(g);
        visitor.visit(&mut sum_a, edge.from, edge.centre, seam);
        visitor.visit(&mut sum_a, edge.to, seam, edge.centre);
    }
    for &t in &inside {
        for g in 3 * t..3 * t + 3 {
            let twin = gap.halfedges[g as usize];
            if partner[g as usize] == NONE && twin != NONE {
                let from = gap.triangles[g as usize];
                visitor.visit(&mut sum_a, from, centre_of(g), centre_of(twin));
            }
        }
    }
    let sums = vec![sum_a, sum_b];
    let (Some((mut triangles, mut halfedges)), Some((triangles_b, halfedges_b))) = (a.flat, b.flat)
    else {
        return Some((None, sums));
    };

    // The merged triangulation: the halves' slots, then the seam
    // triangles, linked to the kept ones.
    debug_assert_eq!((triangles.len(), triangles_b.len()), (slots_a, slots_b));
    triangles.extend_from_slice(&triangles_b);
    halfedges.extend_from_slice(&halfedges_b);
    let first = triangles.len() as u32;
    let merged = |g: u32| first + 3 * new_index[g as usize / 3] + g % 3;
    for &t in &inside {
        for g in 3 * t..3 * t + 3 {
            triangles.push(gap.triangles[g as usize]);
            let p = partner[g as usize];
            let twin = gap.halfedges[g as usize];
            halfedges.push(if p != NONE {
                p
            } else if twin == NONE {
                NONE
            } else {
                merged(twin)
            });
        }
    }
    for (g, &p) in partner.iter().enumerate() {
        if p != NONE {
            halfedges[p as usize] = merged(g as u32);
        }
    }
    Some((
        Some(Triangulation {
            triangles,
            halfedges,
        }),
        sums,
    ))
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

/// The halfedge after `e` in its triangle, in the inserter's numbering.
#[inline]
fn next4(e: u32) -> u32 {
    if e & 3 == 2 { e - 2 } else { e + 1 }
}

/// The halfedge before `e` in its triangle, in the inserter's numbering.
#[inline]
fn prev4(e: u32) -> u32 {
    if e & 3 == 0 { e + 2 } else { e - 1 }
}

/// How far along the spatial order the walk's start looks for a point
/// that is already in (in each direction).
const NEIGHBOUR_REACH: usize = 16;

/// Incremental insertion into a triangulation held as one 32-byte record
/// per triangle (its three vertices, a spare, its three halfedges' twins,
/// a spare), so that a step of the walk or a flip touches one cache line
/// per triangle instead of one in each of two arrays. Halfedge k of
/// triangle t is numbered 4t + k here.
struct Inserter<'a> {
    points: &'a [[f64; 2]],
    /// The triangles made so far.
    mesh: Vec<[u32; 8]>,
    /// Halfedges waiting for the in-circle test.
    stack: Vec<u32>,
    /// A triangle touching the previously inserted point: the walk's start
    /// when neither neighbour along the curve is in yet.
    last: u32,
    /// Per point: a triangle touching it, or [`NONE`] until it is inserted.
    triangle_of: Vec<u32>,
}

impl Inserter<'_> {
    /// The vertex halfedge `e` starts from.
    #[inline]
    fn vertex(&self, e: u32) -> u32 {
        self.mesh[(e >> 2) as usize][(e & 3) as usize]
    }

    /// The twin of halfedge `e`, or [`NONE`].
    #[inline]
    fn twin(&self, e: u32) -> u32 {
        self.mesh[(e >> 2) as usize][4 + (e & 3) as usize]
    }

    #[inline]
    fn set_vertex(&mut self, e: u32, v: u32) {
        self.mesh[(e >> 2) as usize][(e & 3) as usize] = v;
    }

    #[inline]
    fn point(&self, v: u32) -> [f64; 2] {
        self.points[v as usize]
    }

    /// Inserts point `p`. The walk starts next to a neighbour of p in the
    /// spatial order (the points' indices) that is already in, if one is
    /// within [`NEIGHBOUR_REACH`] places: a step or two away, where the
    /// previous point of the same insertion round is several.
    fn insert(&mut self, p: u32) -> Option<()> {
        let i = p as usize;
        let point = self.points[i];
        // The nearest points along the curve before and after p that are
        // in (i - 1 in the last round, which holds half the points; a few
        // places away in the earlier, sparser rounds), and of those two the
        // one nearer p: where the curve steps from one scan path to the
        // next, the other is on another path, and the walk from it is long.
        let inserted = |j: usize| self.triangle_of.get(j).is_some_and(|&t| t != NONE);
        let below = (1..=NEIGHBOUR_REACH.min(i))
            .map(|d| i - d)
            .find(|&j| inserted(j));
        let above = (1..=NEIGHBOUR_REACH).map(|d| i + d).find(|&j| inserted(j));
        let distance2 = |j: usize| {
            let q = self.points[j];
            (q[0] - point[0]).powi(2) + (q[1] - point[1]).powi(2)
        };
        let neighbour = match (below, above) {
            (Some(b), Some(a)) => Some(if distance2(a) < distance2(b) { a } else { b }),
            (b, a) => b.or(a),
        }
        .map(|j| j as u32);
        let (first, count) = match neighbour {
            Some(n) => self.turn_towards(n, point),
            None => (4 * self.last, 3),
        };
        let t = self.locate(first, count, point)?;
        self.split(t, p);
        while let Some(e) = self.stack.pop() {
            self.legalize(e);
        }
        self.last = t;
        Some(())
    }

    /// Where the walk towards `point` starts, from the inserted vertex `n`
    /// (`point`'s neighbour along the curve, usually a Delaunay neighbour
    /// of it): turning about `n` from its known triangle, one orientation
    /// test per triangle, to the one whose corner at `n` holds `point`.
    /// Returns that triangle's halfedge opposite `n` and 1 (the only edge
    /// left to test), or, when the turn goes on for too long, a halfedge of
    /// the triangle reached and 3. A hint only: the walk that follows is
    /// right from any start.
    fn turn_towards(&self, n: u32, point: [f64; 2]) -> (u32, u32) {
        const MAX_TURN: usize = 16;
        let t = self.triangle_of[n as usize];
        let record = self.mesh[t as usize];
        let corner = if record[0] == n {
            0
        } else if record[1] == n {
            1
        } else {
            2
        };
        // `out` runs from n to a; the triangle is (n, a, b).
        let mut out = 4 * t + corner;
        let at = self.point(n);
        let a = self.point(record[((corner + 1) % 3) as usize]);
        if orient(at, a, point) < 0.0 {
            // `point` is clockwise of n → a: turn clockwise.
            for _ in 0..MAX_TURN {
                let twin = self.twin(out);
                if twin == NONE {
                    break;
                }
                out = next4(twin);
                let c = self.point(self.vertex(next4(out)));
                if orient(at, c, point) >= 0.0 {
                    return (next4(out), 1);
                }
            }
        } else {
            // Counter-clockwise while `point` is beyond n → b.
            for _ in 0..MAX_TURN {
                let b = self.point(self.vertex(prev4(out)));
                if orient(at, b, point) <= 0.0 {
                    return (next4(out), 1);
                }
                let twin = self.twin(prev4(out));
                if twin == NONE {
                    break;
                }
                out = twin;
            }
        }
        (out & !3, 3)
    }

    /// The triangle containing `point` (inside or on its boundary), by a
    /// visibility walk that starts by testing the `count` edges of a
    /// triangle from halfedge `first` on and crosses any edge `point` lies
    /// strictly beyond, trying the edges in turn after the one it came in
    /// by (which `point` is known to lie beyond, so is not tried again).
    fn locate(&self, first: u32, count: u32, point: [f64; 2]) -> Option<u32> {
        let (mut first, mut count) = (first, count);
        let mut t = first >> 2;
        // A Delaunay walk visits each triangle at most once.
        'walk: for _ in 0..=self.mesh.len() {
            let record = self.mesh[t as usize];
            let mut e = first;
            let mut a = self.point(record[(e & 3) as usize]);
            for k in 0..3 {
                if k == count {
                    break;
                }
                let b = self.point(record[(next4(e) & 3) as usize]);
                if orient(a, b, point) < 0.0 {
                    let twin = record[4 + (e & 3) as usize];
                    if twin == NONE {
                        return None; // outside the polygon
                    }
                    t = twin >> 2;
                    (first, count) = (next4(twin), 2);
                    continue 'walk;
                }
                (e, a) = (next4(e), b);
            }
            return Some(t);
        }
        None
    }

    #[inline]
    fn link(&mut self, a: u32, b: u32) {
        self.mesh[(a >> 2) as usize][4 + (a & 3) as usize] = b;
        if b != NONE {
            self.mesh[(b >> 2) as usize][4 + (b & 3) as usize] = a;
        }
    }

    /// Splits triangle `t` = (a, b, c) into (a, b, p), (b, c, p), (c, a, p)
    /// and queues their outer edges. A point on an edge leaves one of them
    /// flat; the in-circle test of that edge always flips it away.
    fn split(&mut self, t: u32, p: u32) {
        let record = self.mesh[t as usize];
        let [a, b, c] = [record[0], record[1], record[2]];
        let (twin_bc, twin_ca) = (record[5], record[6]);
        let t1 = self.mesh.len() as u32;
        let t2 = t1 + 1;
        self.mesh[t as usize][2] = p;
        self.mesh.push([b, c, p, 0, NONE, NONE, NONE, 0]);
        self.mesh.push([c, a, p, 0, NONE, NONE, NONE, 0]);
        self.triangle_of[c as usize] = t1;
        self.triangle_of[p as usize] = t;
        // (a, b, p): a→b keeps its twin.
        self.link(4 * t + 1, 4 * t1 + 2); // b→p with p→b
        self.link(4 * t + 2, 4 * t2 + 1); // p→a with a→p
        self.link(4 * t1 + 1, 4 * t2 + 2); // c→p with p→c
        self.link(4 * t1, twin_bc);
        self.link(4 * t2, twin_ca);
        self.stack.extend([4 * t, 4 * t1, 4 * t2]);
    }

    /// Halfedge `e` = u→v lies in the triangle (u, v, p) of the newest point
    /// p. If the vertex d across it lies inside that triangle's circumcircle,
    /// flips u–v to p–d and queues the two edges now facing p.
    fn legalize(&mut self, e: u32) {
        let twin = self.twin(e);
        if twin == NONE {
            return;
        }
        let u = self.vertex(e);
        let v = self.vertex(next4(e));
        let p = self.vertex(prev4(e));
        let d = self.vertex(prev4(twin));
        if in_circle(self.point(u), self.point(v), self.point(p), self.point(d)) <= 0.0 {
            return;
        }
        // (u, v, p) and (v, u, d) become (u, d, p) and (v, p, d), keeping
        // the positions of their halfedges.
        let (a0, a1) = (e, next4(e));
        let (b0, b1, b2) = (twin, next4(twin), prev4(twin));
        let twin_a1 = self.twin(a1);
        let twin_b1 = self.twin(b1);
        self.set_vertex(a1, d);
        self.set_vertex(b1, p);
        self.triangle_of[u as usize] = e >> 2;
        self.triangle_of[v as usize] = twin >> 2;
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

    /// Checks that `tri` (unused slots allowed) is a Delaunay triangulation
    /// of all of `points` inside the convex polygon of its first `corners`
    /// points: counter-clockwise triangles with consistent twins, open
    /// edges only between consecutive corners, every point a vertex, the
    /// triangles' areas summing to the polygon's (so they tile it), Euler's
    /// count, and every edge locally Delaunay.
    fn check_delaunay(points: &[[f64; 2]], corners: usize, tri: &Triangulation) {
        let mut used = vec![false; points.len()];
        let mut live = 0;
        let mut area = 0.0;
        for (t, v) in tri.triangles.chunks_exact(3).enumerate() {
            if v[0] == NONE {
                assert!(v[1] == NONE && v[2] == NONE, "slot {t} half unused");
                continue;
            }
            live += 1;
            let [a, b, c] = [v[0], v[1], v[2]].map(|i| coord(points[i as usize]));
            assert!(
                orient2d(a, b, c) > 0.0,
                "triangle {t} not counter-clockwise"
            );
            area += 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
            for &i in v {
                used[i as usize] = true;
            }
        }
        assert!(used.iter().all(|&u| u), "a point is no vertex");
        assert_eq!(live, triangle_count(corners, points.len() - corners));
        let polygon: f64 = (0..corners)
            .map(|k| {
                let (p, q) = (points[k], points[(k + 1) % corners]);
                0.5 * (p[0] * q[1] - p[1] * q[0])
            })
            .sum();
        assert!(
            (area - polygon).abs() <= 1e-9 * polygon,
            "{area} != {polygon}"
        );
        for (e, &twin) in tri.halfedges.iter().enumerate() {
            if tri.triangles[e] == NONE {
                continue;
            }
            if twin == NONE {
                let (from, to) = (tri.triangles[e], tri.triangles[next(e as u32) as usize]);
                assert!(
                    (from as usize) < corners && to as usize == (from as usize + 1) % corners,
                    "open edge {from}→{to} inside the polygon"
                );
                continue;
            }
            assert_ne!(tri.triangles[twin as usize], NONE, "edge {e} into a slot");
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
        let tri = triangulate_in_polygon(&points, 4, &(4..points.len() as u32).collect::<Vec<_>>())
            .unwrap();
        check_delaunay(&points, 4, &tri);
    }

    #[test]
    fn grid_points_with_collinear_and_cocircular_sets() {
        let mut points = square_corners();
        for i in 0..30 {
            for j in 0..30 {
                points.push([i as f64 * 0.25 - 3.0, j as f64 * 0.25 - 3.0]);
            }
        }
        let tri = triangulate_in_polygon(&points, 4, &(4..points.len() as u32).collect::<Vec<_>>())
            .unwrap();
        check_delaunay(&points, 4, &tri);
    }

    /// `points` after the ghost-like corners of a large square, sorted
    /// along a Hilbert-like key (here simply by x then y: any order works
    /// for correctness), triangulated on two threads and checked; the split
    /// path must not give up on these sets.
    fn check_split(name: &str, mut inner: Vec<[f64; 2]>) {
        inner.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        inner.dedup();
        // Split at the median abscissa: the points below it come first.
        let split = inner[inner.len() / 2][0];
        let left = inner.iter().filter(|p| p[0] < split).count();
        let mut points = square_corners();
        points.extend(inner);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let (tri, counts) = pool
            .install(|| triangulate_in_polygon_split(&points, 4, left, split, true, &Count))
            .unwrap_or_else(|| panic!("{name}: the split triangulation gave up"));
        let tri = tri.expect("built when asked for");
        check_delaunay(&points, 4, &tri);
        // The visitor saw each inner halfedge once: three per triangle,
        // less the polygon's four sides.
        assert_eq!(
            counts.iter().sum::<usize>(),
            3 * triangle_count(4, points.len() - 4) - 4,
            "{name}"
        );
    }

    /// A visitor that only counts.
    struct Count;

    impl EdgeVisitor for Count {
        type Sum = usize;
        fn start(&self) -> usize {
            0
        }
        fn visit(&self, sum: &mut usize, _: u32, _: [f64; 2], _: [f64; 2]) {
            *sum += 1;
        }
    }

    fn xorshift(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn split_triangulation_is_delaunay_across_the_seam() {
        let mut state = 0x5eed_1234_abcd_ef01u64;
        let uniform: Vec<[f64; 2]> = (0..20_000)
            .map(|_| {
                [
                    xorshift(&mut state) * 16.0 - 8.0,
                    xorshift(&mut state) * 16.0 - 8.0,
                ]
            })
            .collect();
        check_split("uniform", uniform);

        // A square grid: whole columns lie on the split line (its median
        // abscissa) and every grid square's corners are cocircular, with
        // circles straddling the line.
        let grid: Vec<[f64; 2]> = (0..120)
            .flat_map(|i| {
                (0..120).map(move |j| [i as f64 * 0.125 - 7.4375, j as f64 * 0.125 - 7.5])
            })
            .collect();
        check_split("grid", grid);

        // Concentric rings about a point on the split line: every ring is
        // one cocircular set cut in two by the line.
        let rings: Vec<[f64; 2]> = (1..60)
            .flat_map(|i| {
                (0..240).map(move |j| {
                    let (r, a) = (0.12 * i as f64, std::f64::consts::TAU * j as f64 / 240.0);
                    [r * a.cos(), r * a.sin()]
                })
            })
            .collect();
        check_split("rings", rings);

        // Near-collinear paths crossing the line, points 1e-3 apart.
        let mut paths = Vec::new();
        for _ in 0..60 {
            let start = [
                xorshift(&mut state) * 10.0 - 5.0,
                xorshift(&mut state) * 10.0 - 5.0,
            ];
            let angle = xorshift(&mut state) * std::f64::consts::TAU;
            for k in 0..400 {
                let s = 1e-3 * k as f64 * (1.0 + 1e-3 * xorshift(&mut state));
                paths.push([
                    start[0] + s * angle.cos() * 5.0,
                    start[1] + s * angle.sin() * 5.0,
                ]);
            }
        }
        check_split("paths", paths);
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
        assert!(triangulate_in_polygon(&points, 4, &[4, 5]).is_none());
    }
}
