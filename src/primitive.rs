//! A geometric polygonal primitive: support plane, local frame, outline,
//! running statistics and an occupancy footprint, plus the "shaping" step
//! that turns a support set into one (PCA refit, outline, area, solidity).

use crate::floor::GroundRule;
use crate::geometry::plane::{robust_fit, RobustFit};
use crate::geometry::polygon::{contains, signed_area};
use crate::geometry::{convex_hull, Footprint, Frame, Moments, Plane, Polygon3};
use crate::params::{HullKind, Params, SolidityKind};
use glam::{DMat3, DVec2, DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// Label of a point that no primitive explains.
pub const NO_PRIMITIVE: u32 = u32::MAX;

/// One planar polygon of the scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Primitive {
    /// Stable id (kept while the primitive grows or absorbs another).
    pub id: u32,
    /// Support plane (world frame); the normal points towards the sensor
    /// that first saw it.
    pub plane: Plane,
    /// 2D frame on the plane the outline is expressed in.
    pub frame: Frame,
    /// Outline in frame coordinates (m), simple and counter-clockwise seen
    /// from the normal side.
    pub outline: Vec<DVec2>,
    /// Outline area (m^2).
    pub area: f64,
    /// Number of points that support it (over all scans).
    pub support: u64,
    /// Near-horizontal (within `Params::ground_max_tilt`): road, sidewalk.
    pub ground: bool,
    /// Running moments of all support points (f64), for refits.
    pub moments: Moments,
    /// Where support points fell, in frame coordinates.
    pub footprint: Footprint,
    /// Scan in which it was detected.
    pub born_scan: u64,
    /// Last scan in which it gained support.
    pub last_scan: u64,
}

impl Primitive {
    /// Support points per square metre of outline.
    pub fn density(&self) -> f64 {
        if self.area > 0.0 {
            self.support as f64 / self.area
        } else {
            0.0
        }
    }

    /// Share of the outline's area whose footprint blocks of 2 x 2 cells
    /// hold support (0..1). Blocks, not cells: a far facade's laser rings
    /// lie farther apart than one cell (0.2 m by default) but cover the
    /// surface at the sensor's resolution, and the outline closes them.
    pub fn occupancy(&self) -> f64 {
        if self.area > 0.0 {
            (self.footprint.occupied_block_area() / self.area).min(1.0)
        } else {
            0.0
        }
    }

    /// Outline vertices in world coordinates, in order.
    pub fn vertices(&self) -> Vec<DVec3> {
        self.outline
            .iter()
            .map(|&q| self.frame.to_world(q))
            .collect()
    }

    /// The outline as a 3D polygon.
    pub fn polygon(&self) -> Polygon3 {
        Polygon3 {
            frame: self.frame,
            ring: self.outline.clone(),
        }
    }

    /// Whether the world point `w` lies on this polygon: within `within`
    /// (m) of its plane and inside its outline.
    pub(crate) fn holds(&self, w: DVec3, within: f64) -> bool {
        self.plane.signed_distance(w).abs() <= within
            && contains(&self.outline, self.frame.to_local(w))
    }

    /// RMS distance of the (robust inner) support from the plane (m).
    pub fn rms(&self) -> f64 {
        self.moments
            .fit_plane()
            .map_or(0.0, |(_, vals)| vals[0].max(0.0).sqrt())
    }

    /// The distance from its plane within which a point is this
    /// primitive's own noise: three times its RMS, at least 3 cm (`cap`
    /// when that is smaller), at most `cap`. Expansion's perpendicular gate
    /// (`cap` = `expandAcross`), and the band the merge pass refits a piece
    /// tilted by a strip of another surface from (`cap` = the inlier
    /// distance).
    pub(crate) fn noise_gate(&self, cap: f64) -> f64 {
        crate::geometry::clamp(3.0 * self.rms(), 0.03f64.min(cap), cap)
    }

    /// Does it pass the acceptance tests on its shape: at least
    /// `min_inliers` support points, area above `min_area`, width above
    /// `min_width`, solidity? (Detection also tests the support's roughness,
    /// which needs the points.)
    pub fn acceptable(&self, params: &Params) -> bool {
        self.acceptable_with(params, params.min_inliers)
    }

    /// [`Primitive::acceptable`] with `min_support` support points instead
    /// of `min_inliers`.
    pub(crate) fn acceptable_with(&self, params: &Params, min_support: usize) -> bool {
        self.support >= min_support as u64
            && self.area >= params.min_area
            && min_width(&self.outline) >= params.min_width
            && match params.solidity {
                SolidityKind::Density => self.density() >= params.min_density,
                SolidityKind::Occupancy => self.occupancy() >= params.min_occupancy,
            }
    }

    /// Outline radius used for this primitive (m): the parameters' radius
    /// for its kind of surface, in the same ratio to its footprint's cell
    /// as to the parameters' cell (one-shot detection's coarse pass traces
    /// sparse surfaces on coarser cells).
    pub fn alpha(&self, params: &Params) -> f64 {
        let s = params.surface(self.ground);
        // The ratio is exactly 1 for the usual footprint.
        s.alpha * (self.footprint.cell() / s.cell)
    }

    /// Clustering tolerance of this primitive (m), scaled as
    /// [`Primitive::alpha`] is: how far from its true edge its outline can
    /// lie.
    pub(crate) fn cluster_tolerance(&self, params: &Params) -> f64 {
        let s = params.surface(self.ground);
        s.cluster_tolerance * (self.footprint.cell() / s.cell)
    }

