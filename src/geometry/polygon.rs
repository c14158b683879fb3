//! Simple polygons in 2D (a ring of vertices, no repeated closing vertex) and
//! planar polygons in 3D.

use super::plane::{Frame, Plane};
pub use super::ring::{orient, signed_area};
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// Squared distance from `p` to the segment `a b`.
#[inline]
pub fn segment_distance_sq(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).length_squared()
}

/// Is `p` strictly inside the ring (even-odd rule)? Points exactly on an edge
/// may go either way; use [`distance`] for a tolerance.
pub fn contains(ring: &[DVec2], p: DVec2) -> bool {
    let n = ring.len();
    if n < 3 {
        return false;
    }
    let mut inside = false;
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (ring[i], ring[j]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if p.x < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Distance from `p` to the ring's boundary.
pub fn boundary_distance(ring: &[DVec2], p: DVec2) -> f64 {
    let n = ring.len();
    let mut best = f64::INFINITY;
    for i in 0..n {
        best = best.min(segment_distance_sq(p, ring[i], ring[(i + 1) % n]));
    }
    best.sqrt()
}

/// Distance from `p` to the polygon region: 0 inside, else to the boundary.
pub fn distance(ring: &[DVec2], p: DVec2) -> f64 {
    if ring.is_empty() {
        return f64::INFINITY;
    }
    if contains(ring, p) {
        0.0
    } else {
        boundary_distance(ring, p)
    }
}

/// Do the closed segments `a b` and `c d` intersect (touching counts)?
pub fn segments_intersect(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let d1 = orient(c, d, a);
    let d2 = orient(c, d, b);
    let d3 = orient(a, b, c);
    let d4 = orient(a, b, d);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

/// Is the ring a simple polygon: at least three distinct vertices, non-zero
/// area, no edge folding back onto its neighbour, and no two non-adjacent
/// edges touching? Short rings compare every pair of edges; long ones (a
/// traced road outline has thousands of vertices) only the pairs sharing a
/// cell of a uniform grid over the ring's box, about linear time for the
/// axis-aligned rings the outline tracer makes. Both give the same answer:
/// two touching edges share their touching point, and so its cell.
pub fn is_simple(ring: &[DVec2]) -> bool {
    let n = ring.len();
    if n < 3 || signed_area(ring).abs() <= 0.0 {
        return false;
    }
    if ring.iter().any(|p| !p.is_finite()) {
        return false;
    }
    for i in 0..n {
        let (prev, cur, next) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
        if cur == next {
            return false;
        }
        // Adjacent edges share one vertex; they must not fold back.
        if orient(prev, cur, next) == 0.0 && (prev - cur).dot(next - cur) > 0.0 {
            return false;
        }
    }
    // Non-adjacent pairs: (i, j) with i + 1 < j, except the first and last
    // edge, which share vertex 0.
    let crossing = |i: usize, j: usize| {
        let (i, j) = (i.min(j), i.max(j));
        j > i + 1
            && !(i == 0 && j == n - 1)
            && segments_intersect(ring[i], ring[i + 1], ring[j], ring[(j + 1) % n])
    };
    if n <= 32 {
        return !(0..n).any(|i| (i + 2..n).any(|j| crossing(i, j)));
    }
    match edges_by_cell(ring) {
        Some((start, edges)) => !start.windows(2).any(|w| {
            let cell = &edges[w[0] as usize..w[1] as usize];
            cell.iter().enumerate().any(|(a, &i)| {
                cell[a + 1..]
                    .iter()
                    .any(|&j| crossing(i as usize, j as usize))
            })
        }),
        None => !(0..n).any(|i| (i + 2..n).any(|j| crossing(i, j))),
    }
}

/// The ring's edges bucketed by the cells of a grid of about `n` cells over
/// its box (edge `i` in every cell its box overlaps): cell `c` holds
/// `edges[start[c]..start[c + 1]]`. `None` when the edges' boxes cover too
/// many cells (long diagonal edges), where comparing all pairs is cheaper.
fn edges_by_cell(ring: &[DVec2]) -> Option<(Vec<u32>, Vec<u32>)> {
    let n = ring.len();
    let (mut lo, mut hi) = (ring[0], ring[0]);
    for &p in ring {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let g = ((n as f64).sqrt().ceil() as usize).max(1);
    let size = (hi - lo) / g as f64;
    if !size.is_finite() {
        // Coordinates so far apart that their difference overflows.
        return None;
    }
    // Monotone in the coordinate, so a point on two edges' boxes maps to a
    // cell inside both edges' cell ranges.
    let index = |v: f64, lo: f64, size: f64| -> usize {
        if size > 0.0 {
            (((v - lo) / size) as usize).min(g - 1)
        } else {
            0
        }
    };
    let range = |i: usize| {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let (x0, x1) = (
            index(a.x.min(b.x), lo.x, size.x),
            index(a.x.max(b.x), lo.x, size.x),
        );
        let (y0, y1) = (
            index(a.y.min(b.y), lo.y, size.y),
            index(a.y.max(b.y), lo.y, size.y),
        );
        (x0, x1, y0, y1)
    };
    let mut count = vec![0u32; g * g + 1];
    let mut total = 0usize;
    for i in 0..n {
        let (x0, x1, y0, y1) = range(i);
        total += (x1 - x0 + 1) * (y1 - y0 + 1);
        if total > 16 * n {
            return None;
        }
        for y in y0..=y1 {
            for x in x0..=x1 {
                count[y * g + x + 1] += 1;
            }
        }
    }
    for c in 1..count.len() {
        count[c] += count[c - 1];
    }
    let start = count.clone();
    let mut edges = vec![0u32; total];
    for i in 0..n {
        let (x0, x1, y0, y1) = range(i);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let c = &mut count[y * g + x];
                edges[*c as usize] = i as u32;
                *c += 1;
            }
        }
    }
    Some((start, edges))
}

/// Make the ring counter-clockwise (reversing it if needed).
pub fn make_ccw(ring: &mut [DVec2]) {
    if signed_area(ring) < 0.0 {
        ring.reverse();
    }
}

/// Remove consecutive duplicates and vertices on a straight line between
/// their neighbours.
pub fn remove_collinear(ring: &mut Vec<DVec2>) {
    let mut changed = true;
    while changed && ring.len() > 3 {
        changed = false;
        let n = ring.len();
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            let prev = ring[(i + n - 1) % n];
            let cur = ring[i];
            let next = ring[(i + 1) % n];
            let scale = (next - prev).length_squared().max(1e-300);
            if cur == prev || orient(prev, cur, next).abs() <= 1e-12 * scale {
                changed = true;
                continue;
            }
            out.push(cur);
        }
        if out.len() < 3 {
            return;
        }
        *ring = out;
    }
}

/// Douglas–Peucker simplification of a closed ring within `tolerance` metres,
/// with at most `max_vertices` vertices, that never returns a non-simple
/// ring. The tolerance is raised (x1.5 steps) until both hold; if the ring at
/// `tolerance` has few enough vertices but self-intersects, smaller
/// tolerances are tried first. Last resort: the ring's convex hull.
pub fn simplify(ring: &[DVec2], tolerance: f64, max_vertices: usize) -> Vec<DVec2> {
    let mut splits = DouglasPeucker::new(ring, tolerance);
    splits
        .within(tolerance, max_vertices)
        .unwrap_or_else(|| splits.raised(tolerance, max_vertices))
}

/// The rest of [`simplify`] once [`simplify_within`] found no ring: the
/// tolerance raised until one fits, or the convex hull.
pub fn simplify_raised(ring: &[DVec2], tolerance: f64, max_vertices: usize) -> Vec<DVec2> {
    DouglasPeucker::new(ring, tolerance).raised(tolerance, max_vertices)
}

/// [`simplify`] without raising the tolerance: `None` when the ring needs
/// a larger tolerance than `tolerance` to fit in `max_vertices` simply.
pub fn simplify_within(ring: &[DVec2], tolerance: f64, max_vertices: usize) -> Option<Vec<DVec2>> {
    DouglasPeucker::new(ring, tolerance).within(tolerance, max_vertices)
}

/// Douglas–Peucker simplification of a closed ring at many tolerances from
/// one pass. The ring is split at vertex 0 and the vertex farthest from
/// it, then each piece at its vertex farthest from the chord, down to the
/// floor given to `new` (a smaller tolerance, which `within` rarely tries,
/// splits it again down to every vertex off its chord): which vertex
/// splits which piece does not depend on the tolerance, only how deep the
/// splitting goes. So a vertex is kept at tolerance `t` when its own
/// distance and those of all the splits above it exceed `t`: the smallest
/// of them, kept per vertex, is compared with `t`, and the answer is the
/// same vertices as a Douglas–Peucker run at `t`. [`simplify`] tries
/// tolerance after tolerance on rings of thousands of vertices (a road's
/// or a plaza's traced outline), each try one pass over the vertices.
pub(crate) struct DouglasPeucker<'a> {
    ring: &'a [DVec2],
    /// The smallest tolerance the splits are wanted for (m).
    floor: f64,
    /// The vertex farthest from vertex 0: both are always kept.
    far: usize,
    /// Per vertex, the smallest squared chord distance on its path of
    /// splits (0 for a vertex never split at); empty until the first
    /// [`DouglasPeucker::at`].
    keep_above: Vec<f64>,
}

