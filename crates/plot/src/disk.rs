//! The hemisphere as a disk: Lambert's azimuthal equal-area projection
//! and the nearest-sample raster of the residual maps.
//!
//! A direction at angle θ' from the hemisphere's normal and azimuth φ maps
//! to `r = 2 sin(θ'/2)`, `(x, y) = r (cos φ, sin φ)`: the hemisphere becomes
//! the disk of radius √2 and every region keeps its area, so a patch of the
//! map is as large as the solid angle it covers (the same projection
//! brtf-gonio uses for its solid angles). φ = 0 points right, φ = 90° up.
//! The back hemisphere is projected about the back normal with the same φ
//! (seen through the sample from the front).
//!
//! [`Coverage`] gives every pixel of the disk to its nearest sample, as
//! long as that sample is no farther than its own distance to its nearest
//! neighbour or [`FILL_DEG`], whichever is larger: gaps wider than twice
//! that stay uncovered. The maps colour the pixels by their owner, and as
//! every pixel stands for the same solid angle, the same grid is the
//! quadrature of the hemispherical integrals.
//!
//! The nearest sample is exact wherever one lies within 1.5 pixels (found
//! among the samples of the 3 × 3 pixels around; the pixel's own first,
//! and when one of those is nearer than half a pixel, the others cannot
//! be nearer and are not looked at). Pixels in gaps take the
//! nearest of their neighbours' samples, propagated over the grid in two
//! sweeps (down and up; the upper and lower halves of the rows at the same
//! time), then the nearest among the samples around that one: in rare
//! pixels this is not the nearest sample but one a fraction of a pixel
//! farther (at most a quarter of a pixel in the tests; on the 127 039-point
//! pgII scan `golden_paper.txt`, 183 of 205 892 pixels, all inside the
//! coverage, differ from the exact search). A search per pixel costs as
//! much as all the rest of the plots on ring-shaped scans.

use brtf_gonio::Hemisphere;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Radius of the projected hemisphere.
pub(crate) const RADIUS: f64 = std::f64::consts::SQRT_2;

/// Projects unit direction `v` about the normal of `hemisphere`.
pub fn project(v: DVec3, hemisphere: Hemisphere) -> (f64, f64) {
    let c = match hemisphere {
        Hemisphere::Front => v.z,
        Hemisphere::Back => -v.z,
    };
    // Not `hypot` (a libm call): the disk's radii are far from its
    // overflow and underflow.
    let s = (v.x * v.x + v.y * v.y).sqrt();
    let r = (2.0 * (1.0 - c)).max(0.0).sqrt();
    if s < 1e-12 {
        (0.0, 0.0)
    } else {
        (v.x * r / s, v.y * r / s)
    }
}

/// Projected radius of polar angle `theta_deg` from the normal.
pub fn radius_of(theta_deg: f64) -> f64 {
    2.0 * (0.5 * theta_deg.to_radians()).sin()
}

