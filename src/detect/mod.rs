//! One-shot detection of planar polygons: the paper's Algorithm 1, a cascade
//! of rounds, each finding a plane by RANSAC, clustering its inliers,
//! refitting, outlining and judging the candidates, and removing what it
//! explained. Which rules run is a [`CascadePolicy`]; the stages of a round
//! live in `round`, the plane search in [`ransac`].

pub(crate) mod cluster;
mod coarse;
pub mod kernels;
mod policy;
pub mod ransac;
pub(crate) mod riser;
mod round;
mod viewpoint;

pub use crate::primitive::NO_PRIMITIVE;
pub use policy::{CascadePolicy, GroundBy};

use crate::clock;
use crate::cloud::Cloud;
use crate::error::{Error, Result};
use crate::floor::{sensor_could_stand_at, FloorGrid, GroundRule};
use crate::hash::VoxelGrid;
use crate::params::Params;
use crate::primitive::Primitive;
use crate::rng::Rng;
use glam::{DVec3, Vec3};
use ransac::PlanePool;
use serde::Serialize;
use std::ops::ControlFlow;

/// When a stalled cascade clears clutter
/// ([`CascadePolicy::clear_scattered_on_stall`]): a sampling voxel holds no
/// plane when its live points spread across their best-fitting plane
/// (RMS) by more than this many times the median RMS of the supports
/// accepted so far: the noise of this cloud's own surfaces, so a noisier
/// sensor keeps more. Clutter (crowns, trunks, poles, bins, people) spreads
/// by tens of centimetres.
const SCATTERED_SPREAD: f64 = 1.5;
/// The spread allowed before any support was accepted, as a share of the
/// inlier distance (which is set at about three times the surfaces' noise).
const SCATTERED_SPREAD_UNKNOWN: f64 = 1.0 / 3.0;
/// The least spread allowed, as a share of the inlier distance: noise-free
/// synthetic surfaces would otherwise set it to rounding error.
const SCATTERED_SPREAD_FLOOR: f64 = 0.05;
/// Fewest live points in a voxel for its spread to be judged.
const SCATTERED_MIN_POINTS: usize = 8;

/// One round of the cascade (for the paper's Fig. 9 analysis).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct CascadeStep {
    /// Points still in play before this round (in the coarse pass's
    /// rounds, of that pass's points).
    pub points_left: usize,
    /// RANSAC inliers of the round's best plane.
    pub inliers: usize,
    /// Points in the largest cluster of those inliers.
    pub cluster: usize,
    /// Primitives accepted in this round (the largest cluster and, with
    /// [`CascadePolicy::every_cluster`], the plane's other clusters),
    /// before the final merge pass.
    pub accepted: usize,
    /// Outline area of the candidate (m^2; 0 when it had no outline).
    pub area: f64,
    /// Wall time of the round (ms).
    pub time_ms: f64,
}

/// What one detection found.
#[derive(Clone, Debug, Default)]
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
    /// The sensor position [`detect`] went by (world, m): `viewpoint` when
    /// given, the origin when it took the cloud for a scan in its own
    /// frame, `None` when it saw the cloud from no single viewpoint (a
    /// map, with or without [`detect_from`]'s sensor positions). `None`
    /// from [`Detector::run`], which is given its viewpoint.
    pub sensor: Option<DVec3>,
}