impl<'a> DouglasPeucker<'a> {
    /// The splits of `ring` for tolerances from `floor` (m) up; made at the
    /// first [`DouglasPeucker::at`], and again for a smaller tolerance.
    pub(crate) fn new(ring: &'a [DVec2], floor: f64) -> Self {
        DouglasPeucker {
            ring,
            floor: floor.max(0.0),
            far: 0,
            keep_above: Vec::new(),
        }
    }

    /// Split down to pieces within `self.floor` of their chords: such a
    /// piece keeps none of its inner vertices at any tolerance from the
    /// floor up.
    fn split(&mut self) {
        let (ring, n) = (self.ring, self.ring.len());
        let floor2 = self.floor * self.floor;
        let mut keep_above = vec![0.0; n];
        // Split at the two mutually farthest-ish vertices: vertex 0 and the
        // one farthest from it.
        let far = (1..n)
            .max_by(|&i, &j| {
                (ring[i] - ring[0])
                    .length_squared()
                    .total_cmp(&(ring[j] - ring[0]).length_squared())
            })
            .unwrap_or(n / 2);
        // Pieces as (first, end, the smallest split distance above them).
        let mut stack = vec![(0usize, far, f64::INFINITY), (far, n, f64::INFINITY)];
        while let Some((s, e, above)) = stack.pop() {
            if e <= s + 1 {
                continue;
            }
            let (a, b) = (ring[s], ring[e % n]);
            let mut best = (0.0, 0usize);
            for (i, &p) in ring.iter().enumerate().take(e).skip(s + 1) {
                let d = segment_distance_sq(p, a, b);
                if d > best.0 {
                    best = (d, i);
                }
            }
            if best.0 > floor2 {
                let k = best.0.min(above);
                keep_above[best.1] = k;
                stack.push((s, best.1, k));
                stack.push((best.1, e, k));
            }
        }
        self.far = far;
        self.keep_above = keep_above;
    }

