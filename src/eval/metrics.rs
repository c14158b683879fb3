//! The numbers [`evaluate`](super::evaluate) returns.

use super::options::EvalOptions;
use crate::geometry::Polygon3;
use serde::Serialize;

/// Bytes per polygon vertex in the compact encoding: `x, y, z` as `f32`.
pub const BYTES_PER_VERTEX: u64 = 12;
/// Bytes per polygon for its plane in the compact encoding: normal and
/// offset as four `f32`.
pub const BYTES_PER_POLYGON: u64 = 16;
/// Bytes per input point: `x, y, z` as `f32`.
pub const BYTES_PER_INPUT_POINT: u64 = 12;

/// Every metric of one evaluation, with the options used. Serialises to
/// JSON with `serde_json`; `Display` prints an aligned text report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Metrics {
    /// The options the metrics were computed with.
    pub options: EvalOptions,
    /// One-sided Hausdorff distance from the predictions to the ground truth.
    pub accuracy: Accuracy,
    /// Share of the observed ground truth near a prediction.
    pub completeness: Completeness,
    /// Plane-level precision and recall.
    pub detection: Detection,
    /// Overlapping near-coplanar prediction pairs.
    pub duplicates: Duplicates,
    /// Size of the polygons against the size of the input points.
    pub compactness: Compactness,
    /// One entry per ground-truth surface, in input order.
    pub surfaces: Vec<SurfaceReport>,
    /// One entry per prediction, in input order.
    pub predictions: Vec<PredictionReport>,
}

/// One-sided Hausdorff distance from the predicted polygons to the union of
/// the ground-truth surfaces, over dense samples of the predictions.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Accuracy {
    /// Number of grid (area) samples that found a ground-truth surface.
    pub area_samples: usize,
    /// Number of outline samples (they only enter `max`).
    pub boundary_samples: usize,
    /// Area (m^2) the area samples stand for (sum of `spacing^2`).
    pub sampled_area: f64,
    /// Area-weighted mean distance (m); `None` without samples.
    pub mean: Option<f64>,
    /// Area-weighted median distance (m); `None` without samples.
    pub median: Option<f64>,
    /// Largest distance (m) over area and outline samples; `None` without
    /// samples.
    pub max: Option<f64>,
}

/// Share of the observed ground-truth area within the completeness
/// tolerance of some prediction, all surfaces together.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Completeness {
    /// Observed area (m^2) of all surfaces (occupied cells).
    pub observed_area: f64,
    /// Covered part (m^2) of it.
    pub covered_area: f64,
    /// `covered_area / observed_area`, 0 when nothing was observed.
    pub completeness: f64,
}

/// Plane-level precision and recall.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Detection {
    /// Number of predicted polygons.
    pub predictions: usize,
    /// Predictions with more than the true-positive share of their area on
    /// one ground-truth surface.
    pub true_positives: usize,
    /// `true_positives / predictions`, 0 without predictions.
    pub precision: f64,
    /// Surfaces with at least the minimum observed area.
    pub eligible_surfaces: usize,
    /// Eligible surfaces found by the predictions.
    pub found_surfaces: usize,
    /// `found_surfaces / eligible_surfaces`, 0 without eligible surfaces.
    pub recall: f64,
    /// Harmonic mean of precision and recall, 0 when both are 0.
    pub f1: f64,
}

impl Detection {
    /// Counts and ratios from the per-prediction and per-surface reports.
    pub(crate) fn new(predictions: &[PredictionReport], surfaces: &[SurfaceReport]) -> Self {
        let true_positives = predictions.iter().filter(|p| p.true_positive).count();
        let eligible_surfaces = surfaces.iter().filter(|s| s.eligible).count();
        let found_surfaces = surfaces.iter().filter(|s| s.found).count();
        let precision = ratio(true_positives as f64, predictions.len() as f64);
        let recall = ratio(found_surfaces as f64, eligible_surfaces as f64);
        Detection {
            predictions: predictions.len(),
            true_positives,
            precision,
            eligible_surfaces,
            found_surfaces,
            recall,
            f1: ratio(2.0 * precision * recall, precision + recall),
        }
    }
}

