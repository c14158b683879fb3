//! Planes, local 2D frames and plane fitting from running statistics.

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// World "up" axis: near-horizontal planes get their normals pointing this way.
pub const UP: DVec3 = DVec3::Z;

/// An oriented plane `normal · x + offset = 0` (`normal` is a unit vector).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    /// Unit normal.
    pub normal: DVec3,
    /// Offset `d` in metres: `normal · x + d = 0` for points on the plane.
    pub offset: f64,
}

impl Plane {
    /// The plane through `point` with unit `normal`.
    pub fn from_point_normal(point: DVec3, normal: DVec3) -> Self {
        Plane {
            normal,
            offset: -normal.dot(point),
        }
    }

    /// Signed distance in metres (positive on the normal's side).
    #[inline]
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) + self.offset
    }

    /// Angle between the two planes' normals in radians, ignoring orientation.
    pub fn angle_to(&self, other: &Plane) -> f64 {
        libm::acos(self.normal.dot(other.normal).abs().min(1.0))
    }

    /// Is the plane ground as seen from `viewpoint`: near-horizontal (the
    /// cosine of its tilt at least `min_cos`) with the viewpoint more than
    /// `depth` above it? Either orientation of the normal gives the same
    /// answer. The one ground test of detection: RANSAC picks the inlier
    /// distance and clustering tolerance by it, and shaping marks ground
    /// primitives by it. Takes the cosine, which RANSAC computes once per
    /// round, not once per hypothesis.
    pub fn is_ground_below(&self, viewpoint: DVec3, min_cos: f64, depth: f64) -> bool {
        self.normal.z.abs() >= min_cos
            && self.signed_distance(viewpoint) * self.normal.z.signum() > depth
    }

    /// The same plane with the normal flipped when needed so that it points
    /// towards `viewpoint` (the side the sensor saw it from). A plane through
    /// the viewpoint itself keeps a normal pointing up (or is left as is
    /// when vertical).
    pub fn oriented(self, viewpoint: DVec3) -> Self {
        let sd = self.signed_distance(viewpoint);
        let flip = if sd.abs() > 1e-9 {
            sd < 0.0
        } else {
            self.normal.dot(UP) < 0.0
        };
        if flip {
            Plane {
                normal: -self.normal,
                offset: -self.offset,
            }
        } else {
            self
        }
    }
}

/// A right-handed frame in a plane: `u × v = normal`. 2D coordinates are
/// `(u · (p - origin), v · (p - origin))`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// Origin, on the plane, in world coordinates (metres).
    pub origin: DVec3,
    /// First in-plane axis (unit).
    pub u: DVec3,
    /// Second in-plane axis (unit).
    pub v: DVec3,
    /// Plane normal (unit), `u × v`.
    pub normal: DVec3,
}

impl Frame {
    /// A frame on `plane` with its origin at the projection of `near`.
    ///
    /// For walls `u` is horizontal and `v` points up along the wall; for
    /// near-horizontal planes `u` follows the world x axis as closely as possible.
    pub fn on_plane(plane: &Plane, near: DVec3) -> Self {
        let n = plane.normal;
        let origin = near - n * plane.signed_distance(near);
        // Horizontal in-plane direction, unless the plane is (almost) horizontal.
        let h = UP.cross(n);
        let u = if h.length_squared() > 1e-6 {
            h.normalize()
        } else {
            let x = DVec3::X - n * n.x;
            if x.length_squared() > 1e-12 {
                x.normalize()
            } else {
                (DVec3::Y - n * n.y).normalize()
            }
        };
        let v = n.cross(u);
        Frame {
            origin,
            u,
            v,
            normal: n,
        }
    }

    /// The plane this frame lies on.
    pub fn plane(&self) -> Plane {
        Plane::from_point_normal(self.origin, self.normal)
    }

    /// 2D coordinates of the orthogonal projection of `p`.
    #[inline]
    pub fn to_local(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(self.u.dot(d), self.v.dot(d))
    }