    /// The ring simplified within `tol` (m): vertex 0, the vertex farthest
    /// from it, and the vertices whose splits all lie farther than `tol`
    /// from their chords. The same vertices as Douglas–Peucker run at
    /// `tol`.
    pub(crate) fn at(&mut self, tol: f64) -> Vec<DVec2> {
        if self.ring.is_empty() {
            return Vec::new();
        }
        if tol < self.floor {
            self.floor = 0.0;
            self.keep_above.clear();
        }
        if self.keep_above.is_empty() {
            self.split();
        }
        let tol2 = tol * tol;
        let far = self.far;
        self.ring
            .iter()
            .zip(&self.keep_above)
            .enumerate()
            .filter_map(|(i, (&p, &k))| (k > tol2 || i == 0 || i == far).then_some(p))
            .collect()
    }

    /// See [`simplify_within`].
    pub(crate) fn within(&mut self, tolerance: f64, max_vertices: usize) -> Option<Vec<DVec2>> {
        let ring = self.ring;
        let n = ring.len();
        let max_vertices = max_vertices.max(4);
        if n <= 4 || (n <= max_vertices && tolerance <= 0.0) {
            return Some(ring.to_vec());
        }
        let tol = tolerance.max(0.0);
        let first = self.at(tol);
        if first.len() <= max_vertices && is_simple(&first) {
            return Some(first);
        }
        if first.len() <= max_vertices {
            let mut t = tol * 0.5;
            for _ in 0..20 {
                let out = self.at(t);
                if out.len() > max_vertices {
                    break;
                }
                if is_simple(&out) {
                    return Some(out);
                }
                t *= 0.5;
            }
        }
        None
    }

