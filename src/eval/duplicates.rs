//! Pairs of predictions that describe the same piece of surface twice.

use super::index::Aabb;
use super::metrics::{DuplicatePair, Duplicates};
use super::options::{normals_match, EvalOptions};
use super::sampling::sample_polygon;
use crate::geometry::polygon::{contains, signed_area};
use crate::geometry::{Plane, Polygon3};
use glam::{DVec2, DVec3};

/// What the pair tests need of one polygon.
struct Shape {
    plane: Plane,
    centroid: DVec3,
    bounds: Aabb,
    area: f64,
}

impl Shape {
    fn new(poly: &Polygon3) -> Self {
        Shape {
            plane: poly.plane(),
            centroid: poly.frame.to_world(ring_centroid(&poly.ring)),
            bounds: Aabb::of(&poly.vertices()),
            area: poly.area(),
        }
    }
}

/// Area centroid of a ring (vertex mean when its area is zero).
fn ring_centroid(ring: &[DVec2]) -> DVec2 {
    let n = ring.len();
    if n == 0 {
        return DVec2::ZERO;
    }
    let a = signed_area(ring);
    if a.abs() <= 1e-12 {
        return ring.iter().copied().sum::<DVec2>() / n as f64;
    }
    let mut c = DVec2::ZERO;
    // Relative to the first vertex, for precision far from the origin.
    let o = ring[0];
    for i in 0..n {
        let (p, q) = (ring[i] - o, ring[(i + 1) % n] - o);
        c += (p + q) * p.perp_dot(q);
    }
    o + c / (6.0 * a)
}

/// Every duplicate pair among `pred`.
pub(crate) fn find(pred: &[Polygon3], opts: &EvalOptions) -> Duplicates {
    let shapes: Vec<Shape> = pred.iter().map(Shape::new).collect();
    let mut pairs = Vec::new();
    for i in 0..pred.len() {
        for j in (i + 1)..pred.len() {
            if !near_coplanar(&shapes[i], &shapes[j], opts) {
                continue;
            }
            // Sample the smaller polygon, test against the larger outline.
            let (small, large) = if shapes[j].area < shapes[i].area {
                (j, i)
            } else {
                (i, j)
            };
            let overlap = overlap_area(&pred[small], &pred[large], opts);
            if overlap > opts.duplicate_min_overlap {
                let cos = shapes[i].plane.normal.dot(shapes[j].plane.normal).abs();
                pairs.push(DuplicatePair {
                    first: i,
                    second: j,
                    angle_deg: libm::acos(cos.min(1.0)).to_degrees(),
                    overlap_area: overlap,
                });
            }
        }
    }
    Duplicates {
        count: pairs.len(),
        pairs,
    }
}

/// Matching normals, each centroid near the other's plane, boxes close.
fn near_coplanar(a: &Shape, b: &Shape, opts: &EvalOptions) -> bool {
    let tol = opts.duplicate_plane_distance;
    normals_match(a.plane.normal, b.plane.normal, opts.cos_max_angle())
        && a.plane.signed_distance(b.centroid).abs() <= tol
        && b.plane.signed_distance(a.centroid).abs() <= tol
        && a.bounds.box_distance(&b.bounds) <= tol
}

/// Area (m^2) of `a`'s grid samples whose projection on `b`'s plane falls
/// inside `b`'s outline.
fn overlap_area(a: &Polygon3, b: &Polygon3, opts: &EvalOptions) -> f64 {
    let samples = sample_polygon(a, opts);
    let (lo, hi) = b
        .ring
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let inside = samples
        .area
        .iter()
        .map(|&q| b.frame.to_local(a.frame.to_world(q)))
        .filter(|q| q.cmpge(lo).all() && q.cmple(hi).all() && contains(&b.ring, *q))
        .count();
    inside as f64 * samples.weight()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centroid_of_an_l_shape() {
        let l = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 1.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 2.0),
            DVec2::new(0.0, 2.0),
        ];
        let c = ring_centroid(&l);
        // Two unit squares at (0.5, 0.5) and (1.5, 0.5), one at (0.5, 1.5).
        let expected = DVec2::new(2.5 / 3.0, 2.5 / 3.0);
        assert!((c - expected).length() < 1e-12, "{c}");
    }
}
