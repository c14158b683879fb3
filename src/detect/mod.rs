//! One-shot detection of planar polygons: the paper's Algorithm 1, a cascade
//! of RANSAC plane search, Euclidean clustering, PCA refit, outline and
//! acceptance tests, each round removing what it explained.

pub mod cluster;
pub mod kernels;
pub mod ransac;

use crate::clock;
use crate::cloud::Cloud;
use crate::error::Result;
use crate::geometry::polygon::{contains, distance};
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
    /// Whether a primitive was accepted.
    pub accepted: bool,
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
    if prim.plane.signed_distance(viewpoint).abs() >= 2.0 * p.distance {
        return false;
    }
    let foot = prim.frame.to_local(viewpoint);
    !contains(&prim.outline, foot) && distance(&prim.outline, foot) > 1.0
}

/// The detection cascade with its parameters (validated by the caller).
pub struct Detector<'p> {
    params: &'p Params,
}

impl<'p> Detector<'p> {
    /// A detector with these parameters.
    pub fn new(params: &'p Params) -> Self {
        Detector { params }
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
        let mut pool = PlanePool::new(pts, p.sample_radius, rng);
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
            let flat: Vec<DVec2> = coords
                .iter()
                .map(|p| frame.to_local(p.as_dvec3()))
                .collect();
            // The ground, seen at grazing angles, has its own tolerance.
            let tol = if plane.ground {
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
                    accepted: false,
                    area: 0.0,
                    time_ms: clock::now_ms() - ts,
                });
                rejections += 1;
                continue;
            }
            let (mut cluster, mut support_pts) = (Vec::new(), Vec::new());
            for (c, &l) in comp.iter().enumerate() {
                if l == largest {
                    cluster.push(inliers[c]);
                    support_pts.push(coords[c]);
                }
            }
            // 3-4. PCA refit, frame, outline, area and solidity.
            let shaped = shape(origin, &support_pts, p, viewpoint);
            // 5. Accept when large and solid enough.
            let mut step = CascadeStep {
                points_left,
                inliers: inliers.len(),
                cluster: cluster.len(),
                accepted: false,
                area: shaped.as_ref().map_or(0.0, |s| s.primitive.area),
                time_ms: 0.0,
            };
            // 6. Take the support out of play (the whole cluster when rejected).
            match shaped {
                Some(s)
                    if s.primitive.acceptable(p)
                        && s.roughness <= p.max_roughness
                        && !seen_edge_on(&s, viewpoint, p)
                        && s.consistency(origin, &support_pts, p) >= p.min_normal_consistency =>
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
                    step.accepted = true;
                    rejections = 0;
                }
                _ => {
                    pool.remove(&cluster);
                    rejections += 1;
                }
            }
            step.time_ms = clock::now_ms() - ts;
            steps.push(step);
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