    /// See [`simplify_raised`].
    pub(crate) fn raised(&mut self, tolerance: f64, max_vertices: usize) -> Vec<DVec2> {
        let ring = self.ring;
        let max_vertices = max_vertices.max(4);
        let tol = tolerance.max(0.0);
        let mut t = if tol > 0.0 { tol } else { 1e-3 };
        for _ in 0..80 {
            t *= 1.5;
            let out = self.at(t);
            if out.len() <= max_vertices && is_simple(&out) {
                return out;
            }
            if out.len() < 3 {
                break;
            }
        }
        match super::hull::convex_hull(ring) {
            Some(h) if h.len() <= max_vertices => h,
            // Any subset of a convex polygon's vertices is convex and simple.
            Some(h) => (0..max_vertices)
                .map(|k| h[k * h.len() / max_vertices])
                .collect(),
            None => ring.to_vec(),
        }
    }
}

/// Smallest distance between the boundaries of two rings, or 0 when they
/// overlap (one contains a vertex of the other, or edges cross).
pub fn ring_distance(a: &[DVec2], b: &[DVec2]) -> f64 {
    closest_sq(a, b, f64::INFINITY, -1.0).sqrt()
}

/// `ring_distance(a, b) <= gap`, the same answer for every input, found
/// with less work: edge pairs whose boxes lie farther apart than `gap`
/// are skipped (they can neither cross nor come within `gap`), and the
/// search stops at the first pair within `gap`.
pub fn rings_within(a: &[DVec2], b: &[DVec2], gap: f64) -> bool {
    // For finite `gap >= 0`, sqrt(gap * gap) is `gap` exactly, so the
    // search may stop at a squared distance of `gap * gap`; boxes are
    // compared with a relative margin far above rounding.
    closest_sq(a, b, gap * (1.0 + 1e-9) + 1e-12, gap * gap).sqrt() <= gap
}

/// Smallest squared distance between the boundaries of two rings (0 when
/// they overlap, infinite for a ring of under three vertices). Edge pairs
/// whose boxes lie more than `skip` apart are passed over, and the search
/// ends at the first squared distance of at most `enough`.
fn closest_sq(a: &[DVec2], b: &[DVec2], skip: f64, enough: f64) -> f64 {
    if a.len() < 3 || b.len() < 3 {
        return f64::INFINITY;
    }
    if contains(a, b[0]) || contains(b, a[0]) {
        return 0.0;
    }
    let edge_box = |r: DVec2, s: DVec2| {
        let (mut lo, mut hi) = (r, r);
        super::numeric::grow_box(&mut lo, &mut hi, s);
        (lo, hi)
    };
    let boxes: Vec<(DVec2, DVec2)> = (0..b.len())
        .map(|j| edge_box(b[j], b[(j + 1) % b.len()]))
        .collect();
    let mut best = f64::INFINITY;
    for i in 0..a.len() {
        let (p, q) = (a[i], a[(i + 1) % a.len()]);
        let (lo, hi) = edge_box(p, q);
        let (lo, hi) = (lo - DVec2::splat(skip), hi + DVec2::splat(skip));
        for (j, &(blo, bhi)) in boxes.iter().enumerate() {
            if blo.x > hi.x || blo.y > hi.y || bhi.x < lo.x || bhi.y < lo.y {
                continue;
            }
            let (r, s) = (b[j], b[(j + 1) % b.len()]);
            if segments_intersect(p, q, r, s) {
                return 0.0;
            }
            for d in [
                segment_distance_sq(p, r, s),
                segment_distance_sq(q, r, s),
                segment_distance_sq(r, p, q),
                segment_distance_sq(s, p, q),
            ] {
                best = if d < best { d } else { best };
            }
            if best <= enough {
                return best;
            }
        }
    }
    best
}

/// A planar polygon in 3D: a frame on its plane and a simple counter-clockwise
/// ring in that frame's 2D coordinates (so it is counter-clockwise seen from
/// the normal side).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Polygon3 {
    /// Frame on the polygon's plane.
    pub frame: Frame,
    /// Outline in frame coordinates (metres), counter-clockwise.
    pub ring: Vec<DVec2>,
}

