//! RANSAC plane search over the points still unexplained, built to find the
//! plane an exhaustive MSAC search would (the best soft consensus, below)
//! with far less work:
//!
//! - **Local sampling.** The first point of a hypothesis is drawn uniformly;
//!   the other two from the same voxel of side `sample_radius`, so one sample
//!   rarely mixes two surfaces (Schnabel et al.'s locality argument). Plain
//!   uniform triples hit a 5 % wall with probability 1.25e-4; local ones with
//!   roughly 5 % x 1/4.
//! - **MSAC scores.** A hypothesis scores `1 - (d/t)^2` for each point at
//!   distance `d < t` (Torr and Zisserman's truncated quadratic loss, as a
//!   soft inlier count), not 1 per inlier. With plain counts a plane tilted
//!   by half a degree across a road and the strip of sidewalk its slab
//!   reaches wins over the road's own plane (it holds more points, fitted
//!   far worse); the support it gathers is rough and rejected, and a whole
//!   location's road went with it. Soft scores rank the road's plane first.
//! - **Scoring on a subsample.** The remaining points are kept in one fixed
//!   random order, so any prefix is a uniform random subsample. Hypotheses are
//!   scored on a prefix of `k` points (4096 to start); when even the best
//!   scores too few subsample inliers to be ranked reliably (soft score < 40), `k` grows
//!   fourfold and the search restarts, up to all points.
//! - **Local test.** A hypothesis must explain at least 30 % of the live
//!   points of the voxel it was sampled in, or it mixed two surfaces or came
//!   from clutter; it is dropped before any global scoring.
//! - **Early rejection.** A hypothesis is scored on the first eighth of the
//!   prefix first and dropped if it is below half the best's pro-rata score;
//!   then at a quarter, a half and three quarters of the prefix, dropped if
//!   below 70 % of it. By then the running score has 1024 to 3072 points of
//!   a 4096-point prefix behind it: a hypothesis at least as good as the
//!   best rarely falls that short, and the best it would have replaced is
//!   about as good. Most hypotheses that pass the first eighth are
//!   mediocre, and scoring them on the whole prefix was 70 % of the
//!   scoring work on real scans.
//! - **Adaptive stop.** After each improvement the number of hypotheses
//!   needed for `confidence` is recomputed from the best inlier ratio (with
//!   an assumed chance of 1/2 that a local triple started on a plane stays on it), bounded by
//!   `[24, max_hypotheses]` (twice that with the plain sampler; see
//!   [`Params::max_hypotheses`]). Rounds after the large surfaces hit the
//!   bound: their best planes hold a percent or two of the points left.
//! - **Local optimisation and confirmation.** The best hypothesis is refit
//!   by robust least squares (f64 PCA, trimmed) on its inliers among a
//!   random subsample of at most 16 384 points; it replaces the hypothesis
//!   when it scores at least as well there (with the same threshold), and
//!   its inliers are then collected once from all remaining points.
//!
//! Bounds on work per round (`h` the bound on hypotheses above): at most
//! `h * k` distance evaluations per prefix size (and at most `4 h` samples),
//! prefix sizes grow geometrically to `n`, plus three passes over at most
//! 16 384 points for the local optimisation and at most one pass over the
//! `n` remaining points (with a test per live voxel) to collect the inliers.
//! Every evaluation is counted in `work` so the cascade can enforce
//! `Params::max_work`.

use super::kernels::{self, PlaneF32};
use crate::floor::GroundRule;
use crate::geometry::plane::{plane_through, robust_fit, smallest_eigen3, Moments};
use crate::geometry::Plane;
use crate::hash::VoxelGrid;
use crate::params::Params;
use crate::rng::Rng;
use glam::{DVec3, Vec3};

/// A voxel whose own plane lies more than this many degrees off a round's
/// plane holds a surface crossing it (see
/// [`PlanePool::off_crossing_surfaces`]).
const CROSSING_ANGLE: f64 = 30.0;
/// A hypothesis within this many degrees of a set-aside plane, and within
/// its inlier distance, is that plane again (see [`PlanePool::set_aside`]).
const SET_ASIDE_ANGLE: f64 = 2.0;

/// A plane in the cloud's local coordinates with the threshold it was
/// counted with.
#[derive(Clone, Copy, Debug)]
pub struct LocalPlane {
    /// Unit normal.
    pub normal: DVec3,
    /// Offset: `normal · p + offset = 0` for local points `p`.
    pub offset: f64,
    /// Inlier distance used (m).
    pub threshold: f64,
    /// Counted as ground (near-horizontal, at least `ground_depth` below
    /// the viewpoint): `threshold` is then `ground_distance`.
    pub ground: bool,
}

impl LocalPlane {
    /// The plane in f32, as the kernels test points against it.
    fn as_f32(&self) -> PlaneF32 {
        PlaneF32 {
            nx: self.normal.x as f32,
            ny: self.normal.y as f32,
            nz: self.normal.z as f32,
            d: self.offset as f32,
        }
    }
}

