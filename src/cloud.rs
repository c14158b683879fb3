//! Point clouds as the pipeline sees them: f32 coordinates relative to an f64
//! origin, so that map coordinates (UTM is ~10^6 m) keep millimetre precision.

use crate::error::{Error, Result};
use glam::{DMat4, DVec3, Vec3};

/// Largest world coordinate accepted (m): beyond any geodetic frame (the
/// Earth's radius is 6.4e6 m), and small enough that every derived length,
/// area and grid index stays finite and exact enough.
pub const MAX_COORDINATE: f64 = 1e9;

/// Most points one cloud (a scan, or a cloud given to detection) may hold:
/// 2^24 = 16,777,216. Processing takes about 100 bytes a point at its
/// peak (a scan at the limit: 1.84 GB resident in Node, the input
/// included), so a cloud at the limit fits in the 4 GiB of a wasm instance
/// with room for the map; beyond it the input is refused before anything
/// is allocated, rather than running out of memory part-way.
pub const MAX_POINTS: usize = 1 << 24;

/// [`Error::TooManyPoints`] when `points` exceeds [`MAX_POINTS`].
pub fn check_count(points: usize) -> Result<()> {
    if points > MAX_POINTS {
        return Err(Error::TooManyPoints {
            points,
            limit: MAX_POINTS,
        });
    }
    Ok(())
}

/// The first point whose world coordinates lie beyond [`MAX_COORDINATE`].
fn check_range(points: impl Iterator<Item = DVec3>) -> Result<()> {
    for (i, p) in points.enumerate() {
        if p.abs().max_element() > MAX_COORDINATE {
            return Err(Error::OutOfRange {
                point: i,
                limit: MAX_COORDINATE,
            });
        }
    }
    Ok(())
}

/// Check that a flat buffer has a valid stride and finite x, y, z; returns
/// the largest absolute coordinate.
pub fn check_finite(values: &[f32], stride: usize) -> Result<f32> {
    if stride != 3 && stride != 4 {
        return Err(Error::BadStride(stride));
    }
    if values.len() % stride != 0 {
        return Err(Error::BadLength {
            len: values.len(),
            stride,
        });
    }
    check_count(values.len() / stride)?;
    largest_coordinate(values, stride)
}

/// The largest absolute coordinate of the points (checked as in
/// [`check_finite`], whose checks the caller has made on stride and length).
fn largest_coordinate(values: &[f32], stride: usize) -> Result<f32> {
    let mut largest = 0.0f32;
    for (i, p) in values.chunks_exact(stride).enumerate() {
        if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
            return Err(Error::NonFinite { point: i });
        }
        let m = p[0].abs().max(p[1].abs()).max(p[2].abs());
        if m > largest {
            largest = m;
        }
    }
    Ok(largest)
}

/// Check that `m` is a rigid transform: finite, orthonormal rotation with
/// determinant +1 (tolerance 1e-4), bottom row `0 0 0 1`.
pub fn check_rigid(m: &DMat4) -> Result<()> {
    let a = m.to_cols_array();
    if a.iter().any(|v| !v.is_finite()) {
        return Err(Error::BadPose("it has a NaN or infinite entry".into()));
    }
    if a[3] != 0.0 || a[7] != 0.0 || a[11] != 0.0 || (a[15] - 1.0).abs() > 1e-9 {
        return Err(Error::BadPose("its bottom row must be 0 0 0 1".into()));
    }
    let r = glam::DMat3::from_mat4(*m);
    let rtr = r.transpose() * r;
    let dev = (rtr - glam::DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |acc, v| acc.max(v.abs()));
    if dev > 1e-4 {
        return Err(Error::BadPose(format!(
            "its rotation part is not orthonormal (max |R^T R - I| = {dev:.3e}); \
             scaling or shear is not allowed"
        )));
    }
    if r.determinant() < 0.0 {
        return Err(Error::BadPose(
            "its rotation is a reflection (determinant -1)".into(),
        ));
    }
    Ok(())
}

/// A cloud in a local frame: world point `i` is `origin + points[i]`.
#[derive(Clone, Debug, Default)]
pub struct Cloud {
    /// Local origin in world coordinates (metres).
    pub origin: DVec3,
    /// Coordinates relative to `origin` (metres).
    pub points: Vec<Vec3>,
}

