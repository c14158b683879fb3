//! Outline methods: how a primitive's outline is computed, grown and
//! merged. One file per method ([`HullKind::Convex`] in `convex.rs`,
//! [`HullKind::Concave`] in `concave.rs`), as geo keeps its `convex_hull`
//! and `concave_hull` apart.
//!
//! [`HullKind`] is a plain enum (it is a parameter: serialised as
//! `"convex"` / `"concave"`, and also reachable as `crate::params::HullKind`)
//! whose methods answer what the rest of the code asks of a method:
//!
//! - `HullKind::outline`: the outline of a new primitive's support, and
//!   the raster region it keeps points in (if it drops any);
//! - `HullKind::grown`: the outline after the primitive gained points;
//! - `HullKind::grows_by_hull`: does expansion reach farther through the
//!   hull of the outline and the points taken (or only through the
//!   footprint raster)?
//! - `HullKind::carried_vertices`: what a merge carries over of the
//!   absorbed primitive's outline;
//! - `HullKind::merges_detected_pieces`: does one-shot detection end with
//!   a pass that merges the pieces it found?
//!
//! Each method is a `match` that calls the method's file, so the dispatch
//! costs one branch on a `Copy` enum and the calls run exactly the float
//! operations the inlined code ran before. A trait (one type per method)
//! would need the method chosen at compile time or a `dyn` object behind
//! the parameter, while the choice is a run-time option of the page and the
//! command line. Adding a method: a file here, a variant, an arm in each
//! method below, and the name in the option lists (`build.rs`'s TypeScript
//! type and the page's options).
//!
//! The algorithms the methods build on stay where the rest of the crate
//! uses them too: the convex hull and polygon simplification in
//! [`crate::geometry`], the footprint (a primitive's occupancy raster, kept
//! by both methods and serialised in snapshots) and its alpha-hull tracing
//! in [`crate::geometry::footprint`], the bit raster in `crate::raster`.
//! This module imports geometry; nothing it imports imports it back.

mod concave;
mod convex;

use crate::geometry::{Footprint, Frame, Region};
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// How a primitive's outline is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HullKind {
    /// 2D convex hull of the support (the paper's default). Over-covers
    /// L-shaped and partly occluded surfaces.
    Convex,
    /// Discrete alpha hull of the support's occupancy raster: follows
    /// concavities wider than `2 * alpha`. Always a simple polygon.
    Concave,
}

impl HullKind {
    /// Outline of a new primitive whose support points near the plane are
    /// `points` (frame coordinates) and whose footprint is `footprint`:
    /// closing radius `alpha`, simplification `tolerance` (metres), at most
    /// `max_vertices` vertices, holes of at least `min_hole` square metres
    /// left out (concave; see [`Footprint::outline_region`]). With the outline, the region of footprint
    /// cells it was traced from when the method keeps only the points in
    /// it (concave: the largest connected region), `None` when it keeps
    /// them all. `None` when no outline exists.
    pub(crate) fn outline(
        self,
        points: &[DVec2],
        footprint: &Footprint,
        alpha: f64,
        tolerance: f64,
        max_vertices: usize,
        min_hole: f64,
    ) -> Option<(Vec<DVec2>, Option<Region>)> {
        match self {
            HullKind::Convex => Some((convex::outline(points, tolerance, max_vertices)?, None)),
            HullKind::Concave => {
                let (ring, region) =
                    concave::outline(footprint, alpha, tolerance, max_vertices, min_hole)?;
                Some((ring, Some(region)))
            }
        }
    }

    /// The outline of a primitive that gained support: `outline` is its
    /// current one, `extra` the new points (frame coordinates; the convex
    /// hull grows from them) and `footprint` its footprint with their cells
    /// already marked (the concave outline is traced from it again).
    /// Arguments as for [`HullKind::outline`]; `None` when no outline exists.
    pub(crate) fn grown(
        self,
        outline: &[DVec2],
        extra: &[DVec2],
        footprint: &Footprint,
        alpha: f64,
        tolerance: f64,
        max_vertices: usize,
    ) -> Option<Vec<DVec2>> {
        match self {
            HullKind::Convex => convex::grown(outline, extra, tolerance, max_vertices),
            HullKind::Concave => concave::grown(footprint, alpha, tolerance, max_vertices),
        }
    }

