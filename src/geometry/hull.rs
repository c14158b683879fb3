//! 2D convex hull: Andrew's monotone chain after an Akl–Toussaint pre-filter
//! (points inside the octagon of extreme points cannot be on the hull), so
//! half a million road points cost one linear pass plus a sort of the few
//! survivors.

use super::ring::{orient, signed_area};
use glam::DVec2;

/// Counter-clockwise convex hull without collinear vertices, or `None` when
/// the points are fewer than three or all collinear.
pub fn convex_hull(points: &[DVec2]) -> Option<Vec<DVec2>> {
    let mut cand = prefilter(points);
    if cand.len() < 3 {
        return None;
    }
    // A total order (equal means identical): heapsort gives the library
    // sort's result in a fraction of its wasm size.
    super::numeric::heap_sort_by(&mut cand, |a, b| {
        a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y))
    });
    cand.dedup();
    if cand.len() < 3 {
        return None;
    }
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * cand.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(cand.iter())
        } else {
            Box::new(cand.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && orient(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    if hull.len() < 3 {
        return None;
    }
    Some(hull)
}

/// Drop the points strictly inside the octagon spanned by the extremes along
/// x, y, x+y and x-y.
fn prefilter(points: &[DVec2]) -> Vec<DVec2> {
    if points.len() < 64 {
        return points.to_vec();
    }
    let keys: [fn(DVec2) -> f64; 4] = [|p| p.x, |p| p.y, |p| p.x + p.y, |p| p.x - p.y];
    let mut ext = [DVec2::ZERO; 8];
    for (k, key) in keys.iter().enumerate() {
        let (mut lo, mut hi) = (points[0], points[0]);
        for &p in points {
            if key(p) < key(lo) {
                lo = p;
            }
            if key(p) > key(hi) {
                hi = p;
            }
        }
        ext[2 * k] = lo;
        ext[2 * k + 1] = hi;
    }
    // Octagon in counter-clockwise order: min x, min x-y.. walk by angle.
    // Order: minX, min(x+y), minY, max(x-y), maxX, max(x+y), maxY, min(x-y).
    let oct = [
        ext[0], ext[4], ext[2], ext[7], ext[1], ext[5], ext[3], ext[6],
    ];
    let mut ring: Vec<DVec2> = Vec::with_capacity(8);
    for p in oct {
        if ring.last() != Some(&p) && ring.first() != Some(&p) {
            ring.push(p);
        }
    }
    if ring.len() < 3 || signed_area(&ring) <= 0.0 {
        return points.to_vec();
    }
    points
        .iter()
        .copied()
        .filter(|&p| {
            let n = ring.len();
            (0..n).any(|i| orient(ring[i], ring[(i + 1) % n], p) <= 0.0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polygon::{contains, is_simple};
    use crate::rng::Rng;

    #[test]
    fn hull_of_random_points_contains_all_and_is_ccw() {
        let mut r = Rng::new(3);
        let pts: Vec<DVec2> = (0..5000)
            .map(|_| DVec2::new(r.range(-5.0, 5.0), r.range(-2.0, 2.0)))
            .collect();
        let h = convex_hull(&pts).unwrap();
        assert!(signed_area(&h) > 0.0 && is_simple(&h));
        for i in 0..h.len() {
            let (a, b, c) = (h[i], h[(i + 1) % h.len()], h[(i + 2) % h.len()]);
            assert!(orient(a, b, c) > 0.0, "strictly convex");
        }
        for &p in &pts {
            let on = crate::geometry::polygon::boundary_distance(&h, p) < 1e-9;
            assert!(contains(&h, p) || on);
        }
    }

    #[test]
    fn degenerate_inputs() {
        assert!(convex_hull(&[]).is_none());
        assert!(convex_hull(&[DVec2::ONE; 10]).is_none());
        let line: Vec<DVec2> = (0..100)
            .map(|i| DVec2::new(i as f64, 2.0 * i as f64))
            .collect();
        assert!(convex_hull(&line).is_none());
        let sq = [
            DVec2::ZERO,
            DVec2::X,
            DVec2::ONE,
            DVec2::Y,
            DVec2::splat(0.5),
        ];
        assert_eq!(convex_hull(&sq).unwrap().len(), 4);
    }
}
