//! The general path: equal-area Voronoi cells, for scattered layouts.
//!
//! 1. Each hemisphere is handled on its own. Its directions are mapped to
//!    the plane with the Lambert azimuthal equal-area projection about the
//!    hemisphere's normal, `r = 2 sin(θ'/2)`, `(x, y) = r (cos φ, sin φ)`,
//!    where θ' is the angle from that normal. The hemisphere becomes the
//!    disk of radius √2, and **areas are preserved**: a region's planar area
//!    equals its solid angle in sr.
//! 2. The planar Voronoi diagram of the projected points (via a Delaunay
//!    triangulation) partitions the plane. A ring of 32 ghost
//!    points at radius 3√2 closes the outer cells; no ghost cell reaches
//!    into the disk, because every disk point is at most 2√2 from any
//!    sample and at least 2√2 from any ghost.
//! 3. Each cell is intersected exactly with the disk (polygon ∩ circle,
//!    arcs included). The clipped cell areas are the solid angles; they sum
//!    to 2π per hemisphere up to rounding.
//!
//! The cells are the equal-area images of a partition of the hemisphere in
//! which every sample owns the region of directions nearest to it in the
//! projected plane: not the spherical Voronoi cells, but an exact
//! partition, so a constant integrates exactly and smooth functions to
//! quadrature accuracy. Coincident directions (after rounding the projected
//! coordinates to 2⁻³⁰) share one cell equally. The result is
//! deterministic and independent of the sample order: points are sorted
//! (by a Hilbert-curve key, then by their coordinates) before the
//! triangulation.
//!
//! The triangulation is our own incremental Delaunay in a biased randomised
//! Hilbert order with exact predicates behind a floating-point filter
//! (module `delaunay`), several times faster than `delaunator` on the real
//! scans' long near-collinear paths. With two threads and enough points
//! ([`disk_voronoi_areas`]):
//!
//! 1. one pass, in parallel pieces, checks the points and takes their
//!    bounding box; a histogram of x (counted the same way) gives a split
//!    line with about half the points on either side (from the histogram,
//!    so independent of the input order);
//! 2. each half, on its own thread, computes its points' Hilbert keys
//!    (four curve levels per table look-up), sorts them (a stable radix
//!    sort, ties by the coordinates) and merges coincident points, then
//!    triangulates them with the ghost ring;
//! 3. each half keeps the triangles whose circumcircle lies on its side of
//!    the line and sums their share of the cells as it classifies them:
//!    per Delaunay halfedge u → v, the origin-fan term of its dual Voronoi
//!    edge (the circumcentres left and right of it, clipped to the disk)
//!    added to u's cell. No pass over stored circumcentres, no pointer
//!    chasing around vertices;
//! 4. the seam between the halves is triangulated again and checked, and
//!    its halfedges add their terms the same way (module `delaunay`);
//! 5. each point's weight is its cell's per-thread sums, added in a fixed
//!    order, divided by the number of points sharing the cell.
//!
//! With one thread the same steps run on all the points at once. The
//! Voronoi diagram does not depend on the triangulation method, so both,
//! and the delaunator-based [`reference_disk_voronoi_areas`], give the same
//! cells up to rounding; the reference is what the tests compare with, and
//! the fallback for points the fast path does not accept (outside radius
//! 2√2 or not finite).

use std::collections::HashMap;

use delaunator::{EMPTY, Point, next_halfedge, triangulate};
use rayon::prelude::*;

use super::delaunay::{self, circumcentre};
use crate::measurement::Hemisphere;

/// Radius of the equal-area disk that one hemisphere maps to (√2).
pub const DISK_RADIUS: f64 = std::f64::consts::SQRT_2;

/// Projected coordinates are rounded to multiples of this (2⁻³⁰ ≈ 9.3e-10,
/// about 5e-8 degrees), so the triangulation never sees near-duplicates.
const GRID: f64 = 1.0 / (1u64 << 30) as f64;