    /// Recompute the outline after the footprint or hull points changed.
    /// `extra` are new support points (frame coordinates) for convex hulls.
    /// Returns false (leaving the primitive unchanged) when no outline exists.
    pub(crate) fn reshape(&mut self, params: &Params, extra: &[DVec2]) -> bool {
        if params.hull == HullKind::Concave {
            if let Some(r) = self.thin_rectangle() {
                self.area = signed_area(&r);
                self.outline = r;
                return true;
            }
        }
        let ring = params.hull.grown(
            &self.outline,
            extra,
            &self.footprint,
            self.alpha(params),
            params.simplify,
            params.max_vertices,
        );
        match ring {
            Some(r) if r.len() >= 3 => {
                self.area = signed_area(&r);
                self.outline = r;
                true
            }
            _ => false,
        }
    }

    /// The outline of a primitive narrower than two footprint cells (a
    /// curb's or a step's 15 cm face, whose outline is the rectangle
    /// between the two surfaces it joins) grown to the footprint: the same
    /// rectangle, across its narrow side as it was, along its long side
    /// out to the centres of the footprint's end cells. The raster cannot
    /// hold such a face: traced, one row of 0.2 m cells is more than its
    /// height, and only the largest region the closing joins is kept (the
    /// simulated crossing's curbs, with gaps of up to 1 m between a ring's
    /// points, traced to a tenth of their rectangles: 0.16 of 1.76 m^2).
    /// `None` for an outline, or support cells, two cells wide or more.
    fn thin_rectangle(&self) -> Option<Vec<DVec2>> {
        let hull = convex_hull(&self.outline)?;
        let (width, along) = narrowest_axis(&hull);
        let cell = self.footprint.cell();
        if width >= 2.0 * cell {
            return None;
        }
        let across = along.perp();
        let centres = self.footprint.cell_centres();
        // The support too must be a strip: a wide surface merged into a
        // riser in its plane (a wall standing on a curb's line) is traced.
        let (s0, s1) = span(centres.iter().copied(), across);
        if s1 - s0 >= 2.0 * cell {
            return None;
        }
        let (c0, c1) = span(hull.iter().copied(), across);
        let (a0, a1) = span(hull.iter().copied().chain(centres), along);
        if !(a1 > a0 && c1 > c0) {
            return None;
        }
        let at = |a: f64, c: f64| along * a + across * c;
        let mut ring = vec![at(a0, c0), at(a1, c0), at(a1, c1), at(a0, c1)];
        crate::geometry::polygon::make_ccw(&mut ring);
        Some(ring)
    }
}

/// The sense a thin rectangle's long axis is given: any fixed direction
/// away from the frame's axes (along which strips run).
const SENSE: DVec2 = DVec2::new(0.984_807_753_012_208, 0.173_648_177_666_930_3);

/// Widths (m) closer than this to the smallest count as equal in
/// [`narrowest_axis`].
const WIDTH_TIE: f64 = 1e-6;

/// The smallest width of a convex hull and the direction of its long axis:
/// the mean direction of the hull edges as narrow as the narrowest (within
/// [`WIDTH_TIE`]), in the sense of [`SENSE`]. A riser's quadrilateral
/// (its long edges where its plane meets two surfaces a hair out of
/// parallel) is exactly as narrow from either long edge, so rounding alone
/// would pick one edge's direction or the other's; the mean does not
/// depend on that.
fn narrowest_axis(h: &[DVec2]) -> (f64, DVec2) {
    let n = h.len();
    let widths: Vec<(f64, DVec2)> = (0..n)
        .map(|i| {
            let (a, b) = (h[i], h[(i + 1) % n]);
            let e = crate::geometry::unit_or_zero(b - a);
            let w = h
                .iter()
                .map(|&p| e.perp_dot(p - a))
                .fold(0.0f64, |w, d| if d > w { d } else { w });
            (w, e)
        })
        .collect();
    let best = widths
        .iter()
        .fold(f64::INFINITY, |b, &(w, _)| if w < b { w } else { b });
    let sum = widths
        .iter()
        .filter(|&&(w, _)| w <= best + WIDTH_TIE)
        .fold(DVec2::ZERO, |s, &(_, e)| {
            s + if e.dot(SENSE) < 0.0 { -e } else { e }
        });
    let along = crate::geometry::unit_or_zero(sum);
    let along = if along == DVec2::ZERO {
        DVec2::X
    } else {
        along
    };
    (best, along)
}

/// The least and greatest of the points' coordinates along `dir`.
fn span(pts: impl Iterator<Item = DVec2>, dir: DVec2) -> (f64, f64) {
    pts.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
        let t = p.dot(dir);
        (if t < lo { t } else { lo }, if t > hi { t } else { hi })
    })
}

/// The band a primitive's expansion takes points from, along the frame's
/// second axis (up the plane, for walls): for a riser (an outline spanning
/// less than `width` along it: detection accepts nothing narrower than
/// `minWidth`) its outline's span, for any other primitive all of it.
pub(crate) fn strip_span(ring: &[DVec2], width: f64) -> (f64, f64) {
    let (lo, hi) = span(ring.iter().copied(), DVec2::Y);
    if hi - lo < width {
        (lo, hi)
    } else {
        (f64::NEG_INFINITY, f64::INFINITY)
    }
}

