//! The stages of one round of the cascade after RANSAC found its plane:
//! cluster the plane's inliers, pick the candidates, shape and judge each.

use super::cluster::Clusterer;
use super::policy::CascadePolicy;
use super::ransac::LocalPlane;
use super::viewpoint::{pull_towards, seen_edge_on};
use crate::floor::GroundRule;
use crate::geometry::{Frame, Plane};
use crate::params::Params;
use crate::primitive::{shape, ShapeRules, Shaped};
use glam::{DVec2, DVec3, Vec3};

/// A round's inliers split into connected clusters in their plane.
pub(crate) struct Clusters {
    /// Cluster label of every inlier (not dense).
    comp: Vec<u32>,
    /// Size of each label.
    sizes: Vec<u32>,
    /// The label of the largest cluster (the first of equals).
    largest: u32,
}

impl Clusters {
    /// Points in the largest cluster.
    pub(crate) fn largest_size(&self) -> usize {
        self.sizes
            .get(self.largest as usize)
            .map_or(0, |&s| s as usize)
    }
}

/// Cluster the inliers (`coords`, local to `origin`) in their plane. The
/// ground, seen at grazing angles, has its own tolerance, which with
/// [`CascadePolicy::range_pulled_ground`] grows with range beyond
/// `groundClusterRange`.
pub(crate) fn cluster_inliers(
    clusterer: &mut Clusterer,
    plane: &LocalPlane,
    coords: &[Vec3],
    local_viewpoint: DVec3,
    p: &Params,
    policy: &CascadePolicy,
) -> Clusters {
    let local = Plane {
        normal: plane.normal,
        offset: plane.offset,
    };
    let frame = Frame::on_plane(&local, coords[0].as_dvec3());
    let mut flat: Vec<DVec2> = coords
        .iter()
        .map(|p| frame.to_local(p.as_dvec3()))
        .collect();
    if plane.ground && policy.range_pulled_ground {
        let foot = frame.to_local(local_viewpoint);
        pull_towards(&mut flat, foot, p.ground_cluster_range);
    }
    let tol = p.surface(plane.ground).cluster_tolerance;
    let (comp, sizes) = clusterer.clusters(&flat, tol);
    let largest = comp
        .iter()
        .copied()
        .reduce(|b, c| {
            if sizes[c as usize] > sizes[b as usize] {
                c
            } else {
                b
            }
        })
        .unwrap_or(0);
    Clusters {
        comp,
        sizes,
        largest,
    }
}

/// A candidate: its points as pool positions and as local coordinates.
pub(crate) type Candidate = (Vec<u32>, Vec<Vec3>);

/// The candidates of a round: the largest cluster, then with
/// [`CascadePolicy::every_cluster`] the plane's other clusters of
/// `minInliers` points or more, largest first (ties in the order of their
/// first point), so that `maxPrimitives` keeps the larger ones.
pub(crate) fn candidates(
    c: &Clusters,
    inliers: &[u32],
    coords: &[Vec3],
    p: &Params,
    policy: &CascadePolicy,
) -> Vec<Candidate> {
    let (comp, sizes) = (&c.comp, &c.sizes);
    let mut roots = vec![c.largest];
    let mut slot = vec![u32::MAX; sizes.len()];
    slot[c.largest as usize] = 0;
    if policy.every_cluster {
        for &l in comp {
            if slot[l as usize] == u32::MAX && sizes[l as usize] as usize >= p.min_inliers {
                slot[l as usize] = 0;
                roots.push(l);
            }
        }
        crate::geometry::insertion_sort_by(&mut roots[1..], |&a, &b| {
            sizes[b as usize].cmp(&sizes[a as usize])
        });
        for (k, &l) in roots.iter().enumerate() {
            slot[l as usize] = k as u32;
        }
    }
    // Their points, in one pass.
    let mut members: Vec<Candidate> = roots
        .iter()
        .map(|&l| {
            let n = sizes[l as usize] as usize;
            (Vec::with_capacity(n), Vec::with_capacity(n))
        })
        .collect();
    for (i, &l) in comp.iter().enumerate() {
        if let Some(m) = members.get_mut(slot[l as usize] as usize) {
            m.0.push(inliers[i]);
            m.1.push(coords[i]);
        }
    }
    members
}