/// The points not yet explained, and the sampling structures over them.
///
/// Points are known by their *position*: their rank in voxel order
/// (`grid.members.items[v]` is the original index of position `v`). Per-point
/// state lives in position order, so what one round touches (the inliers of
/// one plane, collected voxel by voxel) is close together in memory; only
/// labels go back to original indices.
pub struct PlanePool {
    /// Planes no hypothesis may repeat: unit normal, offset and inlier
    /// distance (see [`PlanePool::set_aside`]).
    set_aside: Vec<(DVec3, f64, f64)>,
    /// Per position: still in play?
    alive: Vec<bool>,
    rx: Vec<f32>,
    ry: Vec<f32>,
    rz: Vec<f32>,
    /// Scoring pool: positions in random order.
    ridx: Vec<u32>,
    /// Per position: its voxel.
    cell_of: Vec<u32>,
    /// The sampling voxels: `grid.members` holds the original indices
    /// grouped by voxel (position `v` is `grid.members.items[v]`).
    grid: VoxelGrid,
    /// Coordinates by position (NaN once dead): the full inlier collection
    /// reads only the voxels a plane's slab crosses.
    cell_pts: Vec<Vec3>,
    /// Position of each original index.
    cell_pos_of: Vec<u32>,
    /// Bounding box of each voxel's points (centre, half extent), f64, and
    /// the rounding margin of its inlier test (see [`PlanePool::collect`]).
    cell_box: Vec<(DVec3, DVec3, f64)>,
    /// Live points per voxel.
    cell_live: Vec<u32>,
    rng: Rng,
    /// Points still in play.
    live: usize,
    /// Of those, how many are in the scoring pool (whose arrays may also
    /// hold dead ones, with x = NaN).
    pool_live: usize,
    /// Pool position of each position (`u32::MAX` when not in the pool).
    pos_of: Vec<u32>,
    /// The points within [`NEAR_VIEWPOINT`] of the viewpoint, when planes
    /// seen edge-on are no hypotheses (see [`PlanePool::seen_edge_on`]).
    near: Option<Near>,
    /// Smallest height of a sample triangle on its longest side, relative
    /// to that side (0: any triple not near-collinear; see
    /// [`PlanePool::reject_slivers`]).
    min_fatness: f64,
    /// Only triples from one voxel (see [`PlanePool::local_triples`]).
    local_only: bool,
    /// Hypotheses per round, in units of `max_hypotheses` (see
    /// [`PlanePool::hypothesis_scale`]).
    hypothesis_scale: usize,
    /// Point-to-plane distance evaluations so far.
    pub work: u64,
    /// Hypotheses scored so far.
    scored: u64,
}

/// Radius (m) around the viewpoint within which points tell whether the
/// sensor stands on a plane that passes through it.
const NEAR_VIEWPOINT: f64 = 1.5;
/// Live points of a plane within [`NEAR_VIEWPOINT`] that make it the floor
/// the sensor stands on.
const NEAR_SUPPORT: usize = 10;
/// Most points near the viewpoint that are kept for that test.
const NEAR_CAP: usize = 4096;
/// Smallest height of a sample triangle on its longest side, relative to
/// that side, when slivers are rejected ([`PlanePool::reject_slivers`]).
const MIN_FATNESS: f64 = 0.15;

const START_K: usize = 4096;
const MIN_RANKABLE: usize = 40;
const MIN_HYPOTHESES: usize = 24;
/// Share of the best's pro-rata score a hypothesis must keep at each
/// quarter of the prefix after the first eighth (see `score_prefix`).
const LATE_SHARE: f64 = 0.7;
/// Most points in the scoring pool: hypotheses are ranked on prefixes of a
/// random subset of this size. Planes too small to reach `MIN_RANKABLE`
/// inliers in it (under 0.015 % of the cloud) are below any sensible
/// `min_inliers` in clouds of up to ~10^6 points, and building a random
/// order of a ten-million-point cloud would cost more than detecting in it.
const POOL_CAP: usize = 1 << 18;
/// Most points the local optimisation (robust refit) looks at.
const LO_SAMPLE: usize = 16_384;

impl PlanePool {
    /// All of `pts` in play, shuffled once with `rng`, in sampling voxels of
    /// side `sample_radius`. With `edge_on` (the sensor in the points'
    /// coordinates), planes seen edge-on from it are never hypotheses.
    pub fn new(pts: &[Vec3], sample_radius: f64, edge_on: Option<DVec3>, rng: Rng) -> Self {
        Self::on_grid(pts, Self::grid(pts, sample_radius), edge_on, rng)
    }

    /// The sampling voxels of `pts` for [`PlanePool::on_grid`]: side
    /// `sample_radius` (at least 1 mm).
    pub fn grid(pts: &[Vec3], sample_radius: f64) -> VoxelGrid {
        VoxelGrid::new(pts, sample_radius.max(1e-3))
    }

    /// [`PlanePool::new`] on sampling voxels already built
    /// ([`PlanePool::grid`]), which [`PlanePool::into_grid`] gives back.
    pub fn on_grid(pts: &[Vec3], grid: VoxelGrid, edge_on: Option<DVec3>, mut rng: Rng) -> Self {
        let n = pts.len();
        // The scoring pool: every point in random order, or beyond POOL_CAP
        // points a uniform random subset of POOL_CAP; every prefix is a
        // uniform random subsample, which is all the scoring needs.
        let mut order: Vec<u32> = (0..n as u32).collect();
        if n <= POOL_CAP {
            for i in (1..n).rev() {
                let j = rng.below(i + 1);
                order.swap(i, j);
            }
        } else {
            random_prefix(&mut order, POOL_CAP, &mut rng);
        }
        // Sampling voxels (ids in first-seen order of the original indices).
        let cells = grid.voxels.coords.len();
        let buckets = &grid.members;
        let cell_pts: Vec<Vec3> = buckets.items.iter().map(|&i| pts[i as usize]).collect();
        let mut cell_pos_of = vec![0u32; n];
        for (pos, &i) in buckets.items.iter().enumerate() {
            cell_pos_of[i as usize] = pos as u32;
        }
        let mut cell_of = Vec::with_capacity(n);
        for c in 0..cells {
            cell_of.resize(buckets.range(c).end, c as u32);
        }
        // Boxes from the points themselves, not from the voxel keys (keys
        // wrap for coordinates beyond 2^21 voxels, boxes never lie).
        let mut cell_box = Vec::with_capacity(cells);
        let mut cell_live = Vec::with_capacity(cells);
        for c in 0..cells {
            let members = &cell_pts[buckets.range(c)];
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for p in members {
                crate::geometry::grow_box(&mut lo, &mut hi, p.as_dvec3());
            }
            let centre = (lo + hi) * 0.5;
            cell_box.push((centre, (hi - lo) * 0.5, 1e-6 * centre.abs().max_element()));
            cell_live.push(members.len() as u32);
        }
        // The points near the viewpoint, found through the voxels' boxes.
        let near = edge_on.map(|viewpoint| {
            let r2 = NEAR_VIEWPOINT * NEAR_VIEWPOINT;
            let mut near = Vec::new();
            for (c, &(centre, half, _)) in cell_box.iter().enumerate() {
                let gap = ((centre - viewpoint).abs() - half).max(DVec3::ZERO);
                if gap.length_squared() <= r2 {
                    for pos in buckets.range(c) {
                        if cell_pts[pos].as_dvec3().distance_squared(viewpoint) <= r2 {
                            near.push(pos as u32);
                        }
                    }
                }
            }
            // An even-strided subset is enough to tell a floor under the
            // sensor, and keeps each look bounded (a sensor close to
            // surfaces has many points near it).
            let step = near.len().div_ceil(NEAR_CAP).max(1);
            let positions: Vec<u32> = near.into_iter().step_by(step).collect();
            let coords = |k: usize| -> Vec<f32> {
                positions.iter().map(|&v| cell_pts[v as usize][k]).collect()
            };
            Near {
                xs: coords(0),
                ys: coords(1),
                zs: coords(2),
                positions,
                hits: Vec::new(),
            }
        });
        let mut pool = PlanePool {
            set_aside: Vec::new(),
            pool_live: 0,
            cell_pts,
            cell_pos_of,
            cell_box,
            cell_live,
            live: n,
            pos_of: vec![u32::MAX; n],
            alive: vec![true; n],
            rx: Vec::new(),
            ry: Vec::new(),
            rz: Vec::new(),
            ridx: Vec::new(),
            cell_of,
            grid,
            rng,
            near,
            min_fatness: 0.0,
            local_only: false,
            hypothesis_scale: 1,
            work: 0,
            scored: 0,
        };
        for i in order.iter_mut() {
            *i = pool.cell_pos_of[*i as usize];
        }
        pool.set_pool(order);
        pool
    }