impl Polygon3 {
    /// Build from world vertices in outline order. The normal comes from
    /// Newell's method (so it follows the vertex order: counter-clockwise seen
    /// from the normal side). `None` for fewer than three vertices or zero area.
    pub fn from_world(vertices: &[DVec3]) -> Option<Self> {
        let n = vertices.len();
        if n < 3 || vertices.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let c = vertices.iter().copied().sum::<DVec3>() / n as f64;
        let mut normal = DVec3::ZERO;
        for i in 0..n {
            let a = vertices[i] - c;
            let b = vertices[(i + 1) % n] - c;
            normal += a.cross(b);
        }
        let len = normal.length();
        if len <= 0.0 || !len.is_finite() {
            return None;
        }
        let plane = Plane::from_point_normal(c, normal / len);
        let frame = Frame::on_plane(&plane, c);
        let ring: Vec<DVec2> = vertices.iter().map(|&v| frame.to_local(v)).collect();
        Some(Polygon3 { frame, ring })
    }

    /// The support plane.
    pub fn plane(&self) -> Plane {
        self.frame.plane()
    }

    /// Outline vertices in world coordinates, in order.
    pub fn vertices(&self) -> Vec<DVec3> {
        self.ring.iter().map(|&q| self.frame.to_world(q)).collect()
    }

    /// Area in square metres.
    pub fn area(&self) -> f64 {
        signed_area(&self.ring).abs()
    }

    /// Exact Euclidean distance from a world point to the polygon (a flat
    /// region including its interior).
    pub fn distance(&self, p: DVec3) -> f64 {
        let h = self.frame.plane().signed_distance(p);
        let d = distance(&self.ring, self.frame.to_local(p));
        (h * h + d * d).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Douglas–Peucker run at one tolerance, recursively: the reference the
    /// splits made once must agree with (the same start, the last of
    /// equally far vertices from vertex 0, and the first farthest vertex
    /// of each piece).
    fn dp_reference(ring: &[DVec2], tol: f64) -> Vec<DVec2> {
        fn keep_in(ring: &[DVec2], s: usize, e: usize, tol2: f64, keep: &mut [bool]) {
            let (a, b) = (ring[s], ring[e % ring.len()]);
            let split = (s + 1..e)
                .map(|i| (segment_distance_sq(ring[i], a, b), i))
                .fold(
                    (0.0, 0),
                    |best, (d, i)| if d > best.0 { (d, i) } else { best },
                );
            if split.0 > tol2 {
                keep[split.1] = true;
                keep_in(ring, s, split.1, tol2, keep);
                keep_in(ring, split.1, e, tol2, keep);
            }
        }
        let mut far = ring.len() / 2;
        let mut far_d = f64::NEG_INFINITY;
        for (i, p) in ring.iter().enumerate().skip(1) {
            let d = (*p - ring[0]).length_squared();
            if d.total_cmp(&far_d).is_ge() {
                (far, far_d) = (i, d);
            }
        }
        let mut keep = vec![false; ring.len()];
        keep[0] = true;
        keep[far] = true;
        keep_in(ring, 0, far, tol * tol, &mut keep);
        keep_in(ring, far, ring.len(), tol * tol, &mut keep);
        ring.iter()
            .zip(keep)
            .filter_map(|(&p, k)| k.then_some(p))
            .collect()
    }

    #[test]
    fn splits_made_once_keep_what_douglas_peucker_keeps_at_each_tolerance() {
        let mut rng = crate::rng::Rng::new(3);
        for case in 0..200 {
            // Staircases on a 0.2 m grid (as traced footprints are), wobbly
            // stars, and rings with repeated and collinear vertices.
            let n = 5 + rng.below(400);
            let ring: Vec<DVec2> = (0..n)
                .map(|k| {
                    let a = k as f64 / n as f64 * std::f64::consts::TAU;
                    let r = 5.0 + 3.0 * rng.uniform();
                    let p = DVec2::new(r * a.cos(), r * a.sin());
                    match case % 3 {
                        0 => (p / 0.2).floor() * 0.2,
                        1 => p,
                        _ => DVec2::new((p.x * 2.0).round() * 0.5, p.y),
                    }
                })
                .collect();
            // The floor first, then tolerances above and below it (below
            // makes the splits again, deeper).
            let floor = 0.05 + 0.3 * rng.uniform();
            let mut splits = DouglasPeucker::new(&ring, floor);
            for tol in [
                floor,
                floor * 1.5,
                2.0,
                0.0,
                floor * 0.25,
                1e-9,
                f64::INFINITY,
            ] {
                assert_eq!(
                    splits.at(tol),
                    dp_reference(&ring, tol),
                    "case {case}, tol {tol}"
                );
            }
        }
        assert!(DouglasPeucker::new(&[], 0.1).at(0.1).is_empty());
        let one = [DVec2::ONE];
        assert_eq!(DouglasPeucker::new(&one, 0.1).at(0.1), one.to_vec());
    }

    /// Every pair of edges: the reference the bucketed test must agree with.
    fn is_simple_brute_force(ring: &[DVec2]) -> bool {
        let n = ring.len();
        if n < 3 || signed_area(ring).abs() <= 0.0 || ring.iter().any(|p| !p.is_finite()) {
            return false;
        }
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            if a == b {
                return false;
            }
            for j in (i + 1)..n {
                let (c, d) = (ring[j], ring[(j + 1) % n]);
                if j == i + 1 || (i == 0 && j == n - 1) {
                    let (shared, p, q) = if j == i + 1 { (b, a, d) } else { (a, b, c) };
                    if orient(p, shared, q) == 0.0 && (p - shared).dot(q - shared) > 0.0 {
                        return false;
                    }
                } else if segments_intersect(a, b, c, d) {
                    return false;
                }
            }
        }
        true
    }