/// A shaped candidate and whether it passed every acceptance test.
pub(crate) struct Judged {
    /// The refit, outlined candidate; `None` when degenerate.
    pub(crate) shaped: Option<Shaped>,
    /// Large, solid, smooth, consistent and not seen edge-on.
    pub(crate) accepted: bool,
    /// Passed every test but roughness.
    pub(crate) only_too_rough: bool,
    /// The noise of its surfaces, from the consistency test's patch fits
    /// ([`Shaped::consistency`]), when it got that far.
    pub(crate) noise: Option<f64>,
    /// Accepted, but with fewer of its points within half the inlier
    /// distance than a surface as rough as `maxRoughness` allows would
    /// have ([`least_tight_share`]), or seen only as single laser rings
    /// ([`Consistency::rings_only`](crate::primitive::Consistency)):
    /// perhaps two surfaces that one plane between them holds, smoothly
    /// enough to pass.
    pub(crate) maybe_two: bool,
}

/// The share of a surface's points within half the inlier distance of its
/// plane when their distances are normal with an RMS of `maxRoughness`
/// times the inlier distance: the share of the roughest surface the
/// roughness test accepts (0.73 at the default 0.45). Points spread evenly
/// through the slab put a half there.
#[inline(never)]
pub(crate) fn least_tight_share(p: &Params) -> f64 {
    // erf(x) by its Taylor series (libm's erf added 2.6 kB to the wasm);
    // beyond x = 3 it is 1 to within 3e-5.
    let x = 0.5 / (p.max_roughness * core::f64::consts::SQRT_2);
    if x.is_nan() || x >= 3.0 {
        return 1.0;
    }
    let (mut term, mut sum) = (x, x);
    for n in 1..60 {
        term *= -x * x / n as f64;
        sum += term / (2 * n + 1) as f64;
    }
    sum * core::f64::consts::FRAC_2_SQRT_PI
}

/// What judging a candidate needs besides its points: where the cloud and
/// the sensor are, what is ground, the parameters and the policy.
#[derive(Clone, Copy)]
pub(crate) struct Judge<'a> {
    /// The cloud's origin (candidate points are local to it).
    pub(crate) origin: DVec3,
    /// The sensor (world).
    pub(crate) viewpoint: DVec3,
    /// The sensors a candidate seen edge-on from every one of is laser
    /// rings (with [`CascadePolicy::reject_edge_on_candidates`]): the
    /// viewpoint, or the sensors of an accumulated cloud.
    pub(crate) edge_on_from: &'a [DVec3],
    pub(crate) ground: GroundRule<'a>,
    pub(crate) p: &'a Params,
    pub(crate) policy: &'a CascadePolicy,
    /// The least support of a candidate: `minInliers`, or with
    /// [`CascadePolicy::pool_support`] the pool's (near-horizontal
    /// candidates at ground depth below the sensor still need
    /// `minInliers`, see [`Judge::judge`]).
    pub(crate) min_support: usize,
}