    /// Draw no sliver triples: the triangle of the three sample points must
    /// be at least 0.15 times (`MIN_FATNESS`) as high, on its longest side, as
    /// that side is long. Three points almost in a line fix the line, not
    /// the plane: the noise across it tilts the plane at random, and what
    /// comes out most often is a plane across a wall through a thin band of
    /// it (a horizontal plane through a car's side or a facade). Such a
    /// plane gathers bands from every car and facade along the street; its
    /// clusters are rejected, and the bands leave play with them.
    pub fn reject_slivers(mut self) -> Self {
        self.min_fatness = MIN_FATNESS;
        self
    }

    /// Draw every triple from one voxel: a voxel without three live points
    /// gives no hypothesis (by default its second and third points then
    /// come from anywhere in the cloud). A triple across the cloud is a
    /// plane through unrelated points, and the best of many such is a
    /// level slab through everything's laser rings at one height (a band
    /// of each facade and car around, fragments whose clusters are
    /// rejected), which outscores the sparse surfaces still to be found
    /// and takes their bands out of play round after round.
    pub fn local_triples(mut self) -> Self {
        self.local_only = true;
        self
    }

    /// Score up to `scale` times `max_hypotheses` per round (default 1).
    pub fn hypothesis_scale(mut self, scale: usize) -> Self {
        self.hypothesis_scale = scale;
        self
    }

    /// Most hypotheses scored per round.
    fn hypothesis_budget(&self, params: &Params) -> usize {
        params.max_hypotheses.saturating_mul(self.hypothesis_scale)
    }

    /// The sampling voxels it was built on.
    pub fn into_grid(self) -> VoxelGrid {
        self.grid
    }

    /// Original index of position `v`.
    pub fn original(&self, v: u32) -> u32 {
        self.grid.members.items[v as usize]
    }

    /// Number of points still in play.
    pub fn remaining(&self) -> usize {
        self.live
    }

    /// Replace the scoring pool by a fresh random subset (at most
    /// `POOL_CAP`) of the live points, in random order.
    fn refill(&mut self) {
        for &i in &self.ridx {
            self.pos_of[i as usize] = u32::MAX;
        }
        // Live points in original order (as always: the same random subset).
        let mut order: Vec<u32> = self
            .cell_pos_of
            .iter()
            .copied()
            .filter(|&v| self.alive[v as usize])
            .collect();
        random_prefix(&mut order, POOL_CAP, &mut self.rng);
        self.set_pool(order);
    }

    /// Make these (live) positions the scoring pool, in this order. Two
    /// passes: gathering the coordinates and scattering the positions in
    /// one loop ran at half the speed (each stalls the other's misses).
    fn set_pool(&mut self, order: Vec<u32>) {
        for v in [&mut self.rx, &mut self.ry, &mut self.rz] {
            v.clear();
            v.reserve(order.len());
        }
        for &i in &order {
            let p = self.cell_pts[i as usize];
            self.rx.push(p.x);
            self.ry.push(p.y);
            self.rz.push(p.z);
        }
        for (pos, &i) in order.iter().enumerate() {
            self.pos_of[i as usize] = pos as u32;
        }
        self.pool_live = order.len();
        self.ridx = order;
    }

    /// Take these positions out of play. Their x coordinate in the pool
    /// becomes NaN: every distance computed from it is NaN (a zero normal
    /// component times NaN is still NaN), which fails every inlier test, so
    /// no pass over the pool needs to check liveness. Only x: the pool is in
    /// random order, so each write is a cache miss, one per point instead of
    /// three. The arrays are compacted only once half of them is dead (which
    /// keeps the order, so prefixes stay random).
    pub fn remove(&mut self, positions: &[u32]) {
        for &i in positions {
            if !self.alive[i as usize] {
                continue;
            }
            self.alive[i as usize] = false;
            self.live -= 1;
            self.cell_pts[i as usize] = Vec3::NAN;
            self.cell_live[self.cell_of[i as usize] as usize] -= 1;
            let pos = self.pos_of[i as usize];
            if pos != u32::MAX {
                let pos = pos as usize;
                self.rx[pos] = f32::NAN;
                self.pool_live -= 1;
            }
        }
        if 2 * self.pool_live >= self.ridx.len() {
            return;
        }
        let mut w = 0;
        for r in 0..self.ridx.len() {
            let i = self.ridx[r];
            if self.alive[i as usize] {
                self.ridx[w] = i;
                self.rx[w] = self.rx[r];
                self.ry[w] = self.ry[r];
                self.rz[w] = self.rz[r];
                self.pos_of[i as usize] = w as u32;
                w += 1;
            }
        }
        self.ridx.truncate(w);
        self.rx.truncate(w);
        self.ry.truncate(w);
        self.rz.truncate(w);
    }

