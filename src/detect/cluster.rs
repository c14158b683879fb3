//! Euclidean clustering of a plane's inliers, in linear expected time.
//!
//! The inliers are projected into the plane, so distances are measured in
//! the plane. Points go into a 2D grid of cells of side `tol / sqrt(2)`: two
//! points in one cell are always within `tol`, so each cell is one node of a
//! union-find. Two cells are joined when some pair of their points is closer
//! than `tol`; only cells whose boxes are closer than `tol` are compared (a
//! 5x5 neighbourhood), and the comparison stops at the first close pair.

use crate::geometry::grow_box;
use crate::hash::{Buckets, CellIds};
use glam::DVec2;

/// Indices of the points in the largest cluster (ties: the cluster holding
/// the lowest index), in increasing order. Empty input gives an empty result.
#[cfg(test)]
pub fn largest_cluster(points: &[DVec2], tol: f64) -> Vec<u32> {
    let (comp, sizes) = clusters(points, tol);
    let Some(&first) = comp.first() else {
        return Vec::new();
    };
    let mut best = first;
    for &c in &comp {
        if sizes[c as usize] > sizes[best as usize] {
            best = c;
        }
    }
    (0..comp.len() as u32)
        .filter(|&i| comp[i as usize] == best)
        .collect()
}

/// Cluster label of every point (labels are cell ids of the cluster's root,
/// so not dense) and the size of each label.
#[cfg(test)]
pub fn clusters(points: &[DVec2], tol: f64) -> (Vec<u32>, Vec<u32>) {
    Clusterer::default().clusters(points, tol)
}

/// Cell grids of up to this many cells plus four per point are indexed by a
/// dense array (4 bytes a cell, with a margin two cells wide: about 8 MiB
/// plus 16 bytes a point at most, kept between calls and cleared cell by
/// cell), larger ones by a hash map: a plane slicing a whole street
/// scatters a few thousand inliers over 10^5 cells, where hashing would
/// cost more than the rest of the clustering.
const DENSE_CELLS: u128 = 1 << 21;

/// [`clusters`] with its working memory kept between calls: the detection
/// cascade clusters once per round, and fresh multi-megabyte buffers every
/// round cost more in page faults than the clustering itself.
#[derive(Default)]
pub struct Clusterer {
    ids: CellIds,
    cell_of: Vec<u32>,
    buckets: Buckets,
    /// Bounding box (min, max) of each cell's points.
    bbox: Vec<(DVec2, DVec2)>,
    near: Vec<DVec2>,
    parent: Vec<u32>,
}