    /// World point of 2D frame coordinates.
    #[inline]
    pub fn to_world(&self, q: DVec2) -> DVec3 {
        self.origin + self.u * q.x + self.v * q.y
    }

    /// This frame moved onto `plane` (a refit) with the smallest rotation, so
    /// that 2D coordinates keep (almost) their meaning: the in-plane axes are
    /// rotated with the normal and the origin is projected onto the new plane.
    pub fn realigned(&self, plane: &Plane) -> Self {
        let n = plane.normal;
        let origin = self.origin - n * plane.signed_distance(self.origin);
        // Gram–Schmidt: keep u as close as possible to the old u.
        let mut u = self.u - n * n.dot(self.u);
        if u.length_squared() < 1e-12 {
            return Frame::on_plane(plane, self.origin);
        }
        u = u.normalize();
        let v = n.cross(u);
        Frame {
            origin,
            u,
            v,
            normal: n,
        }
    }
}

/// Running first and second moments of a point set, in f64, relative to a
/// fixed reference point: constant memory, mergeable, enough for a PCA plane
/// fit at any time. This replaces keeping every support point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Moments {
    /// Reference point the sums are taken relative to (world, metres).
    pub reference: DVec3,
    /// Number of points.
    pub count: f64,
    /// Sum of `p - reference`.
    pub sum: DVec3,
    /// Sums of products `xx, xy, xz, yy, yz, zz` of `p - reference`.
    pub sum_sq: [f64; 6],
}

impl Moments {
    /// No points yet, sums relative to `reference`.
    pub fn new(reference: DVec3) -> Self {
        Moments {
            reference,
            count: 0.0,
            sum: DVec3::ZERO,
            sum_sq: [0.0; 6],
        }
    }

    /// Add one point.
    #[inline]
    pub fn push(&mut self, p: DVec3) {
        let d = p - self.reference;
        self.count += 1.0;
        self.sum += d;
        self.sum_sq[0] += d.x * d.x;
        self.sum_sq[1] += d.x * d.y;
        self.sum_sq[2] += d.x * d.z;
        self.sum_sq[3] += d.y * d.y;
        self.sum_sq[4] += d.y * d.z;
        self.sum_sq[5] += d.z * d.z;
    }

    /// Add another set's moments (any reference point).
    pub fn merge(&mut self, other: &Moments) {
        if other.count == 0.0 {
            return;
        }
        // Shift the other's sums to our reference: d' = d + s, s = ref_o - ref.
        let s = other.reference - self.reference;
        let n = other.count;
        let so = other.sum;
        let q = &other.sum_sq;
        self.sum_sq[0] += q[0] + 2.0 * s.x * so.x + n * s.x * s.x;
        self.sum_sq[1] += q[1] + s.x * so.y + s.y * so.x + n * s.x * s.y;
        self.sum_sq[2] += q[2] + s.x * so.z + s.z * so.x + n * s.x * s.z;
        self.sum_sq[3] += q[3] + 2.0 * s.y * so.y + n * s.y * s.y;
        self.sum_sq[4] += q[4] + s.y * so.z + s.z * so.y + n * s.y * s.z;
        self.sum_sq[5] += q[5] + 2.0 * s.z * so.z + n * s.z * s.z;
        self.sum += so + s * n;
        self.count += n;
    }

    /// Take out the moments of a subset of the points these were summed
    /// from, with the same reference point (cheaper than summing the rest
    /// again when the subset is small).
    pub fn remove(&mut self, subset: &Moments) {
        debug_assert_eq!(self.reference, subset.reference);
        self.count -= subset.count;
        self.sum -= subset.sum;
        for (a, b) in self.sum_sq.iter_mut().zip(&subset.sum_sq) {
            *a -= b;
        }
    }

