//! Exact ray casting of a scene for a spinning LiDAR.
//!
//! For a sensor whose spin axis is vertical, the rays of one azimuth column
//! lie in a vertical half-plane through the sensor. So, per column, each
//! candidate polygon is cut by that half-plane into segments in `(r, z)`
//! coordinates (horizontal distance, height), the lasers whose elevation lies
//! between a segment's two ends are found by bisection, and only those get a
//! ray/plane intersection. Poles and trunks (vertical cylinders) and crowns
//! (spheres) are intersected analytically. The nearest hit wins.
//!
//! Candidates per column come from azimuth bins built once per scan: every
//! primitive within range goes into the bins its azimuth interval (seen from
//! the sensor) covers, or into an "always" list if its footprint contains the
//! sensor (the road under the car).

use super::builder::{newell, Clutter};
use super::normal::Ziggurat;
use super::scene::Scene;
use super::sensor::{Beams, SensorModel};
use super::truth::{SurfaceKind, CLUTTER};
use crate::geometry::polygon::signed_area;
use crate::geometry::{Frame, Plane};
use crate::rng::Rng;
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// Azimuth bins per scan.
const BINS: usize = 1024;
/// Planar surfaces with more vertices are cut into pieces for casting.
const MAX_PIECE_VERTICES: usize = 16;
/// Angular margin added to every binned interval, radians.
const BIN_MARGIN: f64 = 1e-6;

#[derive(Clone, Copy, Debug)]
enum Shape {
    /// A planar polygon: `verts[start..start + len]`, unit normal, and offset
    /// (`normal · x + offset = 0`), scene-local.
    Poly {
        start: u32,
        len: u32,
        normal: DVec3,
        offset: f64,
    },
    /// A vertical cylinder from `z0` to `z1`.
    Cylinder {
        centre: DVec2,
        radius: f64,
        z0: f64,
        z1: f64,
    },
    /// A sphere.
    Sphere { centre: DVec3, radius: f64 },
}

#[derive(Clone, Copy, Debug)]
struct Prim {
    shape: Shape,
    label: u32,
    reflectivity: f64,
    lo: DVec3,
    hi: DVec3,
}

/// Scan-time data of a primitive, relative to the sensor position.
#[derive(Clone, Copy, Debug)]
enum Local {
    Poly {
        start: u32,
        len: u32,
        normal: DVec3,
        /// Signed distance of the sensor from the plane.
        e: f64,
    },
    Cylinder {
        centre: DVec2,
        /// `|centre|² - radius²`.
        cc: f64,
        radius: f64,
        z0: f64,
        z1: f64,
    },
    Sphere {
        centre: DVec3,
        cc: f64,
        radius: f64,
    },
}

#[derive(Clone, Copy, Debug)]
struct Cand {
    local: Local,
    label: u32,
    reflectivity: f64,
}

/// A scene prepared for casting (scene-local coordinates).
#[derive(Clone, Debug)]
pub(crate) struct Caster {
    prims: Vec<Prim>,
    verts: Vec<DVec3>,
    normal: Ziggurat,
}

/// One simulated scan: points `x, y, z, intensity` in the sensor frame and
/// per-point labels.
pub(crate) struct Cast {
    pub points: Vec<f32>,
    pub labels: Vec<u32>,
}

fn reflectivity(kind: Option<SurfaceKind>) -> f64 {
    match kind {
        Some(SurfaceKind::Road) => 0.18,
        Some(SurfaceKind::Sidewalk) => 0.32,
        Some(SurfaceKind::Curb) => 0.4,
        Some(SurfaceKind::Facade) => 0.55,
        Some(SurfaceKind::Door) => 0.35,
        Some(SurfaceKind::Wall) => 0.45,
        Some(SurfaceKind::Vehicle) => 0.75,
        Some(SurfaceKind::Ramp) => 0.22,
        None => 0.5,
    }
}