/// Smallest width of the outline's convex hull (rotating calipers over the
/// hull edges), in metres.
pub fn min_width(ring: &[DVec2]) -> f64 {
    convex_hull(ring).map_or(0.0, |h| narrowest_axis(&h).0)
}

/// The result of shaping a support set: the primitive (id 0, scans 0) and
/// which of the given points it kept as support (a concave outline keeps
/// only the largest connected region).
pub(crate) struct Shaped {
    pub primitive: Primitive,
    pub kept: Vec<bool>,
    /// RMS distance of all kept support points from the plane (m), as a
    /// share of the inlier distance: ~0.58 for points spread evenly through
    /// the inlier slab (a plane cutting through objects), far less for a
    /// surface.
    pub roughness: f64,
    /// Share of the kept support points within half the inlier distance of
    /// the plane: near 1 for a surface with noise, about a half for points
    /// spread evenly through the slab, in between for a plane that holds
    /// two surfaces, one at either side of it (a road and the sidewalk a
    /// curb above it, under a plane tilted to hold both).
    pub tight_share: f64,
    /// Frame coordinates of every support point (for
    /// [`Shaped::consistency`]).
    q: Vec<DVec2>,
}

impl Shaped {
    /// Share of the support's local patches (cells of `2 x cell`) whose own
    /// PCA normal lies within 15 degrees of the plane's: ~1 for a surface,
    /// low for a plane cutting through crossing surfaces (a horizontal slab
    /// through a car's sides, whose laser rings look flat from afar, or a
    /// plane tilted across a curb). 1 when no patch has a well-defined
    /// normal. `origin` and `pts` are what [`shape`] was given. Computed on
    /// demand: it is the costliest acceptance test (a plane fit per patch),
    /// so the cascade asks for it only when every other test passed.
    /// With it, from the same patch fits, the noise of the support's
    /// surfaces ([`Consistency::noise`]).
    ///
    /// A patch whose own plane passes through one of `sensors`
    /// ([`one_laser_ring`]) holds a single laser ring, whose points lie on
    /// that laser's cone whatever the surface: its normal is the cone's (15-25
    /// degrees off level for the lower lasers near the sensor), and its
    /// spread is not the surface's noise (micrometres when the range noise
    /// lies along the beam). Such patches count only when the support has
    /// no other patch with a normal. Where rings lie farther apart than a
    /// patch (sparse sensors, far ground), most patches are rings: counted,
    /// their cones would vote level ground out, and their spread would make
    /// the dominant-layer test's noise band too thin to find any layer. A
    /// support seen only as lone rings is judged on them: a plane through
    /// one ring is no evidence of a surface, and their cones rarely agree
    /// with it. The plane is then unproven ([`Consistency::rings_only`]): two
    /// ring arcs metres apart fit one plane within centimetres.
    pub fn consistency(
        &self,
        origin: DVec3,
        pts: &[Vec3],
        params: &Params,
        sensors: &[DVec3],
    ) -> Consistency {
        normal_consistency(
            origin,
            pts,
            &self.q,
            &self.kept,
            &self.primitive.frame,
            2.0 * params.other.cell,
            |normal, at| one_laser_ring(normal, at, sensors, params),
        )
    }
}

/// Share of a support's spread off its plane that a quadric must explain,
/// and the 90th percentile of that quadric's slope over the points that it
/// must exceed (tan 10 degrees: its normal turns by 20 degrees across
/// them), for [`Shaped::domed`].
const DOME_EXPLAINED: f64 = 0.5;
const DOME_SLOPE: f64 = 0.176_326_980_708_464_98;
/// The cosines of 15 and 75 degrees: a plane seen from below and tilted
/// between them from level is a slant cut through a crown's underside, and
/// one within 15 degrees of level above the sensor is seen from below
/// whichever way its fit leans ([`Shaped::domed`]).
const SLANT_COS: (f64, f64) = (0.965_925_826_289_068_3, 0.258_819_045_102_520_8);

