//! Metrics of predicted polygons against ground-truth surfaces.
//!
//! Inputs are plain data: predicted [`Polygon3`]s (their index is their id),
//! ground-truth [`GtSurface`]s, and the observation points with, for each,
//! the id of the surface it was sampled from (`u32::MAX`, or any id that
//! names no surface, for clutter). The *observed* part of a surface is where
//! its labelled points fell. [`evaluate`] returns [`Metrics`]; lengths are in
//! metres, areas in square metres, defaults in [`EvalOptions`].
//!
//! # Definitions
//!
//! **Accuracy** is the one-sided Hausdorff distance from the predictions to
//! the ground truth, as in Oliveira et al. (2016, Table 4). Each prediction is
//! sampled at the centres of a square grid in its own frame (spacing
//! `sample_spacing`, 0.1 m; coarsened so that a polygon yields at most
//! `max_samples_per_polygon`, 200 000, grid samples; refined, down to a tenth
//! of the spacing, so that small polygons get about 16) and along its outline
//! (every vertex, then points at most `sample_spacing` apart). For each
//! sample the exact Euclidean distance to the nearest ground-truth polygon
//! (its closed planar region) is computed; candidate polygons are culled by
//! bounding boxes with exact lower and upper bounds, so the nearest is always
//! found. `mean` and `median` are over the grid samples, each weighted by the
//! area it stands for (`spacing^2`), hence area-weighted over all
//! predictions; `max` is over grid and outline samples.
//!
//! **Completeness**: each surface's labelled points are projected into its
//! frame and rasterised into square cells of `cell_size` (0.25 m); the
//! occupied cells are its observed area (each counts a full cell). A cell is
//! represented by the mean of its points projected on the surface's plane
//! (the cell centre could lie up to `cell_size / sqrt(2)` off the surface at
//! its edges); it is *covered* when that point is within
//! `completeness_tolerance` (0.1 m) of any predicted polygon, whatever its
//! orientation. Completeness is covered area over observed area, per surface
//! and over all surfaces together (area-weighted); 0 when nothing was
//! observed.
//!
//! **Recall**: a surface is *eligible* when its observed area is at least
//! `min_observed_area` (1 m^2, and non-zero). A cell is *matched* when its
//! representative point is within `found_tolerance` (0.15 m, exact
//! point-to-polygon distance: off the plane and beyond the outline both
//! count) of a prediction whose normal is within `max_normal_angle_deg`
//! (10 degrees, orientation ignored) of the surface's. An eligible surface is
//! *found* when the matched cells (the union over all matching predictions)
//! make at least `found_coverage` (0.5) of its observed area. Recall is
//! found over eligible surfaces, 0 when none is eligible.
//!
//! **Precision**: a grid sample of a prediction *lies on* a surface when it is
//! within `on_surface_tolerance` (0.15 m) of it and their normals match. A
//! prediction is a *true positive* when more than `true_positive_share` (0.5)
//! of its grid samples lie on one and the same surface. Precision is true
//! positives over predictions, 0 without predictions (a method that outputs
//! nothing does not score). Polygons too small to get a grid sample are
//! never true positives. `f1` is the harmonic mean of the two.
//!
//! **Duplicates**: two predictions form a duplicate pair when their normals
//! match, each one's area centroid is within `duplicate_plane_distance`
//! (0.08 m) of the other's plane, and their overlap is more than
//! `duplicate_min_overlap` (0.25 m^2). The overlap is estimated from the grid
//! samples of the smaller polygon whose projection on the larger one's plane
//! falls inside its outline.
//!
//! **Compactness** compares the polygons in a compact encoding — `f32`
//! `x, y, z` per vertex (12 bytes) plus the plane as four `f32` (16 bytes) per
//! polygon — with the input points as `f32` `x, y, z` (12 bytes each).
//!
//! **On the data** ([`on_data`], no ground truth needed, so it applies to
//! real scans) is the share of the predictions' area that has a point of the
//! cloud within a radius (3D Euclidean distance, inclusive): an outline that
//! stays on the data has every part of its area near some return; area far
//! from every point is space the polygon claims but nothing was seen in.
//! Each polygon is sampled at the centres of a square grid in its own frame
//! (spacing [`ON_DATA_SPACING`], 0.05 m; coarsened to at most
//! [`ON_DATA_MAX_SAMPLES`], 200 000, samples; refined for small polygons as
//! above); its share is the fraction of its samples near a point (of its
//! outline samples when it is too small for a grid sample). The total is
//! area-weighted: `sum(area_i * share_i) / sum(area_i)`.
//!
//! The evaluation is deterministic (no hashing, no threads, `libm` for the
//! transcendental functions) and does not panic: invalid inputs are errors.

mod accuracy;
mod coverage;
mod duplicates;
mod index;
mod metrics;
mod ondata;
mod options;
mod report;
mod sampling;
#[cfg(test)]
mod tests;

pub use metrics::{
    Accuracy, Compactness, Completeness, Detection, DuplicatePair, Duplicates, Metrics,
    PredictionReport, SurfaceReport, BYTES_PER_INPUT_POINT, BYTES_PER_POLYGON, BYTES_PER_VERTEX,
};
pub use ondata::{OnData, PolygonOnData, ON_DATA_MAX_SAMPLES, ON_DATA_SPACING};
pub use options::EvalOptions;

use crate::error::{Error, Result};
use crate::geometry::Polygon3;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Label of observation points that belong to no ground-truth surface.
pub const CLUTTER: u32 = u32::MAX;

/// A ground-truth planar surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GtSurface {
    /// Id that observation labels refer to; unique, not [`CLUTTER`].
    pub id: u32,
    /// The surface's extent.
    pub polygon: Polygon3,
}