/// Two near-coplanar predictions whose outlines overlap.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DuplicatePair {
    /// Index of the first prediction.
    pub first: usize,
    /// Index of the second prediction (`> first`).
    pub second: usize,
    /// Angle (degrees) between their normals, orientation ignored.
    pub angle_deg: f64,
    /// Estimated overlap area (m^2).
    pub overlap_area: f64,
}

/// Overlapping near-coplanar prediction pairs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Duplicates {
    /// Number of pairs.
    pub count: usize,
    /// The pairs, ordered by `(first, second)`.
    pub pairs: Vec<DuplicatePair>,
}

/// Size of the polygon map against the size of the input points.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Compactness {
    /// Number of polygons.
    pub polygons: usize,
    /// Total number of outline vertices.
    pub vertices: usize,
    /// Bytes of the polygons in the compact encoding:
    /// [`BYTES_PER_VERTEX`] per vertex plus [`BYTES_PER_POLYGON`] per polygon.
    pub polygon_bytes: u64,
    /// Number of input points (as given by the caller).
    pub input_points: usize,
    /// Bytes of the input points, [`BYTES_PER_INPUT_POINT`] each.
    pub input_bytes: u64,
    /// `polygon_bytes / input_bytes`; `None` without input points.
    pub ratio: Option<f64>,
}

impl Compactness {
    /// Sizes of `polygons` against `input_points` points.
    pub fn new(polygons: &[Polygon3], input_points: usize) -> Self {
        let vertices: usize = polygons.iter().map(|p| p.ring.len()).sum();
        let polygon_bytes = (vertices as u64)
            .saturating_mul(BYTES_PER_VERTEX)
            .saturating_add((polygons.len() as u64).saturating_mul(BYTES_PER_POLYGON));
        let input_bytes = (input_points as u64).saturating_mul(BYTES_PER_INPUT_POINT);
        Compactness {
            polygons: polygons.len(),
            vertices,
            polygon_bytes,
            input_points,
            input_bytes,
            ratio: (input_bytes > 0).then(|| polygon_bytes as f64 / input_bytes as f64),
        }
    }
}

/// What the evaluation found for one ground-truth surface.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SurfaceReport {
    /// The surface's id.
    pub id: u32,
    /// Number of observation points labelled with it.
    pub points: usize,
    /// Observed area (m^2): occupied cells times the cell area.
    pub observed_area: f64,
    /// Observed area (m^2) within the completeness tolerance of any prediction.
    pub covered_area: f64,
    /// `covered_area / observed_area`, 0 when nothing was observed.
    pub completeness: f64,
    /// Observed area (m^2) within the found tolerance of a prediction with a
    /// matching normal (union over predictions).
    pub matched_area: f64,
    /// `matched_area / observed_area`, 0 when nothing was observed.
    pub matched_coverage: f64,
    /// Does the surface count for recall (enough observed area)?
    pub eligible: bool,
    /// Is it eligible and matched over at least the found coverage?
    pub found: bool,
    /// Predictions that matched at least one of its cells, ascending.
    pub matching_predictions: Vec<usize>,
}

/// What the evaluation found for one prediction.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PredictionReport {
    /// Index in the prediction slice.
    pub index: usize,
    /// Area (m^2) of the outline.
    pub area: f64,
    /// Number of outline vertices.
    pub vertices: usize,
    /// Grid spacing (m) its samples were taken at.
    pub spacing: f64,
    /// Number of grid (area) samples.
    pub samples: usize,
    /// Mean distance (m) of its area samples to the ground truth.
    pub mean_distance: Option<f64>,
    /// Largest distance (m) of its area and outline samples.
    pub max_distance: Option<f64>,
    /// The ground-truth surface holding most of its samples, if any.
    pub surface: Option<u32>,
    /// Share of its area samples lying on `surface`.
    pub on_surface_share: f64,
    /// Is `on_surface_share` above the true-positive share?
    pub true_positive: bool,
}

/// `num / den`, 0 when `den` is 0.
pub(crate) fn ratio(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}
