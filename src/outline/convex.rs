//! The convex method: a primitive's outline is the 2D convex hull of its
//! support (the paper's), capped at a number of vertices. It grows as the
//! hull of the old outline and the new points, so a merge carries the
//! absorbed outline's vertices over, and expansion reaches farther through
//! the hull of the outline and the points it took.

use crate::geometry::convex_hull;
use crate::geometry::polygon::simplify;
use crate::geometry::Frame;
use glam::DVec2;

/// Expansion grows by the hull of outline and taken points.
pub(crate) const GROWS_BY_HULL: bool = true;

/// One-shot detection's outlines need no final merge pass.
pub(crate) const MERGES_DETECTED_PIECES: bool = false;

/// The convex hull of `points`, capped at `max_vertices`; `None` for fewer
/// than three points or collinear ones.
pub(crate) fn outline(points: &[DVec2], tolerance: f64, max_vertices: usize) -> Option<Vec<DVec2>> {
    Some(cap(convex_hull(points)?, tolerance, max_vertices))
}

/// The hull of the old `outline` and the new points `extra`, capped.
pub(crate) fn grown(
    outline: &[DVec2],
    extra: &[DVec2],
    tolerance: f64,
    max_vertices: usize,
) -> Option<Vec<DVec2>> {
    let mut pts = outline.to_vec();
    pts.extend_from_slice(extra);
    convex_hull(&pts).map(|h| cap(h, tolerance, max_vertices))
}

/// The vertices of `ring` (frame `from`) in the frame `into`: the hull of
/// the merged primitive grows from them.
pub(crate) fn carried_vertices(from: &Frame, ring: &[DVec2], into: &Frame) -> Vec<DVec2> {
    ring.iter()
        .map(|&q| into.to_local(from.to_world(q)))
        .collect()
}

/// A hull of more than `max_vertices` vertices, simplified within
/// `tolerance` to at most that many.
fn cap(h: Vec<DVec2>, tolerance: f64, max_vertices: usize) -> Vec<DVec2> {
    if h.len() > max_vertices {
        simplify(&h, tolerance, max_vertices)
    } else {
        h
    }
}