/// Only the duplicate check of [`evaluate`] (cheap: no sampling of ground
/// truth), for checking a scenario after every scan.
pub fn duplicates(pred: &[Polygon3], opts: &EvalOptions) -> Duplicates {
    duplicates::find(pred, opts)
}

/// Share of the area of `polygons` that has a point of `points` within
/// `radius` metres (3D distance, inclusive), overall (area-weighted) and per
/// polygon. See the [module docs](self) for the sampling.
///
/// Total, never panics: non-finite points are ignored; a polygon with a
/// non-finite or non-orthonormal frame or a non-finite vertex counts with
/// area 0 and share 0; a negative or NaN `radius` counts as 0 (a point must
/// sit on a sample), an infinite one makes any point count. Without polygon
/// area the share is 1 (no area lies off the data); with area but without
/// points it is 0.
///
/// ```
/// use glam::DVec3;
/// use polyscene::geometry::Polygon3;
/// // A 1 x 1 m square at z = 0 and points every 0.1 m over it, 0.1 m above.
/// let square = Polygon3::from_world(&[
///     DVec3::new(0.0, 0.0, 0.0),
///     DVec3::new(1.0, 0.0, 0.0),
///     DVec3::new(1.0, 1.0, 0.0),
///     DVec3::new(0.0, 1.0, 0.0),
/// ])
/// .unwrap();
/// let above = |z: f64| -> Vec<DVec3> {
///     (0..100)
///         .map(|k| DVec3::new(0.05 + 0.1 * (k % 10) as f64, 0.05 + 0.1 * (k / 10) as f64, z))
///         .collect()
/// };
/// let on = polyscene::eval::on_data(&[square.clone()], &above(0.1), 0.2);
/// assert_eq!(on.share, 1.0);
/// assert_eq!(on.polygons[0].share, 1.0);
/// // The same points 0.5 m above the plane: none is within 0.2 m.
/// let off = polyscene::eval::on_data(&[square], &above(0.5), 0.2);
/// assert_eq!(off.share, 0.0);
/// ```
pub fn on_data(polygons: &[Polygon3], points: &[DVec3], radius: f64) -> OnData {
    ondata::measure(polygons, points, radius)
}

/// Evaluate predicted polygons `pred` against the ground truth `gt`, given
/// the observation `points` with their surface `labels` (one per point, a
/// surface id or [`CLUTTER`]) and the number of points of the input cloud
/// (`input_points`, for compactness only). See the [module docs](self) for
/// the definitions.
///
/// Errors when `points` and `labels` differ in length, a point, frame or
/// vertex is not finite, a frame is not orthonormal (tolerance 1e-6), a
/// surface id repeats or is [`CLUTTER`], or an option is out of range.
pub fn evaluate(
    pred: &[Polygon3],
    gt: &[GtSurface],
    points: &[DVec3],
    labels: &[u32],
    input_points: usize,
    opts: &EvalOptions,
) -> Result<Metrics> {
    opts.validate()?;
    check_inputs(pred, gt, points, labels)?;
    let (accuracy, predictions) = accuracy::measure(pred, gt, opts);
    let surfaces = coverage::measure(gt, pred, points, labels, opts);
    Ok(Metrics {
        options: opts.clone(),
        accuracy,
        completeness: coverage::completeness(&surfaces),
        detection: Detection::new(&predictions, &surfaces),
        duplicates: duplicates::find(pred, opts),
        compactness: Compactness::new(pred, input_points),
        surfaces,
        predictions,
    })
}

fn check_inputs(
    pred: &[Polygon3],
    gt: &[GtSurface],
    points: &[DVec3],
    labels: &[u32],
) -> Result<()> {
    if points.len() != labels.len() {
        return Err(Error::Invalid(format!(
            "{} observation points but {} labels: expected one label per point",
            points.len(),
            labels.len()
        )));
    }
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { point: i });
    }
    for (i, p) in pred.iter().enumerate() {
        check_polygon(p).map_err(|why| Error::Invalid(format!("prediction {i}: {why}")))?;
    }
    for (i, g) in gt.iter().enumerate() {
        check_polygon(&g.polygon).map_err(|why| {
            Error::Invalid(format!("ground-truth surface {i} (id {}): {why}", g.id))
        })?;
    }
    check_ids(gt)
}

/// Finite frame and ring, orthonormal frame.
fn check_polygon(p: &Polygon3) -> std::result::Result<(), &'static str> {
    let f = &p.frame;
    if ![f.origin, f.u, f.v, f.normal].iter().all(|v| v.is_finite()) {
        return Err("its frame has a NaN or infinite value");
    }
    if !p.ring.iter().all(|q| q.is_finite()) {
        return Err("its outline has a NaN or infinite vertex");
    }
    let unit = |v: DVec3| (v.length() - 1.0).abs() <= 1e-6;
    let orthogonal = f.u.dot(f.v).abs() <= 1e-6
        && f.u.dot(f.normal).abs() <= 1e-6
        && f.v.dot(f.normal).abs() <= 1e-6;
    if !(unit(f.u) && unit(f.v) && unit(f.normal) && orthogonal) {
        return Err("its frame is not orthonormal (tolerance 1e-6)");
    }
    Ok(())
}

fn check_ids(gt: &[GtSurface]) -> Result<()> {
    let mut ids: Vec<u32> = gt.iter().map(|g| g.id).collect();
    ids.sort_unstable();
    if ids.last() == Some(&CLUTTER) {
        return Err(Error::Invalid(format!(
            "ground-truth surface id {CLUTTER} is reserved for clutter"
        )));
    }
    if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
        return Err(Error::Invalid(format!(
            "ground-truth surface id {} is used twice; ids must be unique",
            w[0]
        )));
    }
    Ok(())
}