impl Clusterer {
    /// See [`clusters`].
    pub fn clusters(&mut self, points: &[DVec2], tol: f64) -> (Vec<u32>, Vec<u32>) {
        let n = points.len();
        if n == 0 {
            return (Vec::new(), Vec::new());
        }
        let tol = if tol.is_finite() && tol > 0.0 {
            tol
        } else {
            1e-9
        };
        let side = tol / std::f64::consts::SQRT_2;
        let inv = 1.0 / side;
        // Cell ids in first-seen order and each point's cell.
        self.ids
            .assign_points(points, inv, DENSE_CELLS, &mut self.cell_of);
        let cells = self.ids.keys.len();
        self.buckets.fill(&self.cell_of, cells);
        let buckets = &self.buckets;
        // Each cell's box. Most cells hold a handful of points: the first
        // eight (repeating the last when fewer) in a loop of fixed length,
        // whose end the CPU predicts, unlike a loop over each cell's count.
        self.bbox.clear();
        self.bbox.extend((0..cells).map(|c| {
            let of = buckets.of(c);
            let last = of.len() - 1;
            let (mut lo, mut hi) = (points[of[0] as usize], points[of[0] as usize]);
            for k in 1..8 {
                grow_box(&mut lo, &mut hi, points[of[k.min(last)] as usize]);
            }
            for &i in of.get(8..).unwrap_or(&[]) {
                grow_box(&mut lo, &mut hi, points[i as usize]);
            }
            (lo, hi)
        }));
        // Half neighbourhood (each unordered pair once) whose boxes are < tol apart.
        let mut offsets = [(0i64, 0i64); 12];
        let mut count = 0;
        for dx in -2i64..=2 {
            for dy in -2i64..=2 {
                if (dx, dy) <= (0, 0) {
                    continue;
                }
                let gx = (dx.abs() - 1).max(0) as f64 * side;
                let gy = (dy.abs() - 1).max(0) as f64 * side;
                if gx * gx + gy * gy < tol * tol {
                    offsets[count] = (dx, dy);
                    count += 1;
                }
            }
        }
        let offsets = &offsets[..count];
        // With the dense array, the offsets as steps in it from the cell two
        // rows below (all non-negative, and in the array thanks to its
        // margin: no range tests). Always twelve, for a loop of fixed
        // length: when rounding kept ten offsets, the first one repeats (a
        // neighbour seen twice is harmless).
        let grid = self.ids.dense_grid();
        let mut steps = [0usize; 12];
        if let Some((_, stride)) = grid {
            for (k, step) in steps.iter_mut().enumerate() {
                let (dx, dy) = offsets[if k < count { k } else { 0 }];
                *step = (dy + 2) as usize * stride + dx as usize;
            }
        }
        // Most neighbour pairs are settled by the cells' boxes alone; the rest
        // compare only the points of each cell within `tol` of the other's box
        // (near the sensor a cell holds hundreds of points, and two diagonal
        // cells without a close pair would otherwise cost the product of
        // their sizes).
        let box_gap2 = |p: DVec2, b: &(DVec2, DVec2)| {
            let dx = max0(b.0.x - p.x, p.x - b.1.x);
            let dy = max0(b.0.y - p.y, p.y - b.1.y);
            dx * dx + dy * dy
        };
        self.parent.clear();
        self.parent.extend(0..cells as u32);
        let tol2 = tol * tol;
        let (parent, near) = (&mut self.parent, &mut self.near);
        for c in 0..cells {
            let (cx, cy) = self.ids.keys[c];
            // The occupied neighbours first, without a branch per empty one
            // (most are empty, in no predictable pattern).
            let mut found = [0u32; 12];
            let mut count = 0;
            if let Some((ids, stride)) = grid {
                let base = cy as usize * stride + cx as usize;
                for &step in &steps {
                    let nb = ids[base + step];
                    found[count] = nb;
                    count += (nb != u32::MAX) as usize;
                }
            } else {
                for &(dx, dy) in offsets {
                    let nb = self
                        .ids
                        .get(cx.wrapping_add(dx), cy.wrapping_add(dy))
                        .unwrap_or(u32::MAX);
                    found[count] = nb;
                    count += (nb != u32::MAX) as usize;
                }
            }
            // This cell's root, found once: only a union below changes it
            // (to the smaller of the two roots).
            let mut ra = if count > 0 { find(parent, c as u32) } else { 0 };
            let (a, ba) = (buckets.of(c), &self.bbox[c]);
            // Quick look first (below): in a dense surface a few points of
            // each cell usually already include a close pair. Four spread
            // over the cell's points (all of them up to four), first and
            // last included: they come mostly in scan order, so those are
            // the cell's ends along the scan line (the first four alone
            // sent 2.5 times as many pairs to the per-point test).
            let spread = |of: &[u32]| {
                let l = of.len() - 1;
                [of[0], of[(l + 1) / 3], of[(2 * l + 1) / 3], of[l]].map(|i| points[i as usize])
            };
            let pa = spread(a);
            for &nb in &found[..count] {
                let rb = find(parent, nb);
                if ra == rb {
                    continue;
                }
                let bb = &self.bbox[nb as usize];
                let gx = max0(bb.0.x - ba.1.x, ba.0.x - bb.1.x);
                let gy = max0(bb.0.y - ba.1.y, ba.0.y - bb.1.y);
                if gx * gx + gy * gy >= tol2 {
                    continue;
                }
                let b = buckets.of(nb as usize);
                // The quick look: all sixteen pairs at once, without a
                // branch each.
                let pb = spread(b);
                let mut close = false;
                for p in pa {
                    for q in pb {
                        close |= (q - p).length_squared() < tol2;
                    }
                }
                if !close {
                    near.clear();
                    near.extend(
                        a.iter()
                            .map(|&i| points[i as usize])
                            .filter(|&p| box_gap2(p, bb) < tol2),
                    );
                    close = !near.is_empty()
                        && b.iter().any(|&j| {
                            let q = points[j as usize];
                            box_gap2(q, ba) < tol2
                                && near.iter().any(|&p| (q - p).length_squared() < tol2)
                        });
                }
                if close {
                    // Union by smaller root id: deterministic.
                    let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
                    parent[hi as usize] = lo;
                    ra = lo;
                }
            }
        }
        // Every parent is at most its child (a union hangs the larger root
        // under the smaller, path halving only shortens), so in increasing
        // order a cell's parent already points at its root.
        for c in 0..cells {
            parent[c] = parent[parent[c] as usize];
        }
        let mut size = vec![0u32; cells];
        for c in 0..cells {
            size[parent[c] as usize] += buckets.of(c).len() as u32;
        }
        let root_of_point = self.cell_of.iter().map(|&c| parent[c as usize]).collect();
        (root_of_point, size)
    }
}

