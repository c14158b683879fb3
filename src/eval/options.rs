//! Tolerances and sampling densities of the evaluation.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Tolerances and sampling densities of [`evaluate`](super::evaluate). All
/// lengths are in metres, areas in square metres, angles in degrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EvalOptions {
    /// Grid spacing (m) of the samples taken on every predicted polygon, and
    /// of the samples along its outline. Default `0.1`.
    pub sample_spacing: f64,
    /// Most grid samples per predicted polygon: a polygon larger than
    /// `max_samples_per_polygon * sample_spacing^2` gets a coarser grid (its
    /// spacing becomes `sqrt(area / max_samples_per_polygon)`); its outline
    /// samples are capped the same way. Default `200_000`.
    pub max_samples_per_polygon: usize,
    /// Side (m) of the square cells that rasterise the labelled points of a
    /// ground-truth surface in its own frame: the occupied cells are the
    /// observed area. Default `0.25`.
    pub cell_size: f64,
    /// Completeness: an observed cell counts as covered when its
    /// representative point is within this distance (m) of any predicted
    /// polygon. Default `0.1`.
    pub completeness_tolerance: f64,
    /// Largest angle (degrees) between two normals that still "match",
    /// orientation ignored. Used by recall, precision and duplicates.
    /// Default `10`.
    pub max_normal_angle_deg: f64,
    /// Recall: an observed cell of a surface is covered by a matching
    /// prediction when it is within this distance (m) of a predicted polygon
    /// whose normal matches. Default `0.15`.
    pub found_tolerance: f64,
    /// Recall: the share of a surface's observed area that matching
    /// predictions must cover (union) for the surface to be found.
    /// Default `0.5`.
    pub found_coverage: f64,
    /// Recall: surfaces with less observed area (m^2) are not counted.
    /// Default `1.0`.
    pub min_observed_area: f64,
    /// Precision: a sample of a predicted polygon lies on a ground-truth
    /// surface when it is within this distance (m) of it and the normals
    /// match. Default `0.15`.
    pub on_surface_tolerance: f64,
    /// Precision: a prediction is a true positive when more than this share
    /// of its area lies on one ground-truth surface. Default `0.5`.
    pub true_positive_share: f64,
    /// Duplicates: each polygon's area centroid must be within this distance
    /// (m) of the other's plane. Default `0.08`: parallel surfaces one curb
    /// apart (0.15 m, a road and its sidewalk) or two neighbouring car roofs
    /// of different heights are distinct surfaces, not duplicates, even where
    /// their outlines overlap in plan view by the outline resolution.
    pub duplicate_plane_distance: f64,
    /// Duplicates: smallest overlap area (m^2) of two near-coplanar polygons
    /// reported as a duplicate pair. Default `0.25`.
    pub duplicate_min_overlap: f64,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            sample_spacing: 0.1,
            max_samples_per_polygon: 200_000,
            cell_size: 0.25,
            completeness_tolerance: 0.1,
            max_normal_angle_deg: 10.0,
            found_tolerance: 0.15,
            found_coverage: 0.5,
            min_observed_area: 1.0,
            on_surface_tolerance: 0.15,
            true_positive_share: 0.5,
            duplicate_plane_distance: 0.08,
            duplicate_min_overlap: 0.25,
        }
    }
}

fn bad(key: &str, reason: &str) -> Error {
    Error::BadOption {
        key: key.into(),
        reason: reason.into(),
    }
}

fn positive(key: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(bad(key, &format!("must be a finite number > 0, got {v}")))
    }
}

fn non_negative(key: &str, v: f64) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(bad(key, &format!("must be a finite number >= 0, got {v}")))
    }
}

fn share(key: &str, v: f64) -> Result<()> {
    if (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(bad(key, &format!("must be in [0, 1], got {v}")))
    }
}

impl EvalOptions {
    /// Check every field's range: spacings and sizes finite and > 0,
    /// tolerances finite and >= 0, shares in `[0, 1]`, the angle in
    /// `[0, 90]` degrees, at least one sample per polygon.
    pub fn validate(&self) -> Result<()> {
        positive("sample_spacing", self.sample_spacing)?;
        positive("cell_size", self.cell_size)?;
        if self.max_samples_per_polygon == 0 {
            return Err(bad("max_samples_per_polygon", "must be at least 1"));
        }
        non_negative("completeness_tolerance", self.completeness_tolerance)?;
        non_negative("found_tolerance", self.found_tolerance)?;
        non_negative("min_observed_area", self.min_observed_area)?;
        non_negative("on_surface_tolerance", self.on_surface_tolerance)?;
        non_negative("duplicate_plane_distance", self.duplicate_plane_distance)?;
        non_negative("duplicate_min_overlap", self.duplicate_min_overlap)?;
        share("found_coverage", self.found_coverage)?;
        share("true_positive_share", self.true_positive_share)?;
        if !(0.0..=90.0).contains(&self.max_normal_angle_deg) {
            return Err(bad(
                "max_normal_angle_deg",
                &format!(
                    "must be in [0, 90] degrees, got {}",
                    self.max_normal_angle_deg
                ),
            ));
        }
        Ok(())
    }

    /// Cosine of [`max_normal_angle_deg`](Self::max_normal_angle_deg): two
    /// unit normals match when `|a · b| >= cos_max_angle()`.
    pub(crate) fn cos_max_angle(&self) -> f64 {
        libm::cos(self.max_normal_angle_deg.to_radians())
    }
}

/// Do two unit normals agree within the angle whose cosine is `cos_max`,
/// orientation ignored?
#[inline]
pub(crate) fn normals_match(a: glam::DVec3, b: glam::DVec3, cos_max: f64) -> bool {
    a.dot(b).abs() >= cos_max
}