/// Detect planar polygons in a world-frame cloud seen from
/// `params.viewpoint` (the sensor position), if given. Without one, the
/// origin is taken for the sensor when one could have stood there (0.3 m
/// to 5 m above the lowest points within 10 m: a scan in its own frame);
/// otherwise (a map, a tile, scans accumulated from many poses) the cloud
/// is seen from nowhere: the rules that need a viewpoint are off
/// ([`CascadePolicy::without_viewpoint`]) and ground is decided from the
/// cloud's local floor. Normals face the viewpoint; without one, a point
/// 10 km above the cloud's centre (near-horizontal ones up, a wall the side
/// its slight tilt turns up: mostly, not always, towards the centre).
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
/// let params = Params { viewpoint: Some([5.0, 5.0, 1.8]), ..Params::gpp2() };
/// let found = detect(&cloud, &params).unwrap();
/// assert_eq!(found.primitives.len(), 1);
/// assert!((found.primitives[0].area - 99.0).abs() < 3.0);
/// ```
///
/// Fewer than `minInliers` points far from the bulk of the cloud (beyond
/// 16 times its 10-90 % spread from the median, and beyond 10 km) cannot
/// form a polygon: they are left out of the search, unlabelled, so they
/// change nothing (the cloud's origin already ignores them). More of them
/// may be a second site, and all points are searched.
pub fn detect(cloud: &Cloud, params: &Params) -> Result<Detection> {
    detect_from(cloud, params, &[])
}

/// [`detect`] of a cloud accumulated from scans whose sensors stood at
/// `viewpoints` (world, m), with no `params.viewpoint`: the cloud is seen
/// from no single viewpoint, as [`detect`] sees a map, except that a
/// candidate whose plane passes through every one of them, away from each,
/// is dropped as laser rings (the sensors of a drive on level ground all
/// lie in the plane of the rings at their height, and a patch of those
/// rings is no surface). A plane seen edge-on from some of them only is
/// kept: the others saw it face-on. Empty `viewpoints`: [`detect`].
pub fn detect_from(cloud: &Cloud, params: &Params, viewpoints: &[DVec3]) -> Result<Detection> {
    let found = detect_with_progress(
        cloud,
        params,
        viewpoints,
        &mut |_| ControlFlow::Continue(()),
    )?;
    // Never stopped, so always `Some`.
    Ok(found.unwrap_or_default())
}

/// Is `len` numbers a flat list of x, y, z of each sensor position for
/// [`detect_from`] (the JS `viewpoints` option, the CLI's `--viewpoints`)?
/// Else [`Error::BadOption`] `viewpoints`.
pub(crate) fn check_flat_positions(len: usize) -> Result<()> {
    if len % 3 == 0 {
        Ok(())
    } else {
        Err(Error::BadOption {
            key: "viewpoints".into(),
            reason: format!("must be a flat list of x, y, z of each position, got {len} values"),
        })
    }
}

/// [`detect_from`] that calls `progress` after each round of the cascade (the
/// rounds' count is not known in advance: `points_left` falls towards 0);
/// [`ControlFlow::Break`] stops it there and gives `Ok(None)`. The result of
/// a detection that runs to its end is the same as [`detect_from`]'s.
pub fn detect_with_progress(
    cloud: &Cloud,
    params: &Params,
    viewpoints: &[DVec3],
    progress: &mut dyn FnMut(&Progress) -> ControlFlow<()>,
) -> Result<Option<Detection>> {
    params.validate()?;
    if !viewpoints.is_empty() && params.viewpoint.is_some() {
        return Err(Error::BadOption {
            key: "viewpoint".into(),
            reason: "not with the viewpoints of an accumulated cloud: give one or the other".into(),
        });
    }
    if let Some(i) = viewpoints.iter().position(|v| !v.is_finite()) {
        return Err(Error::BadOption {
            key: "viewpoints".into(),
            reason: format!("position {i} is not finite"),
        });
    }
    let Some((median, reach)) =
        crate::cloud::bulk_extent(cloud.points.iter().map(|p| p.as_dvec3()))
    else {
        return Ok(detect_all(cloud, params, viewpoints, progress));
    };
    let far = |p: &glam::Vec3| (p.as_dvec3() - median).abs().max_element() > reach;
    let outliers = cloud.points.iter().filter(|p| far(p)).count();
    if outliers >= params.min_inliers {
        return Ok(detect_all(cloud, params, viewpoints, progress));
    }
    let kept: Vec<u32> = (0..cloud.len() as u32)
        .filter(|&i| !far(&cloud.points[i as usize]))
        .collect();
    let bulk = Cloud {
        origin: cloud.origin,
        points: kept.iter().map(|&i| cloud.points[i as usize]).collect(),
    };
    let Some(mut det) = detect_all(&bulk, params, viewpoints, progress) else {
        return Ok(None);
    };
    let mut labels = vec![NO_PRIMITIVE; cloud.len()];
    for (&i, &l) in kept.iter().zip(&det.labels) {
        labels[i as usize] = l;
    }
    det.labels = labels;
    Ok(Some(det))
}

