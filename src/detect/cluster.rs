//! Euclidean clustering of a plane's inliers, in linear expected time.
//!
//! The inliers are projected into the plane, so distances are measured in
//! the plane. Points go into a 2D grid of cells of side `tol / sqrt(2)`: two
//! points in one cell are always within `tol`, so each cell is one node of a
//! union-find. Two cells are joined when some pair of their points is closer
//! than `tol`; only cells whose boxes are closer than `tol` are compared (a
//! 5x5 neighbourhood), and the comparison stops at the first close pair.

use crate::hash::{key2, GridMap};
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
    // Cell ids in first-seen order.
    let mut map: GridMap<u64, u32> = GridMap::default();
    let mut cell_key: Vec<(i64, i64)> = Vec::new();
    let mut cell_of = Vec::with_capacity(n);
    for p in points {
        let (cx, cy) = (
            crate::hash::floor_i64(p.x / side),
            crate::hash::floor_i64(p.y / side),
        );
        let id = *map.entry(key2(cx, cy)).or_insert_with(|| {
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
            let Some(&nb) = map.get(&key2(cx + dx, cy + dy)) else {
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