impl Caster {
    /// Prepare the scene's scene-local geometry.
    pub fn new(scene: &Scene) -> Self {
        let mut c = Caster {
            prims: Vec::new(),
            verts: Vec::new(),
            normal: Ziggurat::new(),
        };
        for (label, s) in &scene.local {
            let refl = reflectivity(s.kind);
            let n = newell(&s.verts);
            let len = n.length();
            if !len.is_finite() || len <= 0.0 {
                continue;
            }
            let normal = n / len;
            let centroid = s.verts.iter().copied().sum::<DVec3>() / s.verts.len() as f64;
            let offset = -normal.dot(centroid);
            if s.verts.len() <= MAX_PIECE_VERTICES {
                c.push_poly(&s.verts, normal, offset, *label, refl);
            } else {
                let frame = Frame::on_plane(&Plane::from_point_normal(centroid, normal), centroid);
                let ring: Vec<DVec2> = s.verts.iter().map(|&v| frame.to_local(v)).collect();
                let mut pieces = Vec::new();
                split(ring, 0, &mut pieces);
                for piece in pieces {
                    let verts: Vec<DVec3> = piece.iter().map(|&q| frame.to_world(q)).collect();
                    c.push_poly(&verts, normal, offset, *label, refl);
                }
            }
        }
        for cl in &scene.local_clutter {
            let (shape, refl) = match *cl {
                Clutter::Pole {
                    base,
                    radius,
                    height,
                } => (
                    Shape::Cylinder {
                        centre: base.truncate(),
                        radius,
                        z0: base.z,
                        z1: base.z + height,
                    },
                    0.65,
                ),
                Clutter::Trunk {
                    base,
                    radius,
                    height,
                } => (
                    Shape::Cylinder {
                        centre: base.truncate(),
                        radius,
                        z0: base.z,
                        z1: base.z + height,
                    },
                    0.3,
                ),
                Clutter::Crown { centre, radius } => (Shape::Sphere { centre, radius }, 0.2),
            };
            let (lo, hi) = match shape {
                Shape::Cylinder {
                    centre,
                    radius,
                    z0,
                    z1,
                } => ((centre - radius).extend(z0), (centre + radius).extend(z1)),
                Shape::Sphere { centre, radius } => (centre - radius, centre + radius),
                Shape::Poly { .. } => (DVec3::ZERO, DVec3::ZERO),
            };
            if !(lo.is_finite() && hi.is_finite()) {
                continue;
            }
            c.prims.push(Prim {
                shape,
                label: CLUTTER,
                reflectivity: refl,
                lo,
                hi,
            });
        }
        c
    }

    fn push_poly(&mut self, verts: &[DVec3], normal: DVec3, offset: f64, label: u32, refl: f64) {
        if verts.len() < 3 || verts.iter().any(|v| !v.is_finite()) {
            return;
        }
        let start = self.verts.len() as u32;
        self.verts.extend_from_slice(verts);
        let lo = verts.iter().copied().fold(DVec3::INFINITY, DVec3::min);
        let hi = verts.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
        self.prims.push(Prim {
            shape: Shape::Poly {
                start,
                len: verts.len() as u32,
                normal,
                offset,
            },
            label,
            reflectivity: refl,
            lo,
            hi,
        });
    }