/// `max(a, b, 0)` by comparisons (`f64::max` also tests for NaN in wasm);
/// the gaps it computes are finite.
#[inline]
fn max0(a: f64, b: f64) -> f64 {
    let m = if b > a { b } else { a };
    if m > 0.0 {
        m
    } else {
        0.0
    }
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let gp = parent[parent[x as usize] as usize];
        parent[x as usize] = gp;
        x = gp;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_at_gaps_wider_than_tolerance_only() {
        let mut pts = Vec::new();
        for i in 0..100 {
            pts.push(DVec2::new(i as f64 * 0.1, 0.0)); // 0 .. 9.9
        }
        for i in 0..50 {
            pts.push(DVec2::new(10.8 + i as f64 * 0.1, 0.0)); // gap 0.9
        }
        let c = largest_cluster(&pts, 0.5);
        assert_eq!(c.len(), 100);
        assert!(c.iter().all(|&i| i < 100));
        let c = largest_cluster(&pts, 1.0);
        assert_eq!(c.len(), 150);
    }

    /// Sizes of the connected components of the "closer than `tol`" graph.
    fn brute_force_sizes(pts: &[DVec2], tol: f64) -> Vec<usize> {
        let n = pts.len();
        let mut seen = vec![false; n];
        let mut sizes = Vec::new();
        for s in 0..n {
            if seen[s] {
                continue;
            }
            seen[s] = true;
            let mut stack = vec![s];
            let mut sz = 0;
            while let Some(i) = stack.pop() {
                sz += 1;
                for j in 0..n {
                    if !seen[j] && (pts[i] - pts[j]).length() < tol {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
            sizes.push(sz);
        }
        sizes.sort_unstable();
        sizes
    }

    fn sizes_of(pts: &[DVec2], tol: f64) -> Vec<usize> {
        let (comp, sizes) = clusters(pts, tol);
        let mut roots: Vec<u32> = comp.clone();
        roots.sort_unstable();
        roots.dedup();
        let mut out: Vec<usize> = roots.iter().map(|&r| sizes[r as usize] as usize).collect();
        out.sort_unstable();
        out
    }

    #[test]
    fn matches_brute_force_on_random_points() {
        let mut r = crate::rng::Rng::new(11);
        let pts: Vec<DVec2> = (0..600)
            .map(|_| DVec2::new(r.range(0.0, 20.0), r.range(0.0, 20.0)))
            .collect();
        let tol = 0.7;
        assert_eq!(sizes_of(&pts, tol), brute_force_sizes(&pts, tol));
        assert_eq!(
            largest_cluster(&pts, tol).len(),
            *brute_force_sizes(&pts, tol).last().unwrap()
        );
    }

    #[test]
    fn dense_cells_and_grid_edges_match_brute_force() {
        // Dense clumps (tens of points a cell: the boxes' loop past eight
        // points, quick looks that miss, the per-point fallback), and
        // single rows and columns of cells, whose neighbours lie in the
        // dense array's margin.
        let mut r = crate::rng::Rng::new(13);
        let tol = 0.5;
        let clumps: Vec<DVec2> = (0..2500)
            .map(|i| {
                let c = DVec2::new((i % 5) as f64 * 1.3, (i % 3) as f64 * 1.1);
                c + DVec2::new(r.range(0.0, 0.9), r.range(0.0, 0.9))
            })
            .collect();
        let row: Vec<DVec2> = (0..300)
            .map(|_| DVec2::new(r.range(0.0, 60.0), 1e-3 * r.uniform()))
            .collect();
        let column: Vec<DVec2> = row.iter().map(|p| DVec2::new(p.y, p.x)).collect();
        let mut c = Clusterer::default();
        for pts in [&clumps, &row, &column] {
            assert_eq!(c.clusters(pts, tol).0.len(), pts.len());
            assert!(c.ids.is_dense());
            assert_eq!(sizes_of(pts, tol), brute_force_sizes(pts, tol));
        }
    }

    #[test]
    fn ten_neighbour_offsets_match_brute_force() {
        // For some tolerances two cell sides squared round to at least
        // tol^2, and the corner cells two steps away drop out: the dense
        // path then repeats an offset to make up twelve.
        let tol = (1..1000)
            .map(|k| 0.3 + k as f64 * 1e-3)
            .find(|&t| {
                let side = t / std::f64::consts::SQRT_2;
                side * side + side * side >= t * t
            })
            .expect("such a tolerance");
        let mut r = crate::rng::Rng::new(14);
        let pts: Vec<DVec2> = (0..800)
            .map(|_| DVec2::new(r.range(0.0, 12.0), r.range(0.0, 12.0)))
            .collect();
        assert_eq!(sizes_of(&pts, tol), brute_force_sizes(&pts, tol));
    }

    #[test]
    fn hashed_grid_matches_brute_force_too() {
        // Clumps scattered over 2 km x 2 km: far more cells than the dense
        // grid takes, so the hashed path runs.
        let mut r = crate::rng::Rng::new(12);
        let mut pts = Vec::new();
        for _ in 0..12 {
            let c = DVec2::new(r.range(0.0, 2000.0), r.range(0.0, 2000.0));
            let k = 10 + r.below(60);
            for _ in 0..k {
                pts.push(c + DVec2::new(r.range(0.0, 3.0), r.range(0.0, 1.0)));
            }
        }
        let tol = 0.5;
        let mut c = Clusterer::default();
        assert_eq!(c.clusters(&pts, tol).0.len(), pts.len());
        assert!(!c.ids.is_dense(), "the dense grid was used");
        assert_eq!(sizes_of(&pts, tol), brute_force_sizes(&pts, tol));
        // The same instance, reused on a dense input, gives the same as a
        // fresh one.
        let dense: Vec<DVec2> = (0..400)
            .map(|_| DVec2::new(r.range(0.0, 15.0), r.range(0.0, 15.0)))
            .collect();
        assert_eq!(c.clusters(&dense, 0.6), clusters(&dense, 0.6));
        assert!(c.ids.is_dense(), "the hashed path was used");
        // And back: hashed after dense, dense after hashed.
        assert_eq!(c.clusters(&pts, tol), clusters(&pts, tol));
        assert_eq!(c.clusters(&dense, 0.6), clusters(&dense, 0.6));
    }

    #[test]
    fn degenerate() {
        assert!(largest_cluster(&[], 0.5).is_empty());
        assert_eq!(largest_cluster(&[DVec2::ONE; 5], 0.5).len(), 5);
    }
}
