//! The concave method: a primitive's outline is the discrete alpha hull of
//! its footprint, traced by [`Footprint::outline_region`] (see
//! [`crate::geometry::footprint`]): it follows concavities wider than
//! `2 * alpha`, keeps the largest connected region (the support outside it
//! is dropped) and is always simple. It grows by marking the new points'
//! cells and tracing again, so a merge carries no vertices (the footprints
//! merge), and one-shot detection ends by merging the pieces its
//! clustering split.

use crate::geometry::{Footprint, Frame, Region};
use glam::DVec2;

/// Expansion takes points near the outline only; the footprint grows.
pub(crate) const GROWS_BY_HULL: bool = false;

/// One-shot detection merges the pieces of one surface at the end.
pub(crate) const MERGES_DETECTED_PIECES: bool = true;

/// The footprint's alpha hull and the region of cells it was traced from.
pub(crate) fn outline(
    footprint: &Footprint,
    alpha: f64,
    tolerance: f64,
    max_vertices: usize,
    min_hole: f64,
) -> Option<(Vec<DVec2>, Region)> {
    footprint.outline_region(alpha, tolerance, max_vertices, min_hole)
}

/// The alpha hull of the footprint with the new points' cells marked, its
/// holes filled (a grown primitive is the scenario's, whose outlines keep
/// their holes: `CascadePolicy::cut_holes`).
pub(crate) fn grown(
    footprint: &Footprint,
    alpha: f64,
    tolerance: f64,
    max_vertices: usize,
) -> Option<Vec<DVec2>> {
    footprint.outline(alpha, tolerance, max_vertices, f64::INFINITY)
}

/// Nothing: the merged footprint holds the absorbed primitive's cells.
pub(crate) fn carried_vertices(_from: &Frame, _ring: &[DVec2], _into: &Frame) -> Vec<DVec2> {
    Vec::new()
}