impl Shaped {
    /// Is this a dome seen from below (a tree crown's underside), not a
    /// surface? Its normal, turned towards the sensor, points down, or up
    /// within 15 degrees of vertical, its points lie above the sensor on
    /// average, and either the plane is slanted
    /// (tilted between 15 and 75 degrees from level, [`SLANT_COS`]) or its
    /// points bend: a quadric about their centre (the distance off the plane
    /// as `a x^2 + b x y + c y^2` plus a constant) explains more than half of
    /// their spread off the plane, and its normal turns by more than 20
    /// degrees across them (twice the 90th percentile of its slope over the
    /// points). A plane slab cut from a crown's underside passes every other
    /// test: its points fill the slab's lower half evenly enough to be smooth
    /// and its patches lean less than 15 degrees. A real surface seen from
    /// below is level (a ceiling, an awning) or upright (a wall's overhang).
    /// A slant cut through what the pool gathers of a crown's underside over
    /// many scans need not bend the way a quadric explains. A car's body,
    /// which bends as much, is seen from above or from the side. Seen from
    /// nearly level (the points a few degrees above the sensor), a plane
    /// fitted through a crown's underside can lean more than the line of
    /// sight, so that its face towards the sensor points up; such a plane is
    /// judged too, and is a dome when it bends as above with its rim higher
    /// than its middle (on the own simulator's drives such a cut, 1.5-2.2
    /// m^2 at 2 m, passed as a surface; a crest of ground above the sensor
    /// bends the other way). `origin` and
    /// `pts` are what [`shape`] was given; large supports are judged on an
    /// even-strided subsample of 20,000 points.
    pub fn domed(&self, origin: DVec3, pts: &[Vec3], viewpoint: DVec3) -> bool {
        let f = &self.primitive.frame;
        if (0.0..SLANT_COS.0).contains(&f.normal.z) {
            return false;
        }
        let step = pts.len().div_ceil(20_000).max(1);
        let chosen: Vec<usize> = (0..pts.len())
            .step_by(step)
            .filter(|&i| self.kept[i])
            .collect();
        let n = chosen.len() as f64;
        if chosen.len() < 12 {
            return false;
        }
        // Above the sensor: below it, a sparse face's few laser rings (a
        // far car's side) bend any fit in their handful of heights.
        let height = chosen
            .iter()
            .map(|&i| origin.z + f64::from(pts[i].z))
            .sum::<f64>()
            / n;
        if height <= viewpoint.z {
            return false;
        }
        if -f.normal.z < SLANT_COS.0 && -f.normal.z > SLANT_COS.1 {
            return true;
        }
        let mid = chosen.iter().fold(DVec2::ZERO, |m, &i| m + self.q[i]) / n;
        // (offset from the centre, distance off the plane)
        let rows: Vec<(DVec2, f64)> = chosen
            .iter()
            .map(|&i| {
                let off = f.normal.dot(origin + pts[i].as_dvec3() - f.origin);
                (self.q[i] - mid, off)
            })
            .collect();
        let terms = |u: DVec2| DVec3::new(u.x * u.x, u.x * u.y, u.y * u.y);
        let (mx, md) = rows.iter().fold((DVec3::ZERO, 0.0), |(a, b), &(u, d)| {
            (a + terms(u) / n, b + d / n)
        });
        // Least squares `d = a x^2 + b x y + c y^2 + e` (a quadric about
        // the centre), by the normal equations of the centred terms.
        let (mut xx, mut xd, mut sdd) = (DMat3::ZERO, DVec3::ZERO, 0.0);
        for &(u, d) in &rows {
            let x = terms(u) - mx;
            xx += DMat3::from_cols(x * x.x, x * x.y, x * x.z);
            xd += x * (d - md);
            sdd += (d - md) * (d - md);
        }
        // Singular (all points on a line or one spot), or NaN: no dome.
        let scale = xx.x_axis.x * xx.y_axis.y * xx.z_axis.z;
        if xx.determinant().partial_cmp(&(1e-12 * scale)) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let co = xx.inverse() * xd;
        // The share of the spread the fit explains.
        if co.dot(xd) <= DOME_EXPLAINED * sdd {
            return false;
        }
        // Facing up, only a bend that opens upwards (its rim higher than its
        // middle) is a crown's underside: a crest above the sensor (ground
        // over a rise ahead) bends the other way.
        if f.normal.z > 0.0 && co.x + co.z <= 0.0 {
            return false;
        }
        // Its slope at each point, and the 90th percentile of that.
        let mut slope: Vec<f64> = rows
            .iter()
            .map(|&(u, _)| {
                DVec2::new(2.0 * co.x * u.x + co.y * u.y, co.y * u.x + 2.0 * co.z * u.y).length()
            })
            .collect();
        crate::geometry::heap_sort_by(&mut slope, f64::total_cmp);
        slope[slope.len() * 9 / 10] > DOME_SLOPE
    }
}

/// Does a plane at signed distance `d` from the viewpoint pass through it
/// (within two inlier distances)? Every ray from the sensor to such a plane
/// grazes it. The test of the RANSAC hypotheses, of the candidates (the
/// edge-on rules, module `detect`) and of the consistency test's patches
/// ([`one_laser_ring`]).
pub(crate) fn through_viewpoint(d: f64, p: &Params) -> bool {
    d.abs() < 2.0 * p.other.distance
}

/// Does a patch whose plane has `normal` and passes through `at` hold a
/// single laser ring of a sensor at one of `sensors`: does that plane pass
/// through one ([`through_viewpoint`])? A laser's cone contains its sensor.
fn one_laser_ring(normal: DVec3, at: DVec3, sensors: &[DVec3], params: &Params) -> bool {
    sensors
        .iter()
        .any(|&v| through_viewpoint(normal.dot(v - at), params))
}

/// What [`Shaped::consistency`] found in a support's patches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Consistency {
    /// Share of the patches with a normal whose normal lies within 15
    /// degrees of the plane's, single laser rings left out unless only
    /// they have one (1 when no patch has one).
    pub(crate) share: f64,
    /// The noise of the support's surfaces: the median over those patches
    /// of their points' RMS distance from their own planes. For a support
    /// seen only as single laser rings ([`Consistency::rings_only`]), the
    /// median over the rings of their points' RMS spread along the plane's
    /// normal instead, about each ring's centroid: a ring's spread off its
    /// laser's cone is not the surface's (micrometres when the range noise
    /// lies along the beam). `None` when no patch has a normal.
    pub(crate) noise: Option<f64>,
    /// Every patch with a normal is a single laser ring: the plane was put
    /// through rings, and two ring arcs metres apart fit one plane within
    /// centimetres (a road's ring and the sidewalk's beyond it, a curb up,
    /// under a plane tilted by a degree or two): no patch sees the
    /// surface.
    pub(crate) rings_only: bool,
}