impl Judge<'_> {
    /// PCA refit, frame, outline, then the acceptance tests: support
    /// (`min_support`, and `minInliers` near-horizontal at ground depth),
    /// area, width and solidity
    /// ([`Primitive::acceptable`](crate::primitive::Primitive::acceptable)),
    /// roughness, not a plane seen edge-on, not a dome seen from below (by
    /// policy), normal consistency.
    pub(crate) fn judge(&self, support_pts: &[Vec3]) -> Judged {
        let (p, viewpoint) = (self.p, self.viewpoint);
        let shaped = shape(
            self.origin,
            support_pts,
            p,
            viewpoint,
            self.ground,
            ShapeRules {
                bridge_ring_gaps: self.policy.bridge_ring_gaps,
                cut_holes: self.policy.cut_holes,
            },
        );
        let cheap_ok = |s: &&Shaped| {
            s.primitive.acceptable_with(p, self.min_support)
                // (Only the pool's smaller least support lets such a
                // candidate through to here.)
                && !(s.primitive.support < p.min_inliers as u64 && self.at_ground_depth(s))
                && !(self.policy.reject_edge_on_candidates
                    && self.edge_on_from.iter().all(|&v| seen_edge_on(s, v, p)))
                && !(self.policy.reject_domes && s.domed(self.origin, support_pts, viewpoint))
        };
        // The costliest test last, and only when the others passed.
        let patches = shaped
            .as_ref()
            .filter(cheap_ok)
            .map(|s| s.consistency(self.origin, support_pts, p, self.ring_sensors()));
        let smooth = shaped
            .as_ref()
            .is_some_and(|s| s.roughness <= p.max_roughness);
        let rest = patches.is_some_and(|c| c.share >= p.min_normal_consistency);
        let tight = shaped
            .as_ref()
            .is_some_and(|s| s.tight_share >= least_tight_share(p));
        Judged {
            shaped,
            accepted: smooth && rest,
            only_too_rough: !smooth && rest,
            noise: patches.and_then(|c| c.noise),
            // A plane through single laser rings alone is unproven (two
            // ring arcs metres apart fit one within centimetres): it may
            // hold two surfaces, however tight.
            maybe_two: smooth && rest && (!tight || patches.is_some_and(|c| c.rings_only)),
        }
    }

    /// The sensor whose single laser rings the consistency test knows by
    /// their plane: the one viewpoint of a cloud seen from one position (a
    /// scan, or the scenario's scan with its pool, whose earlier points lie
    /// off this scan's cones; a map given one viewpoint is taken as seen
    /// from there). No sensor for a cloud seen from no known position, or
    /// from several (`--poses`): there a patch through one sensor can also
    /// hold other scans' points, off that sensor's cones.
    fn ring_sensors(&self) -> &[DVec3] {
        if self.policy.reject_edge_on_candidates && self.edge_on_from.len() == 1 {
            self.edge_on_from
        } else {
            &[]
        }
    }

    /// Is a candidate ground by detection's ground test
    /// ([`Plane::is_ground_below`](crate::geometry::Plane::is_ground_below))
    /// judged where it lies, under the sensor's height at the centroid of
    /// its fit rather than under the sensor (a plane a few degrees off
    /// level, far from the sensor, passes metres above or below it)?
    fn at_ground_depth(&self, s: &Shaped) -> bool {
        let (p, c) = (self.p, s.primitive.moments.mean());
        let above = DVec3::new(c.x, c.y, self.viewpoint.z);
        let min_cos = libm::cos(p.ground_max_tilt.to_radians());
        s.primitive
            .plane
            .is_ground_below(above, min_cos, p.ground_depth)
    }

    /// The part of a candidate (`cluster`, `support_pts`) at `at`
    /// (ascending indices in it), and its judgement.
    pub(crate) fn judge_part(
        &self,
        cluster: &[u32],
        support_pts: &[Vec3],
        at: &[usize],
    ) -> (Candidate, Judged) {
        let part: Candidate = (
            at.iter().map(|&i| cluster[i]).collect(),
            at.iter().map(|&i| support_pts[i]).collect(),
        );
        let judged = self.judge(&part.1);
        (part, judged)
    }

    /// A candidate (`cluster`, `support_pts`) that failed only roughness
    /// ([`Judged::only_too_rough`]) or may hold two surfaces
    /// ([`Judged::maybe_two`]), judged again as its dominant layer:
    /// - when its points lie in two parallel layers with a gap between them
    ///   ([`two_layers`], a road and a plaza a step up), the points within
    ///   the inlier distance of the plane of the layer that holds more;
    /// - else the points within twice the noise band of the plane that
    ///   holds the most of the candidate's points within that band
    ///   ([`tightest_plane`]; the band is three times the candidate's local
    ///   noise, [`Judged::noise`], at most half the inlier distance), when
    ///   most of them lie within the band itself, as a surface's do (at
    ///   least [`least_tight_share`]; a slab cut from uniform clutter puts
    ///   half of its points there).
    ///
    /// `Some((layer, judged))` when the layer is accepted; the rest of the
    /// candidate stays in play.
    pub(crate) fn dominant_layer(
        &self,
        judged: &Judged,
        cluster: &[u32],
        support_pts: &[Vec3],
    ) -> Option<(Candidate, Judged)> {
        let s = judged.shaped.as_ref()?;
        let world: Vec<DVec3> = support_pts
            .iter()
            .map(|q| self.origin + q.as_dvec3())
            .collect();
        let distance = self.p.surface(s.primitive.ground).distance;
        // The layers are found on every k-th point (at most about 50,000):
        // a plane needs no more, and a road's candidate can hold a million.
        let every = world.len().div_ceil(50_000).max(1);
        let sample: Vec<DVec3> = world.iter().copied().step_by(every).collect();
        let plane = &s.primitive.plane;
        let (layer, band, tight) = match two_layers(plane, &sample, distance) {
            Some(layer) => (layer, distance, false),
            None => {
                let band = judged.noise.map_or(0.5 * distance, |sigma| {
                    (NOISE_BAND * sigma).min(0.5 * distance)
                });
                // A stream of its own, fixed by the seed and the
                // candidate's size: the same input gives the same planes.
                let mut rng = crate::rng::Rng::derive(self.p.seed, world.len() as u64);
                let layer = tightest_plane(&sample, band, &mut rng)?;
                (layer, 2.0 * band, true)
            }
        };
        let off: Vec<f64> = world
            .iter()
            .map(|&w| layer.signed_distance(w).abs())
            .collect();
        let near: Vec<usize> = (0..world.len()).filter(|&i| off[i] <= band).collect();
        if near.len() < self.p.min_inliers || near.len() == world.len() {
            return None;
        }
        let within = off.iter().filter(|&&d| d <= 0.5 * band).count();
        if tight && (within as f64) < least_tight_share(self.p) * near.len() as f64 {
            return None;
        }
        let (layer, again) = self.judge_part(cluster, support_pts, &near);
        again.accepted.then_some((layer, again))
    }
}