/// The largest spread (m) of a voxel's points across their best plane that
/// still counts as a surface when a stalled cascade clears clutter.
fn scattered_spread(accepted_rms: &mut [f64], p: &Params) -> f64 {
    if accepted_rms.is_empty() {
        return SCATTERED_SPREAD_UNKNOWN * p.other.distance;
    }
    crate::geometry::heap_sort_by(accepted_rms, f64::total_cmp);
    let median = accepted_rms[accepted_rms.len() / 2];
    (SCATTERED_SPREAD * median).max(SCATTERED_SPREAD_FLOOR * p.other.distance)
}

/// [`detect_with_progress`] on every point (parameters validated): `None`
/// when `progress` stopped it.
fn detect_all(
    cloud: &Cloud,
    params: &Params,
    sensors: &[DVec3],
    progress: &mut dyn FnMut(&Progress) -> ControlFlow<()>,
) -> Option<Detection> {
    // The given viewpoint, or the origin for a scan in its own frame.
    let sensor = match params.viewpoint {
        Some(v) => Some(DVec3::from_array(v)),
        None if sensors.is_empty() => {
            sensor_could_stand_at(&cloud.points, -cloud.origin).then_some(DVec3::ZERO)
        }
        None => None,
    };
    let (policy, viewpoint) = match sensor {
        Some(v) => (CascadePolicy::one_shot(), v),
        None => {
            // Seen from nowhere: normals face a point high above the centre.
            let n = cloud.points.len().max(1) as f64;
            let mean = cloud.points.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / n;
            let above = cloud.origin + mean + DVec3::new(0.0, 0.0, 1e4);
            let policy = CascadePolicy::one_shot().without_viewpoint();
            let policy = if sensors.is_empty() {
                policy
            } else {
                policy.seen_from_all()
            };
            (policy, above)
        }
    };
    let det = Detector {
        sensors,
        ..Detector::new(params, policy)
    };
    let rng = Rng::new(params.seed);
    let (found, stopped) = det.run_inner(&cloud.points, cloud.origin, viewpoint, rng, progress);
    (!stopped).then_some(Detection { sensor, ..found })
}

/// Where a detection is, after one of its rounds ([`detect_with_progress`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Rounds done (each finds the plane of largest consensus among the
    /// points left and takes out its accepted or rejected patches).
    pub round: usize,
    /// Points not yet taken out (explained or discarded). In the coarse
    /// pass of a cloud seen from nowhere
    /// ([`CascadePolicy::coarse_pass`]), the points of that pass not yet
    /// taken out: it starts again from the sparse unexplained points, which
    /// can be more than the first pass left in play.
    pub points_left: usize,
    /// Points of the cloud.
    pub points: usize,
    /// Primitives accepted so far (before the final merge).
    pub primitives: usize,
}

/// A cloud as one pass of the cascade sees it: points local to `origin`,
/// the sensor (world), and what tells ground.
#[derive(Clone, Copy)]
struct Seen<'a> {
    pts: &'a [Vec3],
    origin: DVec3,
    viewpoint: DVec3,
    ground: GroundRule<'a>,
}

/// The detection cascade: parameters (validated by the caller) and the
/// rule set.
pub struct Detector<'p> {
    params: &'p Params,
    policy: CascadePolicy,
    /// The sensors an accumulated cloud was gathered from
    /// ([`detect_from`]); empty: the viewpoint alone.
    sensors: &'p [DVec3],
}