/// The variance along unit `n` of points with covariance `c`.
fn along(c: [[f64; 3]; 3], n: DVec3) -> f64 {
    let n = n.to_array();
    (0..3)
        .map(|i| (0..3).map(|j| n[i] * c[i][j] * n[j]).sum::<f64>())
        .sum()
}

/// See [`Shaped::consistency`].
fn normal_consistency(
    origin: DVec3,
    pts: &[Vec3],
    q: &[DVec2],
    kept: &[bool],
    frame: &Frame,
    cell: f64,
    one_ring: impl Fn(DVec3, DVec3) -> bool,
) -> Consistency {
    // Large supports are judged on an even-strided subsample of 100k points.
    let step = pts.len().div_ceil(100_000).max(1);
    let chosen: Vec<usize> = (0..pts.len()).step_by(step).filter(|&i| kept[i]).collect();
    let xy: Vec<(i64, i64)> = chosen
        .iter()
        .map(|&i| {
            (
                crate::geometry::floor_i64(q[i].x / cell),
                crate::geometry::floor_i64(q[i].y / cell),
            )
        })
        .collect();
    // Patches in first-seen order, each gathering its points in input order.
    let (mut ids, mut patch_of) = (crate::hash::CellIds::default(), Vec::new());
    ids.assign(&xy, 1 << 16, &mut patch_of);
    let mut cells: Vec<Moments> = Vec::with_capacity(ids.keys.len());
    for (&i, &c) in chosen.iter().zip(&patch_of) {
        let w = origin + pts[i].as_dvec3();
        if c as usize == cells.len() {
            cells.push(Moments::new(w));
        }
        cells[c as usize].push(w);
    }
    // (agreeing, with a normal, their noise): the patches of the surface
    // itself, and those of single laser rings.
    let mut tally: [(usize, usize, Vec<f64>); 2] = Default::default();
    let cos_max = libm::cos(15f64.to_radians());
    for m in &cells {
        if m.count < 6.0 {
            continue;
        }
        // Only patches that are truly two-dimensional have a normal. The
        // closed-form solution is exact enough for this test: a flat patch
        // has its smallest eigenvalue well apart from the others.
        let Some((vals, normal)) = crate::geometry::plane::smallest_eigen3(m.covariance()) else {
            continue;
        };
        if vals[2] <= 0.0 || vals[1] < 0.05 * vals[2] {
            continue;
        }
        let ring = one_ring(normal, m.mean());
        // A ring's spread off its own plane (its laser's cone) is not the
        // surface's; along the plane's normal, about the ring's centroid,
        // it is what the surface shows there.
        let spread = if ring {
            along(m.covariance(), frame.normal)
        } else {
            vals[0]
        };
        let t = &mut tally[ring as usize];
        t.0 += (normal.dot(frame.normal).abs() >= cos_max) as usize;
        t.1 += 1;
        t.2.push(spread.max(0.0).sqrt());
    }
    let [own, rings] = tally;
    let rings_only = own.1 == 0 && rings.1 > 0;
    let (good, total, mut noise) = if own.1 > 0 { own } else { rings };
    let mid = noise.len() / 2;
    let median = (!noise.is_empty()).then(|| *noise.select_nth_unstable_by(mid, f64::total_cmp).1);
    Consistency {
        share: if total == 0 {
            1.0
        } else {
            good as f64 / total as f64
        },
        noise: median,
        rings_only,
    }
}

/// The rules of [`shape`] that differ between detection's uses, as its
/// cascade policy (`CascadePolicy`, module `detect`) sets them; the default
/// has neither.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ShapeRules {
    /// Ground footprints fill the gaps between laser rings that the
    /// range-pulled clustering bridged.
    pub(crate) bridge_ring_gaps: bool,
    /// Concave outlines leave out the holes of `minArea` or more.
    pub(crate) cut_holes: bool,
}