/// Points on the rim of the cone of half-angle `half_deg` about `axis`,
/// projected, split where the cone leaves the hemisphere.
pub(crate) fn cone_outline(
    axis: DVec3,
    half_deg: f64,
    hemisphere: Hemisphere,
) -> Vec<Vec<(f64, f64)>> {
    let axis = axis.normalize();
    let helper = if axis.z.abs() < 0.9 {
        DVec3::Z
    } else {
        DVec3::X
    };
    let e1 = axis.cross(helper).normalize();
    let e2 = axis.cross(e1);
    let (s, c) = half_deg.to_radians().sin_cos();
    let mut runs = Vec::new();
    let mut run = Vec::new();
    for k in 0..=180 {
        let a = k as f64 * std::f64::consts::TAU / 180.0;
        let v = axis * c + (e1 * a.cos() + e2 * a.sin()) * s;
        let inside = match hemisphere {
            Hemisphere::Front => v.z >= 0.0,
            Hemisphere::Back => v.z < 0.0,
        };
        if inside {
            run.push(project(v, hemisphere));
        } else if !run.is_empty() {
            runs.push(std::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

/// `floor` without the libm call (the build targets baseline x86-64,
/// where `f64::floor` is not one instruction).
fn floor(v: f64) -> isize {
    let t = v as isize;
    if (t as f64) > v { t - 1 } else { t }
}

/// The points bucketed by the pixels of a square grid over the projected
/// disk, for nearest-point queries. Bucket `(column, row)` is the pixel's
/// square, row 0 at the top (y = +RADIUS), as in [`Coverage`]; the points
/// are stored bucket by bucket, row-major, so a run of buckets of one row
/// is one contiguous slice.
struct Buckets {
    /// Buckets per side.
    size: usize,
    /// Side of a bucket, projected units.
    cell: f64,
    /// Bucket `c` holds `sorted[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    /// The original index of each stored point.
    items: Vec<u32>,
    /// The points in bucket order.
    sorted: Vec<(f64, f64)>,
}

impl Buckets {
    fn new(points: &[(f64, f64)], size: usize) -> Buckets {
        let size = size.max(1);
        let cell = 2.0 * RADIUS / size as f64;
        let last = size as isize - 1;
        // Points on or a rounding error beyond the square's edge go to the
        // edge buckets: the searches' distance bounds only shrink by that
        // error, which their slack covers.
        let bucket = |&(x, y): &(f64, f64)| {
            let column = (floor((x + RADIUS) / cell)).clamp(0, last) as usize;
            let row = (floor((RADIUS - y) / cell)).clamp(0, last) as usize;
            row * size + column
        };
        // A counting sort, the bucket of a point found twice rather than
        // kept (fewer fresh pages: on a 127k-point scan the page faults of
        // these vectors cost more than the arithmetic).
        let mut start = vec![0u32; size * size + 1];
        for p in points {
            start[bucket(p)] += 1;
        }
        // Then `start[c]` is the end of bucket c; the points are placed
        // from the last, each bucket filled from its end, which leaves
        // `start[c]` at the bucket's beginning and keeps every bucket in
        // index order.
        for i in 1..size * size {
            start[i] += start[i - 1];
        }
        start[size * size] = points.len() as u32;
        let mut items = vec![0u32; points.len()];
        let mut sorted = vec![(0.0, 0.0); points.len()];
        for (p, point) in points.iter().enumerate().rev() {
            let c = bucket(point);
            start[c] -= 1;
            let at = start[c] as usize;
            items[at] = p as u32;
            sorted[at] = *point;
        }
        Buckets {
            size,
            cell,
            start,
            items,
            sorted,
        }
    }

    /// Calls `visit(index, squared distance)` for every point within `r`
    /// of (x, y) (and a few just beyond, never one nearer that is left
    /// out), bucket row by bucket row over the square around the circle,
    /// until `visit` returns false.
    fn scan(&self, x: f64, y: f64, r: f64, mut visit: impl FnMut(u32, f64) -> bool) {
        // Position and radius in bucket units; a hair wider so that a
        // point at distance exactly `r` is not lost to rounding.
        let fx = (x + RADIUS) / self.cell;
        let fy = (RADIUS - y) / self.cell;
        let reach = r / self.cell * (1.0 + 1e-12) + 1e-9;
        let last = self.size as isize - 1;
        let (row0, row1) = (floor(fy - reach).max(0), floor(fy + reach).min(last));
        let (c0, c1) = (floor(fx - reach).max(0), floor(fx + reach).min(last));
        if c1 < c0 {
            return;
        }
        for row in row0..=row1 {
            let base = row as usize * self.size;
            let (a, b) = (
                self.start[base + c0 as usize] as usize,
                self.start[base + c1 as usize + 1] as usize,
            );
            for (&(px, py), &p) in self.sorted[a..b].iter().zip(&self.items[a..b]) {
                if !visit(p, (px - x) * (px - x) + (py - y) * (py - y)) {
                    return;
                }
            }
        }
    }

    /// Nearest point to (x, y) no farther than `r`, other than `skip`
    /// (ties: the lower index), with its squared distance.
    fn nearest_within(&self, x: f64, y: f64, r: f64, skip: Option<u32>) -> Option<(u32, f64)> {
        let r2 = r * r;
        let mut best: Option<(u32, f64)> = None;
        self.scan(x, y, r, |p, d2| {
            if d2 <= r2
                && Some(p) != skip
                && best.is_none_or(|(bp, b)| d2 < b || (d2 == b && p < bp))
            {
                best = Some((p, d2));
            }
            true
        });
        best
    }

    /// Offers the points at bucket positions `a..b` to `best`, the nearest
    /// to (x, y) so far (ties: the lower index). The outcome does not
    /// depend on the order of the offers.
    #[inline(always)]
    fn offer(&self, a: u32, b: u32, x: f64, y: f64, best: &mut Best) {
        for at in a..b {
            let (px, py) = self.sorted[at as usize];
            let d2 = (px - x) * (px - x) + (py - y) * (py - y);
            if d2 < best.d2 || (d2 == best.d2 && self.before(at, best.at)) {
                *best = Best { at, d2 };
            }
        }
    }

    /// Offers the points of buckets `c0..=c1` of bucket row `row` to `best`.
    #[inline(always)]
    fn offer_row(&self, row: usize, c0: usize, c1: usize, x: f64, y: f64, best: &mut Best) {
        let base = row * self.size;
        self.offer(self.start[base + c0], self.start[base + c1 + 1], x, y, best);
    }

    /// The point at bucket position `a` has the lower index than the one
    /// at `b` (any point comes before none, `b` = `u32::MAX`).
    fn before(&self, a: u32, b: u32) -> bool {
        self.items
            .get(b as usize)
            .is_none_or(|&item| self.items[a as usize] < item)
    }
}

/// The nearest point to a pixel's centre found so far: its position in
/// bucket order (`u32::MAX`: none yet) and squared distance.
#[derive(Debug, Clone, Copy)]
struct Best {
    at: u32,
    d2: f64,
}

impl Best {
    const NONE: Best = Best {
        at: u32::MAX,
        d2: f64::INFINITY,
    };
}

/// A pixel's nearest point so far while [`Coverage::new`] propagates
/// points over the grid. The point's coordinates are kept with it, in
/// single precision (enough to compare candidates; the owners are
/// measured again in double), so that neighbours offer theirs without a
/// look-up.
#[derive(Debug, Clone, Copy)]
struct Seed {
    /// Position of the point in bucket order (MAX: none yet).
    at: u32,
    /// Squared distance to the pixel's centre; negative when final (the
    /// exact nearest).
    d2: f32,
    /// The point's coordinates.
    x: f32,
    y: f32,
}

impl Seed {
    const NONE: Seed = Seed {
        at: u32::MAX,
        d2: f32::INFINITY,
        x: 0.0,
        y: 0.0,
    };
}

/// Pixel value of [`Coverage::owner`] for pixels no sample reaches.
pub(crate) const NONE: u32 = u32::MAX;

/// Side in pixels of the coverage grid of one hemisphere.
pub const COVERAGE_SIZE: u32 = 512;

/// Every sample covers the directions within this angle (degrees) that are
/// nearer to it than to any other sample; wider gaps stay uncovered.
pub const FILL_DEG: f64 = 4.0;

/// The disk as a grid of pixels, each owned by its nearest sample (see the
/// module docs). Pixel centres span [−RADIUS, RADIUS], row 0 at the top
/// (y = +RADIUS). Because the projection keeps areas, every pixel stands
/// for the same solid angle, [`Coverage::pixel_sr`].
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    /// Pixels per side.
    pub size: u32,
    /// Row-major owner of every pixel (an index given with the points), or [`NONE`].
    pub owner: Vec<u32>,
}

impl Coverage {
    /// Assigns every pixel of a `size × size` grid to its nearest point
    /// `ids[k]` at `points[k]`, if that point is within its reach: its
    /// distance to its own nearest neighbour, but at least `min_reach`
    /// (projected units) and one pixel. Points with a non-finite
    /// coordinate own no pixel.
    pub fn new(points: &[(f64, f64)], ids: &[u32], size: u32, min_reach: f64) -> Coverage {
        debug_assert_eq!(points.len(), ids.len());
        let mut owner = vec![NONE; (size * size) as usize];
        if points.is_empty() || size == 0 {
            return Coverage { size, owner };
        }
        let width = size as usize;
        let pixel = 2.0 * RADIUS / size as f64;
        let min_reach = min_reach.max(pixel);
        // Typical spacing: the mean area per point.
        let spacing = (std::f64::consts::PI * RADIUS * RADIUS / points.len() as f64).sqrt();
        // The points bucketed by the pixels themselves: dense scans put a
        // few points in a bucket, and a pixel's search in a sparse region
        // costs a couple of loads per row of buckets, not per bucket.
        let buckets = Buckets::new(points, width);
        // Isolated samples reach at most a few typical spacings, which also
        // bounds the search of pixels in gaps.
        let far = (4.0 * spacing).max(min_reach);
        // A sample's own nearest-neighbour distance is only needed when a
        // pixel lies beyond the minimum reach: found then, and remembered.
        // Never when the minimum reach is as far as any pixel looks (dense
        // scans): then no slots either.
        let reach: Vec<OnceLock<f64>> = if far > min_reach {
            (0..points.len()).map(|_| OnceLock::new()).collect()
        } else {
            Vec::new()
        };
        let reach_of = |k: u32| {
            *reach[k as usize].get_or_init(|| {
                let (x, y) = points[k as usize];
                buckets
                    .nearest_within(x, y, far, Some(k))
                    .map_or(far, |(_, d2)| d2.sqrt())
                    .max(min_reach)
            })
        };
        let rim2 = RADIUS * RADIUS;
        let centre = |i: usize, j: usize| {
            (
                -RADIUS + (i as f64 + 0.5) * pixel,
                RADIUS - (j as f64 + 0.5) * pixel,
            )
        };
        // The pixels of each row whose centres lie on the disk.
        let spans: Vec<(usize, usize)> = (0..width)
            .map(|j| {
                let (_, y) = centre(0, j);
                let half = (rim2 - y * y).max(0.0).sqrt();
                let lo = ((RADIUS - half) / pixel - 0.5).max(0.0) as usize;
                let mut lo = lo.saturating_sub(1);
                while lo < width && {
                    let (x, _) = centre(lo, j);
                    x * x + y * y > rim2
                } {
                    lo += 1;
                }
                // Symmetric about the centre column.
                (lo, width - lo)
            })
            .collect();
        // Each pixel's nearest point so far ([`Seed`]). First the exact
        // nearest among the points of the 3 × 3 pixels around it: final
        // when nearer than 1.5 pixels (every other point is farther), which
        // is every pixel of a dense region.
        let exact2 = (1.5 * pixel * (1.0 - 1e-9)).powi(2);
        // Every point of another bucket is at least half a pixel from the
        // pixel's centre, less rounding (the margin).
        let half2 = (0.5 * pixel * (1.0 - 1e-9)).powi(2);
        let mut nearest = vec![Seed::NONE; width * width];
        nearest
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(j, row)| {
                let (lo, hi) = spans[j];
                let base = j * width;
                for (i, slot) in row.iter_mut().enumerate().take(hi).skip(lo) {
                    let (x, y) = centre(i, j);
                    // The pixel's own bucket first: a point nearer than
                    // half a pixel beats every point of the 8 around.
                    let mut best = Best::NONE;
                    let own = base + i;
                    buckets.offer(buckets.start[own], buckets.start[own + 1], x, y, &mut best);
                    if best.d2 >= half2 {
                        if i > 0 {
                            buckets.offer(
                                buckets.start[own - 1],
                                buckets.start[own],
                                x,
                                y,
                                &mut best,
                            );
                        }
                        if i + 1 < width {
                            buckets.offer(
                                buckets.start[own + 1],
                                buckets.start[own + 2],
                                x,
                                y,
                                &mut best,
                            );
                        }
                        let (c0, c1) = (i.saturating_sub(1), (i + 1).min(width - 1));
                        if j > 0 {
                            buckets.offer_row(j - 1, c0, c1, x, y, &mut best);
                        }
                        if j + 1 < width {
                            buckets.offer_row(j + 1, c0, c1, x, y, &mut best);
                        }
                    }
                    if best.at != u32::MAX {
                        let (px, py) = buckets.sorted[best.at as usize];
                        *slot = Seed {
                            at: best.at,
                            d2: if best.d2 <= exact2 {
                                -1.0
                            } else {
                                best.d2 as f32
                            },
                            x: px as f32,
                            y: py as f32,
                        };
                    }
                }
            });
        // Then the pixels in gaps take the nearest of their neighbours'
        // points, propagated in two sweeps (down the rows, then up, each
        // row both ways): an approximate nearest-point transform. Its
        // point is the true nearest at nearly every pixel, and else one
        // a hair farther (see the module docs).
        let offer = |slot: &mut Seed, candidate: Seed, x: f32, y: f32| {
            if candidate.at == u32::MAX || candidate.at == slot.at {
                return;
            }
            let d2 = (candidate.x - x) * (candidate.x - x) + (candidate.y - y) * (candidate.y - y);
            if d2 < slot.d2
                || (d2 == slot.d2 && (slot.at == u32::MAX || buckets.before(candidate.at, slot.at)))
            {
                *slot = Seed { d2, ..candidate };
            }
        };
        // One row `j` of a sweep: from the row before it in the sweep
        // (`other`, above or below, if any), then along the row in both
        // directions. Final pixels (negative distance) are only sources.
        let sweep_row = |row: &mut [Seed], other: Option<&[Seed]>, j: usize| {
            let (lo, hi) = spans[j];
            let y = (RADIUS - (j as f64 + 0.5) * pixel) as f32;
            let x_of = |i: usize| (-RADIUS + (i as f64 + 0.5) * pixel) as f32;
            for i in lo..hi {
                if row[i].d2 < 0.0 {
                    continue;
                }
                let x = x_of(i);
                if i > lo {
                    let left = row[i - 1];
                    offer(&mut row[i], left, x, y);
                }
                if let Some(other) = other {
                    if i > 0 {
                        offer(&mut row[i], other[i - 1], x, y);
                    }
                    offer(&mut row[i], other[i], x, y);
                    if i + 1 < width {
                        offer(&mut row[i], other[i + 1], x, y);
                    }
                }
            }
            for i in (lo..hi.saturating_sub(1)).rev() {
                if row[i].d2 >= 0.0 {
                    let right = row[i + 1];
                    offer(&mut row[i], right, x_of(i), y);
                }
            }
        };
        // A sweep over the rows of `part` (whose first row is row `first`
        // of the grid), down or up, the first row from `edge` (the row
        // next to it in the sweep, outside `part`), if any.
        let sweep = |part: &mut [Seed], first: usize, down: bool, edge: Option<&[Seed]>| {
            let rows = part.len() / width;
            for step in 0..rows {
                let r = if down { step } else { rows - 1 - step };
                if step == 0 {
                    sweep_row(&mut part[r * width..(r + 1) * width], edge, first + r);
                } else if down {
                    let (before, rest) = part.split_at_mut(r * width);
                    sweep_row(
                        &mut rest[..width],
                        Some(&before[(r - 1) * width..]),
                        first + r,
                    );
                } else {
                    let (rest, after) = part.split_at_mut((r + 1) * width);
                    sweep_row(&mut rest[r * width..], Some(&after[..width]), first + r);
                }
            }
        };
        // The two halves of the rows at the same time: first the upper
        // half down and the lower half up, then each the other way from a
        // copy of the other half's row next to it. Every pixel is reached
        // from every direction, as by one sweep down and one up.
        let half = width / 2;
        let (top, bottom) = nearest.split_at_mut(half * width);
        rayon::join(
            || sweep(top, 0, true, None),
            || sweep(bottom, half, false, None),
        );
        let top_edge = (half > 0).then(|| top[(half - 1) * width..].to_vec());
        let bottom_edge = (bottom.len() >= width).then(|| bottom[..width].to_vec());
        rayon::join(
            || sweep(top, 0, false, bottom_edge.as_deref()),
            || sweep(bottom, half, true, top_edge.as_deref()),
        );
        // Owners: the nearest point when within its reach. A propagated
        // point is first refined among the points around it (the true
        // nearest of a pixel in a gap is nearly always one of them).
        let last = width as isize - 1;
        owner
            .par_chunks_mut(width)
            .zip(nearest.par_chunks(width))
            .enumerate()
            .for_each(|(j, (row, found))| {
                let (lo, hi) = spans[j];
                for (i, (cell, seed)) in row.iter_mut().zip(found).enumerate() {
                    if seed.at == u32::MAX || i < lo || i >= hi {
                        continue;
                    }
                    let (x, y) = centre(i, j);
                    let (px, py) = buckets.sorted[seed.at as usize];
                    let mut best = Best {
                        at: seed.at,
                        d2: (px - x) * (px - x) + (py - y) * (py - y),
                    };
                    if seed.d2 >= 0.0 {
                        // The seed's own bucket is among these: starting
                        // from the seed, a point must beat it.
                        let bi = floor((px + RADIUS) / pixel).clamp(0, last) as usize;
                        let bj = floor((RADIUS - py) / pixel).clamp(0, last) as usize;
                        let (c0, c1) = (bi.saturating_sub(1), (bi + 1).min(width - 1));
                        for r in bj.saturating_sub(1)..=(bj + 1).min(width - 1) {
                            buckets.offer_row(r, c0, c1, x, y, &mut best);
                        }
                    }
                    let k = buckets.items[best.at as usize];
                    let d = best.d2.sqrt();
                    if d <= far && (d <= min_reach || d <= reach_of(k)) {
                        *cell = ids[k as usize];
                    }
                }
            });
        Coverage { size, owner }
    }

    /// Solid angle of one pixel, sr.
    pub fn pixel_sr(&self) -> f64 {
        let p = 2.0 * RADIUS / self.size as f64;
        p * p
    }

    /// |cos| of the angle from the normal at the centre of pixel (i, j).
    pub fn cosine_at(&self, i: u32, j: u32) -> f64 {
        let p = 2.0 * RADIUS / self.size as f64;
        let x = -RADIUS + (i as f64 + 0.5) * p;
        let y = RADIUS - (j as f64 + 0.5) * p;
        (1.0 - 0.5 * (x * x + y * y)).max(0.0)
    }

    /// The owners resampled (nearest pixel) to an `out × out` grid.
    pub fn resampled(&self, out: u32) -> Vec<u32> {
        if out == self.size {
            return self.owner.clone();
        }
        let mut v = Vec::with_capacity((out * out) as usize);
        for j in 0..out {
            let sj = ((j as u64 * self.size as u64 + self.size as u64 / 2) / out as u64)
                .min(self.size as u64 - 1) as u32;
            for i in 0..out {
                let si = ((i as u64 * self.size as u64 + self.size as u64 / 2) / out as u64)
                    .min(self.size as u64 - 1) as u32;
                v.push(self.owner[(sj * self.size + si) as usize]);
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_keeps_the_rim_and_the_azimuth() {
        let (x, y) = project(DVec3::new(1.0, 0.0, 0.0), Hemisphere::Front);
        assert!((x - RADIUS).abs() < 1e-12 && y.abs() < 1e-12);
        let (x, y) = project(DVec3::new(0.0, 0.0, 1.0), Hemisphere::Front);
        assert_eq!((x, y), (0.0, 0.0));
        let v = brtf_model::direction(60.0, 90.0);
        let (x, y) = project(v, Hemisphere::Front);
        assert!(x.abs() < 1e-12 && (y - radius_of(60.0)).abs() < 1e-12);
        let (x, _) = project(brtf_model::direction(150.0, 0.0), Hemisphere::Back);
        assert!((x - radius_of(30.0)).abs() < 1e-12);
    }

    #[test]
    fn raster_fills_near_points_and_leaves_gaps() {
        // A regular grid of points on the left half only.
        let mut pts = Vec::new();
        for i in 0..40 {
            for j in 0..80 {
                let x = -RADIUS + (i as f64 + 0.5) * RADIUS / 40.0;
                let y = -RADIUS + (j as f64 + 0.5) * 2.0 * RADIUS / 80.0;
                if x * x + y * y < RADIUS * RADIUS {
                    pts.push((x, y));
                }
            }
        }
        let size = 100;
        let ids: Vec<u32> = (0..pts.len() as u32).collect();
        let c = Coverage::new(&pts, &ids, size, 0.0);
        let owner = |i: u32, j: u32| c.owner[(j * size + i) as usize];
        assert_ne!(owner(25, 50), NONE, "left half is covered");
        assert_eq!(owner(80, 50), NONE, "right half is a gap");
        assert_eq!(owner(0, 0), NONE, "corner is outside the disk");
        // Equal areas: the covered pixels add up to the covered solid angle.
        let covered = c.owner.iter().filter(|o| **o != NONE).count() as f64 * c.pixel_sr();
        assert!((covered - std::f64::consts::PI).abs() < 0.08, "{covered}");
        // Resampling keeps the layout.
        let r = c.resampled(50);
        assert_ne!(r[(25 * 50 + 12) as usize], NONE);
        assert_eq!(r[(25 * 50 + 40) as usize], NONE);
    }

    #[test]
    fn coverage_matches_brute_force() {
        // Scattered points with a dense cluster, a gap and repeated points.
        let mut state = 7u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pts = Vec::new();
        while pts.len() < 1500 {
            let (x, y) = (
                RADIUS * (2.0 * uniform() - 1.0),
                RADIUS * (2.0 * uniform() - 1.0),
            );
            let dense = pts.len() % 3 == 0;
            let (x, y) = if dense {
                (0.3 + 0.1 * x, -0.2 + 0.1 * y)
            } else {
                (x, y)
            };
            if x * x + y * y < RADIUS * RADIUS && !(x > 0.6 && y > 0.2) {
                pts.push((x, y));
            }
        }
        pts.extend_from_within(..20);
        let ids: Vec<u32> = (0..pts.len() as u32).map(|k| k * 2 + 1).collect();
        let (size, min_reach) = (96, radius_of(2.0));
        let c = Coverage::new(&pts, &ids, size, min_reach);
        let pixel = 2.0 * RADIUS / size as f64;
        let spacing = (std::f64::consts::PI * RADIUS * RADIUS / pts.len() as f64).sqrt();
        let far = (4.0 * spacing).max(min_reach.max(pixel));
        let dist = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1);
        let reach: Vec<f64> = (0..pts.len())
            .map(|k| {
                let d = (0..pts.len())
                    .filter(|&m| m != k)
                    .map(|m| dist(pts[k], pts[m]))
                    .fold(f64::INFINITY, f64::min);
                d.min(far).max(min_reach.max(pixel))
            })
            .collect();
        // The raster's point is the nearest, or one at most a quarter of
        // a pixel farther (in gaps, where the nearest is propagated);
        // nearly every pixel matches exactly.
        let (mut covered, mut differ) = (0, 0);
        let index_of = |id: u32| ids.iter().position(|&i| i == id).unwrap();
        for j in 0..size {
            for i in 0..size {
                let q = (
                    -RADIUS + (i as f64 + 0.5) * pixel,
                    RADIUS - (j as f64 + 0.5) * pixel,
                );
                let mut expected = NONE;
                let mut nearest = f64::NAN;
                if q.0 * q.0 + q.1 * q.1 <= RADIUS * RADIUS {
                    // The nearest point, the lower index on ties.
                    let (k, d) = (0..pts.len())
                        .map(|k| (k, dist(q, pts[k])))
                        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
                        .unwrap();
                    nearest = d;
                    if d <= far && (d <= min_reach.max(pixel) || d <= reach[k]) {
                        expected = ids[k];
                        covered += 1;
                    }
                }
                let got = c.owner[(j * size + i) as usize];
                if got == expected {
                    continue;
                }
                differ += 1;
                // A different point: barely farther, and covered alike.
                assert!(got != NONE && expected != NONE, "pixel ({i}, {j})");
                let d = dist(q, pts[index_of(got)]);
                assert!(
                    d - nearest <= 0.25 * pixel,
                    "pixel ({i}, {j}): {d} vs {nearest}"
                );
            }
        }
        assert!(covered > 1000, "{covered}");
        assert!(
            differ * 200 <= covered,
            "{differ} of {covered} pixels differ"
        );
    }

    #[test]
    fn pixels_near_a_point_get_the_exact_nearest() {
        // Points on the pixels' edges and corners (where a pixel's own
        // bucket and its neighbours' meet), at their centres, repeated,
        // and pairs at equal distances from a pixel centre: wherever a
        // point lies within 1.5 pixels, the owner is the nearest point,
        // the lower index on ties (ids here rise with the index).
        let size = 64u32;
        let pixel = 2.0 * RADIUS / size as f64;
        let edge = |k: i32| -RADIUS + k as f64 * pixel;
        let centre = |k: i32| -RADIUS + (k as f64 + 0.5) * pixel;
        let mut pts = Vec::new();
        for k in 0..800 {
            let (i, j) = (k % 50 + 7, (k / 50 * 7 + k * 3) % 50 + 7);
            let p = match k % 5 {
                0 => (edge(i), centre(j)),
                1 => (centre(i), edge(j)),
                2 => (edge(i), edge(j)),
                3 => (centre(i) + 0.3 * pixel, centre(j) - 0.45 * pixel),
                // Mirror images about a pixel centre: a tie.
                _ => (centre(i) - 0.7 * pixel, centre(j)),
            };
            pts.push(p);
            if k % 5 == 4 {
                pts.push((centre(i) + 0.7 * pixel, centre(j)));
            }
        }
        pts.extend_from_within(..30);
        let ids: Vec<u32> = (0..pts.len() as u32).map(|k| 5 + 2 * k).collect();
        // Every pixel within 1.5 pixels of a point is covered.
        let c = Coverage::new(&pts, &ids, size, 1.6 * pixel);
        let mut checked = 0;
        for j in 0..size as i32 {
            for i in 0..size as i32 {
                let (x, y) = (centre(i), -centre(j));
                if x * x + y * y > RADIUS * RADIUS {
                    continue;
                }
                let (k, d2) = pts
                    .iter()
                    .map(|&(px, py)| (px - x) * (px - x) + (py - y) * (py - y))
                    .enumerate()
                    .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
                    .unwrap();
                if d2 < (1.49 * pixel).powi(2) {
                    let got = c.owner[(j as u32 * size + i as u32) as usize];
                    assert_eq!(got, ids[k], "pixel ({i}, {j})");
                    checked += 1;
                }
            }
        }
        assert!(checked > 1000, "{checked}");
    }

    #[test]
    fn nearest_matches_brute_force() {
        let pts: Vec<(f64, f64)> = (0..500)
            .map(|k| {
                let a = k as f64 * 2.399963;
                let r = RADIUS * ((k as f64 + 0.5) / 500.0).sqrt();
                (r * a.cos(), r * a.sin())
            })
            .collect();
        let buckets = Buckets::new(&pts, 57);
        for q in 0..200 {
            let (x, y) = (
                -1.3 + 2.6 * ((q * 37) % 200) as f64 / 200.0,
                -1.3 + 2.6 * q as f64 / 200.0,
            );
            let brute = pts
                .iter()
                .map(|&(px, py)| ((px - x).powi(2) + (py - y).powi(2)).sqrt())
                .fold(f64::INFINITY, f64::min);
            let (_, d2) = buckets.nearest_within(x, y, 10.0, None).unwrap();
            let d = d2.sqrt();
            // Within a radius just above the nearest distance, the same.
            let (_, again) = buckets
                .nearest_within(x, y, brute * (1.0 + 1e-9), None)
                .unwrap();
            assert_eq!(again, d2, "{q}");
            // Not found within a radius just below it.
            assert!(
                buckets
                    .nearest_within(x, y, brute * (1.0 - 1e-9), None)
                    .is_none(),
                "{q}"
            );
            assert!((d - brute).abs() < 1e-12, "{q}: {d} vs {brute}");
        }
    }
}