impl Cloud {
    /// From world coordinates in f64. The origin is the centre of the bounding
    /// box rounded to whole metres, so translated copies of a cloud get the
    /// same local coordinates.
    pub fn from_world_f64(points: &[DVec3]) -> Result<Self> {
        check_count(points.len())?;
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(Error::NonFinite { point: i });
        }
        check_range(points.iter().copied())?;
        Ok(Self::around_box_centre(points.iter().copied()))
    }

    /// From a flat f32 buffer (stride 3 or 4), world frame.
    pub fn from_flat(values: &[f32], stride: usize) -> Result<Self> {
        let largest = check_finite(values, stride)?;
        let at = |p: &[f32]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        if largest as f64 > MAX_COORDINATE {
            check_range(values.chunks_exact(stride).map(at))?;
        }
        Ok(Self::around_box_centre(values.chunks_exact(stride).map(at)))
    }

    /// Finite world points (read twice, never copied) around the centre of
    /// their box rounded to whole metres; the box of the bulk of the points
    /// when a few lie far from it (see [`robust_centre`]), so that f32 keeps
    /// the bulk's precision.
    fn around_box_centre(points: impl Iterator<Item = DVec3> + Clone) -> Self {
        let origin = robust_centre(points.clone()).round();
        Cloud {
            origin,
            points: points.map(|p| (p - origin).as_vec3()).collect(),
        }
    }

    /// From a flat f32 buffer in a sensor frame and a world-from-sensor pose:
    /// the origin is the sensor position rounded to whole metres, and each
    /// point is transformed in f64.
    pub fn from_sensor(values: &[f32], stride: usize, pose: &DMat4) -> Result<Self> {
        let largest = check_finite(values, stride)?;
        check_rigid(pose)?;
        let t = pose.w_axis.truncate();
        if t.abs().max_element() > MAX_COORDINATE {
            return Err(Error::BadPose(format!(
                "its translation lies more than {MAX_COORDINATE:e} m from the world origin"
            )));
        }
        // A rotation keeps lengths: the points stay within |t| + sqrt(3)
        // times their largest coordinate, and only beyond that bound is
        // each one checked.
        let reach = t.abs().max_element() + 3f64.sqrt() * largest as f64;
        let check = reach > MAX_COORDINATE;
        let origin = t.round();
        let mut points = Vec::with_capacity(values.len() / stride);
        for (i, p) in values.chunks_exact(stride).enumerate() {
            let w = pose.transform_point3(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
            if check && w.abs().max_element() > MAX_COORDINATE {
                return Err(Error::OutOfRange {
                    point: i,
                    limit: MAX_COORDINATE,
                });
            }
            points.push((w - origin).as_vec3());
        }
        Ok(Cloud { origin, points })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// No points?
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// World coordinates of point `i`.
    #[inline]
    pub fn world(&self, i: usize) -> DVec3 {
        self.origin + self.points[i].as_dvec3()
    }
}

/// Points farther than this from the bulk's median, per axis, in units of
/// the bulk's spread (its 10th to 90th percentile), are outliers to
/// [`robust_centre`].
const OUTLIER_SPREADS: f64 = 16.0;

/// Nor are points within this distance of the median (m) ever outliers:
/// what a sensor sees, or a town, stays one bulk.
const OUTLIER_FLOOR: f64 = 1e4;

/// At most this many points (every k-th) estimate the median and spread.
const ROBUST_SAMPLE: usize = 1 << 16;

/// The centre of the points' bounding box, leaving out outliers (see
/// [`bulk_extent`]). When there are none (the usual case) this is exactly
/// the whole box's centre.
fn robust_centre(points: impl Iterator<Item = DVec3> + Clone) -> DVec3 {
    match bulk_extent(points.clone()) {
        None => bbox_centre(points),
        Some((median, reach)) => {
            bbox_centre(points.filter(|p| (*p - median).abs().max_element() <= reach))
        }
    }
}

/// Where the bulk of `points` lies, when some lie outside it: the per-axis
/// median and the reach around it (per axis, m) beyond which a point is an
/// outlier (`OUTLIER_SPREADS` times the bulk's 10-90 % spread, at least
/// `OUTLIER_FLOOR`). `None` when every point is in the bulk.
pub(crate) fn bulk_extent(points: impl Iterator<Item = DVec3> + Clone) -> Option<(DVec3, f64)> {
    let n = points.clone().count();
    if n == 0 {
        return None;
    }
    let step = n.div_ceil(ROBUST_SAMPLE);
    let sample: Vec<DVec3> = points.clone().step_by(step).collect();
    let (mut median, mut reach) = (DVec3::ZERO, 0.0f64);
    for k in 0..3 {
        let mut axis: Vec<f64> = sample.iter().map(|p| p[k]).collect();
        let m = axis.len();
        let at = |axis: &mut Vec<f64>, q: usize| *axis.select_nth_unstable_by(q, f64::total_cmp).1;
        median[k] = at(&mut axis, m / 2);
        let spread = at(&mut axis, m * 9 / 10) - at(&mut axis, m / 10);
        reach = reach.max(spread * OUTLIER_SPREADS);
    }
    let reach = reach.max(OUTLIER_FLOOR);
    let mut points = points;
    points
        .any(|p| (p - median).abs().max_element() > reach)
        .then_some((median, reach))
}

fn bbox_centre(points: impl Iterator<Item = DVec3>) -> DVec3 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    let mut any = false;
    for p in points {
        // By selects: `f64::min`/`max` also test for NaN in wasm (the
        // points are finite here, so the results are the same).
        crate::geometry::grow_box(&mut lo, &mut hi, p);
        any = true;
    }
    if any {
        (lo + hi) * 0.5
    } else {
        DVec3::ZERO
    }
}