    #[test]
    fn bucketed_simplicity_test_agrees_with_all_pairs() {
        let mut rng = crate::rng::Rng::new(5);
        let (mut simple, mut not) = (0, 0);
        for case in 0..400 {
            let n = 33 + rng.below(200);
            let ring: Vec<DVec2> = match case % 5 {
                // A comb: one long bottom edge, teeth on top; sometimes one
                // tooth reaches down to touch the long edge far from its
                // ends (the case a bucketing bug would miss).
                4 => {
                    let m = n / 4;
                    let deep = rng.below(2) == 0;
                    let hit = 1 + rng.below(m - 2);
                    let mut r = vec![DVec2::new(0.0, 0.0), DVec2::new(2.0 * m as f64, 0.0)];
                    for k in (0..m).rev() {
                        let x = 2.0 * k as f64;
                        let low = if deep && k == hit { 0.0 } else { 1.0 };
                        r.push(DVec2::new(x + 2.0, 3.0));
                        r.push(DVec2::new(x + 1.5, 3.0));
                        r.push(DVec2::new(x + 1.5, low));
                        r.push(DVec2::new(x + 0.5, low));
                        r.push(DVec2::new(x + 0.5, 3.0));
                    }
                    r.push(DVec2::new(0.0, 3.0));
                    r.dedup();
                    r
                }
                // Star-shaped around the origin: simple unless radii repeat.
                0 => (0..n)
                    .map(|k| {
                        let t = k as f64 / n as f64 * std::f64::consts::TAU;
                        let r = 1.0 + rng.below(100) as f64 / 50.0;
                        DVec2::new(r * t.cos(), r * t.sin())
                    })
                    .collect(),
                // Random walk on a coarse lattice: axis-aligned edges that
                // often touch or overlap (pinches, back-tracks).
                1 => {
                    let mut p = DVec2::ZERO;
                    (0..n)
                        .map(|_| {
                            let q = p;
                            let step = (1 + rng.below(3)) as f64;
                            match rng.below(4) {
                                0 => p.x += step,
                                1 => p.y += step,
                                2 => p.x -= step,
                                _ => p.y -= step,
                            }
                            q
                        })
                        .collect()
                }
                // A staircase (simple), sometimes with one vertex moved onto
                // another edge.
                2 => {
                    let m = n / 2;
                    let mut r: Vec<DVec2> = (0..m)
                        .flat_map(|k| {
                            let k = k as f64;
                            [DVec2::new(k, k), DVec2::new(k + 1.0, k)]
                        })
                        .collect();
                    r.push(DVec2::new(m as f64, m as f64 + 5.0));
                    r.push(DVec2::new(-1.0, m as f64 + 5.0));
                    if rng.below(2) == 0 {
                        let k = 2 * rng.below(m - 2) + 2;
                        r[k] = DVec2::new(r[k].x - 1.0, r[k].y);
                    }
                    r
                }
                // Uniform random points: almost never simple.
                _ => (0..n)
                    .map(|_| DVec2::new(rng.below(1000) as f64, rng.below(1000) as f64))
                    .collect(),
            };
            let expected = is_simple_brute_force(&ring);
            assert_eq!(is_simple(&ring), expected, "case {case}: {ring:?}");
            if expected {
                simple += 1;
            } else {
                not += 1;
            }
        }
        assert!(simple > 100 && not > 100, "{simple} simple, {not} not");
        // Extreme coordinates: the bucket grid cannot span them; the answer
        // must still be right.
        let far: Vec<DVec2> = (0..40)
            .map(|k| {
                let t = k as f64 / 40.0 * std::f64::consts::TAU;
                DVec2::new(1e308 * t.cos(), 1e308 * t.sin())
            })
            .collect();
        assert_eq!(is_simple(&far), is_simple_brute_force(&far));
    }