    /// Cast one scan from scene-local position `pos` with heading `yaw`
    /// given as `(cos, sin)`; the sensor's spin axis is vertical.
    pub fn cast(
        &self,
        beams: &Beams,
        sensor: &SensorModel,
        pos: DVec3,
        yaw: (f64, f64),
        rng: &mut Rng,
    ) -> Cast {
        let nl = beams.lasers();
        let n_az = beams.az_cos.len();
        let rel: Vec<DVec3> = self.verts.iter().map(|&v| v - pos).collect();
        let bins = Bins::new(self, &rel, pos, sensor.max_range);

        let mut out = Cast {
            points: Vec::with_capacity(4 * nl * n_az),
            labels: Vec::with_capacity(nl * n_az),
        };
        let mut best_t = vec![f64::INFINITY; nl];
        let mut best_c = vec![0u32; nl];
        let mut best_cos = vec![0.0f64; nl];
        let mut xs: Vec<(f64, f64, f64)> = Vec::with_capacity(16);
        let (cy, sy) = yaw;
        let yaw_angle = libm::atan2(sy, cy);
        for j in 0..n_az {
            let (cp, sp) = (beams.az_cos[j], beams.az_sin[j]);
            // World azimuth of the column.
            let c = cy * cp - sy * sp;
            let s = sy * cp + cy * sp;
            let mut psi = TAU * j as f64 / n_az as f64 + yaw_angle;
            if psi < 0.0 {
                psi += TAU;
            }
            if psi >= TAU {
                psi -= TAU;
            }
            let bin = ((psi / TAU * BINS as f64) as usize).min(BINS - 1);
            best_t.fill(f64::INFINITY);
            let range = bins.start[bin] as usize..bins.start[bin + 1] as usize;
            for &ci in bins.always.iter().chain(&bins.items[range]) {
                let cand = &bins.cands[ci as usize];
                let mut hit = |k: usize, t: f64, cos_inc: f64| {
                    if t > 0.0 && t < best_t[k] {
                        best_t[k] = t;
                        best_c[k] = ci;
                        best_cos[k] = cos_inc;
                    }
                };
                match cand.local {
                    Local::Poly {
                        start,
                        len,
                        normal,
                        e,
                    } => {
                        let vs = &rel[start as usize..(start + len) as usize];
                        poly_column(vs, normal, e, c, s, beams, &mut xs, &mut hit);
                    }
                    Local::Cylinder {
                        centre,
                        cc,
                        radius,
                        z0,
                        z1,
                    } => {
                        let hc = c * centre.x + s * centre.y;
                        let disc = hc * hc - cc;
                        if hc <= 0.0 || disc < 0.0 {
                            continue;
                        }
                        let sq = disc.sqrt();
                        let rho = hc - sq;
                        if rho <= 0.0 {
                            continue;
                        }
                        let (a, b) = (z1 / rho, z0 / rho);
                        let lo = beams.tan.partition_point(|&t| t > a);
                        let hi = beams.tan.partition_point(|&t| t >= b);
                        for k in lo..hi.max(lo) {
                            hit(k, rho / beams.cos[k], beams.cos[k] * sq / radius);
                        }
                    }
                    Local::Sphere { centre, cc, radius } => {
                        let hc = c * centre.x + s * centre.y;
                        for k in 0..nl {
                            let b = beams.cos[k] * hc + beams.sin[k] * centre.z;
                            let disc = b * b - cc;
                            if b <= 0.0 || disc < 0.0 {
                                continue;
                            }
                            let sq = disc.sqrt();
                            hit(k, b - sq, sq / radius);
                        }
                    }
                }
            }
            // Emit the column in laser output order.
            for l in 0..nl {
                let k = beams.rank[l];
                let t = best_t[k];
                if !(t >= sensor.min_range && t <= sensor.max_range) {
                    continue;
                }
                if sensor.dropout > 0.0 && rng.uniform() < sensor.dropout {
                    continue;
                }
                let mut r = t;
                if sensor.range_sigma > 0.0 {
                    r += sensor.range_sigma * self.normal.sample(rng);
                    if r <= 0.0 {
                        continue;
                    }
                }
                let cand = &bins.cands[best_c[k] as usize];
                let falloff = 1.0 / (1.0 + (t / 150.0) * (t / 150.0));
                let mut intensity =
                    cand.reflectivity * (0.2 + 0.8 * best_cos[k].min(1.0)) * falloff;
                if sensor.intensity_sigma > 0.0 {
                    // Uniform noise with the requested standard deviation.
                    intensity +=
                        sensor.intensity_sigma * 3.464_101_615_137_754_5 * (rng.uniform() - 0.5);
                }
                let ce = beams.cos[k];
                out.points.extend_from_slice(&[
                    (r * ce * cp) as f32,
                    (r * ce * sp) as f32,
                    (r * beams.sin[k]) as f32,
                    intensity.clamp(0.0, 1.0) as f32,
                ]);
                out.labels.push(cand.label);
            }
        }
        out
    }
}

