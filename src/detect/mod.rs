//! One-shot detection of planar polygons: the paper's Algorithm 1, a cascade
//! of RANSAC plane search, Euclidean clustering, PCA refit, outline and
//! acceptance tests, each round removing what it explained.

pub mod cluster;
pub mod kernels;
pub mod ransac;

use crate::clock;
use crate::cloud::Cloud;
use crate::error::Result;
use crate::geometry::plane::Moments;
use crate::geometry::polygon::{contains, distance, signed_area};
use crate::geometry::{Frame, Plane};
use crate::params::Params;
use crate::primitive::{shape, Primitive, Shaped};
use crate::rng::Rng;
use glam::{DVec2, DVec3, Vec3};
use ransac::PlanePool;
use serde::Serialize;

/// Label of a point that no primitive explains.
pub const NO_PRIMITIVE: u32 = u32::MAX;

/// One round of the cascade (for the paper's Fig. 9 analysis).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct CascadeStep {
    /// Points still in play before this round.
    pub points_left: usize,
    /// RANSAC inliers of the round's best plane.
    pub inliers: usize,
    /// Points in the largest cluster of those inliers.
    pub cluster: usize,
    /// Primitives accepted in this round (the largest cluster and, with
    /// [`Detector::new`], the plane's other clusters), before the final
    /// merge pass.
    pub accepted: usize,
    /// Outline area of the candidate (m^2; 0 when it had no outline).
    pub area: f64,
    /// Wall time of the round (ms).
    pub time_ms: f64,
}

/// What one detection found.
#[derive(Clone, Debug)]
pub struct Detection {
    /// Accepted primitives, in the order found (ids 0, 1, ...).
    pub primitives: Vec<Primitive>,
    /// Per input point: the index of the primitive it supports, or
    /// [`NO_PRIMITIVE`].
    pub labels: Vec<u32>,
    /// The cascade, round by round.
    pub steps: Vec<CascadeStep>,
    /// Point-to-plane distance evaluations spent.
    pub work: u64,
    /// Wall time (ms).
    pub time_ms: f64,
}

/// Detect planar polygons in a world-frame cloud seen from
/// `params.viewpoint` (the sensor position; the origin for a scan in its own
/// frame). Normals of non-horizontal planes point towards the viewpoint,
/// near-horizontal ones up.
///
/// ```
/// use polyscene::{cloud::Cloud, detect::detect, params::Params};
/// // A 10 m x 10 m floor sampled every 10 cm.
/// let mut pts = Vec::new();
/// for i in 0..100 {
///     for j in 0..100 {
///         pts.extend_from_slice(&[i as f32 * 0.1, j as f32 * 0.1, 0.0]);
///     }
/// }
/// let cloud = Cloud::from_flat(&pts, 3).unwrap();
/// // The sensor 1.8 m above the floor's centre.
/// let params = Params { viewpoint: [5.0, 5.0, 1.8], ..Params::gpp2() };
/// let found = detect(&cloud, &params).unwrap();
/// assert_eq!(found.primitives.len(), 1);
/// assert!((found.primitives[0].area - 99.0).abs() < 3.0);
/// ```
pub fn detect(cloud: &Cloud, params: &Params) -> Result<Detection> {
    params.validate()?;
    let viewpoint = DVec3::from_array(params.viewpoint);
    Ok(Detector::new(params).run(&cloud.points, cloud.origin, viewpoint))
}

/// Does a plane at signed distance `d` from the viewpoint pass through it
/// (within two inlier distances)? Every ray from the sensor to such a plane
/// grazes it. The test of both the RANSAC hypotheses (one-shot detection)
/// and the candidates.
pub(crate) fn through_viewpoint(d: f64, p: &Params) -> bool {
    d.abs() < 2.0 * p.distance
}

