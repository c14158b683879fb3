//! The sensor model: a spinning multi-beam LiDAR, by default a Velodyne
//! HDL-64E.

use crate::error::{Error, Result};

/// Elevation angles in degrees of the 64 lasers of a Velodyne HDL-64E, from
/// the top: the upper block from +2.0° down to -8.33° in 1/3° steps, the lower
/// block from -8.87° down to -24.87° in 16/31° (about 0.516°) steps.
pub fn hdl64_elevations_deg() -> Vec<f64> {
    let upper = (0..32).map(|i| 2.0 - i as f64 / 3.0);
    let lower = (0..32).map(|i| -8.87 - i as f64 * 16.0 / 31.0);
    upper.chain(lower).collect()
}

/// Most rays per scan a [`SensorModel`] may have (lasers × azimuth steps).
pub const MAX_RAYS: usize = 10_000_000;

/// A spinning multi-beam LiDAR: one column of lasers at fixed elevations,
/// fired at `azimuth_steps` evenly spaced azimuths per turn. A scan is
/// instantaneous (no motion distortion) and every laser returns the nearest
/// surface along its ray.
///
/// The sensor frame is x forward, y left, z up; column `j` is at azimuth
/// `2π j / azimuth_steps` counter-clockwise from +x.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SensorModel {
    /// Laser elevation angles in degrees above the horizontal, one per laser,
    /// in output order; default: the 64 HDL-64E angles, +2.0° to -24.87°
    /// ([`hdl64_elevations_deg`]).
    pub elevations_deg: Vec<f64>,
    /// Azimuth steps per turn (columns per scan), count; default 2000 (0.18°).
    pub azimuth_steps: usize,
    /// Height of the sensor's origin above the road surface, metres; default 1.8.
    pub mount_height: f64,
    /// Minimum range, metres: nearer returns are lost; default 0.9.
    pub min_range: f64,
    /// Maximum range, metres: farther returns are lost; default 120.
    pub max_range: f64,
    /// Standard deviation of the Gaussian noise added to each range, metres;
    /// default 0.02.
    pub range_sigma: f64,
    /// Probability that a return is randomly lost, in `[0, 1]`; default 0.05.
    pub dropout: f64,
    /// Standard deviation of the (uniform) noise added to each intensity, in
    /// intensity units (intensities are in `[0, 1]`); default 0.02.
    pub intensity_sigma: f64,
}

impl Default for SensorModel {
    fn default() -> Self {
        SensorModel {
            elevations_deg: hdl64_elevations_deg(),
            azimuth_steps: 2000,
            mount_height: 1.8,
            min_range: 0.9,
            max_range: 120.0,
            range_sigma: 0.02,
            dropout: 0.05,
            intensity_sigma: 0.02,
        }
    }
}

impl SensorModel {
    /// The default Velodyne HDL-64E (same as [`Default`]).
    pub fn hdl64() -> Self {
        Self::default()
    }

    /// The HDL-64E without any randomness: no range noise, no dropout, no
    /// intensity noise. Every point lies exactly on the surface it hit.
    pub fn noise_free() -> Self {
        Self::default().without_noise()
    }

    /// This model with range noise, dropout and intensity noise set to zero.
    pub fn without_noise(mut self) -> Self {
        self.range_sigma = 0.0;
        self.dropout = 0.0;
        self.intensity_sigma = 0.0;
        self
    }

    /// Number of lasers.
    pub fn lasers(&self) -> usize {
        self.elevations_deg.len()
    }

    /// Rays per scan (`lasers × azimuth_steps`, saturating): an upper bound
    /// on points.
    pub fn rays(&self) -> usize {
        self.lasers().saturating_mul(self.azimuth_steps)
    }

    /// Check every field's range; the error names the field.
    pub fn validate(&self) -> Result<()> {
        let bad = |key: &str, reason: String| {
            Err(Error::BadOption {
                key: key.into(),
                reason,
            })
        };
        let n = self.elevations_deg.len();
        if n == 0 || n > 1024 {
            return bad(
                "elevations_deg",
                format!("expected 1 to 1024 lasers, got {n}"),
            );
        }
        if let Some(e) = self
            .elevations_deg
            .iter()
            .find(|e| !(e.is_finite() && e.abs() < 89.0))
        {
            return bad(
                "elevations_deg",
                format!("elevation {e} is not a finite angle within ±89 degrees"),
            );
        }
        if !(1..=100_000).contains(&self.azimuth_steps) {
            return bad(
                "azimuth_steps",
                format!("expected 1 to 100000, got {}", self.azimuth_steps),
            );
        }
        if self.rays() > MAX_RAYS {
            return bad(
                "azimuth_steps",
                format!(
                    "{} lasers × {} azimuth steps is more than {MAX_RAYS} rays per scan",
                    n, self.azimuth_steps
                ),
            );
        }
        let in_range = |v: f64, lo: f64, hi: f64| v.is_finite() && v >= lo && v <= hi;
        if !in_range(self.mount_height, 0.2, 10.0) {
            return bad(
                "mount_height",
                format!("expected 0.2 to 10 metres, got {}", self.mount_height),
            );
        }
        if !in_range(self.min_range, 0.0, 100.0) {
            return bad(
                "min_range",
                format!("expected 0 to 100 metres, got {}", self.min_range),
            );
        }
        if !in_range(self.max_range, 1.0, 1000.0) || self.max_range <= self.min_range {
            return bad(
                "max_range",
                format!(
                    "expected 1 to 1000 metres and more than min_range ({}), got {}",
                    self.min_range, self.max_range
                ),
            );
        }
        if !in_range(self.range_sigma, 0.0, 1.0) {
            return bad(
                "range_sigma",
                format!("expected 0 to 1 metre, got {}", self.range_sigma),
            );
        }
        if !in_range(self.dropout, 0.0, 1.0) {
            return bad(
                "dropout",
                format!("expected a probability in [0, 1], got {}", self.dropout),
            );
        }
        if !in_range(self.intensity_sigma, 0.0, 1.0) {
            return bad(
                "intensity_sigma",
                format!("expected 0 to 1, got {}", self.intensity_sigma),
            );
        }
        Ok(())
    }
}