    /// Does expansion grow the region it takes points near by the hull of
    /// the outline and the points taken (repeating until nothing more is
    /// taken), as the paper does? Otherwise the outline alone decides.
    pub(crate) fn grows_by_hull(self) -> bool {
        match self {
            HullKind::Convex => convex::GROWS_BY_HULL,
            HullKind::Concave => concave::GROWS_BY_HULL,
        }
    }

    /// What merging a primitive into another carries over of its outline
    /// (`ring` in frame `from`), as points in the frame `into` of the
    /// primitive that absorbs it: the vertices (the convex hull grows from
    /// them), or none (the concave outline is traced from the merged
    /// footprint).
    pub(crate) fn carried_vertices(self, from: &Frame, ring: &[DVec2], into: &Frame) -> Vec<DVec2> {
        match self {
            HullKind::Convex => convex::carried_vertices(from, ring, into),
            HullKind::Concave => concave::carried_vertices(from, ring, into),
        }
    }

    /// Does one-shot detection end with a pass that merges the pieces of
    /// one surface it found apart (concave outlines, whose clustering
    /// splits what the outline would join)?
    pub(crate) fn merges_detected_pieces(self) -> bool {
        match self {
            HullKind::Convex => convex::MERGES_DETECTED_PIECES,
            HullKind::Concave => concave::MERGES_DETECTED_PIECES,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::HullKind;
    use crate::geometry::{Footprint, Frame, Plane};
    use glam::{DVec2, DVec3};

    #[test]
    fn serialised_by_lowercase_name_and_reachable_from_params() {
        let kind: crate::params::HullKind = HullKind::Concave;
        assert_eq!(serde_json::to_string(&kind).unwrap(), "\"concave\"");
        assert_eq!(
            serde_json::from_str::<HullKind>("\"convex\"").unwrap(),
            HullKind::Convex
        );
        assert!(serde_json::from_str::<HullKind>("\"Convex\"").is_err());
    }

    #[test]
    fn each_method_answers_for_itself() {
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let mut fp = Footprint::new(0.25);
        let cells: Vec<DVec2> = (0..16)
            .map(|k| DVec2::new((k % 4) as f64 * 0.25 + 0.1, (k / 4) as f64 * 0.25 + 0.1))
            .collect();
        fp.mark_all(&cells);
        let (ring, region) = HullKind::Convex
            .outline(&square, &fp, 0.5, 0.0, 64, f64::INFINITY)
            .unwrap();
        assert_eq!((ring.len(), region.is_none()), (4, true));
        let (ring, region) = HullKind::Concave
            .outline(&square, &fp, 0.5, 0.0, 64, f64::INFINITY)
            .unwrap();
        assert!(ring.len() >= 4 && region.unwrap().contains(DVec2::splat(0.5)));
        // Growing: the convex hull from the new points, the concave outline
        // from the footprint only.
        let far = [DVec2::new(3.0, 0.5)];
        let grown = HullKind::Convex.grown(&square, &far, &fp, 0.5, 0.0, 64);
        assert!(grown.unwrap().contains(&far[0]));
        let traced = HullKind::Concave.grown(&square, &far, &fp, 0.5, 0.0, 64);
        assert!(!traced.unwrap().contains(&far[0]));
        let frame = Frame::on_plane(
            &Plane::from_point_normal(DVec3::ZERO, DVec3::Z),
            DVec3::ZERO,
        );
        assert_eq!(
            HullKind::Convex
                .carried_vertices(&frame, &square, &frame)
                .len(),
            4
        );
        assert!(HullKind::Concave
            .carried_vertices(&frame, &square, &frame)
            .is_empty());
        assert!(HullKind::Convex.grows_by_hull() && !HullKind::Concave.grows_by_hull());
        assert!(HullKind::Concave.merges_detected_pieces());
        assert!(!HullKind::Convex.merges_detected_pieces());
    }
}