    /// Take out of play the live points of every voxel that holds at least
    /// `min_points` of them and no plane: their spread across the best
    /// fitting plane (the square root of the smallest eigenvalue of their
    /// covariance) exceeds `max_spread`. Returns how many left play.
    pub fn remove_scattered(&mut self, min_points: usize, max_spread: f64) -> usize {
        let before = self.live;
        let max_var = max_spread * max_spread;
        let mut out: Vec<u32> = Vec::new();
        for c in 0..self.cell_box.len() {
            if (self.cell_live[c] as usize) < min_points.max(4) {
                continue;
            }
            let flat = self.voxel_plane(c).is_none_or(|(var, _)| var <= max_var);
            if !flat {
                out.extend(
                    self.grid
                        .members
                        .range(c)
                        .filter(|&pos| self.alive[pos])
                        .map(|pos| pos as u32),
                );
            }
        }
        self.remove(&out);
        before - self.live
    }

    /// The plane through the live points of voxel `c`: the variance of
    /// their distances from it (the smallest eigenvalue of their
    /// covariance) and its unit normal; `None` when no single plane is
    /// defined (see [`smallest_eigen3`]).
    fn voxel_plane(&self, c: usize) -> Option<(f64, DVec3)> {
        let mut m = Moments::new(self.cell_box[c].0);
        for pos in self.grid.members.range(c).filter(|&pos| self.alive[pos]) {
            m.push(self.cell_pts[pos].as_dvec3());
        }
        smallest_eigen3(m.covariance()).map(|(l, v)| (l[0], v))
    }

    /// Of `positions` (points of a plane with unit `normal`), the indices
    /// in it (ascending) of those not on another surface crossing it: a
    /// point is kept out of the answer when
    /// its voxel holds at least `min_points` live points (and 4), they lie
    /// on a plane of their own within `max_spread` (RMS, m), and that
    /// plane is more than [`CROSSING_ANGLE`] degrees off `normal`.
    /// Positions in voxel order (as [`PlanePool::best_plane`] gives them)
    /// judge each voxel once.
    pub(crate) fn off_crossing_surfaces(
        &self,
        positions: &[u32],
        normal: DVec3,
        min_points: usize,
        max_spread: f64,
    ) -> Vec<usize> {
        let max_var = max_spread * max_spread;
        let cos_max = CROSSING_ANGLE.to_radians().cos();
        let mut last: Option<(u32, bool)> = None;
        let mut out = Vec::with_capacity(positions.len());
        for (i, &pos) in positions.iter().enumerate() {
            let c = self.cell_of[pos as usize];
            let crossing = match last {
                Some((lc, v)) if lc == c => v,
                _ => {
                    let c = c as usize;
                    let v = self.cell_live[c] as usize >= min_points.max(4)
                        && self.voxel_plane(c).is_some_and(|(var, n)| {
                            var <= max_var && n.dot(normal).abs() < cos_max
                        });
                    last = Some((c as u32, v));
                    v
                }
            };
            if !crossing {
                out.push(i);
            }
        }
        out
    }

    /// Take `positions` (points of `plane` that explain nothing: a
    /// rejected candidate, or inliers without a patch large enough) out of
    /// play, except those on another surface the plane crosses
    /// ([`PlanePool::off_crossing_surfaces`]). When any stay, the plane is
    /// set aside: no later hypothesis (nor a refit) within
    /// [`SET_ASIDE_ANGLE`] degrees of it and within its inlier distance is
    /// tried, so the bands it spared cannot bring it back round after
    /// round. Returns how many left play.
    pub(crate) fn set_aside(
        &mut self,
        positions: &[u32],
        plane: &LocalPlane,
        min_points: usize,
        max_spread: f64,
    ) -> usize {
        let doomed: Vec<u32> = self
            .off_crossing_surfaces(positions, plane.normal, min_points, max_spread)
            .into_iter()
            .map(|i| positions[i])
            .collect();
        if doomed.len() < positions.len() {
            self.set_aside
                .push((plane.normal, plane.offset, plane.threshold));
        }
        let before = self.live;
        self.remove(&doomed);
        before - self.live
    }

    /// Is `plane` one set aside ([`PlanePool::set_aside`])?
    fn is_set_aside(&self, plane: &LocalPlane) -> bool {
        let cos_max = SET_ASIDE_ANGLE.to_radians().cos();
        self.set_aside.iter().any(|&(n, d, t)| {
            let c = n.dot(plane.normal);
            c.abs() > cos_max && (d - c.signum() * plane.offset).abs() < t
        })
    }

