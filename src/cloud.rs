//! Point clouds as the pipeline sees them: f32 coordinates relative to an f64
//! origin, so that map coordinates (UTM is ~10^6 m) keep millimetre precision.
//!
//! Input comes as float32 or float64 ([`Coordinates`]). Float64 input is
//! re-centred in f64 before anything becomes f32, so it may lie anywhere
//! within [`MAX_COORDINATE`]. Float32 input must lie within
//! [`MAX_F32_COORDINATE`] (10^5 m) of the world origin: beyond it float32
//! holds a coordinate only to 8 mm steps or coarser (0.5 m at 4.5e6 m, a
//! UTM northing), and detection would find planes along the rounding
//! steps; such input is refused with an error that names the fix (pass
//! float64, e.g. a `Float64Array`, or move the points near the origin).

use crate::error::{Error, Result, Sci};
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

/// Largest absolute coordinate accepted in float32 input (m): 10^5 m, where
/// float32's steps are 7.8 mm, a tenth of the inlier distances. Farther
/// points must come as float64 ([`Coordinates::F64`]).
pub const MAX_F32_COORDINATE: f64 = 1e5;

/// Interleaved point coordinates (`x, y, z[, intensity]`, stride 3 or 4)
/// as a reader or a caller holds them.
#[derive(Clone, Debug, PartialEq)]
pub enum Coordinates {
    /// Float32 values: within [`MAX_F32_COORDINATE`] of the world origin.
    F32(Vec<f32>),
    /// Float64 values (map coordinates): re-centred in f64.
    F64(Vec<f64>),
}

impl Coordinates {
    /// Number of values (points times stride).
    pub fn len(&self) -> usize {
        match self {
            Coordinates::F32(v) => v.len(),
            Coordinates::F64(v) => v.len(),
        }
    }

    /// No values?
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// World-frame cloud ([`Cloud::from_flat`] or [`Cloud::from_flat_f64`]).
    pub fn cloud(&self, stride: usize) -> Result<Cloud> {
        match self {
            Coordinates::F32(v) => Cloud::from_flat(v, stride),
            Coordinates::F64(v) => Cloud::from_flat_f64(v, stride),
        }
    }

    /// Sensor-frame cloud moved by `pose` ([`Cloud::from_sensor`] or
    /// [`Cloud::from_sensor_f64`]).
    pub fn cloud_in_sensor_frame(&self, stride: usize, pose: &DMat4) -> Result<Cloud> {
        match self {
            Coordinates::F32(v) => Cloud::from_sensor(v, stride, pose),
            Coordinates::F64(v) => Cloud::from_sensor_f64(v, stride, pose),
        }
    }

    /// Point `i`'s `x, y, z` in f64 (`None` past the end).
    pub fn point(&self, stride: usize, i: usize) -> Option<DVec3> {
        let at = i.checked_mul(stride)?;
        match self {
            Coordinates::F32(v) => v
                .get(at..at + 3)
                .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)),
            Coordinates::F64(v) => v.get(at..at + 3).map(|p| DVec3::new(p[0], p[1], p[2])),
        }
    }
}

