//! Euclidean clustering of a plane's inliers, in linear expected time.
//!
//! The inliers are projected into the plane, so distances are measured in
//! the plane. Points go into a 2D grid of cells of side `tol / sqrt(2)`: two
//! points in one cell are always within `tol`, so each cell is one node of a
//! union-find. Two cells are joined when some pair of their points is closer
//! than `tol`; only cells whose boxes are closer than `tol` are compared (a
//! 5x5 neighbourhood), and the comparison stops at the first close pair.

use crate::hash::{floor_i64, key2, GridMap};
use glam::DVec2;

/// Indices of the points in the largest cluster (ties: the cluster holding
/// the lowest index), in increasing order. Empty input gives an empty result.
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
pub fn clusters(points: &[DVec2], tol: f64) -> (Vec<u32>, Vec<u32>) {
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
    // Cell ids in first-seen order; looked up in a dense array when the
    // bounding box is small enough (the usual case), else in a hash map.
    let cell_of_point = |p: &DVec2| (floor_i64(p.x / side), floor_i64(p.y / side));
    let (mut lo, mut hi) = ((i64::MAX, i64::MAX), (i64::MIN, i64::MIN));
    for p in points {
        let (x, y) = cell_of_point(p);
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    }
    let (gw, gh) = ((hi.0 - lo.0 + 1) as u128, (hi.1 - lo.1 + 1) as u128);
    let dense = gw * gh <= 4 * n as u128 + 65_536;
    let mut lookup = CellLookup::new(dense, lo, (gw as usize, gh as usize));
    let mut cell_key: Vec<(i64, i64)> = Vec::new();
    let mut cell_of = Vec::with_capacity(n);
    for p in points {
        let (cx, cy) = cell_of_point(p);
        let id = lookup.get_or_insert(cx, cy, || {
            cell_key.push((cx, cy));
            (cell_key.len() - 1) as u32
        });
        cell_of.push(id);
    }
    let cells = cell_key.len();
    // CSR of points per cell.
    let mut start = vec![0u32; cells + 1];
    for &c in &cell_of {
        start[c as usize + 1] += 1;
    }
    for i in 0..cells {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut items = vec![0u32; n];
    for (i, &c) in cell_of.iter().enumerate() {
        items[fill[c as usize] as usize] = i as u32;
        fill[c as usize] += 1;
    }
    // Half neighbourhood (each unordered pair once) whose boxes are < tol apart.
    let mut offsets = Vec::new();
    for dx in -2i64..=2 {
        for dy in -2i64..=2 {
            if (dx, dy) <= (0, 0) {
                continue;
            }
            let gx = (dx.abs() - 1).max(0) as f64 * side;
            let gy = (dy.abs() - 1).max(0) as f64 * side;
            if gx * gx + gy * gy < tol * tol {
                offsets.push((dx, dy));
            }
        }
    }
    let mut parent: Vec<u32> = (0..cells as u32).collect();
    let tol2 = tol * tol;
    for c in 0..cells {
        let (cx, cy) = cell_key[c];
        let a = &items[start[c] as usize..start[c + 1] as usize];
        for &(dx, dy) in &offsets {
            let Some(nb) = lookup.get(cx + dx, cy + dy) else {
                continue;
            };
            let (ra, rb) = (find(&mut parent, c as u32), find(&mut parent, nb));
            if ra == rb {
                continue;
            }
            let b = &items[start[nb as usize] as usize..start[nb as usize + 1] as usize];
            let close = a.iter().any(|&i| {
                let p = points[i as usize];
                b.iter()
                    .any(|&j| (points[j as usize] - p).length_squared() < tol2)
            });
            if close {
                // Union by smaller root id: deterministic.
                let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
                parent[hi as usize] = lo;
            }
        }
    }
    let mut size = vec![0u32; cells];
    let mut root_of_point = Vec::with_capacity(n);
    for &c in &cell_of {
        let r = find(&mut parent, c);
        size[r as usize] += 1;
        root_of_point.push(r);
    }
    (root_of_point, size)
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let gp = parent[parent[x as usize] as usize];
        parent[x as usize] = gp;
        x = gp;
    }
    x
}

/// Cell id lookup: a dense array over the cells' bounding box, or a hash map.
enum CellLookup {
    Dense {
        lo: (i64, i64),
        w: usize,
        h: usize,
        ids: Vec<u32>,
    },
    Sparse(GridMap<u64, u32>),
}

impl CellLookup {
    fn new(dense: bool, lo: (i64, i64), (w, h): (usize, usize)) -> Self {
        if dense {
            CellLookup::Dense {
                lo,
                w,
                h,
                ids: vec![u32::MAX; w * h],
            }
        } else {
            CellLookup::Sparse(GridMap::default())
        }
    }

    fn get(&self, x: i64, y: i64) -> Option<u32> {
        match self {
            CellLookup::Dense { lo, w, h, ids } => {
                let (dx, dy) = (x - lo.0, y - lo.1);
                if dx < 0 || dy < 0 || dx as usize >= *w || dy as usize >= *h {
                    return None;
                }
                let id = ids[dy as usize * w + dx as usize];
                (id != u32::MAX).then_some(id)
            }
            CellLookup::Sparse(map) => map.get(&key2(x, y)).copied(),
        }
    }

    fn get_or_insert(&mut self, x: i64, y: i64, new: impl FnOnce() -> u32) -> u32 {
        match self {
            CellLookup::Dense { lo, w, ids, .. } => {
                let k = (y - lo.1) as usize * *w + (x - lo.0) as usize;
                if ids[k] == u32::MAX {
                    ids[k] = new();
                }
                ids[k]
            }
            CellLookup::Sparse(map) => *map.entry(key2(x, y)).or_insert_with(new),
        }
    }
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

    #[test]
    fn matches_brute_force_on_random_points() {
        let mut r = crate::rng::Rng::new(11);
        let pts: Vec<DVec2> = (0..600)
            .map(|_| DVec2::new(r.range(0.0, 20.0), r.range(0.0, 20.0)))
            .collect();
        let tol = 0.7;
        // Brute-force components.
        let n = pts.len();
        let mut comp = vec![usize::MAX; n];
        let mut sizes = Vec::new();
        for s in 0..n {
            if comp[s] != usize::MAX {
                continue;
            }
            let id = sizes.len();
            let mut stack = vec![s];
            comp[s] = id;
            let mut sz = 0;
            while let Some(i) = stack.pop() {
                sz += 1;
                for j in 0..n {
                    if comp[j] == usize::MAX && (pts[i] - pts[j]).length() < tol {
                        comp[j] = id;
                        stack.push(j);
                    }
                }
            }
            sizes.push(sz);
        }
        let best = *sizes.iter().max().unwrap();
        assert_eq!(largest_cluster(&pts, tol).len(), best);
    }

    #[test]
    fn degenerate() {
        assert!(largest_cluster(&[], 0.5).is_empty());
        assert_eq!(largest_cluster(&[DVec2::ONE; 5], 0.5).len(), 5);
    }
}