impl<'p> Detector<'p> {
    /// A detector with these parameters and rules.
    pub fn new(params: &'p Params, policy: CascadePolicy) -> Self {
        Detector {
            params,
            policy,
            sensors: &[],
        }
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
        self.run_inner(pts, origin, viewpoint, rng, &mut |_| {
            ControlFlow::Continue(())
        })
        .0
    }

    /// The cascade, with `progress` called after each round; the flag:
    /// stopped by `progress` (the detection is then incomplete and unmerged).
    fn run_inner(
        &self,
        pts: &[Vec3],
        origin: DVec3,
        viewpoint: DVec3,
        rng: Rng,
        progress: &mut dyn FnMut(&Progress) -> ControlFlow<()>,
    ) -> (Detection, bool) {
        let (p, policy) = (self.params, &self.policy);
        let t0 = clock::now_ms();
        let floor = (policy.ground == GroundBy::LocalFloor).then(|| FloorGrid::new(pts));
        let ground = match &floor {
            Some(f) => GroundRule::LocalFloor(f),
            None => GroundRule::BelowViewpoint,
        };
        // The coarse pass's generator, derived from the cascade's first
        // draw: an explicit generator fixes both.
        let coarse_rng = Rng::derive(rng.clone().next_u64(), coarse::STREAM);
        let seen = Seen {
            pts,
            origin,
            viewpoint,
            ground,
        };
        let grid = PlanePool::grid(pts, p.sample_radius);
        let (mut out, stopped, grid) = self.rounds(seen, grid, rng, progress);
        if stopped {
            return (out, true);
        }
        // 7. A coarser cascade on the points too sparse for this one.
        if policy.coarse_pass && coarse::pass(self, &mut out, seen, &grid, coarse_rng, progress) {
            return (out, true);
        }
        drop(grid);
        // 8. Merge the pieces of one surface that rounds or passes found
        //    apart.
        if policy.merge_pieces && p.hull.merges_detected_pieces() {
            crate::merge::points::merge_pieces(
                &mut out.primitives,
                &mut out.labels,
                pts,
                origin,
                p,
            );
        }
        // 9. The risers between near-horizontal surfaces a step apart.
        if policy.find_risers {
            riser::add_risers(
                &mut out.primitives,
                &mut out.labels,
                pts,
                origin,
                viewpoint,
                p,
                policy.range_pulled_ground.then(|| viewpoint.truncate()),
            );
        }
        out.time_ms = clock::now_ms() - t0;
        (out, false)
    }