/// Number of ghost points closing the outer Voronoi cells.
const GHOSTS: usize = 32;

/// Equal-area Voronoi cell areas (sr) of the `count` directions
/// `direction(k)` = `(θ, φ)` in degrees, all valid and in `hemisphere`.
pub(crate) fn hemisphere_areas(
    count: usize,
    direction: impl Fn(usize) -> (f64, f64) + Sync,
    hemisphere: Hemisphere,
) -> Vec<f64> {
    let points: Vec<[f64; 2]> = (0..count)
        .into_par_iter()
        .with_min_len(4096)
        .map(|k| {
            let (theta, phi) = direction(k);
            project(theta, phi, hemisphere)
        })
        .collect();
    disk_voronoi_areas(&points)
}

/// Lambert azimuthal equal-area projection of a direction about the normal
/// of `hemisphere`, rounded to the grid.
///
/// With d = (x, y, z) the unit direction and θ' its angle from the normal,
/// the projected radius is 2 sin(θ'/2) = sin θ' · √(2 / (1 + cos θ')), so
/// the point is (x, y) · √(2 / (1 ± z)): no trigonometry beyond the
/// direction's own.
pub fn project(theta_deg: f64, phi_deg: f64, hemisphere: Hemisphere) -> [f64; 2] {
    let d = brtf_model::direction(theta_deg, phi_deg);
    let cos_from_normal = match hemisphere {
        Hemisphere::Front => d.z,
        Hemisphere::Back => -d.z,
    };
    if cos_from_normal <= -0.5 {
        // Far into the other hemisphere (never a member of this one): the
        // radius from the half angle, which stays exact at the far pole.
        let from_normal = cos_from_normal.acos();
        let r = 2.0 * (from_normal / 2.0).sin();
        let (sp, cp) = brtf_model::sin_cos_degrees(phi_deg);
        return [snap(r * cp), snap(r * sp)];
    }
    let scale = (2.0 / (1.0 + cos_from_normal)).sqrt();
    [snap(d.x * scale), snap(d.y * scale)]
}

fn snap(v: f64) -> f64 {
    (v / GRID).round() * GRID
}

/// Points farther than this from the centre go to the reference path: the
/// fast path needs every point well inside the ghost ring (whose inner
/// radius is 3√2 cos(π/32) ≈ 4.2).
const FAST_PATH_RADIUS: f64 = 2.0 * DISK_RADIUS;

/// Points per piece of the parallel passes over all the points.
const PASS_CHUNK: usize = 16_384;