/// Intersect the lasers of one column (world azimuth `(c, s)`) with a planar
/// polygon given by vertices relative to the sensor.
#[allow(clippy::too_many_arguments)]
#[inline]
fn poly_column(
    vs: &[DVec3],
    normal: DVec3,
    e: f64,
    c: f64,
    s: f64,
    beams: &Beams,
    xs: &mut Vec<(f64, f64, f64)>,
    hit: &mut impl FnMut(usize, f64, f64),
) {
    let n = vs.len();
    if n < 3 {
        return;
    }
    // Side of the column's vertical plane (normal m = (-s, c, 0)), and the
    // direction of the plane/polygon intersection line, n × m.
    let line = DVec3::new(-normal.z * c, -normal.z * s, normal.x * c + normal.y * s);
    xs.clear();
    let mut prev = vs[n - 1];
    let mut sp = c * prev.y - s * prev.x;
    for &v in vs {
        let sv = c * v.y - s * v.x;
        if (sv >= 0.0) != (sp >= 0.0) {
            // Computed from the non-negative end, so that an edge shared by
            // two pieces gives the same point in both.
            let (a, sa, b, sb) = if sv >= 0.0 {
                (v, sv, prev, sp)
            } else {
                (prev, sp, v, sv)
            };
            let q = a + (b - a) * (sa / (sa - sb));
            xs.push((line.dot(q), c * q.x + s * q.y, q.z));
        }
        prev = v;
        sp = sv;
    }
    if xs.len() < 2 {
        return;
    }
    if xs.len() > 2 {
        crate::geometry::insertion_sort_by(xs, |a, b| a.0.total_cmp(&b.0));
    }
    let nr = normal.x * c + normal.y * s;
    let nz = normal.z;
    for pair in xs.chunks_exact(2) {
        let (mut ra, mut za, mut rb, mut zb) = (pair[0].1, pair[0].2, pair[1].1, pair[1].2);
        if ra < 0.0 && rb < 0.0 {
            continue;
        }
        // Keep the part in front of the sensor (r ≥ 0).
        if ra < 0.0 {
            za = zb + (za - zb) * (rb / (rb - ra));
            ra = 0.0;
        } else if rb < 0.0 {
            zb = za + (zb - za) * (ra / (ra - rb));
            rb = 0.0;
        }
        let ia = lasers_above(beams, ra, za);
        let ib = lasers_above(beams, rb, zb);
        for k in ia.min(ib)..ia.max(ib) {
            let denom = beams.cos[k] * nr + beams.sin[k] * nz;
            let t = -e / denom;
            if t.is_finite() {
                hit(k, t, denom.abs());
            }
        }
    }
}