/// Precomputed ray directions of a [`SensorModel`]: azimuth cosines and sines
/// per column, and the lasers sorted by descending elevation (the caster needs
/// them sorted to find the lasers crossing a segment by bisection).
#[derive(Clone, Debug)]
pub(crate) struct Beams {
    /// Cosine of each column's sensor-frame azimuth.
    pub az_cos: Vec<f64>,
    /// Sine of each column's sensor-frame azimuth.
    pub az_sin: Vec<f64>,
    /// Cosine of each laser's elevation, sorted by descending elevation.
    pub cos: Vec<f64>,
    /// Sine of each laser's elevation, sorted by descending elevation.
    pub sin: Vec<f64>,
    /// Tangent of each laser's elevation, sorted by descending elevation.
    pub tan: Vec<f64>,
    /// For each laser in output order, its index in the sorted arrays.
    pub rank: Vec<usize>,
}

impl Beams {
    /// Tables for a validated sensor model.
    pub fn new(sensor: &SensorModel) -> Self {
        let n = sensor.azimuth_steps.max(1);
        let (mut az_cos, mut az_sin) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for j in 0..n {
            let a = std::f64::consts::TAU * j as f64 / n as f64;
            az_cos.push(libm::cos(a));
            az_sin.push(libm::sin(a));
        }
        let el: Vec<f64> = sensor
            .elevations_deg
            .iter()
            .map(|d| d.to_radians())
            .collect();
        let mut order: Vec<usize> = (0..el.len()).collect();
        // Descending elevation; ties keep output order (stable sort).
        crate::geometry::insertion_sort_by(&mut order, |&a, &b| el[b].total_cmp(&el[a]));
        let mut rank = vec![0; el.len()];
        for (k, &l) in order.iter().enumerate() {
            rank[l] = k;
        }
        let cos = order.iter().map(|&l| libm::cos(el[l])).collect();
        let sin = order.iter().map(|&l| libm::sin(el[l])).collect();
        let tan = order.iter().map(|&l| libm::tan(el[l])).collect();
        Beams {
            az_cos,
            az_sin,
            cos,
            sin,
            tan,
            rank,
        }
    }

    /// Number of lasers.
    pub fn lasers(&self) -> usize {
        self.cos.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hdl64_angles_and_validation() {
        let s = SensorModel::default();
        assert_eq!(s.lasers(), 64);
        let e = &s.elevations_deg;
        assert!((e[0] - 2.0).abs() < 1e-12);
        assert!((e[31] + 8.333).abs() < 1e-3);
        assert!((e[32] + 8.87).abs() < 1e-12);
        assert!((e[63] + 24.87).abs() < 1e-9);
        assert!(e.windows(2).all(|w| w[0] > w[1]));
        assert!(s.validate().is_ok());
        assert!(SensorModel::noise_free().validate().is_ok());
        let mut bad = SensorModel {
            dropout: 1.5,
            ..SensorModel::default()
        };
        assert!(matches!(bad.validate(), Err(Error::BadOption { key, .. }) if key == "dropout"));
        bad = SensorModel::default();
        bad.elevations_deg.clear();
        assert!(bad.validate().is_err());
        bad = SensorModel::default();
        bad.max_range = 0.5;
        assert!(bad.validate().is_err());
        bad = SensorModel::default();
        bad.azimuth_steps = 100_000;
        bad.elevations_deg = vec![0.0; 200];
        assert!(bad.validate().is_err());
        bad = SensorModel::default();
        bad.range_sigma = f64::NAN;
        assert!(bad.validate().is_err());
    }

    #[test]
    fn beams_are_sorted_and_ranked() {
        let s = SensorModel {
            elevations_deg: vec![-5.0, 1.0, -20.0, 0.0],
            ..SensorModel::default()
        };
        let b = Beams::new(&s);
        assert!(b.sin.windows(2).all(|w| w[0] >= w[1]));
        assert_eq!(b.rank, vec![2, 0, 3, 1]);
        assert_eq!(b.az_cos.len(), 2000);
    }
}