    /// Mean of the points (world).
    pub fn mean(&self) -> DVec3 {
        if self.count == 0.0 {
            self.reference
        } else {
            self.reference + self.sum / self.count
        }
    }

    /// Covariance matrix (row-major symmetric 3x3) about the mean.
    pub fn covariance(&self) -> [[f64; 3]; 3] {
        if self.count == 0.0 {
            return [[0.0; 3]; 3];
        }
        let n = self.count;
        let m = self.sum / n;
        let q = &self.sum_sq;
        let xx = q[0] / n - m.x * m.x;
        let xy = q[1] / n - m.x * m.y;
        let xz = q[2] / n - m.x * m.z;
        let yy = q[3] / n - m.y * m.y;
        let yz = q[4] / n - m.y * m.z;
        let zz = q[5] / n - m.z * m.z;
        [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
    }

    /// Least-squares plane (PCA: normal along the smallest eigenvector of the
    /// covariance) and its eigenvalues in ascending order. `None` for fewer
    /// than three points or a degenerate (collinear or single-point) set.
    pub fn fit_plane(&self) -> Option<(Plane, [f64; 3])> {
        if self.count < 3.0 {
            return None;
        }
        let (vals, vecs) = symmetric_eigen3(self.covariance());
        // Collinear (second eigenvalue ~ 0) or all identical: no unique plane.
        let scale = vals[2].max(1e-300);
        if vals[1] <= 1e-12 * scale || vals[2] <= 0.0 {
            return None;
        }
        let n = vecs[0];
        let len = n.length();
        if !len.is_finite() || len < 0.5 {
            return None;
        }
        Some((Plane::from_point_normal(self.mean(), n / len), vals))
    }
}

/// A plane fitted robustly by [`robust_fit`].
pub struct RobustFit {
    /// The plane (normal orientation as PCA left it).
    pub plane: Plane,
    /// Moments of the points of the last fit.
    pub moments: Moments,
    /// Per point: used in the last fit?
    pub inner: Vec<bool>,
}

/// The plane through three points (unit normal and offset, the normal's
/// sign as the cross product gives it), or `None` for a near-collinear
/// triple: twice the triangle's area under 1 cm^2, or its height on the
/// longest side under `min_fatness` times that side. Three points almost
/// in a line fix the line, not the plane. Used by RANSAC's sampler and by
/// the dominant-layer search. Not inlined: one copy is 0.24 kB gzipped
/// less wasm, and a call per triple is nothing beside its scoring.
#[inline(never)]
pub(crate) fn plane_through(
    p1: DVec3,
    p2: DVec3,
    p3: DVec3,
    min_fatness: f64,
) -> Option<(DVec3, f64)> {
    let cr = (p2 - p1).cross(p3 - p1);
    // std sqrt (a single instruction in wasm; glam with libm calls software):
    // both are correctly rounded, so the bits are the same.
    let len = cr.length_squared().sqrt();
    if len.is_nan() || len <= 1e-4 {
        return None;
    }
    // `len` is the height on the longest side times that side. The points
    // are finite here (`len` is not NaN): `max` by comparison (`f64::max`
    // also tests for NaN in wasm).
    let mut longest = (p2 - p1).length_squared();
    for side in [(p3 - p1).length_squared(), (p3 - p2).length_squared()] {
        longest = if side > longest { side } else { longest };
    }
    if len < min_fatness * longest {
        return None;
    }
    let nrm = cr / len;
    Some((nrm, -nrm.dot(p1)))
}

/// Robust least-squares plane: a PCA fit of every point, then three refits
/// on the points within 2.5 robust standard deviations (1.4826 x the median
/// absolute residual, at least 0.1 mm) of the last plane, stopping early
/// when a refit has no plane. A tilted plane that caught a surface and the
/// edge of a crossing one (a road and its kerb, a tread and its riser)
/// converges to the majority surface. Sums are taken relative to
/// `reference`. `None` when the points have no plane (fewer than three,
/// collinear). Used by RANSAC's local optimisation and by shaping.
///
/// ```
/// use glam::DVec3;
/// use polyscene::geometry::plane::robust_fit;
/// // A floor at z = 0 and a few points of a wall rising from its edge.
/// let mut pts: Vec<DVec3> = (0..400)
///     .map(|i| DVec3::new((i % 20) as f64 * 0.1, (i / 20) as f64 * 0.1, 0.0))
///     .collect();
/// pts.extend((1..6).map(|k| DVec3::new(2.0, 1.0, k as f64 * 0.02)));
/// let fit = robust_fit(&pts, pts[0]).unwrap();
/// assert!(fit.plane.normal.z.abs() > 0.999_999);
/// assert!(!fit.inner[404]);
/// ```
pub fn robust_fit(pts: &[DVec3], reference: DVec3) -> Option<RobustFit> {
    let moments_of = |keep: &dyn Fn(usize) -> bool| {
        let mut m = Moments::new(reference);
        for (i, &p) in pts.iter().enumerate() {
            if keep(i) {
                m.push(p);
            }
        }
        m
    };
    let mut moments = moments_of(&|_| true);
    let mut plane = moments.fit_plane()?.0;
    let mut inner = vec![true; pts.len()];
    let (mut resid, mut sorted) = (Vec::with_capacity(pts.len()), Vec::new());
    for _ in 0..3 {
        resid.clear();
        resid.extend(pts.iter().map(|&p| plane.signed_distance(p).abs()));
        sorted.clone_from(&resid);
        let mid = sorted.len() / 2;
        let med = *sorted.select_nth_unstable_by(mid, f64::total_cmp).1;
        let cut = (2.5 * 1.4826 * med).max(1e-4);
        let trimmed = moments_of(&|i| resid[i] <= cut);
        let Some((next, _)) = trimmed.fit_plane() else {
            break;
        };
        plane = next;
        moments = trimmed;
        for (k, &r) in inner.iter_mut().zip(&resid) {
            *k = r <= cut;
        }
    }
    Some(RobustFit {
        plane,
        moments,
        inner,
    })
}

/// Eigenvalues (ascending) of a symmetric 3x3 matrix in closed form (the
/// trigonometric solution of its characteristic cubic), and a unit
/// eigenvector of the smallest: the longest cross product of two rows of
/// `m - l0 I`. `None` for a multiple of the identity or non-finite input.
/// Several times cheaper than [`symmetric_eigen3`], and accurate to about
/// `1e-15` times the largest eigenvalue, so the vector is only as good as
/// the gap between the two smallest eigenvalues allows: for tests on
/// well-separated cases (is a patch flat, which way does it face), not for
/// fitting.
pub fn smallest_eigen3(m: [[f64; 3]; 3]) -> Option<([f64; 3], DVec3)> {
    let (a01, a02, a12) = (m[0][1], m[0][2], m[1][2]);
    let off = a01 * a01 + a02 * a02 + a12 * a12;
    let q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    let (d0, d1, d2) = (m[0][0] - q, m[1][1] - q, m[2][2] - q);
    let p2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off;
    if !(p2 > 0.0 && p2.is_finite()) {
        return None;
    }
    // std sqrt: one instruction in wasm, correctly rounded everywhere.
    let p = (p2 / 6.0).sqrt();
    // det((m - q I) / p) / 2, in [-1, 1] but for rounding.
    let det =
        d0 * (d1 * d2 - a12 * a12) - a01 * (a01 * d2 - a12 * a02) + a02 * (a01 * a12 - d1 * a02);
    let r = (det / (2.0 * p * p * p)).clamp(-1.0, 1.0);
    let phi = libm::acos(r) / 3.0;
    let top = q + 2.0 * p * libm::cos(phi);
    let low = q + 2.0 * p * libm::cos(phi + 2.0 * std::f64::consts::FRAC_PI_3);
    let mid = 3.0 * q - top - low;
    let rows = [
        DVec3::new(m[0][0] - low, a01, a02),
        DVec3::new(a01, m[1][1] - low, a12),
        DVec3::new(a02, a12, m[2][2] - low),
    ];
    let mut best = rows[0].cross(rows[1]);
    for c in [rows[0].cross(rows[2]), rows[1].cross(rows[2])] {
        if c.length_squared() > best.length_squared() {
            best = c;
        }
    }
    let len = best.length_squared().sqrt();
    if !(len > 0.0 && len.is_finite()) {
        return None;
    }
    Some(([low, super::clamp(mid, low, top), top], best / len))
}

/// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations.
/// Returns eigenvalues ascending and the matching unit eigenvectors.
pub fn symmetric_eigen3(m: [[f64; 3]; 3]) -> ([f64; 3], [DVec3; 3]) {
    let mut a = m;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..32 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * rp[k] - s * rq[k];
                a[q][k] = s * rp[k] + c * rq[k];
            }
            for row in v.iter_mut() {
                let vkp = row[p];
                let vkq = row[q];
                row[p] = c * vkp - s * vkq;
                row[q] = s * vkp + c * vkq;
            }
        }
    }
    let mut idx = [0usize, 1, 2];
    super::numeric::insertion_sort_by(&mut idx, |&i, &j| a[i][i].total_cmp(&a[j][j]));
    let vals = [a[idx[0]][idx[0]], a[idx[1]][idx[1]], a[idx[2]][idx[2]]];
    let col = |j: usize| DVec3::new(v[0][j], v[1][j], v[2][j]);
    (vals, [col(idx[0]), col(idx[1]), col(idx[2])])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ground_below_the_viewpoint_whichever_way_the_normal_points() {
        let cos15 = libm::cos(15f64.to_radians());
        let up = Plane {
            normal: UP,
            offset: 0.0,
        };
        let down = Plane {
            normal: -UP,
            offset: 0.0,
        };
        let sensor = DVec3::new(3.0, -2.0, 1.8);
        for p in [up, down] {
            assert!(p.is_ground_below(sensor, cos15, 1.3));
            // Too close below the sensor, or above it: not ground.
            assert!(!p.is_ground_below(DVec3::new(0.0, 0.0, 1.0), cos15, 1.3));
            assert!(!p.is_ground_below(DVec3::new(0.0, 0.0, -1.8), cos15, 1.3));
        }
        // Tilted 20 degrees: a ramp too steep to be ground.
        let a = 20f64.to_radians();
        let ramp = Plane {
            normal: DVec3::new(libm::sin(a), 0.0, libm::cos(a)),
            offset: 0.0,
        };
        assert!(!ramp.is_ground_below(sensor, cos15, 1.3));
        assert!(ramp.is_ground_below(sensor, libm::cos(25f64.to_radians()), 1.3));
    }

    #[test]
    fn pca_recovers_a_tilted_plane_far_from_origin() {
        let n = DVec3::new(0.3, -0.2, 0.9).normalize();
        let base = DVec3::new(500_000.0, 4_500_000.0, 50.0);
        let f = Frame::on_plane(&Plane::from_point_normal(base, n), base);
        let mut m = Moments::new(base.round());
        for i in 0..20 {
            for j in 0..20 {
                m.push(f.to_world(DVec2::new(i as f64 * 0.5, j as f64 * 0.3)));
            }
        }
        let (p, vals) = m.fit_plane().unwrap();
        assert!(p.normal.dot(n).abs() > 1.0 - 1e-12);
        assert!(p.signed_distance(base).abs() < 1e-6);
        assert!(vals[0].abs() < 1e-9);
    }

    #[test]
    fn merge_equals_pushing_everything() {
        let pts: Vec<DVec3> = (0..50)
            .map(|i| DVec3::new(i as f64 * 0.7, (i * i % 13) as f64, (i % 5) as f64 * 0.1))
            .collect();
        let mut all = Moments::new(DVec3::ZERO);
        pts.iter().for_each(|&p| all.push(p));
        let mut a = Moments::new(DVec3::new(3.0, 1.0, 0.0));
        let mut b = Moments::new(DVec3::new(-10.0, 5.0, 2.0));
        pts[..20].iter().for_each(|&p| a.push(p));
        pts[20..].iter().for_each(|&p| b.push(p));
        a.merge(&b);
        let (ca, cb) = (a.covariance(), all.covariance());
        for i in 0..3 {
            for j in 0..3 {
                assert!((ca[i][j] - cb[i][j]).abs() < 1e-9);
            }
        }
        assert!((a.mean() - all.mean()).length() < 1e-12);
    }

    #[test]
    fn degenerate_sets_have_no_plane() {
        let mut m = Moments::new(DVec3::ZERO);
        for i in 0..10 {
            m.push(DVec3::new(i as f64, 2.0 * i as f64, 0.0));
        }
        assert!(m.fit_plane().is_none(), "collinear");
        let mut m = Moments::new(DVec3::ZERO);
        for _ in 0..10 {
            m.push(DVec3::ONE);
        }
        assert!(m.fit_plane().is_none(), "identical");
    }

    #[test]
    fn frames_are_right_handed_and_round_trip() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            DVec3::new(1.0, 1.0, 0.2).normalize(),
        ] {
            let f = Frame::on_plane(&Plane::from_point_normal(DVec3::ONE, n), DVec3::ZERO);
            assert!((f.u.cross(f.v) - n).length() < 1e-12);
            let q = DVec2::new(1.5, -2.0);
            assert!((f.to_local(f.to_world(q)) - q).length() < 1e-12);
        }
    }

    /// The closed form agrees with the Jacobi rotations on random
    /// covariances of flat, elongated and round point sets, and gives up on
    /// a multiple of the identity.
    #[test]
    fn closed_form_eigen_agrees_with_jacobi() {
        let mut rng = crate::rng::Rng::new(5);
        for case in 0..300 {
            // Axes of random lengths (one of them tiny for a third of the
            // cases: a noisy patch of a surface), randomly rotated.
            let n = DVec3::new(rng.gaussian(), rng.gaussian(), rng.gaussian()).normalize();
            let f = Frame::on_plane(&Plane::from_point_normal(DVec3::ZERO, n), DVec3::ZERO);
            let (a, b) = (rng.range(0.1, 2.0), rng.range(0.1, 2.0));
            let c = if case % 3 == 0 {
                1e-3
            } else {
                rng.range(0.0, 2.0)
            };
            let mut m = Moments::new(DVec3::new(3.0, -1.0, 2.0));
            for _ in 0..50 {
                let q = DVec2::new(a * rng.gaussian(), b * rng.gaussian());
                m.push(f.to_world(q) + n * (c * rng.gaussian()));
            }
            let cov = m.covariance();
            let (vals, vecs) = symmetric_eigen3(cov);
            let (cvals, normal) = smallest_eigen3(cov).unwrap();
            for k in 0..3 {
                assert!(
                    (vals[k] - cvals[k]).abs() <= 1e-9 * vals[2],
                    "{vals:?} {cvals:?}"
                );
            }
            assert!((normal.length() - 1.0).abs() < 1e-12);
            // The vector is as good as the gap to the next eigenvalue allows.
            let gap = (vals[1] - vals[0]) / vals[2];
            assert!(
                normal.dot(vecs[0]).abs() > 1.0 - 1e-9 / (gap * gap),
                "gap {gap}"
            );
        }
        let mut eye = [[0.0; 3]; 3];
        for (k, row) in eye.iter_mut().enumerate() {
            row[k] = 2.5;
        }
        assert!(smallest_eigen3(eye).is_none());
        assert!(smallest_eigen3([[f64::NAN; 3]; 3]).is_none());
    }
}