/// Number of lasers (sorted by descending elevation) passing above the point
/// `(r, z)` of a column's half-plane.
#[inline]
fn lasers_above(beams: &Beams, r: f64, z: f64) -> usize {
    let (mut lo, mut hi) = (0, beams.cos.len());
    while lo < hi {
        let mid = (lo + hi) / 2;
        if beams.cos[mid] * z - beams.sin[mid] * r < 0.0 {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Per-scan candidates and azimuth bins (CSR layout).
struct Bins {
    cands: Vec<Cand>,
    always: Vec<u32>,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Bins {
    fn new(caster: &Caster, rel: &[DVec3], pos: DVec3, max_range: f64) -> Bins {
        let mut cands = Vec::new();
        let mut always = Vec::new();
        let mut spans: Vec<(u32, i64, i64)> = Vec::new();
        let bw = TAU / BINS as f64;
        for p in &caster.prims {
            // Range culling by bounding box.
            let d = (p.lo - pos).max(pos - p.hi).max(DVec3::ZERO);
            if d.length_squared() > max_range * max_range {
                continue;
            }
            let (local, interval) = match p.shape {
                Shape::Poly {
                    start,
                    len,
                    normal,
                    offset,
                } => {
                    let vs = &rel[start as usize..(start + len) as usize];
                    (
                        Local::Poly {
                            start,
                            len,
                            normal,
                            e: normal.dot(pos) + offset,
                        },
                        poly_interval(vs),
                    )
                }
                Shape::Cylinder {
                    centre,
                    radius,
                    z0,
                    z1,
                } => {
                    let c = centre - pos.truncate();
                    (
                        Local::Cylinder {
                            centre: c,
                            cc: c.length_squared() - radius * radius,
                            radius,
                            z0: z0 - pos.z,
                            z1: z1 - pos.z,
                        },
                        disc_interval(c, radius),
                    )
                }
                Shape::Sphere { centre, radius } => {
                    let c = centre - pos;
                    (
                        Local::Sphere {
                            centre: c,
                            cc: c.length_squared() - radius * radius,
                            radius,
                        },
                        disc_interval(c.truncate(), radius),
                    )
                }
            };
            let ci = cands.len() as u32;
            cands.push(Cand {
                local,
                label: p.label,
                reflectivity: p.reflectivity,
            });
            match interval {
                None => always.push(ci),
                Some((lo, hi)) => {
                    let k = libm::floor(lo / TAU);
                    let (lo, hi) = (lo - k * TAU, hi - k * TAU);
                    let b0 = libm::floor((lo - BIN_MARGIN) / bw) as i64;
                    let b1 = libm::floor((hi + BIN_MARGIN) / bw) as i64;
                    if b1 - b0 + 1 >= BINS as i64 {
                        always.push(ci);
                    } else {
                        spans.push((ci, b0, b1));
                    }
                }
            }
        }
        let wrap = |b: i64| b.rem_euclid(BINS as i64) as usize;
        let mut start = vec![0u32; BINS + 1];
        for &(_, b0, b1) in &spans {
            for b in b0..=b1 {
                start[wrap(b) + 1] += 1;
            }
        }
        for i in 0..BINS {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; start[BINS] as usize];
        for &(ci, b0, b1) in &spans {
            for b in b0..=b1 {
                let w = wrap(b);
                items[fill[w] as usize] = ci;
                fill[w] += 1;
            }
        }
        Bins {
            cands,
            always,
            start,
            items,
        }
    }
}

/// Azimuth interval `(lo, hi)` (radians, `hi - lo < 2π`) covered by a
/// polygon's xy footprint seen from the origin, or `None` if the footprint
/// contains or touches the origin.
fn poly_interval(vs: &[DVec3]) -> Option<(f64, f64)> {
    let n = vs.len();
    if n == 0 {
        return None;
    }
    for i in 0..n {
        let (a, b) = (vs[i].truncate(), vs[(i + 1) % n].truncate());
        if crate::geometry::polygon::segment_distance_sq(DVec2::ZERO, a, b) < 1e-12 {
            return None;
        }
    }
    let a0 = libm::atan2(vs[0].y, vs[0].x);
    let (mut cur, mut lo, mut hi) = (a0, a0, a0);
    for i in 0..n {
        let (a, b) = (vs[i].truncate(), vs[(i + 1) % n].truncate());
        cur += libm::atan2(a.perp_dot(b), a.dot(b));
        lo = lo.min(cur);
        hi = hi.max(cur);
    }
    if (cur - a0).abs() > PI || hi - lo >= TAU - 1e-9 {
        return None;
    }
    Some((lo, hi))
}

/// Azimuth interval of a disc of `radius` centred at `c` (relative to the
/// sensor), or `None` if it contains the sensor.
fn disc_interval(c: DVec2, radius: f64) -> Option<(f64, f64)> {
    let d = c.length();
    if d <= radius + 1e-9 {
        return None;
    }
    let mid = libm::atan2(c.y, c.x);
    let half = libm::asin((radius / d).min(1.0));
    Some((mid - half, mid + half))
}

/// Cut a ring into pieces of at most [`MAX_PIECE_VERTICES`] vertices by
/// halving its bounding box along the longer side. Pieces may contain
/// zero-width bridges along the cuts; even-odd casting ignores them.
fn split(ring: Vec<DVec2>, depth: u32, out: &mut Vec<Vec<DVec2>>) {
    if ring.len() < 3 || signed_area(&ring) == 0.0 {
        return;
    }
    if ring.len() <= MAX_PIECE_VERTICES || depth >= 16 {
        out.push(ring);
        return;
    }
    let lo = ring.iter().copied().fold(DVec2::INFINITY, DVec2::min);
    let hi = ring.iter().copied().fold(DVec2::NEG_INFINITY, DVec2::max);
    let axis = if hi.x - lo.x >= hi.y - lo.y { 0 } else { 1 };
    let cut = 0.5 * (lo[axis] + hi[axis]);
    let below = clip(&ring, axis, cut, true);
    let above = clip(&ring, axis, cut, false);
    split(below, depth + 1, out);
    split(above, depth + 1, out);
}

/// Sutherland–Hodgman clip of a ring to `p[axis] ≤ cut` (or `≥ cut`). Cut
/// points are computed from the lower end of each edge, so both halves get
/// bit-identical points.
fn clip(ring: &[DVec2], axis: usize, cut: f64, below: bool) -> Vec<DVec2> {
    let inside = |p: DVec2| {
        if below {
            p[axis] <= cut
        } else {
            p[axis] >= cut
        }
    };
    let n = ring.len();
    let mut out = Vec::with_capacity(n + 4);
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let (ia, ib) = (inside(a), inside(b));
        if ia {
            out.push(a);
        }
        if ia != ib {
            let (p, q) = if a[axis] <= b[axis] { (a, b) } else { (b, a) };
            let t = (cut - p[axis]) / (q[axis] - p[axis]);
            let mut x = p + (q - p) * t;
            x[axis] = cut;
            out.push(x);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_halves_share_cut_points() {
        let ring = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(3.1, 0.7),
            DVec2::new(2.0, 2.9),
            DVec2::new(0.3, 1.7),
        ];
        let a = clip(&ring, 0, 1.37, true);
        let b = clip(&ring, 0, 1.37, false);
        let total = signed_area(&ring);
        assert!((signed_area(&a) + signed_area(&b) - total).abs() < 1e-12);
        let on_a: Vec<_> = a.iter().filter(|p| p.x == 1.37).collect();
        let on_b: Vec<_> = b.iter().filter(|p| p.x == 1.37).collect();
        assert_eq!(on_a.len(), 2);
        for p in on_a {
            assert!(on_b.contains(&p));
        }
    }

    #[test]
    fn intervals() {
        // A wall in front, to the left.
        let wall = [
            DVec3::new(5.0, 1.0, 0.0),
            DVec3::new(5.0, 3.0, 0.0),
            DVec3::new(5.0, 3.0, 2.0),
            DVec3::new(5.0, 1.0, 2.0),
        ];
        let (lo, hi) = poly_interval(&wall).unwrap();
        assert!((lo - libm::atan2(1.0, 5.0)).abs() < 1e-12);
        assert!((hi - libm::atan2(3.0, 5.0)).abs() < 1e-12);
        // A wall behind, straddling ±π.
        let back = wall.map(|v| DVec3::new(-v.x, v.y - 2.0, v.z));
        let (lo, hi) = poly_interval(&back).unwrap();
        assert!(
            (hi - lo - 2.0 * libm::atan2(1.0, 5.0)).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert!((lo < -PI && hi > -PI) || (lo < PI && hi > PI), "{lo} {hi}");
        // A floor around the sensor.
        let floor = [
            DVec3::new(-5.0, -5.0, -1.8),
            DVec3::new(5.0, -5.0, -1.8),
            DVec3::new(5.0, 5.0, -1.8),
            DVec3::new(-5.0, 5.0, -1.8),
        ];
        assert!(poly_interval(&floor).is_none());
        assert!(disc_interval(DVec2::new(0.1, 0.0), 0.5).is_none());
        let (lo, hi) = disc_interval(DVec2::new(0.0, 2.0), 1.0).unwrap();
        assert!((hi - lo - 2.0 * (PI / 6.0)).abs() < 1e-12);
    }
}