/// Areas of the Voronoi cells of `points` clipped to the disk of radius
/// [`DISK_RADIUS`]. Coincident points share their cell equally.
pub fn disk_voronoi_areas(points: &[[f64; 2]]) -> Vec<f64> {
    let n = points.len();
    if n == 0 {
        return Vec::new();
    }
    // One parallel pass: every point finite and within the fast path's
    // radius, and the bounding box (the frame of the Hilbert curve).
    let (accepted, lo, hi) = points
        .par_chunks(PASS_CHUNK)
        .map(|chunk| {
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            let mut accepted = true;
            for p in chunk {
                accepted &= p[0].is_finite()
                    && p[1].is_finite()
                    && p[0] * p[0] + p[1] * p[1] <= FAST_PATH_RADIUS * FAST_PATH_RADIUS;
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            (accepted, lo, hi)
        })
        .reduce(
            || (true, [f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
            |a, b| {
                let lo = [a.1[0].min(b.1[0]), a.1[1].min(b.1[1])];
                let hi = [a.2[0].max(b.2[0]), a.2[1].max(b.2[1])];
                (a.0 && b.0, lo, hi)
            },
        );
    if !accepted || n >= (u32::MAX / 8) as usize {
        return reference_disk_voronoi_areas(points);
    }
    let side = ((1u32 << HILBERT_LEVELS) - 1) as f64;
    let frame = CurveFrame {
        lo,
        scale: side / (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE),
    };

    // With two threads, the points left and right of a vertical line are
    // sorted and triangulated on one thread each.
    let split = (n >= delaunay::SPLIT_MIN_POINTS && rayon::current_num_threads() >= 2)
        .then(|| middle_abscissa(points, lo[0], hi[0]))
        .flatten();
    let pieces = match split {
        Some(x) => {
            let (left, right) = rayon::join(
                || Piece::sorted(points, &frame, |p| p[0] < x),
                || Piece::sorted(points, &frame, |p| p[0] >= x),
            );
            vec![left, right]
        }
        None => vec![Piece::sorted(points, &frame, |_| true)],
    };
    let halves = split.map(|x| (pieces[0].unique.len(), x));

    // The triangulation's vertices: the ghost ring, then each piece's
    // distinct points in its spatial order; `group_of[i]` is point i's cell.
    let distinct: usize = pieces.iter().map(|piece| piece.unique.len()).sum();
    let mut vertices: Vec<[f64; 2]> = Vec::with_capacity(GHOSTS + distinct);
    vertices.extend(ghost_ring());
    let mut group_of = vec![0u32; n];
    let mut group_size: Vec<u32> = Vec::with_capacity(distinct);
    for piece in &pieces {
        let first = group_size.len() as u32;
        vertices.extend_from_slice(&piece.unique);
        group_size.extend_from_slice(&piece.sizes);
        for (&i, &g) in piece.order.iter().zip(&piece.group) {
            group_of[i as usize] = first + g;
        }
    }
    let Some(sums) = cell_sums(&vertices, halves) else {
        return reference_disk_voronoi_areas(points);
    };
    // Each point's share of its cell, the per-thread sums added in a fixed
    // order (so the result does not depend on scheduling).
    let areas: Vec<f64> = group_of
        .par_iter()
        .with_min_len(4096)
        .map(|&g| {
            let i = GHOSTS + g as usize;
            let cell = sums.iter().map(|part| part[i]).sum::<f64>().abs();
            cell / group_size[g as usize] as f64
        })
        .collect();
    // A cell that is not finite (never seen): the reference instead.
    if areas.par_iter().all(|a| a.is_finite()) {
        areas
    } else {
        reference_disk_voronoi_areas(points)
    }
}

/// An abscissa with about half of `points` on either side (from a
/// histogram over `lo..hi`, counted in parallel pieces; it does not depend
/// on their order), or `None` if one side would be empty.
fn middle_abscissa(points: &[[f64; 2]], lo: f64, hi: f64) -> Option<f64> {
    const BINS: usize = 4096;
    let width = (hi - lo) / BINS as f64;
    if width <= 0.0 {
        return None;
    }
    let counts = points
        .par_chunks(PASS_CHUNK)
        .map(|chunk| {
            let mut counts = vec![0usize; BINS];
            for p in chunk {
                counts[(((p[0] - lo) / width) as usize).min(BINS - 1)] += 1;
            }
            counts
        })
        .reduce(
            || vec![0usize; BINS],
            |mut a, b| {
                a.iter_mut().zip(&b).for_each(|(a, b)| *a += b);
                a
            },
        );
    let mut below = 0;
    for (bin, &count) in counts.iter().enumerate() {
        below += count;
        if 2 * below >= points.len() {
            let x = lo + (bin + 1) as f64 * width;
            return (x < hi).then_some(x);
        }
    }
    None
}

/// The frame of the Hilbert curve: the bounding box's low corner and the
/// scale to curve cells.
struct CurveFrame {
    lo: [f64; 2],
    scale: f64,
}

impl CurveFrame {
    fn key(&self, p: [f64; 2]) -> u32 {
        let x = ((p[0] - self.lo[0]) * self.scale) as u32;
        let y = ((p[1] - self.lo[1]) * self.scale) as u32;
        hilbert_key(x, y)
    }
}

/// Some of the points in spatial order, coincident ones merged.
struct Piece {
    /// The points' indices, in Hilbert order (ties by their coordinates).
    order: Vec<u32>,
    /// The distinct point (cell) of each entry of `order`.
    group: Vec<u32>,
    /// The distinct points, in order.
    unique: Vec<[f64; 2]>,
    /// How many points share each distinct point.
    sizes: Vec<u32>,
}

impl Piece {
    /// The points for which `keep` holds.
    fn sorted(points: &[[f64; 2]], frame: &CurveFrame, keep: impl Fn(&[f64; 2]) -> bool) -> Piece {
        let keyed: Vec<u64> = points
            .iter()
            .enumerate()
            .filter(|(_, p)| keep(p))
            .map(|(i, p)| (u64::from(frame.key(*p)) << 32) | i as u64)
            .collect();
        let order = hilbert_order(points, keyed);
        let mut group = Vec::with_capacity(order.len());
        let mut unique: Vec<[f64; 2]> = Vec::with_capacity(order.len());
        let mut sizes: Vec<u32> = Vec::with_capacity(order.len());
        for &i in &order {
            let p = points[i as usize];
            if unique.last() != Some(&p) {
                unique.push(p);
                sizes.push(0);
            }
            *sizes.last_mut().expect("a group was just opened") += 1;
            group.push(unique.len() as u32 - 1);
        }
        Piece {
            order,
            group,
            unique,
            sizes,
        }
    }
}

/// Bits per coordinate of the Hilbert key.
const HILBERT_LEVELS: u32 = 16;

/// The point indices of `keyed` (Hilbert key above, index below) in
/// Hilbert-curve order, ties (the same curve cell) broken by the
/// coordinates, so that coincident points are adjacent and the order does
/// not depend on the input order except among coincident points.
fn hilbert_order(points: &[[f64; 2]], keyed: Vec<u64>) -> Vec<u32> {
    let keyed = sort_by_high_half(keyed);
    let mut order: Vec<u32> = keyed.iter().map(|&k| k as u32).collect();
    // Points in the same curve cell: order them by their coordinates.
    let mut start = 0;
    while start < keyed.len() {
        let key = keyed[start] >> 32;
        let mut end = start + 1;
        while end < keyed.len() && keyed[end] >> 32 == key {
            end += 1;
        }
        if end - start > 1 {
            order[start..end].sort_unstable_by(|&a, &b| {
                let (pa, pb) = (points[a as usize], points[b as usize]);
                pa[0].total_cmp(&pb[0]).then(pa[1].total_cmp(&pb[1]))
            });
        }
        start = end;
    }
    order
}

/// `keys` sorted by their upper 32 bits, stably (a least-significant-digit
/// radix sort, three passes of 11 bits): a few linear passes where a
/// comparison sort costs log n.
fn sort_by_high_half(mut keys: Vec<u64>) -> Vec<u64> {
    const BITS: u32 = 11;
    const BUCKETS: usize = 1 << BITS;
    let digit = |key: u64, pass: u32| ((key >> (32 + BITS * pass)) as usize) & (BUCKETS - 1);
    let mut counts = vec![[0usize; BUCKETS]; 3];
    for &key in &keys {
        for (pass, count) in counts.iter_mut().enumerate() {
            count[digit(key, pass as u32)] += 1;
        }
    }
    let mut spare = vec![0u64; keys.len()];
    for (pass, count) in counts.iter().enumerate() {
        // A digit shared by every key: nothing to do.
        if count.contains(&keys.len()) {
            continue;
        }
        let mut next = [0usize; BUCKETS];
        let mut total = 0;
        for (slot, &c) in next.iter_mut().zip(count) {
            *slot = total;
            total += c;
        }
        for &key in &keys {
            let d = digit(key, pass as u32);
            spare[next[d]] = key;
            next[d] += 1;
        }
        std::mem::swap(&mut keys, &mut spare);
    }
    keys
}

/// For the Hilbert curve: per state (bit 0: the quadrant's axes are
/// swapped, bit 1: complemented) and 4 bits each of x (high nibble) and y,
/// the curve's 8 bits for those 4 levels and, above them, the state for the
/// levels below.
static HILBERT_TABLE: [u16; 1024] = hilbert_table();

const fn hilbert_table() -> [u16; 1024] {
    let mut table = [0u16; 1024];
    let mut entry = 0;
    while entry < 1024 {
        let (state, x, y) = (entry >> 8, (entry >> 4) & 15, entry & 15);
        let (mut swap, mut complement) = (state & 1, state >> 1);
        let mut digits = 0;
        let mut level = 4;
        while level > 0 {
            level -= 1;
            let (mut bx, mut by) = ((x >> level) & 1, (y >> level) & 1);
            if swap == 1 {
                (bx, by) = (by, bx);
            }
            let (rx, ry) = (bx ^ complement, by ^ complement);
            digits = (digits << 2) | ((3 * rx) ^ ry);
            // The sub-square's curve is the transpose, mirrored in the
            // third quadrant.
            if ry == 0 {
                complement ^= rx;
                swap ^= 1;
            }
        }
        table[entry] = (digits | ((swap | (complement << 1)) << 8)) as u16;
        entry += 1;
    }
    table
}

/// Position of the cell `(x, y)` along the Hilbert curve that fills the
/// `2^16` square, four levels per table look-up.
fn hilbert_key(x: u32, y: u32) -> u32 {
    let mut state = 0usize;
    let mut key = 0u32;
    for shift in [12, 8, 4, 0] {
        let nibbles = (((x >> shift) & 15) << 4 | ((y >> shift) & 15)) as usize;
        let entry = HILBERT_TABLE[(state << 8) | nibbles];
        key = (key << 8) | u32::from(entry & 0xff);
        state = usize::from(entry >> 8);
    }
    key
}

/// The ghost points closing the outer cells, counter-clockwise.
fn ghost_ring() -> impl Iterator<Item = [f64; 2]> {
    let ghost_radius = 3.0 * DISK_RADIUS;
    (0..GHOSTS).map(move |k| {
        let a = std::f64::consts::TAU * k as f64 / GHOSTS as f64;
        [ghost_radius * a.cos(), ghost_radius * a.sin()]
    })
}

/// Sums the disk-clipped Voronoi cells of the triangulation's vertices
/// edge by edge.
///
/// A vertex's cell is the polygon of the circumcentres of its triangles,
/// and each of its edges is dual to one of the vertex's Delaunay edges.
/// The clipped area is a sum over the polygon's edges (the signed area of
/// the triangle from the origin to the edge, clipped to the disk), so each
/// Delaunay halfedge u → v adds to u's cell the term of its dual edge,
/// from the circumcentre on its left to the one on its right. The
/// triangulation hands the halfedges over on the thread that made them,
/// right after it computed their triangles' circumcentres: no second pass
/// over the triangulation.
struct CellSums {
    vertices: usize,
}

impl delaunay::EdgeVisitor for CellSums {
    type Sum = Vec<f64>;

    fn start(&self) -> Vec<f64> {
        vec![0.0; self.vertices]
    }

    #[inline]
    fn visit(&self, sums: &mut Vec<f64>, from: u32, a: [f64; 2], b: [f64; 2]) {
        let r2 = DISK_RADIUS * DISK_RADIUS;
        let inside = a[0] * a[0] + a[1] * a[1] <= r2 && b[0] * b[0] + b[1] * b[1] <= r2;
        let area = if inside {
            0.5 * (a[0] * b[1] - a[1] * b[0])
        } else {
            disk_triangle_area(a, b, DISK_RADIUS)
        };
        sums[from as usize] += area;
    }
}

/// The per-thread sums of the disk-clipped Voronoi cells of the
/// triangulation's vertices (ghosts included), in a fixed order, or `None`
/// if the triangulation gave up.
fn cell_sums(vertices: &[[f64; 2]], halves: Option<(usize, f64)>) -> Option<Vec<Vec<f64>>> {
    delaunay::triangulate_spatially_ordered(
        vertices,
        GHOSTS,
        halves,
        &CellSums {
            vertices: vertices.len(),
        },
    )
}

/// Areas of the Voronoi cells of `points` clipped to the disk of radius
/// [`DISK_RADIUS`]. Coincident points share their cell equally.
///
/// The delaunator-based computation this crate used before its own
/// triangulation: the same cells up to rounding, several times slower.
/// Kept as the reference for tests and benchmarks, and as the fallback of
/// [`disk_voronoi_areas`].
pub fn reference_disk_voronoi_areas(points: &[[f64; 2]]) -> Vec<f64> {
    let n = points.len();
    let mut areas = vec![0.0; n];
    if n == 0 {
        return areas;
    }

    // Group coincident points; `unique[k]` is the representative point.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        let ka = (points[a][0], points[a][1]);
        let kb = (points[b][0], points[b][1]);
        ka.0.total_cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    let mut unique: Vec<[f64; 2]> = Vec::with_capacity(n + GHOSTS);
    let mut group_of = vec![0usize; n];
    for (pos, &i) in order.iter().enumerate() {
        let is_new = pos == 0 || points[order[pos - 1]] != points[i];
        if is_new {
            unique.push(points[i]);
        }
        group_of[i] = unique.len() - 1;
    }
    let real = unique.len();
    let unique_areas = unique_cell_areas(&mut unique);
    debug_assert_eq!(unique.len(), real + GHOSTS);

    let mut group_size = vec![0usize; real];
    for &g in &group_of {
        group_size[g] += 1;
    }
    for i in 0..n {
        let g = group_of[i];
        areas[i] = unique_areas[g] / group_size[g] as f64;
    }
    areas
}

/// Cell areas of the distinct points in `unique` (ghosts are appended to
/// it). Returns one area per original entry.
fn unique_cell_areas(unique: &mut Vec<[f64; 2]>) -> Vec<f64> {
    let real = unique.len();
    let ghost_radius = 3.0 * DISK_RADIUS;
    for k in 0..GHOSTS {
        let a = std::f64::consts::TAU * k as f64 / GHOSTS as f64;
        unique.push([ghost_radius * a.cos(), ghost_radius * a.sin()]);
    }
    let input: Vec<Point> = unique.iter().map(|&[x, y]| Point { x, y }).collect();
    let tri = triangulate(&input);

    let circumcenters: Vec<[f64; 2]> = tri
        .triangles
        .chunks_exact(3)
        .map(|t| circumcentre(unique[t[0]], unique[t[1]], unique[t[2]]))
        .collect();
    // One halfedge ending at each point.
    let mut incoming = vec![EMPTY; unique.len()];
    for e in 0..tri.triangles.len() {
        incoming[tri.triangles[next_halfedge(e)]] = e;
    }

    let mut areas = vec![0.0; real];
    let mut missing = Vec::new();
    let mut polygon: Vec<[f64; 2]> = Vec::with_capacity(16);
    for p in 0..real {
        let start = incoming[p];
        if start == EMPTY {
            missing.push(p);
            continue;
        }
        polygon.clear();
        let mut e = start;
        let mut closed = false;
        for _ in 0..tri.triangles.len() {
            polygon.push(circumcenters[e / 3]);
            let twin = tri.halfedges[next_halfedge(e)];
            if twin == EMPTY {
                break;
            }
            e = twin;
            if e == start {
                closed = true;
                break;
            }
        }
        if closed {
            areas[p] = disk_polygon_area(&polygon, DISK_RADIUS).abs();
        } else {
            missing.push(p);
        }
    }
    if !missing.is_empty() {
        share_with_nearest(unique, real, &missing, &mut areas);
    }
    areas
}

/// Points the triangulation skipped (never seen with snapped, distinct
/// input, but handled): each shares the cell of its nearest triangulated
/// neighbour.
fn share_with_nearest(points: &[[f64; 2]], real: usize, missing: &[usize], areas: &mut [f64]) {
    let is_missing: Vec<bool> = {
        let mut v = vec![false; real];
        for &m in missing {
            v[m] = true;
        }
        v
    };
    let mut sharers: HashMap<usize, Vec<usize>> = HashMap::new();
    for &m in missing {
        let nearest = (0..real)
            .filter(|&q| !is_missing[q])
            .min_by(|&a, &b| dist2(points[a], points[m]).total_cmp(&dist2(points[b], points[m])));
        if let Some(q) = nearest {
            sharers.entry(q).or_default().push(m);
        }
    }
    let mut owners: Vec<_> = sharers.into_iter().collect();
    owners.sort_unstable_by_key(|(q, _)| *q);
    for (q, ms) in owners {
        let share = areas[q] / (ms.len() + 1) as f64;
        areas[q] = share;
        for m in ms {
            areas[m] = share;
        }
    }
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Signed area of `polygon ∩ disk(0, radius)` (positive for
/// counter-clockwise polygons).
pub(super) fn disk_polygon_area(polygon: &[[f64; 2]], radius: f64) -> f64 {
    let n = polygon.len();
    let r2 = radius * radius;
    if polygon.iter().all(|p| p[0] * p[0] + p[1] * p[1] <= r2) {
        // The disk is convex: a polygon with every vertex inside is inside.
        return 0.5
            * (0..n)
                .map(|i| {
                    let (p, q) = (polygon[i], polygon[(i + 1) % n]);
                    p[0] * q[1] - p[1] * q[0]
                })
                .sum::<f64>();
    }
    (0..n)
        .map(|i| disk_triangle_area(polygon[i], polygon[(i + 1) % n], radius))
        .sum()
}

/// Signed area of `triangle(origin, a, b) ∩ disk(0, r)`.
fn disk_triangle_area(a: [f64; 2], b: [f64; 2], r: f64) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let qa = d[0] * d[0] + d[1] * d[1];
    if qa.is_nan() || qa <= 0.0 || qa.is_infinite() {
        return 0.0;
    }
    let qb = a[0] * d[0] + a[1] * d[1];
    let qc = a[0] * a[0] + a[1] * a[1] - r * r;
    let disc = qb * qb - qa * qc;
    let mut cuts = [0.0, 1.0, 1.0, 1.0];
    let mut count = 1;
    if disc > 0.0 {
        let root = disc.sqrt();
        for t in [(-qb - root) / qa, (-qb + root) / qa] {
            if t > 0.0 && t < 1.0 {
                cuts[count] = t;
                count += 1;
            }
        }
    }
    cuts[count] = 1.0;
    let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1]];
    let mut area = 0.0;
    for k in 0..count {
        let (s, e) = (cuts[k], cuts[k + 1]);
        if e <= s {
            continue;
        }
        let (p, q) = (at(s), at(e));
        let mid = at(0.5 * (s + e));
        let cross = p[0] * q[1] - p[1] * q[0];
        if mid[0] * mid[0] + mid[1] * mid[1] <= r * r {
            area += 0.5 * cross;
        } else {
            let dot = p[0] * q[0] + p[1] * q[1];
            area += 0.5 * r * r * cross.atan2(dot);
        }
    }
    area
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The Hilbert curve one level at a time, as defined: the quadrant's
    /// digit, then the transform of the sub-square's coordinates.
    fn hilbert_index_per_level(mut x: u32, mut y: u32, levels: u32) -> u64 {
        let n = 1u32 << levels;
        let mut d = 0u64;
        let mut s = n / 2;
        while s > 0 {
            let rx = u32::from(x & s != 0);
            let ry = u32::from(y & s != 0);
            d += u64::from(s) * u64::from(s) * u64::from((3 * rx) ^ ry);
            if ry == 0 {
                if rx == 1 {
                    x = n - 1 - x;
                    y = n - 1 - y;
                }
                std::mem::swap(&mut x, &mut y);
            }
            s /= 2;
        }
        d
    }

    #[test]
    fn hilbert_keys_follow_the_curve() {
        // Every cell of a 2^6 corner, then scattered cells of the full square.
        for x in 0..64 {
            for y in 0..64 {
                assert_eq!(
                    u64::from(hilbert_key(x, y)),
                    hilbert_index_per_level(x, y, HILBERT_LEVELS)
                );
            }
        }
        let mut state = 0x9e37_79b9u32;
        for _ in 0..100_000 {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            let (x, y) = (state >> 16, state & 0xffff);
            assert_eq!(
                u64::from(hilbert_key(x, y)),
                hilbert_index_per_level(x, y, HILBERT_LEVELS)
            );
        }
        // The curve is continuous: consecutive keys are neighbouring cells.
        let mut cells = vec![(0, 0); 1 << 12];
        for x in 0..64u32 {
            for y in 0..64u32 {
                let k = hilbert_key(x << 10, y << 10) >> 20;
                cells[k as usize] = (x, y);
            }
        }
        for w in cells.windows(2) {
            assert_eq!(w[0].0.abs_diff(w[1].0) + w[0].1.abs_diff(w[1].1), 1);
        }
    }

    #[test]
    fn radix_sort_orders_by_the_high_half_stably() {
        let mut state = 0x1234_5678_9abc_def0u64;
        let keys: Vec<u64> = (0..50_000u64)
            .map(|i| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                // Few distinct high halves, so many ties.
                ((state % 3000) << 32) | i
            })
            .collect();
        let mut expected = keys.clone();
        expected.sort_by_key(|k| k >> 32);
        assert_eq!(sort_by_high_half(keys), expected);
    }

    #[test]
    fn disk_clipping_of_simple_shapes() {
        // A square much larger than the disk: the whole disk.
        let big = [[-10.0, -10.0], [10.0, -10.0], [10.0, 10.0], [-10.0, 10.0]];
        assert!((disk_polygon_area(&big, 1.0) - PI).abs() < 1e-12);
        // A square inside the disk: the square.
        let small = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]];
        assert!((disk_polygon_area(&small, 1.0) - 1.0).abs() < 1e-12);
        // Half-plane x > 0 cut by a big rectangle: half the disk.
        let half = [[0.0, -10.0], [10.0, -10.0], [10.0, 10.0], [0.0, 10.0]];
        assert!((disk_polygon_area(&half, 1.0) - PI / 2.0).abs() < 1e-12);
        // A square offset so that it is off-centre and partly outside.
        let off = [[0.5, -0.25], [2.0, -0.25], [2.0, 0.25], [0.5, 0.25]];
        let a = disk_polygon_area(&off, 1.0);
        assert!(a > 0.0 && a < 0.5 * 0.5, "{a}");
    }

    #[test]
    fn cells_partition_the_disk() {
        for pts in [
            vec![[0.0, 0.0]],
            vec![[0.1, 0.0], [-0.1, 0.0]],
            vec![[0.1, 0.0], [0.2, 0.0], [0.3, 0.0]], // collinear
            vec![[0.5, 0.5], [0.5, 0.5], [-0.3, 0.2]], // duplicate
        ] {
            let areas = disk_voronoi_areas(&pts);
            let total: f64 = areas.iter().sum();
            assert!((total - 2.0 * PI).abs() < 1e-9, "{pts:?}: {areas:?}");
        }
        let dup = disk_voronoi_areas(&[[0.5, 0.5], [0.5, 0.5], [-0.3, 0.2]]);
        assert_eq!(dup[0], dup[1]);
    }
}