    /// The plane with the largest consensus among the remaining points, its
    /// inliers (positions, in voxel order) and their coordinates, or `None`
    /// when no plane has `min_inliers`.
    /// `viewpoint` is the sensor in local coordinates; `ground` tells which
    /// planes are counted with the ground distance (by the local floor
    /// where drawn, or below the viewpoint itself: `GroundRule::at_point`).
    pub(crate) fn best_plane(
        &mut self,
        params: &Params,
        min_support: usize,
        viewpoint: DVec3,
        ground: GroundRule,
    ) -> Option<(LocalPlane, Vec<u32>, Vec<Vec3>)> {
        if self.remaining() < min_support.max(3) {
            return None;
        }
        // A scoring subset of a big cloud thins out as planes leave; draw a
        // fresh one from the live points once it holds under a quarter of
        // what it could.
        if 4 * self.pool_live < self.live.min(POOL_CAP) {
            self.refill();
        }
        if self.ridx.is_empty() {
            return None;
        }
        // Prefixes run over the pool arrays, dead (NaN) entries included.
        let n = self.ridx.len();
        let tilt_cos = libm::cos(params.ground_max_tilt.to_radians());
        let plane_for = |normal: DVec3, offset: f64, at: DVec3| {
            let ground = ground.at_point(
                &Plane { normal, offset },
                viewpoint,
                at,
                tilt_cos,
                params.ground_depth,
            );
            LocalPlane {
                normal,
                offset,
                threshold: params.surface(ground).distance,
                ground,
            }
        };
        let mut k = n.min(START_K);
        let (best, best_at) = loop {
            let mut best: Option<(LocalPlane, f64, DVec3)> = None;
            let budget = self.hypothesis_budget(params);
            let mut needed = budget;
            let (mut t, mut attempts) = (0, 0);
            while t < needed.min(budget) && attempts < 4 * budget {
                attempts += 1;
                let Some((normal, offset, cell)) = self.sample() else {
                    continue;
                };
                let at = self.cell_box[cell].0;
                let plane = plane_for(normal, offset, at);
                if self.seen_edge_on(&plane, viewpoint, params) || self.is_set_aside(&plane) {
                    continue;
                }
                // Cheap local test: the plane must explain a fair share of
                // its own voxel, or the sample mixed surfaces / hit clutter.
                if !self.locally_planar(&plane, cell) {
                    continue;
                }
                t += 1;
                self.scored += 1;
                let score = self.score_prefix(&plane, k, best.map_or(0.0, |b| b.1));
                if best.is_none_or(|b| score > b.1) {
                    best = Some((plane, score, at));
                    let w = score / k as f64;
                    needed = hypotheses_needed(w * 0.5, params.confidence);
                }
            }
            let best = best?;
            if best.1 < MIN_RANKABLE as f64 && k < n {
                k = n.min(k * 4);
                continue;
            }
            break (best.0, best.2);
        };
        // Local optimisation on a random subsample (a prefix of the shuffled
        // pool: at most LO_SAMPLE points), then one count on all points with
        // the refined plane.
        let lo_k = n.min(LO_SAMPLE);
        let sample = self.collect_prefix(&best, lo_k);
        let mut plane = best;
        if sample.len() >= 3 {
            if let Some((normal, offset)) = self.refit(&sample) {
                let refit = plane_for(normal, offset, best_at);
                // Keep the refit when it scores at least as well on the
                // subsample, both scored with the hypothesis's threshold.
                self.work += 2 * lo_k as u64;
                let same_t = LocalPlane {
                    threshold: best.threshold,
                    ..refit
                };
                if !self.seen_edge_on(&refit, viewpoint, params)
                    && !self.is_set_aside(&refit)
                    && self.count(&same_t, 0, lo_k) >= self.count(&best, 0, lo_k)
                {
                    plane = refit;
                }
            }
        }
        let (inliers, coords) = self.collect(&plane);
        if inliers.len() < min_support.max(3) {
            return None;
        }
        Some((plane, inliers, coords))
    }

    /// Does `plane` pass through the viewpoint (within two inlier
    /// distances) without the sensor standing on it? Every ray to such a
    /// plane grazes it: what lies on it is the laser rings of the beams at
    /// the sensor's own elevation, across every surface around. As a
    /// candidate it would be rejected (`seen_edge_on` in the cascade), and
    /// the band it cut out of each facade, pole and car would leave play
    /// with it, once per round, a little tilted each time; so such planes
    /// are never hypotheses, and their points stay for the surfaces they
    /// belong to. The sensor stands on the plane when [`NEAR_SUPPORT`] of its
    /// live inliers lie within [`NEAR_VIEWPOINT`] of the viewpoint: a floor
    /// under a low sensor is a plane like any other.
    fn seen_edge_on(&mut self, plane: &LocalPlane, viewpoint: DVec3, params: &Params) -> bool {
        let Some(near) = &mut self.near else {
            return false;
        };
        if !crate::primitive::through_viewpoint(plane.normal.dot(viewpoint) + plane.offset, params)
        {
            return false;
        }
        // The near points on the plane (the vector kernel, the same test
        // as everywhere), then how many of them are still in play.
        near.hits.clear();
        let pts = kernels::Points::new(&near.xs, &near.ys, &near.zs);
        kernels::inliers(
            pts,
            plane.as_f32(),
            plane.threshold as f32,
            0,
            &mut near.hits,
        );
        let on = near
            .hits
            .iter()
            .filter(|&&k| self.alive[near.positions[k as usize] as usize])
            .take(NEAR_SUPPORT)
            .count();
        on < NEAR_SUPPORT
    }

    /// Do at least 30 % of the live points of voxel `cell` lie on `plane`?
    /// Judged on at most 64 of its members (an even stride): near the sensor
    /// a voxel holds thousands of points, and an estimate is all this needs.
    fn locally_planar(&mut self, plane: &LocalPlane, cell: usize) -> bool {
        let members = self.grid.members.range(cell);
        let len = members.len();
        let step = len.div_ceil(64).max(1);
        let (n, d, t) = (
            plane.normal.as_vec3(),
            plane.offset as f32,
            plane.threshold as f32,
        );
        let (mut live, mut on) = (0u32, 0u32);
        for j in members.step_by(step) {
            if self.alive[j] {
                live += 1;
                on += ((n.dot(self.cell_pts[j]) + d).abs() < t) as u32;
            }
        }
        self.work += (len / step) as u64;
        10 * on >= 3 * live
    }