    fn square(s: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(s, 0.0),
            DVec2::new(s, s),
            DVec2::new(0.0, s),
        ]
    }

    #[test]
    fn area_contains_distance() {
        let sq = square(2.0);
        assert_eq!(signed_area(&sq), 4.0);
        assert!(contains(&sq, DVec2::new(1.0, 1.0)));
        assert!(!contains(&sq, DVec2::new(3.0, 1.0)));
        assert_eq!(distance(&sq, DVec2::new(1.0, 1.0)), 0.0);
        assert!((distance(&sq, DVec2::new(3.0, 1.0)) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn simplicity() {
        assert!(is_simple(&square(1.0)));
        let bowtie = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
        ];
        assert!(!is_simple(&bowtie));
        assert!(!is_simple(&[DVec2::ZERO, DVec2::X, DVec2::X * 2.0]));
    }

    #[test]
    fn simplify_keeps_shape_and_simplicity() {
        // A noisy circle.
        let ring: Vec<DVec2> = (0..400)
            .map(|i| {
                let t = i as f64 / 400.0 * std::f64::consts::TAU;
                let r = 10.0 + 0.01 * ((i * 7919) % 13) as f64;
                DVec2::new(r * libm::cos(t), r * libm::sin(t))
            })
            .collect();
        let s = simplify(&ring, 0.05, 64);
        assert!(s.len() <= 64 && s.len() >= 8, "{}", s.len());
        assert!(is_simple(&s));
        assert!((signed_area(&s) - signed_area(&ring)).abs() / signed_area(&ring) < 0.02);
    }

    #[test]
    fn polygon3_distance_and_orientation() {
        let verts = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
            DVec3::new(0.0, 4.0, 3.0),
            DVec3::new(0.0, 0.0, 3.0),
        ];
        let p = Polygon3::from_world(&verts).unwrap();
        assert!((p.plane().normal - DVec3::X).length() < 1e-12);
        assert!(signed_area(&p.ring) > 0.0);
        assert!((p.area() - 12.0).abs() < 1e-9);
        assert!((p.distance(DVec3::new(0.5, 1.0, 1.0)) - 0.5).abs() < 1e-12);
        assert!((p.distance(DVec3::new(0.0, 7.0, 7.0)) - 5.0).abs() < 1e-9);
        for (a, b) in p.vertices().iter().zip(&verts) {
            assert!((*a - *b).length() < 1e-9);
        }
    }

    /// The quick predicate answers as the full distance does: random star
    /// rings near each other (apart, touching, crossing, nested), over
    /// gaps from 0 to beyond their distance, and exactly at it.
    #[test]
    fn rings_within_is_ring_distance_below_the_gap() {
        let mut rng = crate::rng::Rng::new(11);
        let star = |rng: &mut crate::rng::Rng, c: DVec2| -> Vec<DVec2> {
            let k = 3 + rng.below(30);
            (0..k)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / k as f64;
                    let r = rng.range(0.3, 2.0);
                    c + DVec2::new(libm::cos(a), libm::sin(a)) * r
                })
                .collect()
        };
        let (mut near, mut apart) = (0, 0);
        for _ in 0..2000 {
            let a = star(&mut rng, DVec2::ZERO);
            let c = DVec2::new(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0));
            let b = star(&mut rng, c);
            let d = ring_distance(&a, &b);
            for gap in [0.0, 0.1, 0.3, 1.0, 3.0, d, d * 0.999, d * 1.001] {
                let within = rings_within(&a, &b, gap);
                assert_eq!(within, d <= gap, "d {d} gap {gap}");
                near += within as usize;
                apart += !within as usize;
            }
        }
        assert!(near > 1000 && apart > 1000, "{near} {apart}");
        assert!(!rings_within(&[DVec2::ZERO], &[DVec2::ONE; 3], 100.0));
    }
}