/// The plane of the layer holding more of `world`, when the points lie in
/// two parallel layers with a gap between them; `None` for points that
/// fill the band (a plane through clutter). From `plane` (between the
/// layers), fit the side holding more points, then refit on the points
/// within half the inlier `distance` until the plane settles on its layer.
/// The other side's points beyond the inlier distance, seen from that
/// layer, must sit mostly at one offset: fewer than a tenth of their
/// number in the middle third between the layer and their median offset.
fn two_layers(plane: &Plane, world: &[DVec3], distance: f64) -> Option<Plane> {
    use crate::geometry::plane::robust_fit;
    let fit = |pts: &[DVec3]| robust_fit(pts, pts.first()?.round()).map(|f| f.plane);
    let above = world
        .iter()
        .filter(|&&w| plane.signed_distance(w) >= 0.0)
        .count();
    let upper = 2 * above >= world.len();
    let side: Vec<DVec3> = world
        .iter()
        .copied()
        .filter(|&w| (plane.signed_distance(w) >= 0.0) == upper)
        .collect();
    let mut layer = fit(&side)?;
    for _ in 0..4 {
        let near: Vec<DVec3> = world
            .iter()
            .copied()
            .filter(|&w| layer.signed_distance(w).abs() <= 0.5 * distance)
            .collect();
        layer = fit(&near)?;
    }
    // The other layer: the points beyond the inlier distance, on one side.
    let mut h: Vec<f64> = world
        .iter()
        .map(|&w| layer.signed_distance(w))
        .filter(|d| d.abs() > distance)
        .collect();
    if h.is_empty() {
        return None;
    }
    let positive = h.iter().filter(|&&d| d > 0.0).count();
    let sign = if 2 * positive >= h.len() { 1.0 } else { -1.0 };
    h.retain(|&d| d * sign > 0.0);
    let mid = h.len() / 2;
    let step = h.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1.abs();
    let middle = world
        .iter()
        .map(|&w| layer.signed_distance(w) * sign)
        .filter(|&d| d > step / 3.0 && d < 2.0 * step / 3.0)
        .count();
    (10 * middle < h.len()).then_some(layer)
}