    /// One hypothesis from a local triple, with the voxel it came from;
    /// `None` when degenerate.
    fn sample(&mut self) -> Option<(DVec3, f64, usize)> {
        let n = self.ridx.len();
        if n == 0 {
            return None;
        }
        let mut i1 = self.ridx[self.rng.below(n)];
        for _ in 0..8 {
            if self.alive[i1 as usize] {
                break;
            }
            i1 = self.ridx[self.rng.below(n)];
        }
        if !self.alive[i1 as usize] {
            return None;
        }
        let c = self.cell_of[i1 as usize] as usize;
        let members = self.grid.members.range(c);
        // The other two points: a few draws from the first one's voxel,
        // then the first live one there from a random place on
        // (`local_triples`), or any point of the cloud.
        let local_only = self.local_only;
        let pick = |rng: &mut Rng, not: &[u32]| -> Option<u32> {
            for _ in 0..6 {
                let j = (members.start + rng.below(members.len())) as u32;
                if self.alive[j as usize] && !not.contains(&j) {
                    return Some(j);
                }
            }
            if local_only {
                let start = rng.below(members.len());
                return (0..members.len())
                    .map(|k| (members.start + (start + k) % members.len()) as u32)
                    .find(|&j| self.alive[j as usize] && !not.contains(&j));
            }
            let j = self.ridx[rng.below(n)];
            Some(if self.alive[j as usize] { j } else { i1 })
        };
        let i2 = pick(&mut self.rng, &[i1])?;
        let i3 = pick(&mut self.rng, &[i1, i2])?;
        let (p1, p2, p3) = (
            self.cell_pts[i1 as usize].as_dvec3(),
            self.cell_pts[i2 as usize].as_dvec3(),
            self.cell_pts[i3 as usize].as_dvec3(),
        );
        let (nrm, offset) = plane_through(p1, p2, p3, self.min_fatness)?;
        Some((nrm, offset, c))
    }

    /// The scoring pool's coordinates, in pool order.
    fn pool_points(&self) -> kernels::Points<'_> {
        kernels::Points::new(&self.rx, &self.ry, &self.rz)
    }

    /// MSAC score of `plane` over pool entries `lo..hi`: each point within
    /// the threshold counts `1 - (d/t)^2`, others (and dead entries) 0. A
    /// soft inlier count: a plane through the middle of a surface scores
    /// close to its inlier count, one tilted across two surfaces far less.
    /// ([`kernels::msac_sum`]: the same bits on every target.)
    fn count(&self, plane: &LocalPlane, lo: usize, hi: usize) -> f64 {
        let inv = (1.0 / plane.threshold) as f32;
        kernels::msac_sum(self.pool_points().slice(lo..hi), plane.as_f32(), inv)
    }

    /// MSAC score of `plane` over the first `k` pool entries, or an
    /// estimate below `best` once it cannot be the best: scored on the
    /// first eighth, dropped below half the best's pro-rata score there,
    /// then at each further quarter dropped below `LATE_SHARE` of it.
    fn score_prefix(&mut self, plane: &LocalPlane, k: usize, best: f64) -> f64 {
        let head = k / 8;
        let mut c = self.count(plane, 0, head);
        if best > 0.0 && head > 0 && c * 16.0 < best {
            self.work += head as u64;
            return c * 8.0;
        }
        let mut at = head;
        for quarter in 1..4 {
            let next = k * quarter / 4;
            if next <= at {
                continue;
            }
            c += self.count(plane, at, next);
            at = next;
            let pro_rata = c * (k as f64 / at as f64);
            if best > 0.0 && pro_rata < LATE_SHARE * best {
                self.work += at as u64;
                return pro_rata;
            }
        }
        self.work += k as u64;
        c + self.count(plane, at, k)
    }

    /// Pool positions of the inliers of `plane` among the first `k` points.
    fn collect_prefix(&mut self, plane: &LocalPlane, k: usize) -> Vec<u32> {
        self.work += k as u64;
        self.inliers_in(plane, k)
    }

    /// All inliers of `plane` (positions, in voxel order) and their
    /// coordinates (read here in voxel order anyway; gathering them again
    /// by index afterwards costs a cache miss a point). Only the
    /// voxels whose point box reaches within the threshold of the plane are
    /// read: a plane's slab crosses a small share of a street's voxels, so
    /// this costs far less than a pass over every remaining point.
    fn collect(&mut self, plane: &LocalPlane) -> (Vec<u32>, Vec<Vec3>) {
        let (nx, ny, nz) = (
            plane.normal.x as f32,
            plane.normal.y as f32,
            plane.normal.z as f32,
        );
        let (d, t) = (plane.offset as f32, plane.threshold as f32);
        let an = plane.normal.abs();
        let (mut out, mut coords) = (Vec::new(), Vec::new());
        for (c, &(centre, half, slack)) in self.cell_box.iter().enumerate() {
            if self.cell_live[c] == 0 {
                continue;
            }
            self.work += 1;
            // Distance from the centre, less the box's reach along the
            // normal, with a margin for the f32 point test below (a
            // millionth of the centre's largest coordinate, kept per voxel
            // rather than taken with two `max` per voxel and round).
            let reach = an.dot(half) + plane.threshold + 1e-3 + slack;
            if (plane.normal.dot(centre) + plane.offset).abs() > reach {
                continue;
            }
            let range = self.grid.members.range(c);
            let lo = range.start;
            self.work += range.len() as u64;
            for (k, p) in self.cell_pts[range].iter().enumerate() {
                let v = nx * p.x + ny * p.y + nz * p.z + d;
                if v.abs() < t {
                    out.push((lo + k) as u32);
                    coords.push(*p);
                }
            }
        }
        (out, coords)
    }

    /// Pool positions of the inliers of `plane` among the first `k` pool
    /// entries ([`kernels::inliers`]: 64 tests into a bit mask, then the set
    /// bits; inliers are a minority, so most masks are sparse or empty).
    fn inliers_in(&self, plane: &LocalPlane, k: usize) -> Vec<u32> {
        let mut out = Vec::new();
        let (pts, t) = (self.pool_points().slice(0..k), plane.threshold as f32);
        kernels::inliers(pts, plane.as_f32(), t, 0, &mut out);
        out
    }

    /// Robust least-squares plane ([`robust_fit`]) of the points at these
    /// pool positions: a tilted hypothesis that caught a road and the edge
    /// of its sidewalk converges to the road, the majority.
    fn refit(&self, positions: &[u32]) -> Option<(DVec3, f64)> {
        let pts: Vec<DVec3> = positions
            .iter()
            .map(|&p| {
                let p = p as usize;
                DVec3::new(self.rx[p] as f64, self.ry[p] as f64, self.rz[p] as f64)
            })
            .collect();
        let fit = robust_fit(&pts, *pts.first()?)?;
        Some((fit.plane.normal, fit.plane.offset))
    }
}