/// Float32 input with a coordinate beyond [`MAX_F32_COORDINATE`] (called
/// only when the largest is beyond it): [`Error::F32Precision`] for the
/// first such point that belongs to the bulk of the cloud. Far outliers
/// (see [`bulk_extent`]) are no error: detection leaves them out, so their
/// rounding cannot make planes, and one stray return must not refuse a scan.
fn check_f32_precision(values: &[f32], stride: usize) -> Result<()> {
    let limit = MAX_F32_COORDINATE as f32;
    let at = |p: &[f32]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    let bulk = bulk_extent(values.chunks_exact(stride).map(at));
    let in_bulk = |w: DVec3| match bulk {
        None => true,
        Some((median, reach)) => (w - median).abs().max_element() <= reach,
    };
    for (i, p) in values.chunks_exact(stride).enumerate() {
        let m = p[0].abs().max(p[1].abs()).max(p[2].abs());
        if m > limit && in_bulk(at(p)) {
            return Err(Error::F32Precision {
                point: i,
                value: m as f64,
                limit: MAX_F32_COORDINATE,
            });
        }
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
    check_layout(values.len(), stride)?;
    largest_coordinate(values, stride)
}

/// A stride of 3 or 4 and a length that is a whole number of points.
fn check_layout(len: usize, stride: usize) -> Result<()> {
    if stride != 3 && stride != 4 {
        return Err(Error::BadStride(stride));
    }
    if len % stride != 0 {
        return Err(Error::BadLength { len, stride });
    }
    check_count(len / stride)?;
    Ok(())
}

/// The largest absolute coordinate of the points (checked as in
/// [`check_finite`], whose checks the caller has made on stride and length).
fn largest_coordinate(values: &[f32], stride: usize) -> Result<f32> {
    #[cfg(not(target_arch = "wasm32"))]
    {
        let quick = if stride == 3 {
            largest_of::<3>(values)
        } else {
            largest_of::<4>(values)
        };
        if let Some(largest) = quick {
            return Ok(largest);
        }
    }
    // (A point is not finite, natively: which one.)
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

/// [`largest_coordinate`] of points of `S` values (`S` of 3 or 4), `None`
/// when one is not finite. Four points a step, lane by lane, so that the
/// loop vectorises (0.27 -> 0.14 ms on a 120,000-point scan): `|v| < inf`
/// is false for NaN and the infinities alone. Native only: the wasm build has
/// the vectoriser off.
#[cfg(not(target_arch = "wasm32"))]
fn largest_of<const S: usize>(values: &[f32]) -> Option<f32> {
    // Every lane is computed, a point's fourth value too (so that the loop
    // has one body); only the coordinates' lanes count at the end.
    let (mut big, mut fine) = ([0.0f32; 16], [true; 16]);
    let mut quads = values.chunks_exact(4 * S);
    for q in &mut quads {
        for j in 0..4 * S {
            let a = q[j].abs();
            big[j] = if a > big[j] { a } else { big[j] };
            fine[j] &= a < f32::INFINITY;
        }
    }
    for p in quads.remainder().chunks_exact(S) {
        for j in 0..3 {
            let a = p[j].abs();
            big[j] = if a > big[j] { a } else { big[j] };
            fine[j] &= a < f32::INFINITY;
        }
    }
    let xyz = (0..4 * S).filter(|j| j % S < 3);
    xyz.clone()
        .all(|j| fine[j])
        .then(|| xyz.fold(0.0, |m, j| if big[j] > m { big[j] } else { m }))
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
            "its rotation part is not orthonormal (max |R^T R - I| = {dev}); \
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
    /// This cloud moved by the rigid world transform `m`, around the same
    /// origin.
    pub fn transformed(&self, m: &DMat4) -> Cloud {
        let r = glam::DMat3::from_mat4(*m);
        let t = m.transform_point3(self.origin) - self.origin;
        Cloud {
            origin: self.origin,
            points: self
                .points
                .iter()
                .map(|p| (r * p.as_dvec3() + t).as_vec3())
                .collect(),
        }
    }

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

    /// From a flat f32 buffer (stride 3 or 4), world frame. Coordinates must
    /// lie within [`MAX_F32_COORDINATE`]: farther points are an
    /// [`Error::F32Precision`] (pass them in f64, [`Cloud::from_flat_f64`]),
    /// unless they are a few far outliers (beyond 16 times the bulk's 10-90 %
    /// spread and 10 km from its median), which detection leaves out.
    pub fn from_flat(values: &[f32], stride: usize) -> Result<Self> {
        let largest = check_finite(values, stride)?;
        let at = |p: &[f32]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        if largest as f64 > MAX_COORDINATE {
            check_range(values.chunks_exact(stride).map(at))?;
        }
        if largest as f64 > MAX_F32_COORDINATE {
            check_f32_precision(values, stride)?;
        }
        Ok(Self::around_box_centre(values.chunks_exact(stride).map(at)))
    }

    /// From a flat f64 buffer (stride 3 or 4), world frame: re-centred in
    /// f64 (the origin is the centre of the points' box rounded to whole
    /// metres), so map coordinates keep sub-millimetre precision.
    pub fn from_flat_f64(values: &[f64], stride: usize) -> Result<Self> {
        check_layout(values.len(), stride)?;
        let at = |p: &[f64]| DVec3::new(p[0], p[1], p[2]);
        if let Some(i) = values.chunks_exact(stride).position(|p| !at(p).is_finite()) {
            return Err(Error::NonFinite { point: i });
        }
        check_range(values.chunks_exact(stride).map(at))?;
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
    /// point is transformed in f64. Sensor-frame coordinates must lie within
    /// [`MAX_F32_COORDINATE`] (else [`Error::F32Precision`]; see
    /// [`Cloud::from_sensor_f64`]); the pose may move them anywhere within
    /// [`MAX_COORDINATE`].
    pub fn from_sensor(values: &[f32], stride: usize, pose: &DMat4) -> Result<Self> {
        let largest = check_finite(values, stride)?;
        let t = check_pose(pose)?;
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
        if largest as f64 > MAX_F32_COORDINATE {
            check_f32_precision(values, stride)?;
        }
        Ok(Cloud { origin, points })
    }

    /// From a flat f64 buffer in a sensor frame (or a world frame, with the
    /// identity pose) and a world-from-sensor pose, every step in f64. The
    /// origin is the sensor position rounded to whole metres when every
    /// point lies within [`MAX_F32_COORDINATE`] of it (a scan around its
    /// sensor: the origin [`Cloud::from_sensor`] takes), else the centre of
    /// the points' box rounded (points already in map coordinates).
    pub fn from_sensor_f64(values: &[f64], stride: usize, pose: &DMat4) -> Result<Self> {
        check_layout(values.len(), stride)?;
        let t = check_pose(pose)?;
        let at = |p: &[f64]| DVec3::new(p[0], p[1], p[2]);
        if let Some(i) = values.chunks_exact(stride).position(|p| !at(p).is_finite()) {
            return Err(Error::NonFinite { point: i });
        }
        // A rigid pose of a finite point is finite (or overflows to an
        // infinity, which is out of range).
        let world: Vec<DVec3> = values
            .chunks_exact(stride)
            .map(|p| pose.transform_point3(at(p)))
            .collect();
        check_range(world.iter().copied())?;
        let sensor = t.round();
        let near = world
            .iter()
            .all(|w| (*w - sensor).abs().max_element() <= MAX_F32_COORDINATE);
        if near {
            let points = world.iter().map(|w| (*w - sensor).as_vec3()).collect();
            return Ok(Cloud {
                origin: sensor,
                points,
            });
        }
        Ok(Self::around_box_centre(world.into_iter()))
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

/// A rigid pose whose translation lies within [`MAX_COORDINATE`]; returns
/// the translation.
fn check_pose(pose: &DMat4) -> Result<DVec3> {
    check_rigid(pose)?;
    let t = pose.w_axis.truncate();
    if t.abs().max_element() > MAX_COORDINATE {
        return Err(Error::BadPose(format!(
            "its translation lies more than {} m from the world origin",
            Sci(MAX_COORDINATE)
        )));
    }
    Ok(t)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_coordinate_and_the_first_point_not_finite() {
        // 11 points (two steps of four, three left over), both strides.
        let mut rng = crate::rng::Rng::new(5);
        for stride in [3, 4] {
            let mut v: Vec<f32> = (0..11 * stride)
                .map(|_| (rng.uniform() * 200.0 - 100.0) as f32)
                .collect();
            let at = v.iter().enumerate().filter(|(i, _)| i % stride < 3);
            let largest = at.fold(0.0f32, |m, (_, x)| m.max(x.abs()));
            assert_eq!(check_finite(&v, stride).unwrap(), largest);
            // A point's fourth value (intensity) is not a coordinate.
            if stride == 4 {
                v[4 * 5 + 3] = f32::NAN;
                v[4 * 9 + 3] = 1e30;
                assert_eq!(check_finite(&v, stride).unwrap(), largest);
            }
            for (point, bad) in [(9, f32::NAN), (2, f32::INFINITY), (10, f32::NEG_INFINITY)] {
                let mut w = v.clone();
                w[point * stride + 1] = bad;
                let e = check_finite(&w, stride).unwrap_err();
                assert!(
                    matches!(e, Error::NonFinite { point: p } if p == point),
                    "{e}"
                );
            }
        }
    }

    /// A 2 m grid of points at three heights, around `at`.
    fn grid(at: DVec3) -> Vec<DVec3> {
        let mut out = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                for k in 0..3 {
                    let p = DVec3::new(i as f64 * 0.37, j as f64 * 0.41, k as f64 * 0.9);
                    out.push(at + p);
                }
            }
        }
        out
    }

    fn flat_f64(points: &[DVec3]) -> Vec<f64> {
        points.iter().flat_map(|p| p.to_array()).collect()
    }

    #[test]
    fn float32_beyond_the_limit_is_refused_with_the_fix() {
        let utm = DVec3::new(500_000.0, 4_500_000.0, 50.0);
        let far: Vec<f32> = grid(utm)
            .iter()
            .flat_map(|p| p.as_vec3().to_array())
            .collect();
        let e = Cloud::from_flat(&far, 3).unwrap_err();
        assert!(matches!(e, Error::F32Precision { point: 0, .. }), "{e}");
        let text = e.to_string();
        for word in ["float32", "Float64Array", "float64", "500 mm"] {
            assert!(text.contains(word), "{word}: {text}");
        }
        // The same through a scan's sensor frame (identity pose).
        let e = Cloud::from_sensor(&far, 3, &DMat4::IDENTITY).unwrap_err();
        assert!(matches!(e, Error::F32Precision { point: 0, .. }), "{e}");
        // At the limit it is accepted; one step beyond it, point 1 is named.
        let limit = MAX_F32_COORDINATE as f32;
        assert!(Cloud::from_flat(&[limit, -limit, 0.0], 3).is_ok());
        let e = Cloud::from_flat(&[0.0, 0.0, 0.0, 0.0, -1.0001e5, 0.0], 3).unwrap_err();
        assert!(matches!(e, Error::F32Precision { point: 1, .. }), "{e}");
        // Beyond every map it stays an out-of-range error.
        let e = Cloud::from_flat(&[0.0, 0.0, 2e9], 3).unwrap_err();
        assert!(matches!(e, Error::OutOfRange { .. }), "{e}");
    }

    /// Float64 map coordinates become the same local f32 points as the
    /// cloud near the origin (the shift is whole metres), bit for bit.
    #[test]
    fn float64_map_coordinates_are_recentred_exactly() {
        let near = grid(DVec3::new(3.0, -2.0, -1.5));
        let shift = DVec3::new(500_000.0, 4_500_000.0, 50.0);
        let far: Vec<DVec3> = near.iter().map(|p| *p + shift).collect();
        let a = Cloud::from_flat_f64(&flat_f64(&near), 3).unwrap();
        let b = Cloud::from_flat_f64(&flat_f64(&far), 3).unwrap();
        assert_eq!(b.origin - a.origin, shift);
        assert_eq!(a.points, b.points);
        for (i, p) in far.iter().enumerate() {
            assert!((b.world(i) - *p).length() < 1e-6);
        }
        // Stride 4 and bad input.
        let four: Vec<f64> = far.iter().flat_map(|p| [p.x, p.y, p.z, 0.5]).collect();
        assert_eq!(Cloud::from_flat_f64(&four, 4).unwrap().points, b.points);
        assert!(matches!(
            Cloud::from_flat_f64(&[0.0, f64::NAN, 0.0], 3),
            Err(Error::NonFinite { point: 0 })
        ));
        assert!(matches!(
            Cloud::from_flat_f64(&[0.0; 4], 3),
            Err(Error::BadLength { .. })
        ));
        assert!(matches!(
            Cloud::from_flat_f64(&[0.0, 0.0, 0.0, 1e10, 0.0, 0.0], 3),
            Err(Error::OutOfRange { point: 1, .. })
        ));
    }

    /// A float64 scan: around its sensor it takes the sensor origin (the
    /// f32 path's, the same points); in map coordinates with the identity
    /// pose it is re-centred on its points.
    #[test]
    fn float64_scans_keep_their_precision() {
        let local = grid(DVec3::new(-5.0, -4.0, -1.8));
        let pose = DMat4::from_rotation_translation(
            glam::DQuat::from_rotation_z(0.4),
            DVec3::new(500_010.0, 4_500_020.0, 51.0),
        );
        let f32s: Vec<f32> = local.iter().flat_map(|p| p.as_vec3().to_array()).collect();
        let f64s: Vec<f64> = f32s.iter().map(|&v| v as f64).collect();
        let a = Cloud::from_sensor(&f32s, 3, &pose).unwrap();
        let b = Cloud::from_sensor_f64(&f64s, 3, &pose).unwrap();
        assert_eq!((a.origin, &a.points), (b.origin, &b.points));
        // The same scan in map coordinates, identity pose.
        let world: Vec<f64> = (0..b.len()).flat_map(|i| b.world(i).to_array()).collect();
        let c = Cloud::from_sensor_f64(&world, 3, &DMat4::IDENTITY).unwrap();
        assert!((c.origin - pose.w_axis.truncate()).length() < 20.0);
        for i in 0..c.len() {
            assert!((c.world(i) - b.world(i)).length() < 1e-5);
        }
        assert!(Cloud::from_sensor_f64(&[0.0, 0.0, f64::INFINITY], 3, &pose).is_err());
        let far = DMat4::from_translation(DVec3::new(2e9, 0.0, 0.0));
        assert!(matches!(
            Cloud::from_sensor_f64(&world, 3, &far),
            Err(Error::BadPose(_))
        ));
    }
}