/// Is this candidate a plane the sensor lies in, away from it? Its plane
/// passes within two inlier distances of the viewpoint, so every ray to it
/// grazes, and the viewpoint's foot point is more than a metre outside its
/// outline (a floor under a sensor standing on it is kept). Such a
/// candidate is the laser rings of the beams near its own elevation,
/// gathered across everything around (horizontal at sensor height, most
/// often); the outline closes them into solid-looking patches, and the
/// arcs they draw on poles and trunks pass the normal-consistency test.
fn seen_edge_on(s: &Shaped, viewpoint: DVec3, p: &Params) -> bool {
    let prim = &s.primitive;
    if !through_viewpoint(prim.plane.signed_distance(viewpoint), p) {
        return false;
    }
    let foot = prim.frame.to_local(viewpoint);
    !contains(&prim.outline, foot) && distance(&prim.outline, foot) > 1.0
}

/// Pull the points farther than `range` from `foot` towards it
/// ([`crate::geometry::pull_range`]; nothing crosses): clustering the pulled
/// points with a fixed tolerance `t` connects, at distance `r`, points
/// `t (r / range)^2` apart along the line from `foot` and about
/// `t r / (2 range)` across it. On the ground, the gap between neighbouring
/// laser rings grows with the square of the range and the spacing along a
/// ring linearly.
fn pull_towards(flat: &mut [DVec2], foot: DVec2, range: f64) {
    for q in flat {
        let d = *q - foot;
        // std sqrt: one instruction in wasm, the same bits everywhere.
        let r = d.length_squared().sqrt();
        if r > range {
            *q = foot + d * (crate::geometry::pull_range(r, range) / r);
        }
    }
}

/// Merge primitives that are pieces of one surface (the scenario's rule:
/// near-coplanar, outlines touching or overlapping), then number the
/// survivors 0, 1, ... again, labels included. A round's plane can cut a
/// band out of a surface that crosses it at a small angle, and that band is
/// one of the plane's other clusters; when a later round finds the surface
/// whole, its outline covers the band. And the pieces of a road beyond a
/// gap in its rings touch the road once their own rounds outlined them.
/// Concave outlines only (a convex hull of two pieces would cover what lies
/// between them).
///
/// In the order found, a primitive and the newer pieces mergeable with it
/// become one ([`absorb`]). A merged outline is larger and can touch a
/// piece it did not touch before, so passes repeat until nothing merges;
/// after the first, only groups with a primitive grown in the last pass
/// are looked at.
#[inline(never)]
fn merge_pieces(
    primitives: &mut Vec<Primitive>,
    labels: &mut [u32],
    pts: &[Vec3],
    origin: DVec3,
    p: &Params,
) {
    let n = primitives.len();
    if n < 2 || !p.hull.merges_detected_pieces() {
        return;
    }
    let mut into: Vec<u32> = (0..n as u32).collect();
    let mut grown = vec![true; n];
    for _ in 0..n {
        let mut next = vec![false; n];
        for first in 0..n {
            if into[first] != first as u32 {
                continue;
            }
            let mut group: Vec<usize> = (first + 1..n)
                .filter(|&j| {
                    into[j] == j as u32
                        && (grown[first] || grown[j])
                        && crate::scenario::merge::mergeable(&primitives[first], &primitives[j], p)
                })
                .collect();
            if group.is_empty() {
                continue;
            }
            group.push(first);
            let big = group.iter().copied().fold(first, |b, j| {
                if primitives[j].area > primitives[b].area {
                    j
                } else {
                    b
                }
            });
            group.retain(|&j| j != big);
            if let Some(out) = absorb(primitives, labels, big, &group, pts, origin, p) {
                primitives[big] = out;
                for &j in &group {
                    into[j] = big as u32;
                }
                next[big] = true;
            }
        }
        if !next.contains(&true) {
            break;
        }
        grown = next;
    }
    // Survivors in their order, numbered densely; labels follow.
    let mut dense = vec![NO_PRIMITIVE; n];
    let mut k = 0;
    for i in 0..n {
        if into[i] == i as u32 {
            dense[i] = k;
            k += 1;
        }
    }
    if k as usize == n {
        return;
    }
    let mut i = 0;
    primitives.retain(|_| {
        i += 1;
        into[i - 1] == i as u32 - 1
    });
    for (k, q) in primitives.iter_mut().enumerate() {
        q.id = k as u32;
    }
    for l in labels.iter_mut() {
        if *l != NO_PRIMITIVE {
            *l = dense[*l as usize];
        }
    }
}