/// The noise band of [`Judge::dominant_layer`], in multiples of the local
/// noise: a surface with normal noise keeps 99.7 % of its points within it.
const NOISE_BAND: f64 = 3.0;

/// Hypotheses [`tightest_plane`] tries.
const TIGHT_HYPOTHESES: usize = 200;

/// The plane that holds the most of `world` (a candidate's points; at most
/// 5,000 of them) within `band`: the best of [`TIGHT_HYPOTHESES`] planes
/// through three of the points, refit twice on the points within `band`.
/// Where one plane between two surfaces holds both within the inlier
/// distance (a road and the sidewalk a curb above it, the plane tilted to
/// hold one at each side; the two faces of a bent facade), it holds each
/// only in a strip as wide as the band allows, while each surface's own
/// plane holds all of it: with a band near the surfaces' noise, the larger
/// surface's plane wins.
fn tightest_plane(world: &[DVec3], band: f64, rng: &mut crate::rng::Rng) -> Option<Plane> {
    use crate::geometry::plane::{plane_through, robust_fit};
    let every = world.len().div_ceil(5_000).max(1);
    let pts: Vec<DVec3> = world.iter().copied().step_by(every).collect();
    let n = pts.len();
    if n < 3 {
        return None;
    }
    let held = |plane: &Plane| {
        pts.iter()
            .filter(|&&w| plane.signed_distance(w).abs() <= band)
            .count()
    };
    let mut best: Option<(usize, Plane)> = None;
    for _ in 0..TIGHT_HYPOTHESES {
        let (a, b, c) = (pts[rng.below(n)], pts[rng.below(n)], pts[rng.below(n)]);
        // Not a sliver: the triangle's height at least a tenth of its
        // longest side.
        let Some((normal, offset)) = plane_through(a, b, c, 0.1) else {
            continue;
        };
        let plane = Plane { normal, offset };
        let k = held(&plane);
        if best.is_none_or(|(most, _)| k > most) {
            best = Some((k, plane));
        }
    }
    let mut plane = best?.1;
    for _ in 0..2 {
        let near: Vec<DVec3> = pts
            .iter()
            .copied()
            .filter(|&w| plane.signed_distance(w).abs() <= band)
            .collect();
        plane = robust_fit(&near, near.first()?.round())?.plane;
    }
    Some(plane)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_tight_share_is_that_of_normal_noise_at_the_roughness_allowed() {
        // erf(0.5 / (r * sqrt 2)) for r = maxRoughness.
        for (r, share) in [
            (0.45, 0.733_479_474),
            (1.0, 0.382_924_923),
            (0.2, 0.987_580_669),
        ] {
            let p = Params {
                max_roughness: r,
                ..Params::gpp2()
            };
            assert!((least_tight_share(&p) - share).abs() < 1e-8, "{r}");
        }
        // Beyond the series' range: all of a surface's points.
        let p = Params {
            max_roughness: 0.1,
            ..Params::gpp2()
        };
        assert_eq!(least_tight_share(&p), 1.0);
    }
}