    /// The rounds of the cascade (steps 1-6) on `pts` until a stop rule,
    /// with `progress` called after each, sampling in `grid`
    /// ([`PlanePool::grid`] of `pts`); the flag: stopped by `progress`. The
    /// grid comes back for the coarse pass to count neighbours in.
    fn rounds(
        &self,
        seen: Seen,
        grid: VoxelGrid,
        rng: Rng,
        progress: &mut dyn FnMut(&Progress) -> ControlFlow<()>,
    ) -> (Detection, bool, VoxelGrid) {
        let Seen {
            pts,
            origin,
            viewpoint,
            ground,
        } = seen;
        let (p, policy) = (self.params, &self.policy);
        // The least support of a plane and a candidate: by policy, that of
        // the pool's thinned points (the judge keeps `minInliers` for
        // near-horizontal candidates at ground depth).
        let min_support = if policy.pool_support {
            policy::pool_support(p)
        } else {
            p.min_inliers
        };
        let t0 = clock::now_ms();
        let local_viewpoint = viewpoint - origin;
        let mut pool = PlanePool::on_grid(
            pts,
            grid,
            policy.skip_edge_on_hypotheses.then_some(local_viewpoint),
            rng,
        )
        .hypothesis_scale(policy.hypothesis_scale);
        if policy.reject_slivers {
            pool = pool.reject_slivers();
        }
        if policy.local_triples {
            pool = pool.local_triples();
        }
        let mut out = Detection {
            primitives: Vec::new(),
            labels: vec![NO_PRIMITIVE; pts.len()],
            steps: Vec::new(),
            work: 0,
            time_ms: 0.0,
            sensor: None,
        };
        let mut clusterer = cluster::Clusterer::default();
        let mut rejections = 0;
        // Cleared of scattered voxels yet (see `clear_scattered_on_stall`)?
        let mut cleared = !policy.clear_scattered_on_stall;
        // RMS distance (m) of each accepted support from its plane.
        let mut accepted_rms: Vec<f64> = Vec::new();
        // Pool positions of rejected clusters that stayed in play (step 6;
        // only the plane's other clusters can).
        let mut reprieved = vec![false; if policy.every_cluster { pts.len() } else { 0 }];
        let judge = round::Judge {
            origin,
            viewpoint,
            edge_on_from: if self.sensors.is_empty() {
                std::slice::from_ref(&viewpoint)
            } else {
                self.sensors
            },
            ground,
            p,
            policy,
            min_support,
        };
        for _ in 0..4 * p.max_primitives + 64 {
            if !cleared && rejections >= p.max_rejections {
                // Stalled: the rounds keep finding planes through clutter.
                // Take out what holds no plane and go on, once.
                cleared = true;
                let spread = scattered_spread(&mut accepted_rms, p);
                if pool.remove_scattered(SCATTERED_MIN_POINTS, spread) > 0 {
                    rejections = 0;
                }
            }
            if out.primitives.len() >= p.max_primitives
                || pool.work >= p.max_work
                || rejections >= p.max_rejections
            {
                break;
            }
            let ts = clock::now_ms();
            let mut step = CascadeStep {
                points_left: pool.remaining(),
                ..CascadeStep::default()
            };
            // 1. RANSAC: the plane with the largest consensus, or stop.
            let Some((plane, inliers, coords)) =
                pool.best_plane(p, min_support, local_viewpoint, ground)
            else {
                break;
            };
            step.inliers = inliers.len();
            // 2. Cluster its inliers in the plane.
            let clusters =
                round::cluster_inliers(&mut clusterer, &plane, &coords, local_viewpoint, p, policy);
            step.cluster = clusters.largest_size();
            if step.cluster < min_support {
                // No connected patch of this plane is large enough to be a
                // primitive: its inliers are scattered clutter (a plane
                // slicing through trees and cars). Take them all out of play
                // at once rather than one fragment per round. By policy,
                // the bands of other surfaces the plane crosses stay, and the
                // plane is not tried again.
                if policy.spare_crossing_surfaces {
                    let spread = scattered_spread(&mut accepted_rms, p);
                    pool.set_aside(&inliers, &plane, SCATTERED_MIN_POINTS, spread);
                } else {
                    pool.remove(&inliers);
                }
            } else {
                // 3. The candidates: the largest cluster (and, by policy,
                //    the plane's other large ones).
                let candidates = round::candidates(&clusters, &inliers, &coords, p, policy);
                for (k, (cluster, support_pts)) in candidates.iter().enumerate() {
                    if out.primitives.len() >= p.max_primitives {
                        break;
                    }
                    // 4-5. Refit, outline and judge.
                    let mut judged = judge.judge(support_pts);
                    if k == 0 {
                        step.area = judged.shaped.as_ref().map_or(0.0, |s| s.primitive.area);
                    }
                    // Too rough, nothing else wrong, or smooth enough but
                    // not tight or seen only as laser rings: perhaps two
                    // surfaces that one plane holds
                    // (a step, a bend, a road and a sidewalk under a tilted
                    // plane). Judge the dominant one alone; the rest of the
                    // cluster stays in play. (When it fails, a rough
                    // candidate leaves play, and a smooth one is kept.)
                    let mut layer: Option<round::Candidate> = None;
                    if policy.split_rough_layers && (judged.only_too_rough || judged.maybe_two) {
                        if let Some((near, again)) =
                            judge.dominant_layer(&judged, cluster, support_pts)
                        {
                            layer = Some(near);
                            judged = again;
                        }
                    }
                    // By policy, a candidate more than half of whose points
                    // lie on other surfaces crossing its plane holds their
                    // bands: it is judged again without them (a car's roof
                    // with the top rows of its sides), and when that fails
                    // it is a plane through the bands, not a surface
                    // (rejected, the bands spared, the plane set aside).
                    let mut banded = false;
                    if policy.spare_crossing_surfaces
                        && policy.judge_without_crossing_bands
                        && judged.accepted
                    {
                        let (cluster, support_pts) = layer
                            .as_ref()
                            .map_or((&cluster[..], &support_pts[..]), |(c, s)| (c, s));
                        let normal = judged.shaped.as_ref().map(|s| s.primitive.plane.normal);
                        let spread = scattered_spread(&mut accepted_rms, p);
                        let off = normal.map_or_else(Vec::new, |n| {
                            pool.off_crossing_surfaces(cluster, n, SCATTERED_MIN_POINTS, spread)
                        });
                        if 2 * off.len() < cluster.len() {
                            let (own, again) = judge.judge_part(cluster, support_pts, &off);
                            if again.accepted {
                                layer = Some(own);
                                judged = again;
                            } else {
                                judged.accepted = false;
                                banded = true;
                            }
                        }
                    }
                    let cluster: &Vec<u32> = layer.as_ref().map_or(cluster, |(c, _)| c);
                    // 6. Accept and take the support out of play, or take out
                    //    the whole largest cluster (with the plane fitted to
                    //    it, it would come back the same).
                    match judged.shaped {
                        Some(s) if judged.accepted => {
                            let id = out.primitives.len() as u32;
                            let taken: Vec<u32> = cluster
                                .iter()
                                .zip(&s.kept)
                                .filter_map(|(&i, &k)| k.then_some(i))
                                .collect();
                            for &v in &taken {
                                out.labels[pool.original(v) as usize] = id;
                            }
                            pool.remove(&taken);
                            accepted_rms.push(s.roughness * p.surface(s.primitive.ground).distance);
                            out.primitives.push(Primitive { id, ..s.primitive });
                            step.accepted += 1;
                        }
                        // The plane was fitted to the largest cluster; another
                        // was judged on the band of it that the plane's slab
                        // held (a car's side beside the next one's in a row,
                        // a plateau beside a road). It stays in play, once,
                        // to come back whole with its own plane.
                        _ if k > 0 && !cluster.iter().any(|&v| reprieved[v as usize]) => {
                            for &v in cluster.iter() {
                                reprieved[v as usize] = true;
                            }
                        }
                        // By policy, the bands of other surfaces it crossed
                        // stay in play, and the plane is not tried again.
                        _ if policy.spare_crossing_surfaces
                            && (banded || policy.spare_rejected) =>
                        {
                            let spread = scattered_spread(&mut accepted_rms, p);
                            pool.set_aside(cluster, &plane, SCATTERED_MIN_POINTS, spread);
                        }
                        _ => pool.remove(cluster),
                    }
                }
            }
            rejections = if step.accepted > 0 { 0 } else { rejections + 1 };
            step.time_ms = clock::now_ms() - ts;
            out.steps.push(step);
            let at = Progress {
                round: out.steps.len(),
                points_left: pool.remaining(),
                points: pts.len(),
                primitives: out.primitives.len(),
            };
            if progress(&at).is_break() {
                return (out, true, pool.into_grid());
            }
        }
        out.work = pool.work;
        out.time_ms = clock::now_ms() - t0;
        (out, false, pool.into_grid())
    }
}