/// The detection cascade with its parameters (validated by the caller).
pub struct Detector<'p> {
    params: &'p Params,
    whole_planes: bool,
}

impl<'p> Detector<'p> {
    /// A detector with these parameters. Each round judges every cluster
    /// of the round's plane with `min_inliers` points, the ground's
    /// clustering tolerance grows beyond `ground_cluster_range`, and a final
    /// pass merges pieces of one surface (see
    /// [`Detector::largest_cluster_only`]).
    pub fn new(params: &'p Params) -> Self {
        Detector {
            params,
            whole_planes: true,
        }
    }

    /// The paper's cascade: each round keeps only the largest cluster of
    /// its plane (clustered with fixed tolerances), and nothing is merged.
    /// The scenario detects this way on
    /// the points its primitives did not explain (about a tenth of a scan,
    /// mostly clutter; judging the other clusters there too measured less
    /// precise and less accurate, see BENCHMARKS.md) and merges with its own
    /// primitives afterwards.
    pub fn largest_cluster_only(mut self) -> Self {
        self.whole_planes = false;
        self
    }

    /// Run the cascade on `pts` (local coordinates relative to `origin`).
    /// `viewpoint` (world) decides which way non-horizontal normals point.
    pub fn run(&self, pts: &[Vec3], origin: DVec3, viewpoint: DVec3) -> Detection {
        self.run_with_rng(pts, origin, viewpoint, Rng::new(self.params.seed))
    }