/// PCA refit, frame, footprint, outline and area of a support set given in
/// local coordinates relative to `origin`. `None` for degenerate sets (fewer
/// than three points, collinear) or when no outline exists. With
/// `rules.bridge_ring_gaps` (one-shot detection, whose ground clustering
/// grows with range), a ground footprint also fills the gaps between laser
/// rings that the clustering bridged ([`Footprint::bridge_towards`]); with
/// `rules.cut_holes`, the outline leaves out the holes of `minArea` or
/// more.
pub(crate) fn shape(
    origin: DVec3,
    pts: &[Vec3],
    params: &Params,
    viewpoint: DVec3,
    ground: GroundRule,
    rules: ShapeRules,
) -> Option<Shaped> {
    // World coordinates, once: every pass below reads them.
    let world: Vec<DVec3> = pts.iter().map(|p| origin + p.as_dvec3()).collect();
    let tilt = params.ground_max_tilt.to_radians();
    // Robust refit: points of a crossing surface within the inlier distance
    // (the edge of a riser under a tread) tilt a plain least-squares plane.
    // The moments of the points of the last refit are what the primitive
    // keeps for later refits.
    let RobustFit {
        plane: fit,
        mut moments,
        inner,
    } = robust_fit(&world, world.first()?.round())?;
    let plane = fit.oriented(viewpoint);
    // Ground: near-horizontal, well below the sensor's height where the
    // support lies (then, oriented towards the sensor, facing up).
    let ground = ground.of_support(
        &plane,
        viewpoint,
        moments.mean(),
        pts,
        libm::cos(tilt),
        params.ground_depth,
    );
    let frame = Frame::on_plane(&plane, moments.mean());
    let surface = params.surface(ground);
    // Support is what lies within the inlier distance of the final plane.
    let threshold = surface.distance;
    let near: Vec<bool> = world
        .iter()
        .map(|&p| plane.signed_distance(p).abs() < threshold)
        .collect();
    let q: Vec<DVec2> = world.iter().map(|&p| frame.to_local(p)).collect();
    let alpha = surface.alpha;
    let q_near: Vec<DVec2> = q
        .iter()
        .zip(&near)
        .filter_map(|(&p, &k)| k.then_some(p))
        .collect();
    let cell = surface.cell;
    let mut footprint = Footprint::new(cell);
    footprint.mark_all(&q_near);
    if ground && rules.bridge_ring_gaps {
        footprint.bridge_towards(
            frame.to_local(viewpoint),
            params.ground_cluster_range,
            params.ground.cluster_tolerance,
            // Narrower gaps are closed by the outline anyway.
            2.0 * alpha - cell,
        );
    }
    let (outline, region) = params.hull.outline(
        &q_near,
        &footprint,
        alpha,
        params.simplify,
        params.max_vertices,
        if rules.cut_holes {
            params.min_area
        } else {
            f64::INFINITY
        },
    )?;
    // The method's region, if any, decides which points near the plane stay.
    let kept: Vec<bool> = match &region {
        None => near,
        Some(region) => q
            .iter()
            .zip(&near)
            .map(|(&p, &k)| k && region.contains(p))
            .collect(),
    };
    let support = kept.iter().filter(|&&k| k).count() as u64;
    if kept.iter().any(|k| !k) {
        // Keep the statistics of the kept points only: take the dropped
        // ones out of the moments (fewer than the kept), and the footprint
        // cells outside the region (a kept point's cell is exactly a marked
        // cell inside it; with a convex hull every point near the plane is
        // kept, so its footprint is already right).
        let mut dropped = Moments::new(moments.reference);
        for (i, &p) in world.iter().enumerate() {
            if inner[i] && !kept[i] {
                dropped.push(p);
            }
        }
        moments.remove(&dropped);
        if let Some(region) = &region {
            footprint.retain_region(region);
        }
    }
    let area = signed_area(&outline);
    if area.is_nan() || area <= 0.0 {
        return None;
    }
    let (mut sq, mut nk, mut tight) = (0.0, 0usize, 0usize);
    for (&p, _) in world.iter().zip(&kept).filter(|(_, &k)| k) {
        let d = plane.signed_distance(p);
        sq += d * d;
        nk += 1;
        tight += usize::from(d.abs() <= 0.5 * threshold);
    }
    let roughness = (sq / nk.max(1) as f64).sqrt() / threshold;
    let tight_share = tight as f64 / nk.max(1) as f64;
    Some(Shaped {
        primitive: Primitive {
            id: 0,
            plane,
            frame,
            outline,
            area,
            support,
            ground,
            moments,
            footprint,
            born_scan: 0,
            last_scan: 0,
        },
        kept,
        roughness,
        tight_share,
        q,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polygon::is_simple;

    /// The patches of a support on level ground (z = 0) seen from a sensor
    /// 1.8 m above the origin: half a turn of one laser ring at -20 degrees
    /// (range noise of 5 cm along each beam, so each patch of it is
    /// two-dimensional) and, with `surface`, a 1.2 x 1.2 m patch of ground
    /// seen densely (5 mm of noise across it) 9 m away: the ring's patches
    /// outnumber the surface's. The test's findings with the sensor known
    /// and without it.
    fn ring_patches(surface: bool) -> [Consistency; 2] {
        let mut rng = crate::rng::Rng::new(3);
        let sensor = DVec3::new(0.0, 0.0, 1.8);
        let elevation = (-20f64).to_radians();
        let range = 1.8 / elevation.sin().abs();
        let mut world: Vec<DVec3> = (0..900)
            .map(|i| {
                let azimuth = (i as f64 * 0.2).to_radians();
                let dir = DVec3::new(
                    azimuth.cos() * elevation.cos(),
                    azimuth.sin() * elevation.cos(),
                    elevation.sin(),
                );
                sensor + dir * (range + 0.05 * rng.gaussian())
            })
            .collect();
        if surface {
            for i in 0..12 {
                for j in 0..12 {
                    let (x, y) = (9.0 + 0.1 * i as f64, 0.1 * j as f64);
                    world.push(DVec3::new(x, y, 0.005 * rng.gaussian()));
                }
            }
        }
        let plane = Plane::from_point_normal(DVec3::ZERO, DVec3::Z);
        let frame = Frame::on_plane(&plane, DVec3::ZERO);
        let q: Vec<DVec2> = world.iter().map(|&w| frame.to_local(w)).collect();
        let pts: Vec<Vec3> = world.iter().map(|w| w.as_vec3()).collect();
        let kept = vec![true; pts.len()];
        let params = Params::gpp2();
        [vec![sensor], vec![]].map(|sensors| {
            normal_consistency(DVec3::ZERO, &pts, &q, &kept, &frame, 0.4, |n, at| {
                one_laser_ring(n, at, &sensors, &params)
            })
        })
    }

    #[test]
    fn patches_of_a_single_laser_ring_count_only_when_nothing_else_does() {
        // With patches of the surface itself, the ring's patches (their
        // planes through the sensor, leaning 20 degrees with the laser's
        // cone) neither vote nor give the noise.
        let [known, unknown] = ring_patches(true);
        assert_eq!(known.share, 1.0);
        assert!(!known.rings_only);
        let noise = known.noise.unwrap();
        assert!((0.003..0.007).contains(&noise), "noise {noise}");
        assert!(
            unknown.share < 0.5,
            "without the sensor the rings vote: {unknown:?}"
        );
        let noise_unknown = unknown.noise.unwrap();
        assert!(noise_unknown < 0.001, "and give the noise: {noise_unknown}");
        // Seen only as a ring, the support is judged on its patches: their
        // cones disagree with a plane through them. The
        // plane is unproven, and the noise is the ring's spread along the
        // plane's normal: 5 cm of range noise at 20 degrees below level
        // moves a point 1.7 cm up or down.
        let [known, unknown] = ring_patches(false);
        assert_eq!(known.share, unknown.share);
        assert!(known.share < 0.5, "{known:?}");
        assert!(known.rings_only && !unknown.rings_only);
        let noise = known.noise.unwrap();
        assert!((0.013..0.021).contains(&noise), "noise {noise}");
        assert!(unknown.noise.unwrap() < 0.001, "{unknown:?}");
    }

    /// A curb's face as the riser step makes it: the 15 cm rectangle over
    /// x in [0, 3] (frame coordinates: x along the curb, y up), with its
    /// support's cells.
    fn riser() -> Primitive {
        let plane = Plane::from_point_normal(DVec3::ZERO, DVec3::Y);
        let frame = Frame::on_plane(&plane, DVec3::ZERO);
        let outline = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(3.0, 0.0),
            DVec2::new(3.0, 0.15),
            DVec2::new(0.0, 0.15),
        ];
        let mut footprint = Footprint::new(0.2);
        let pts: Vec<DVec2> = (0..30)
            .map(|i| DVec2::new(0.05 + 0.1 * i as f64, 0.07))
            .collect();
        footprint.mark_all(&pts);
        Primitive {
            id: 1,
            plane,
            frame,
            area: signed_area(&outline),
            outline,
            support: 30,
            ground: false,
            moments: Moments::new(DVec3::ZERO),
            footprint,
            born_scan: 0,
            last_scan: 0,
        }
    }

    /// Points every 5 cm over 2 m x 2 m, 2.5 m up at their lowest: the
    /// underside of a sphere of radius `radius` (a tree crown's, at 2 m),
    /// the part within 10 cm of its lowest point; or flat (a ceiling).
    fn underside(radius: Option<f64>) -> Vec<Vec3> {
        let mut pts = Vec::new();
        for i in -20..=20 {
            for j in -20..=20 {
                let (x, y) = (0.05 * i as f64, 0.05 * j as f64);
                let r2 = x * x + y * y;
                let sag = radius.map_or(0.0, |r| r - (r * r - r2).max(0.0).sqrt());
                if sag > 0.1 {
                    continue;
                }
                let z = 2.5 + sag;
                pts.push(Vec3::new(x as f32, y as f32, z as f32));
            }
        }
        pts
    }

    #[test]
    fn a_crown_underside_is_a_dome_and_a_ceiling_is_not() {
        let p = Params::gpp2();
        let judge = |pts: &[Vec3], viewpoint: DVec3| {
            let s = shape(
                DVec3::ZERO,
                pts,
                &p,
                viewpoint,
                GroundRule::BelowViewpoint,
                ShapeRules::default(),
            )
            .expect("a primitive");
            assert!(s.roughness <= p.max_roughness, "{}", s.roughness);
            s.domed(DVec3::ZERO, pts, viewpoint)
        };
        let below = DVec3::new(3.0, 0.0, 1.8);
        assert!(judge(&underside(Some(2.0)), below));
        assert!(!judge(&underside(None), below), "a flat ceiling");
        // A gentler bend, whose normal turns by about 16 degrees across
        // the points (under the 20 a dome needs), is not one.
        assert!(!judge(&underside(Some(8.0)), below), "a gentle bend");
        // The same bend seen from above (a bowl), or with the sensor
        // higher than the points, is no crown's underside.
        assert!(!judge(&underside(Some(2.0)), DVec3::new(3.0, 0.0, 9.0)));
        let mut low = underside(Some(2.0));
        for q in &mut low {
            q.z -= 2.0;
        }
        assert!(!judge(&low, DVec3::new(3.0, 0.0, 1.8)));
        // A flat patch seen from below: slanted 30 degrees (a cut through
        // a crown's underside), or 10 (an awning, level within 15), or
        // upright (a wall's overhang).
        let tilted = |deg: f64| -> Vec<Vec3> {
            let (s, c) = deg.to_radians().sin_cos();
            underside(None)
                .iter()
                .map(|q| {
                    let x = f64::from(q.x);
                    Vec3::new((x * c) as f32, q.y, (2.5 + x * s) as f32)
                })
                .collect()
        };
        assert!(judge(&tilted(30.0), below), "a slant");
        assert!(!judge(&tilted(10.0), below), "an awning");
        assert!(!judge(&tilted(88.0), below), "upright");
        // Seen from nearly level (6 m away, 0.1 m below the points' mean
        // height), with the points dipping 8 degrees towards the sensor:
        // the plane's face towards the sensor points up, yet the sensor
        // sees the crown from below, as it does the flat patch.
        // `bend` 1: rim up (a crown's underside); -1: rim down (a crest).
        let dipped = |deg: f64, radius: Option<f64>, bend: f64| -> Vec<Vec3> {
            let (s, c) = deg.to_radians().sin_cos();
            underside(radius)
                .iter()
                .map(|q| {
                    let (x, z) = (f64::from(q.x), bend * (f64::from(q.z) - 2.5));
                    Vec3::new((x * c + z * s) as f32, q.y, (2.5 - x * s + z * c) as f32)
                })
                .collect()
        };
        let level = DVec3::new(6.0, 0.0, 2.45);
        assert!(
            judge(&dipped(8.0, Some(2.0), 1.0), level),
            "a crown from nearly level"
        );
        assert!(
            !judge(&dipped(8.0, None, 1.0), level),
            "an awning from nearly level"
        );
        assert!(
            !judge(&dipped(8.0, Some(2.0), -1.0), level),
            "a crest from nearly level"
        );
        // Facing up and leaning more than 15 degrees: seen from above.
        assert!(
            !judge(&dipped(30.0, Some(2.0), 1.0), level),
            "a bowl facing up"
        );
    }

    /// Below a viewpoint, ground is judged where a surface lies: a car's
    /// roof 0.3 m under a sensor 20 m away, fitted 5 degrees off level
    /// (its plane passes 1.75 m lower under the sensor), is no ground; the
    /// road, tilted the same way, is. Ground primitives grow 2 m a scan
    /// (`groundExpandAlong`): a roof taken for ground reached the next
    /// parked car's roof in the bench's street drives.
    #[test]
    fn a_roof_fitted_off_level_far_from_the_sensor_is_no_ground() {
        let p = Params::gpp2();
        // Points local to an origin far from the world's (a local/world
        // mix-up in the rule would judge them elsewhere).
        let origin = DVec3::new(1000.0, -500.0, 30.0);
        let sensor = origin + DVec3::new(0.0, 0.0, 1.8);
        // A 2 m x 1.6 m patch centred 20 m from the sensor at height z0
        // (local), rising away from the sensor by `deg`.
        let patch = |z0: f64, deg: f64| -> Vec<Vec3> {
            let slope = deg.to_radians().tan();
            let mut pts = Vec::new();
            for i in 0..=40 {
                for j in 0..=32 {
                    let (x, y) = (19.0 + 0.05 * i as f64, -0.8 + 0.05 * j as f64);
                    let z = z0 + (x - 20.0) * slope;
                    pts.push(Vec3::new(x as f32, y as f32, z as f32));
                }
            }
            pts
        };
        let ground = |pts: &[Vec3]| {
            shape(
                origin,
                pts,
                &p,
                sensor,
                GroundRule::BelowViewpoint,
                ShapeRules::default(),
            )
            .expect("a primitive")
            .primitive
            .ground
        };
        assert!(!ground(&patch(1.5, 5.0)), "a roof off level");
        assert!(!ground(&patch(1.5, 0.0)), "a level roof");
        assert!(ground(&patch(0.0, 5.0)), "a road off level");
        assert!(ground(&patch(0.0, 0.0)), "a level road");
        // Beyond `groundMaxTilt` nothing is ground.
        assert!(!ground(&patch(0.0, 20.0)), "a slope");
    }

    #[test]
    fn a_face_narrower_than_two_cells_grows_as_a_rectangle() {
        let mut r = riser();
        // The next scan sees the curb continue to x = 5, a little lower in
        // the cells (the ring falls elsewhere on the face).
        let more: Vec<DVec2> = (0..20)
            .map(|i| DVec2::new(3.05 + 0.1 * i as f64, 0.02))
            .collect();
        r.footprint.mark_all(&more);
        assert!(r.reshape(&Params::gpp2(), &more));
        // The 15 cm face out to the last cell's centre (x = 4.9): traced
        // from the cells it would be 0.2 m high, or pieces of that.
        assert!(is_simple(&r.outline));
        assert!(
            (min_width(&r.outline) - 0.15).abs() < 1e-9,
            "{:?}",
            r.outline
        );
        assert!((r.area - 0.15 * 4.9).abs() < 1e-9, "{}", r.area);
    }

    #[test]
    fn a_face_two_cells_wide_is_traced() {
        let mut r = riser();
        r.outline = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(3.0, 0.0),
            DVec2::new(3.0, 0.6),
            DVec2::new(0.0, 0.6),
        ];
        let more: Vec<DVec2> = (0..30)
            .flat_map(|i| [0.25, 0.45].map(|y| DVec2::new(0.05 + 0.1 * i as f64, y)))
            .collect();
        r.footprint.mark_all(&more);
        assert!(r.thin_rectangle().is_none());
        assert!(r.reshape(&Params::gpp2(), &more));
        assert!(r.outline.len() >= 4 && r.area > 0.0);
    }

    #[test]
    fn a_wide_surface_merged_into_a_face_is_traced() {
        // A wall 1 m high standing on the curb's line, in the riser's
        // plane: its cells make the support wide, and the outline follows
        // them instead of squashing the wall into the curb's 15 cm.
        let mut r = riser();
        let wall: Vec<DVec2> = (0..30)
            .flat_map(|i| {
                (0..10).map(move |j| DVec2::new(0.05 + 0.1 * i as f64, 0.05 + 0.1 * j as f64))
            })
            .collect();
        r.footprint.mark_all(&wall);
        assert!(r.thin_rectangle().is_none());
        assert!(r.reshape(&Params::gpp2(), &wall));
        assert!(r.area > 2.0, "{}", r.area);
    }
}
