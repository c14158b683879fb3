//! The two measures every ring algorithm starts from: the orientation of a
//! triangle and the signed area of a ring. A leaf, so that the convex hull
//! ([`super::hull`]) and the polygon operations ([`super::polygon`], whose
//! simplification falls back on the hull) both build on it without
//! importing each other; `polygon` re-exports both under their old paths.

use glam::DVec2;

/// The signed area (positive when counter-clockwise).
pub fn signed_area(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    if n < 3 {
        return 0.0;
    }
    let mut s = 0.0;
    for i in 0..n {
        let a = ring[i];
        let b = ring[(i + 1) % n];
        s += a.x * b.y - a.y * b.x;
    }
    0.5 * s
}

/// Orientation of the triangle `a, b, c`: > 0 counter-clockwise.
#[inline]
pub fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}
