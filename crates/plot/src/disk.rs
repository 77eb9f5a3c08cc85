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

use brtf_gonio::Hemisphere;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Radius of the projected hemisphere.
pub const RADIUS: f64 = std::f64::consts::SQRT_2;

/// Projects unit direction `v` about the normal of `hemisphere`.
pub fn project(v: DVec3, hemisphere: Hemisphere) -> (f64, f64) {
    let c = match hemisphere {
        Hemisphere::Front => v.z,
        Hemisphere::Back => -v.z,
    };
    let s = v.x.hypot(v.y);
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
pub fn cone_outline(axis: DVec3, half_deg: f64, hemisphere: Hemisphere) -> Vec<Vec<(f64, f64)>> {
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

/// A uniform bucket grid over the projected disk for nearest-point queries.
/// The points are stored cell by cell, row-major, so the cells of one grid
/// row are one contiguous run.
struct Grid {
    cell: f64,
    n: usize,
    /// Cell `c` holds `sorted[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    /// The original index of each stored point.
    items: Vec<u32>,
    /// The points in cell order.
    sorted: Vec<(f64, f64)>,
    /// Summed-area table of the cell counts, `(n + 1)²`: how many points a
    /// block of cells holds, so empty blocks (gaps in the scan) cost
    /// nothing to search.
    summed: Vec<u32>,
}

impl Grid {
    fn new(points: Vec<(f64, f64)>, cell: f64) -> Grid {
        let n = ((2.0 * RADIUS / cell).ceil() as usize).clamp(1, 2048);
        let cell = 2.0 * RADIUS / n as f64;
        let mut counts = vec![0u32; n * n + 1];
        let index: Vec<usize> = points
            .iter()
            .map(|&(x, y)| Self::cell_of(x, y, cell, n))
            .collect();
        for &i in &index {
            counts[i + 1] += 1;
        }
        for i in 0..n * n {
            counts[i + 1] += counts[i];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; points.len()];
        let mut sorted = vec![(0.0, 0.0); points.len()];
        for (p, &i) in index.iter().enumerate() {
            items[fill[i] as usize] = p as u32;
            sorted[fill[i] as usize] = points[p];
            fill[i] += 1;
        }
        let mut summed = vec![0u32; (n + 1) * (n + 1)];
        for iy in 0..n {
            let mut row = 0;
            for ix in 0..n {
                let c = iy * n + ix;
                row += counts[c + 1] - counts[c];
                summed[(iy + 1) * (n + 1) + ix + 1] = summed[iy * (n + 1) + ix + 1] + row;
            }
        }
        Grid {
            cell,
            n,
            start: counts,
            items,
            sorted,
            summed,
        }
    }

    /// Points in the cells `x0..=x1` × `y0..=y1`.
    fn count(&self, (x0, x1): (usize, usize), (y0, y1): (usize, usize)) -> u32 {
        let w = self.n + 1;
        let at = |x: usize, y: usize| self.summed[y * w + x];
        at(x1 + 1, y1 + 1) + at(x0, y0) - at(x0, y1 + 1) - at(x1 + 1, y0)
    }

    /// Nearest point to (x, y) no farther than `r` (ties: the lower index),
    /// found among the cells that meet the square of half-side `r`. When
    /// `occupied`, the caller knows a point within `r` (so the test for an
    /// empty square is skipped).
    fn nearest_within(&self, x: f64, y: f64, r: f64, occupied: bool) -> Option<(usize, f64)> {
        let n = self.n as isize;
        // Truncation, not `floor` (a libm call here): they differ only
        // below 0, which is clamped to 0 either way.
        let cell_index = |v: f64| (((v + RADIUS) / self.cell) as isize).clamp(0, n - 1) as usize;
        let (x0, x1) = (cell_index(x - r), cell_index(x + r));
        let (y0, y1) = (cell_index(y - r), cell_index(y + r));
        if !occupied && self.count((x0, x1), (y0, y1)) == 0 {
            return None;
        }
        let r2 = r * r;
        let mut best: Option<(u32, f64)> = None;
        for iy in y0..=y1 {
            let row = iy * self.n;
            let (a, b) = (
                self.start[row + x0] as usize,
                self.start[row + x1 + 1] as usize,
            );
            for (&(px, py), &p) in self.sorted[a..b].iter().zip(&self.items[a..b]) {
                let d2 = (px - x) * (px - x) + (py - y) * (py - y);
                if d2 <= r2 && best.is_none_or(|(bp, b)| d2 < b || (d2 == b && p < bp)) {
                    best = Some((p, d2));
                }
            }
        }
        best.map(|(p, d2)| (p as usize, d2.sqrt()))
    }

    fn cell_of(x: f64, y: f64, cell: f64, n: usize) -> usize {
        let ix = (((x + RADIUS) / cell) as isize).clamp(0, n as isize - 1) as usize;
        let iy = (((y + RADIUS) / cell) as isize).clamp(0, n as isize - 1) as usize;
        iy * n + ix
    }

    /// Nearest point to (x, y) other than `skip`, within `max_dist`.
    fn nearest(&self, x: f64, y: f64, max_dist: f64, skip: Option<usize>) -> Option<(usize, f64)> {
        let n = self.n as isize;
        let (gx, gy) = ((x + RADIUS) / self.cell, (y + RADIUS) / self.cell);
        let cx = (gx as isize).clamp(0, n - 1);
        let cy = (gy as isize).clamp(0, n - 1);
        let mut best: Option<(usize, f64)> = None;
        let max_ring = (max_dist / self.cell).ceil() as isize + 1;
        for ring in 0..=max_ring.min(n) {
            let mut visit = |ix: isize, iy: isize| {
                if ix < 0 || iy < 0 || ix >= n || iy >= n {
                    return;
                }
                let c = (iy * n + ix) as usize;
                let (a, b) = (self.start[c] as usize, self.start[c + 1] as usize);
                for (&(px, py), &p) in self.sorted[a..b].iter().zip(&self.items[a..b]) {
                    let p = p as usize;
                    if Some(p) == skip {
                        continue;
                    }
                    let d2 = (px - x) * (px - x) + (py - y) * (py - y);
                    if best.is_none_or(|(bp, b)| d2 < b || (d2 == b && p < bp)) {
                        best = Some((p, d2));
                    }
                }
            };
            if ring == 0 {
                visit(cx, cy);
            } else {
                for ix in cx - ring..=cx + ring {
                    visit(ix, cy - ring);
                    visit(ix, cy + ring);
                }
                for iy in cy - ring + 1..cy + ring {
                    visit(cx - ring, iy);
                    visit(cx + ring, iy);
                }
            }
            // Every point not yet seen lies outside the block of cells
            // visited so far (sides at the grid's edge hold nothing more).
            let side = |inner: f64, edge: bool| if edge { f64::INFINITY } else { inner };
            let margin = side(gx - (cx - ring) as f64, cx - ring <= 0)
                .min(side((cx + ring + 1) as f64 - gx, cx + ring >= n - 1))
                .min(side(gy - (cy - ring) as f64, cy - ring <= 0))
                .min(side((cy + ring + 1) as f64 - gy, cy + ring >= n - 1));
            if let Some((_, b)) = best
                && b.sqrt() <= margin * self.cell
            {
                break;
            }
        }
        best.map(|(p, d2)| (p, d2.sqrt()))
            .filter(|&(_, d)| d <= max_dist)
    }
}

/// Pixel value of [`Coverage::owner`] for pixels no sample reaches.
pub const NONE: u32 = u32::MAX;

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
    /// (projected units) and one pixel.
    pub fn new(points: &[(f64, f64)], ids: &[u32], size: u32, min_reach: f64) -> Coverage {
        debug_assert_eq!(points.len(), ids.len());
        let mut owner = vec![NONE; (size * size) as usize];
        if points.is_empty() || size == 0 {
            return Coverage { size, owner };
        }
        let pixel = 2.0 * RADIUS / size as f64;
        let min_reach = min_reach.max(pixel);
        // Typical spacing: the mean area per point.
        let spacing = (std::f64::consts::PI * RADIUS * RADIUS / points.len() as f64).sqrt();
        // About one point per cell: the searches below look at few points.
        let grid = Grid::new(points.to_vec(), spacing);
        // Isolated samples reach at most a few typical spacings, which also
        // bounds the search of pixels in gaps.
        let far = (4.0 * spacing).max(min_reach);
        // A sample's own nearest-neighbour distance is only needed when a
        // pixel lies beyond the minimum reach: found then, and remembered.
        let reach: Vec<OnceLock<f64>> = (0..points.len()).map(|_| OnceLock::new()).collect();
        let reach_of = |k: usize| {
            *reach[k].get_or_init(|| {
                grid.nearest(points[k].0, points[k].1, far, Some(k))
                    .map_or(far, |(_, d)| d)
                    .max(min_reach)
            })
        };
        let rim2 = RADIUS * RADIUS;
        // Bands of rows, each row bounded by the one above it.
        const BAND: usize = 16;
        let width = size as usize;
        owner
            .par_chunks_mut(width * BAND)
            .enumerate()
            .for_each(|(band, rows)| {
                // Any point's distance bounds a pixel's nearest distance, so
                // only the cells within that bound are searched (the exact
                // nearest all the same). The nearest points of the pixel to
                // the left and of the two above are close to this pixel's,
                // and the nearest of them gives the bound.
                let bound_by = |k: u32, x: f64, y: f64| -> f64 {
                    if k == u32::MAX {
                        return far;
                    }
                    let (px, py) = points[k as usize];
                    let d = ((px - x) * (px - x) + (py - y) * (py - y)).sqrt();
                    // A hair wider, so that point itself is found again.
                    (d * (1.0 + 1e-9) + 1e-12).min(far)
                };
                // The nearest point of each pixel of the row above (MAX: none).
                let mut above = vec![u32::MAX; width + 1];
                for (r, row) in rows.chunks_mut(width).enumerate() {
                    let j = band * BAND + r;
                    let y = RADIUS - (j as f64 + 0.5) * pixel;
                    let mut previous = u32::MAX;
                    for (i, cell) in row.iter_mut().enumerate() {
                        let x = -RADIUS + (i as f64 + 0.5) * pixel;
                        if x * x + y * y > rim2 {
                            continue;
                        }
                        let bound = bound_by(previous, x, y)
                            .min(bound_by(above[i], x, y))
                            .min(bound_by(above[i + 1], x, y));
                        // Below `far`, the bound is a point's distance.
                        let nearest = grid.nearest_within(x, y, bound, bound < far);
                        previous = nearest.map_or(u32::MAX, |(k, _)| k as u32);
                        above[i] = previous;
                        if let Some((k, d)) = nearest.filter(|&(_, d)| d <= far)
                            && (d <= min_reach || d <= reach_of(k))
                        {
                            *cell = ids[k];
                        }
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
        let mut covered = 0;
        for j in 0..size {
            for i in 0..size {
                let q = (
                    -RADIUS + (i as f64 + 0.5) * pixel,
                    RADIUS - (j as f64 + 0.5) * pixel,
                );
                let mut expected = NONE;
                if q.0 * q.0 + q.1 * q.1 <= RADIUS * RADIUS {
                    // The nearest point, the lower index on ties.
                    let (k, d) = (0..pts.len())
                        .map(|k| (k, dist(q, pts[k])))
                        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
                        .unwrap();
                    if d <= far && (d <= min_reach.max(pixel) || d <= reach[k]) {
                        expected = ids[k];
                        covered += 1;
                    }
                }
                assert_eq!(
                    c.owner[(j * size + i) as usize],
                    expected,
                    "pixel ({i}, {j})"
                );
            }
        }
        assert!(covered > 1000, "{covered}");
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
        let grid = Grid::new(pts.clone(), 0.05);
        for q in 0..200 {
            let (x, y) = (
                -1.3 + 2.6 * ((q * 37) % 200) as f64 / 200.0,
                -1.3 + 2.6 * q as f64 / 200.0,
            );
            let brute = pts
                .iter()
                .map(|&(px, py)| ((px - x).powi(2) + (py - y).powi(2)).sqrt())
                .fold(f64::INFINITY, f64::min);
            let (_, d) = grid.nearest(x, y, 10.0, None).unwrap();
            assert!((d - brute).abs() < 1e-12, "{q}: {d} vs {brute}");
        }
    }
}