    /// [`Detector::run`] with an explicit random generator (the scenario
    /// derives one per scan from the seed).
    pub fn run_with_rng(
        &self,
        pts: &[Vec3],
        origin: DVec3,
        viewpoint: DVec3,
        rng: Rng,
    ) -> Detection {
        let p = self.params;
        let t0 = clock::now_ms();
        let mut pool = PlanePool::new(
            pts,
            p.sample_radius,
            self.whole_planes.then_some(viewpoint - origin),
            rng,
        );
        if self.whole_planes {
            pool = pool.reject_slivers();
        }
        let mut labels = vec![NO_PRIMITIVE; pts.len()];
        let mut primitives: Vec<Primitive> = Vec::new();
        let mut steps = Vec::new();
        let max_rounds = 4 * p.max_primitives + 64;
        let mut rejections = 0;
        let mut clusterer = cluster::Clusterer::default();
        for _ in 0..max_rounds {
            if primitives.len() >= p.max_primitives
                || pool.work >= p.max_work
                || rejections >= p.max_rejections
            {
                break;
            }
            let ts = clock::now_ms();
            let points_left = pool.remaining();
            // 1. RANSAC: the plane with the largest consensus, or stop.
            let Some((plane, inliers, coords)) = pool.best_plane(p, viewpoint - origin) else {
                break;
            };
            // 2. Cluster the inliers in the plane; the largest cluster is the support.
            let local = Plane {
                normal: plane.normal,
                offset: plane.offset,
            };
            let frame = Frame::on_plane(&local, coords[0].as_dvec3());
            let mut flat: Vec<DVec2> = coords
                .iter()
                .map(|p| frame.to_local(p.as_dvec3()))
                .collect();
            // The ground, seen at grazing angles, has its own tolerance;
            // beyond the paper's cascade, one growing with range beyond
            // `ground_cluster_range`.
            let tol = if plane.ground {
                if self.whole_planes {
                    let foot = frame.to_local(viewpoint - origin);
                    pull_towards(&mut flat, foot, p.ground_cluster_range);
                }
                p.ground_cluster_tolerance
            } else {
                p.cluster_tolerance
            };
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
            if (sizes[largest as usize] as usize) < p.min_inliers {
                // No connected patch of this plane is large enough to be a
                // primitive: its inliers are scattered clutter (a plane slicing
                // through trees and cars). Take them all out of play at once
                // rather than one fragment per round.
                pool.remove(&inliers);
                steps.push(CascadeStep {
                    points_left,
                    inliers: inliers.len(),
                    cluster: sizes[largest as usize] as usize,
                    accepted: 0,
                    area: 0.0,
                    time_ms: clock::now_ms() - ts,
                });
                rejections += 1;
                continue;
            }
            // The candidates: the largest cluster, then the plane's other
            // clusters of `min_inliers` points or more, largest first (ties in
            // the order of their first point). One plane often holds several
            // surfaces: the sides of cars parked in a row, the facades along
            // a street, pieces of the road beyond a gap in the rings. Each is
            // judged on its own shape, in this round rather than one per
            // round; largest first, so that `max_primitives` keeps the
            // larger ones.
            let mut roots = vec![largest];
            let mut slot = vec![u32::MAX; sizes.len()];
            slot[largest as usize] = 0;
            if self.whole_planes {
                for &l in &comp {
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
            // Their points (positions and coordinates), in one pass.
            let mut members: Vec<(Vec<u32>, Vec<Vec3>)> = roots
                .iter()
                .map(|&l| {
                    let n = sizes[l as usize] as usize;
                    (Vec::with_capacity(n), Vec::with_capacity(n))
                })
                .collect();
            for (c, &l) in comp.iter().enumerate() {
                if let Some(m) = members.get_mut(slot[l as usize] as usize) {
                    m.0.push(inliers[c]);
                    m.1.push(coords[c]);
                }
            }
            let mut step = CascadeStep {
                points_left,
                inliers: inliers.len(),
                cluster: members[0].0.len(),
                accepted: 0,
                area: 0.0,
                time_ms: 0.0,
            };
            for (k, (cluster, support_pts)) in members.iter().enumerate() {
                if primitives.len() >= p.max_primitives {
                    break;
                }
                // 3-4. PCA refit, frame, outline, area and solidity.
                let shaped = shape(origin, support_pts, p, viewpoint, self.whole_planes);
                if k == 0 {
                    step.area = shaped.as_ref().map_or(0.0, |s| s.primitive.area);
                }
                // 5. Accept when large and solid enough; 6. take the support
                // out of play, or the whole cluster when rejected (it would
                // come back with the same shape).
                match shaped {
                    Some(s)
                        if s.primitive.acceptable(p)
                            && s.roughness <= p.max_roughness
                            && !seen_edge_on(&s, viewpoint, p)
                            && s.consistency(origin, support_pts, p)
                                >= p.min_normal_consistency =>
                    {
                        let id = primitives.len() as u32;
                        let taken: Vec<u32> = cluster
                            .iter()
                            .zip(&s.kept)
                            .filter_map(|(&i, &k)| k.then_some(i))
                            .collect();
                        for &v in &taken {
                            labels[pool.original(v) as usize] = id;
                        }
                        pool.remove(&taken);
                        let mut prim = s.primitive;
                        prim.id = id;
                        primitives.push(prim);
                        step.accepted += 1;
                    }
                    _ => pool.remove(cluster),
                }
            }
            if step.accepted > 0 {
                rejections = 0;
            } else {
                rejections += 1;
            }
            step.time_ms = clock::now_ms() - ts;
            steps.push(step);
        }
        if self.whole_planes {
            merge_pieces(&mut primitives, &mut labels, pts, origin, p);
        }
        Detection {
            primitives,
            labels,
            steps,
            work: pool.work,
            time_ms: clock::now_ms() - t0,
        }
    }
}

/// `primitives[big]` with the pieces `group` absorbed, or `None` when the
/// merge would break the detection contract (support near its plane,
/// inside its outline). The largest keeps its plane and frame; the pieces'
/// points on that plane mark its footprint, and one outline trace follows.
/// Each piece must keep nine tenths of its support within the inlier
/// distance of the plane and inside the new raster region, and so must the
/// largest (the larger footprint's trace can simplify another way); the
/// points that do not lose their label. Labels are changed only on success.
fn absorb(
    primitives: &[Primitive],
    labels: &mut [u32],
    big: usize,
    group: &[usize],
    pts: &[Vec3],
    origin: DVec3,
    p: &Params,
) -> Option<Primitive> {
    let n = primitives.len();
    let world = |i: usize| origin + pts[i].as_dvec3();
    let mut out = primitives[big].clone();
    let threshold = if out.ground {
        p.ground_distance
    } else {
        p.distance
    };
    // The pieces' points, with their coordinates in `big`'s frame when they
    // lie on its plane.
    let mut taken: Vec<(usize, Option<DVec2>)> = Vec::new();
    let (mut total, mut bad) = (vec![0usize; n], vec![0usize; n]);
    let mut in_group = vec![false; n];
    for &j in group {
        in_group[j] = true;
    }
    for (i, &l) in labels.iter().enumerate() {
        if l != NO_PRIMITIVE && in_group[l as usize] {
            let w = world(i);
            let on = out.plane.signed_distance(w).abs() < threshold;
            total[l as usize] += 1;
            bad[l as usize] += !on as usize;
            taken.push((i, on.then(|| out.frame.to_local(w))));
        }
    }
    let marks: Vec<DVec2> = taken.iter().filter_map(|t| t.1).collect();
    out.footprint.mark_all(&marks);
    let (ring, region) = out
        .footprint
        .outline_region(out.alpha(p), p.simplify, p.max_vertices)?;
    let mut kept = Vec::with_capacity(taken.len());
    for &(i, q) in &taken {
        let stay = q.is_some_and(|q| region.contains(q));
        bad[labels[i] as usize] += (q.is_some() && !stay) as usize;
        kept.push(stay);
    }
    if group.iter().any(|&j| 10 * bad[j] > total[j]) {
        return None;
    }
    // `out` is `big` with the pieces' cells added (same frame): when the
    // region holds all of `big`'s cells it holds all of its points.
    let keeps_own = primitives[big]
        .footprint
        .cell_centres()
        .iter()
        .all(|&c| region.contains(c));
    let mut own_out = Vec::new();
    if !keeps_own {
        let mut own = 0usize;
        for (i, &l) in labels.iter().enumerate() {
            if l == big as u32 {
                own += 1;
                if !region.contains(out.frame.to_local(world(i))) {
                    own_out.push(i);
                }
            }
        }
        if 10 * own_out.len() > own {
            return None;
        }
    }
    out.area = signed_area(&ring);
    out.outline = ring;
    out.footprint.retain_region(&region);
    let mut gone = Moments::new(out.moments.reference);
    for (&(i, _), &stay) in taken.iter().zip(&kept) {
        if stay {
            labels[i] = big as u32;
            out.support += 1;
        } else {
            labels[i] = NO_PRIMITIVE;
            gone.push(world(i));
        }
    }
    for &i in &own_out {
        labels[i] = NO_PRIMITIVE;
        gone.push(world(i));
    }
    out.support = out.support.saturating_sub(own_out.len() as u64);
    for &j in group {
        out.moments.merge(&primitives[j].moments);
    }
    out.moments.remove(&gone);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points of a vertical patch in the plane y = `tilt` * z, x in `x0..x1`,
    /// z in 0..2, on a grid of 5 cm shifted by `shift`.
    fn patch(x0: f64, x1: f64, tilt: f64, shift: f64) -> Vec<Vec3> {
        let mut out = Vec::new();
        let mut x = x0 + shift;
        while x < x1 {
            let mut z = shift;
            while z < 2.0 {
                out.push(Vec3::new(x as f32, (tilt * z) as f32, z as f32));
                z += 0.05;
            }
            x += 0.05;
        }
        out
    }

    /// Primitives shaped from patches, labelled as detection would.
    fn pieces(patches: &[&[Vec3]], p: &Params) -> (Vec<Primitive>, Vec<u32>, Vec<Vec3>) {
        let view = DVec3::new(2.0, -6.0, 1.5);
        let mut prims = Vec::new();
        let mut labels = Vec::new();
        for (id, pts) in patches.iter().enumerate() {
            let s = shape(DVec3::ZERO, pts, p, view, false).unwrap();
            assert!(s.kept.iter().all(|&k| k));
            let mut prim = s.primitive;
            prim.id = id as u32;
            prims.push(prim);
            labels.extend(std::iter::repeat_n(id as u32, pts.len()));
        }
        (prims, labels, patches.concat())
    }

    /// Two primitives shaped from two patches.
    fn two(a: &[Vec3], b: &[Vec3], p: &Params) -> (Vec<Primitive>, Vec<u32>, Vec<Vec3>) {
        pieces(&[a, b], p)
    }

    #[test]
    fn overlapping_pieces_of_one_surface_merge_and_keep_the_contract() {
        let p = Params::gpp2();
        let (a, b) = (patch(0.0, 4.0, 0.0, 0.0), patch(3.0, 7.0, 0.0, 0.025));
        let (mut prims, mut labels, pts) = two(&a, &b, &p);
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 1);
        let q = &prims[0];
        assert_eq!(q.id, 0);
        assert!(labels.iter().all(|&l| l == 0));
        assert_eq!(q.support, pts.len() as u64);
        // 7 m x 2 m, outlined through the boundary cells' centres.
        assert!(q.area > 12.0 && q.area < 14.1, "area {}", q.area);
        for w in &pts {
            let w = w.as_dvec3();
            assert!(q.plane.signed_distance(w).abs() < p.distance);
            let out = distance(&q.outline, q.frame.to_local(w));
            assert!(out <= q.footprint.cell() + p.simplify + 1e-9);
        }
    }

    /// The first and the third piece lie 3 m apart; the second overlaps
    /// the first and touches the third. Once the first has absorbed the
    /// second, its outline touches the third: one primitive in the end.
    #[test]
    fn a_merged_outline_takes_in_the_pieces_it_touches_once_grown() {
        let p = Params::gpp2();
        let a = patch(0.0, 4.0, 0.0, 0.0);
        let b = patch(3.0, 7.0, 0.0, 0.025);
        let c = patch(7.0, 10.0, 0.0, 0.0125);
        let (mut prims, mut labels, pts) = pieces(&[&a, &b, &c], &p);
        assert!(!crate::scenario::merge::mergeable(&prims[0], &prims[2], &p));
        assert!(crate::scenario::merge::mergeable(&prims[1], &prims[2], &p));
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 1);
        assert!(labels.iter().all(|&l| l == 0));
        assert_eq!(prims[0].support, pts.len() as u64);
        // 10 m x 2 m, outlined through the boundary cells' centres.
        assert!(
            prims[0].area > 18.0 && prims[0].area < 20.1,
            "area {}",
            prims[0].area
        );
    }

    #[test]
    fn pieces_tilted_away_from_the_larger_plane_stay_apart() {
        let p = Params::gpp2();
        // 6 degrees apart (within `mergeAngle`), but the smaller's far edge
        // lies 0.2 m off the larger's plane.
        let (a, b) = (patch(0.0, 5.0, 0.0, 0.0), patch(4.0, 7.0, 0.105, 0.025));
        let (mut prims, mut labels, pts) = two(&a, &b, &p);
        let before = (prims.clone(), labels.clone());
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 2);
        assert_eq!(labels, before.1);
        assert_eq!(prims[1].area, before.0[1].area);
    }

    #[test]
    fn pieces_apart_by_more_than_the_merge_gap_stay_apart() {
        let p = Params::gpp2();
        let (a, b) = (patch(0.0, 4.0, 0.0, 0.0), patch(5.0, 8.0, 0.0, 0.0));
        let (mut prims, mut labels, pts) = two(&a, &b, &p);
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 2);
        assert!(labels[..a.len()].iter().all(|&l| l == 0));
        assert!(labels[a.len()..].iter().all(|&l| l == 1));
    }
}