/// The points within [`NEAR_VIEWPOINT`] of the viewpoint (at most
/// [`NEAR_CAP`]): their positions and coordinates, one array per axis.
struct Near {
    positions: Vec<u32>,
    xs: Vec<f32>,
    ys: Vec<f32>,
    zs: Vec<f32>,
    /// Scratch: indices of those on a plane.
    hits: Vec<u32>,
}

/// Keep a uniform random subset of at most `m` of `order`, in random order
/// (the first steps of a Fisher-Yates shuffle).
fn random_prefix(order: &mut Vec<u32>, m: usize, rng: &mut Rng) {
    let n = order.len();
    let m = n.min(m);
    for i in 0..m {
        let j = i + rng.below(n - i);
        order.swap(i, j);
    }
    order.truncate(m);
}

/// Hypotheses needed so that an all-inlier sample (probability `p` each) was
/// drawn with probability `confidence`.
fn hypotheses_needed(p: f64, confidence: f64) -> usize {
    if p <= 0.0 {
        return usize::MAX;
    }
    if p >= 1.0 {
        return MIN_HYPOTHESES;
    }
    let t = libm::log(1.0 - confidence) / libm::log(1.0 - p);
    (libm::ceil(t) as usize).max(MIN_HYPOTHESES)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10 x 9.4 m floor (z = 0, 6000 points) and 4000 points scattered
    /// through a 10 m cube above it.
    fn pool() -> PlanePool {
        let mut rng = Rng::new(3);
        let mut pts = Vec::new();
        for i in 0..6000 {
            let (x, y) = ((i % 80) as f32 * 0.125, (i / 80) as f32 * 0.125);
            pts.push(Vec3::new(x, y, 0.0));
        }
        pts.extend(scattered(&mut rng, 4000));
        PlanePool::new(&pts, 1.0, None, Rng::new(9))
    }

    /// `n` points scattered uniformly through the cube [0, 10 m]^3.
    fn scattered(rng: &mut Rng, n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|_| {
                Vec3::new(
                    rng.range(0.0, 10.0) as f32,
                    rng.range(0.0, 10.0) as f32,
                    rng.range(0.0, 10.0) as f32,
                )
            })
            .collect()
    }

    /// Hypotheses drawn from a thin band of a wall (4 m long, 0.2 m high,
    /// 1 cm of noise across it): three points nearly in a line along the
    /// band fix that line, not the plane, and such samples come out tilted
    /// at random, often far from the wall. Without slivers they are the
    /// wall.
    #[test]
    fn samples_without_slivers_on_a_thin_band_are_the_wall() {
        let mut rng = Rng::new(4);
        let pts: Vec<Vec3> = (0..4000)
            .map(|_| {
                Vec3::new(
                    rng.range(0.0, 4.0) as f32,
                    (0.01 * rng.gaussian()) as f32,
                    rng.range(0.0, 0.2) as f32,
                )
            })
            .collect();
        let wall_share = |reject: bool| {
            let mut pool = PlanePool::new(&pts, 1.0, None, Rng::new(5));
            if reject {
                pool = pool.reject_slivers();
            }
            let (mut wall, mut all) = (0usize, 0usize);
            for _ in 0..4000 {
                if let Some((n, _, _)) = pool.sample() {
                    all += 1;
                    // Within about 25 degrees of the wall's normal.
                    wall += (n.y.abs() > 0.9) as usize;
                }
            }
            (wall as f64 / all.max(1) as f64, all)
        };
        // Deterministic (fixed seeds): 13.5 % of the plain samples are
        // tilted more than about 25 degrees off the wall, 1.6 % without
        // slivers.
        let (plain, plain_n) = wall_share(false);
        let (fat, fat_n) = wall_share(true);
        assert!(
            1.0 - fat < 0.03,
            "without slivers: {fat} of {fat_n} on the wall"
        );
        assert!(
            1.0 - plain > 0.1,
            "with slivers: {plain} of {plain_n} on the wall"
        );
        assert!(fat_n > 1000, "{fat_n} samples drawn");
    }

    /// Of a horizontal plane's inliers, the band of a wall it crosses is
    /// spared; clutter in its slab and a flat patch of the plane itself (a
    /// table top) are not, nor a wall voxel with too few points to judge.
    #[test]
    fn only_the_bands_of_crossing_surfaces_are_spared() {
        let mut rng = Rng::new(11);
        let mut pts = Vec::new();
        // A wall: x in [0, 4] m, y = 0 (5 mm noise), z in [0, 3] m, a point
        // every 0.1 m.
        for i in 0..40 {
            for k in 0..30 {
                let y = (0.005 * rng.gaussian()) as f32;
                pts.push(Vec3::new(i as f32 * 0.1 + 0.05, y, k as f32 * 0.1 + 0.05));
            }
        }
        let wall = pts.len();
        // A table top in the plane z = 1.5: x in [6, 8], y in [0, 2].
        for i in 0..20 {
            for j in 0..20 {
                pts.push(Vec3::new(6.05 + i as f32 * 0.1, 0.05 + j as f32 * 0.1, 1.5));
            }
        }
        let top = pts.len();
        // Clutter through the slab 1.4 < z < 1.6 over x in [10, 14].
        for _ in 0..1500 {
            let (x, y, z) = (
                rng.range(10.0, 14.0),
                rng.range(0.0, 4.0),
                rng.range(1.4, 1.6),
            );
            pts.push(Vec3::new(x as f32, y as f32, z as f32));
        }
        let clutter = pts.len();
        // Six points of a far wall (x = 20): too few in their voxel.
        for k in 0..6 {
            pts.push(Vec3::new(
                20.0,
                0.5 + 0.1 * k as f32,
                1.45 + 0.02 * k as f32,
            ));
        }
        let pool = PlanePool::new(&pts, 1.0, None, Rng::new(12));
        let mut inliers: Vec<u32> = (0..pts.len())
            .filter(|&i| (pts[i].z - 1.5).abs() < 0.1)
            .map(|i| pool.cell_pos_of[i])
            .collect();
        inliers.sort_unstable();
        let doomed: Vec<usize> = pool
            .off_crossing_surfaces(&inliers, DVec3::Z, 8, 0.02)
            .iter()
            .map(|&i| pool.original(inliers[i]) as usize)
            .collect();
        let count = |r: std::ops::Range<usize>| doomed.iter().filter(|&&i| r.contains(&i)).count();
        let in_slab =
            |r: std::ops::Range<usize>| r.filter(|&i| (pts[i].z - 1.5).abs() < 0.1).count();
        assert!(in_slab(0..wall) >= 80);
        assert_eq!(count(0..wall), 0, "wall points taken");
        assert_eq!(count(wall..top), in_slab(wall..top), "table top spared");
        assert_eq!(count(top..clutter), in_slab(top..clutter), "clutter spared");
        assert_eq!(
            count(clutter..pts.len()),
            6,
            "a voxel too sparse to judge is not spared"
        );
        // Setting the plane aside takes the others out of play and keeps
        // the plane (and any within 2 degrees and its inlier distance) from
        // being a hypothesis again; it sets nothing aside when nothing
        // was spared.
        let mut pool = pool;
        let plane = |n: DVec3, offset: f64| LocalPlane {
            normal: n.normalize(),
            offset,
            threshold: 0.1,
            ground: false,
        };
        let slab = plane(DVec3::Z, -1.5);
        let only_clutter: Vec<u32> = (top..clutter).map(|i| pool.cell_pos_of[i]).collect();
        assert_eq!(pool.set_aside(&only_clutter, &slab, 8, 0.02), clutter - top);
        assert!(!pool.is_set_aside(&slab));
        let left = pool.set_aside(&inliers, &slab, 8, 0.02);
        assert_eq!(left, in_slab(wall..top) + 6);
        assert!(pool.is_set_aside(&slab));
        assert!(pool.is_set_aside(&plane(DVec3::new(0.01, 0.0, 1.0), -1.45)));
        assert!(pool.is_set_aside(&plane(-DVec3::Z, 1.55)));
        assert!(!pool.is_set_aside(&plane(DVec3::Z, -1.7)));
        assert!(!pool.is_set_aside(&plane(DVec3::new(0.1, 0.0, 1.0), -1.5)));
        assert!(!pool.is_set_aside(&plane(DVec3::Y, 0.0)));
    }

    /// Points scattered through a 10 m cube hold no plane any sample could
    /// find well supported, so a round scores as many hypotheses as it may:
    /// `max_hypotheses` times the pool's scale, whichever sampler draws them.
    #[test]
    fn a_round_scores_at_most_its_hypothesis_budget() {
        let pts = scattered(&mut Rng::new(6), 20_000);
        let params = Params {
            min_inliers: 3,
            ..Params::gpp2()
        };
        for (reject, scale) in [(true, 1), (false, 2), (false, 1)] {
            let budget = scale * params.max_hypotheses;
            let mut pool = PlanePool::new(&pts, 1.0, None, Rng::new(7)).hypothesis_scale(scale);
            if reject {
                pool = pool.reject_slivers();
            }
            pool.best_plane(
                &params,
                params.min_inliers,
                DVec3::new(5.0, 5.0, 20.0),
                GroundRule::BelowViewpoint,
            );
            assert_eq!(pool.scored, budget as u64, "slivers redrawn: {reject}");
        }
    }

    fn plane(normal: DVec3, offset: f64) -> LocalPlane {
        LocalPlane {
            normal: normal.normalize(),
            offset,
            threshold: 0.1,
            ground: false,
        }
    }

    #[test]
    fn early_rejection_drops_worse_planes_and_keeps_as_good_ones() {
        let mut pool = pool();
        let k = 4096;
        let floor = plane(DVec3::Z, 0.0);
        let full = pool.count(&floor, 0, k);
        assert!(full > 0.5 * k as f64, "floor score {full}");
        let scored = |pool: &mut PlanePool, p: &LocalPlane, best: f64| {
            let before = pool.work;
            let s = pool.score_prefix(p, k, best);
            (s, pool.work - before)
        };
        // The best itself is scored to the end (the same sum in f32 lanes,
        // added up in other pieces: equal to ~1e-7).
        let (s, spent) = scored(&mut pool, &floor, full);
        assert!((s - full).abs() < 1e-5 * full, "{s} vs {full}");
        assert_eq!(spent, k as u64);
        // A plane 0.3 m above the floor holds only clutter: dropped after
        // the first eighth.
        let (s, spent) = scored(&mut pool, &plane(DVec3::Z, -0.3), full);
        assert!(s < 0.1 * full);
        assert_eq!(spent, (k / 8) as u64);
        // Against a best 1.6 times better, the floor keeps 62 % of its
        // pro-rata score: past the first eighth (50 %), dropped at the first
        // quarter (70 %).
        let (s, spent) = scored(&mut pool, &floor, 1.6 * full);
        assert!(s < 1.6 * full);
        assert_eq!(spent, (k / 4) as u64);
        // Against a best 1.3 times better (77 %) it is scored to the end.
        let (s, spent) = scored(&mut pool, &floor, 1.3 * full);
        assert!((s - full).abs() < 1e-5 * full);
        assert_eq!(spent, k as u64);
    }
}
