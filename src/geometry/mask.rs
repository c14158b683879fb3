//! A polygon rasterised and grown by a distance: constant-time "is this
//! point within `reach` of the polygon?" for the many points of a scan.

use crate::raster::dilate_disk;
use glam::DVec2;

/// Most cells of a mask; larger extents use coarser cells.
const MAX_CELLS: usize = 2_000_000;

/// Where a point is relative to a polygon grown by `reach`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Zone {
    /// In a cell the polygon covers.
    Inside,
    /// Outside the polygon but within `reach` of it.
    Ring,
    /// Farther than `reach`.
    Outside,
}

/// A polygon's cells and those within `reach` of it (its Minkowski sum with
/// a disk, on a grid: exact up to one cell diagonal).
#[derive(Clone, Debug, Default)]
pub struct GrownMask {
    origin: DVec2,
    cell: f64,
    w: usize,
    h: usize,
    zone: Vec<u8>,
}

impl GrownMask {
    /// Rasterise `ring` at `cell` metres (coarsened to fit the cell budget)
    /// and grow it by `reach` metres.
    pub fn new(ring: &[DVec2], reach: f64, cell: f64) -> Self {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for &p in ring {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if ring.len() < 3 || !lo.is_finite() || !hi.is_finite() {
            return GrownMask {
                origin: DVec2::ZERO,
                cell: 1.0,
                w: 0,
                h: 0,
                zone: Vec::new(),
            };
        }
        let reach = reach.max(0.0);
        let mut cell = cell.max(1e-3);
        let size = hi - lo + DVec2::splat(2.0 * reach);
        while (size.x / cell + 3.0) * (size.y / cell + 3.0) > MAX_CELLS as f64 {
            cell *= 2.0;
        }
        let margin = (reach / cell).ceil() as usize + 1;
        let w = ((hi.x - lo.x) / cell).ceil() as usize + 1 + 2 * margin;
        let h = ((hi.y - lo.y) / cell).ceil() as usize + 1 + 2 * margin;
        let origin = lo - DVec2::splat(margin as f64 * cell);
        let mut grid = vec![false; w * h];
        // Scanline fill at cell centres (even-odd).
        let n = ring.len();
        let mut xs: Vec<f64> = Vec::new();
        for row in 0..h {
            let y = origin.y + (row as f64 + 0.5) * cell;
            xs.clear();
            for i in 0..n {
                let (a, b) = (ring[i], ring[(i + 1) % n]);
                if (a.y > y) != (b.y > y) {
                    xs.push(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
                }
            }
            super::numeric::insertion_sort_by(&mut xs, f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                let c0 = ((pair[0] - origin.x) / cell - 0.5).ceil().max(0.0) as usize;
                let c1 = ((pair[1] - origin.x) / cell - 0.5).floor();
                if c1 < 0.0 {
                    continue;
                }
                let c1 = (c1 as usize).min(w - 1);
                for c in c0..=c1 {
                    grid[row * w + c] = true;
                }
            }
        }
        // Boundary cells too (thin polygons may have no cell centre inside).
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            let steps = ((b - a).length() / (0.5 * cell)).ceil().max(1.0) as usize;
            for s in 0..=steps {
                let p = a + (b - a) * (s as f64 / steps as f64);
                let (cx, cy) = (
                    ((p.x - origin.x) / cell) as usize,
                    ((p.y - origin.y) / cell) as usize,
                );
                if cx < w && cy < h {
                    grid[cy * w + cx] = true;
                }
            }
        }
        let r = reach / cell;
        let zone = if r > 0.0 {
            // Distances are between cell centres; allow half a diagonal.
            let grown = dilate_disk(&grid, w, h, r + std::f64::consts::FRAC_1_SQRT_2);
            grid.iter()
                .zip(grown)
                .map(|(&g, d)| {
                    if g {
                        0
                    } else if d {
                        1
                    } else {
                        2
                    }
                })
                .collect()
        } else {
            grid.into_iter().map(|g| if g { 0 } else { 2 }).collect()
        };
        GrownMask {
            origin,
            cell,
            w,
            h,
            zone,
        }
    }

    /// The zone of `p` (to the mask's resolution).
    #[inline]
    pub fn zone(&self, p: DVec2) -> Zone {
        let x = (p.x - self.origin.x) / self.cell;
        let y = (p.y - self.origin.y) / self.cell;
        if x >= 0.0 && y >= 0.0 && (x as usize) < self.w && (y as usize) < self.h {
            match self.zone[y as usize * self.w + x as usize] {
                0 => Zone::Inside,
                1 => Zone::Ring,
                _ => Zone::Outside,
            }
        } else {
            Zone::Outside
        }
    }

    /// Is `p` within reach of the polygon (to the mask's resolution)?
    #[inline]
    pub fn contains(&self, p: DVec2) -> bool {
        self.zone(p) != Zone::Outside
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grown_square_contains_what_is_within_reach() {
        let sq = [
            DVec2::ZERO,
            DVec2::new(4.0, 0.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(0.0, 4.0),
        ];
        let m = GrownMask::new(&sq, 1.0, 0.1);
        assert!(m.contains(DVec2::new(2.0, 2.0)));
        assert!(m.contains(DVec2::new(-0.8, 2.0)));
        assert!(m.contains(DVec2::new(4.85, 4.0)));
        assert!(!m.contains(DVec2::new(-1.4, 2.0)));
        assert!(!m.contains(DVec2::new(5.0, 5.0)), "corner is rounded");
        assert!(!m.contains(DVec2::new(100.0, 2.0)));
        let sliver = [DVec2::ZERO, DVec2::new(10.0, 0.0), DVec2::new(10.0, 0.01)];
        assert!(GrownMask::new(&sliver, 0.0, 0.5).contains(DVec2::new(5.0, 0.0)));
        assert!(!GrownMask::new(&[], 1.0, 0.1).contains(DVec2::ZERO));
        assert_eq!(m.zone(DVec2::new(2.0, 2.0)), Zone::Inside);
        assert_eq!(m.zone(DVec2::new(-0.5, 2.0)), Zone::Ring);
        assert_eq!(m.zone(DVec2::new(-3.0, 2.0)), Zone::Outside);
    }
}
