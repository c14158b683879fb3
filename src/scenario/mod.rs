//! The incremental scenario: scans arrive one at a time and update a live
//! list of primitives (the paper's Algorithm 2, plus merging).
//!
//! Per scan: transform to the world frame (f64, around a local origin),
//! align it to the map (`align.rs`), expand every existing primitive in a
//! cascade, detect new primitives on what is left, merge primitives that
//! grew into each other, report.

mod align;
mod expand;
mod index;
mod pool;
pub mod snapshot;
mod surfaces;
pub use crate::merge::MergeEvent;

use crate::clock;
use crate::cloud::Cloud;
use crate::detect::{CascadePolicy, Detector, NO_PRIMITIVE};
use crate::error::{Error, Result};
use crate::params::Params;
use crate::primindex::PrimIndex;
use crate::primitive::Primitive;
use crate::rng::Rng;
use glam::{DMat4, DVec3};
use index::ScanIndex;
use pool::Pool;
use serde::{Deserialize, Serialize};
use surfaces::Surfaces;

/// Longest snapshot text [`Scenario::from_json`] reads (bytes; 256 MiB):
/// restoring one takes a few times its size in memory, which must fit in
/// the 4 GiB of a wasm instance.
pub const MAX_SNAPSHOT_BYTES: usize = 1 << 28;

/// Voxel side of the per-scan index (m).
const INDEX_VOXEL: f64 = 1.0;

/// Time per stage of one scan (ms).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StageTimes {
    /// Aligning the scan to the map.
    #[serde(default)]
    pub alignment: f64,
    /// Expanding existing primitives.
    pub expansion: f64,
    /// Detecting new ones on the leftover points.
    pub detection: f64,
    /// Merging.
    pub merge: f64,
    /// The whole update, transform included.
    pub total: f64,
}

/// How a scan was aligned to the map before expansion (`alignScans`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Alignment {
    /// Point-to-polygon pairs of the fit's last iteration; 0 when the scan
    /// was not aligned (the first scan, `alignScans` or `expansion` off, no
    /// known polygon in view).
    pub pairs: usize,
    /// How many of the pose's six directions (three turns, three shifts)
    /// the pairs pinned down; along the others the scan kept the last
    /// scan's correction.
    pub constrained: usize,
    /// Whether this scan's fit changed the correction (fewer than 100
    /// pairs of its 2048 sampled points, a step beyond `alignReach`, or one that moves no point within
    /// 50 m of the sensor by more than 3 cm, change nothing).
    pub applied: bool,
    /// How far this scan's fit moved the sensor (m).
    pub shift: f64,
    /// How far it turned the scan (deg).
    pub turn: f64,
    /// The correction the scan's world points were moved by (the last
    /// scan's, refined by this scan's fit): a rigid 4 x 4 transform,
    /// column-major like the poses; the scan's corrected pose is this
    /// times the pose given. The identity while poses need no correction.
    pub correction: [f64; 16],
}

impl Default for Alignment {
    fn default() -> Self {
        Alignment {
            pairs: 0,
            constrained: 0,
            applied: false,
            shift: 0.0,
            turn: 0.0,
            correction: DMat4::IDENTITY.to_cols_array(),
        }
    }
}

/// What one scan did to the scenario.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct ScanReport {
    /// Scan number (0 for the first).
    pub scan: u64,
    /// Points in the scan.
    pub points: usize,
    /// How the scan was aligned to the map before expansion.
    pub alignment: Alignment,
    /// Points taken by the expansion of existing primitives.
    pub explained_by_expansion: usize,
    /// Points given to detection (the rest).
    pub sent_to_detection: usize,
    /// Of those, points taken by the primitives detection added (the others
    /// stay unexplained: clutter, vegetation, too-small surfaces).
    pub explained_by_detection: usize,
    /// Points of the pool (earlier scans' unexplained points, one a voxel)
    /// that detection saw beside this scan's.
    pub pool_to_detection: usize,
    /// Pool points explained this scan (taken by expansion or by a new
    /// primitive).
    pub explained_from_pool: usize,
    /// Points in the pool after the scan.
    pub pool_points: usize,
    /// Ids of new primitives.
    pub added: Vec<u32>,
    /// Ids of existing primitives that grew.
    pub grown: Vec<u32>,
    /// Merges made.
    pub merged: Vec<MergeEvent>,
    /// Primitives after the scan.
    pub polygon_count: usize,
    /// Total outline area after the scan (m^2).
    pub total_area: f64,
    /// Time per stage (ms).
    pub time_ms: StageTimes,
}

/// The live scenario. Holds parameters, primitives (sorted by id) and
/// counters; its size grows with the mapped area, not with the number of
/// scans (primitives keep running moments and a footprint raster, never
/// their points).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Scenario {
    params: Params,
    primitives: Vec<Primitive>,
    next_id: u32,
    scans: u64,
    /// Unexplained points of the last scans (`poolScans`), world frame.
    #[serde(default)]
    pool: Pool,
    /// The correction of the last scan's pose found by aligning it to the
    /// map (`alignScans`): world from the frame the poses give.
    #[serde(default)]
    correction: DMat4,
    #[serde(skip)]
    last_labels: Vec<u32>,
    /// Where the primitives are (derived, rebuilt after a restore).
    #[serde(skip)]
    index: PrimIndex,
    /// The grown masks of the last scan's expansion (derived).
    #[serde(skip)]
    masks: expand::Masks,
}

impl Scenario {
    /// An empty scenario. Errors on invalid parameters, and on a
    /// `viewpoint`: each scan's sensor position comes from its pose.
    pub fn new(params: Params) -> Result<Self> {
        check_params(&params)?;
        Ok(Scenario {
            params,
            primitives: Vec::new(),
            next_id: 0,
            scans: 0,
            pool: Pool::default(),
            correction: DMat4::IDENTITY,
            last_labels: Vec::new(),
            index: PrimIndex::default(),
            masks: expand::Masks::default(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The primitives, sorted by id.
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }

    /// Scans processed so far.
    pub fn scans(&self) -> u64 {
        self.scans
    }

    /// The correction the last scan was moved by, in the world frame (see
    /// [`Alignment::correction`]); the identity before any.
    pub fn correction(&self) -> DMat4 {
        self.correction
    }

    /// Per point of the last scan: the id of the primitive that explained it
    /// (by expansion or detection; after merges, the surviving id), or
    /// [`NO_PRIMITIVE`].
    pub fn last_labels(&self) -> &[u32] {
        &self.last_labels
    }

    /// Add a scan: `points` interleaved with `stride` 3 or 4 in the sensor
    /// frame, `pose` the world-from-sensor rigid transform (refined against
    /// the map with `alignScans`: see [`Alignment`]). Float32 points
    /// must lie within [`MAX_F32_COORDINATE`](crate::cloud::MAX_F32_COORDINATE)
    /// of the sensor; points in map coordinates go through
    /// [`Scenario::add_scan_f64`].
    pub fn add_scan(&mut self, points: &[f32], stride: usize, pose: &DMat4) -> Result<ScanReport> {
        let t0 = clock::now_ms();
        let cloud = Cloud::from_sensor(points, stride, pose)?;
        let sensor = pose.w_axis.truncate();
        Ok(self.add_cloud(&cloud, sensor, t0))
    }

    /// [`Scenario::add_scan`] for float64 points: every step up to the
    /// per-scan origin in f64, so points already in map coordinates (with
    /// the identity pose) keep their precision
    /// ([`Cloud::from_sensor_f64`]).
    pub fn add_scan_f64(
        &mut self,
        points: &[f64],
        stride: usize,
        pose: &DMat4,
    ) -> Result<ScanReport> {
        let t0 = clock::now_ms();
        let cloud = Cloud::from_sensor_f64(points, stride, pose)?;
        let sensor = pose.w_axis.truncate();
        Ok(self.add_cloud(&cloud, sensor, t0))
    }

    /// Add a scan already in the world frame (`cloud`), seen from `sensor`
    /// (world position, used to orient new normals). `t0` is the clock
    /// reading the total time counts from. With `alignScans` the scan is
    /// first moved by the correction its alignment to the map finds
    /// ([`Alignment`]).
    pub fn add_cloud(&mut self, scan_cloud: &Cloud, sensor: DVec3, t0: f64) -> ScanReport {
        let scan = self.scans;
        let n = scan_cloud.len();
        // 0. Alignment to the map: the scan moves by the correction.
        let ta = clock::now_ms();
        let (moved, sensor, alignment) = self.align(scan_cloud, sensor);
        let scan_cloud = moved.as_ref().unwrap_or(scan_cloud);
        let align_ms = clock::now_ms() - ta;
        let p = &self.params;
        // The scan's points, then the pool's: expansion and detection see
        // both, the report and the labels count the scan's.
        // An empty scan brings no evidence: it changes nothing (the pool's
        // points only grow older).
        let joined = if n > 0 {
            self.pool.join(scan_cloud)
        } else {
            None
        };
        let cloud = joined.as_ref().unwrap_or(scan_cloud);
        let all = cloud.len();
        let mut labels = vec![NO_PRIMITIVE; all];
        let mut alive = vec![true; all];
        let mut report = ScanReport {
            scan,
            points: n,
            alignment,
            ..ScanReport::default()
        };
        report.time_ms.alignment = align_ms;

        // 1. Expansion of existing primitives, in a cascade (id order).
        let te = clock::now_ms();
        // The primitives a point of this scan (or of the pool) could reach.
        let mut near: Vec<u32> = Vec::new();
        if p.expansion {
            self.index.ensure(&self.primitives, p);
        }
        if p.expansion && !self.primitives.is_empty() && all > 0 {
            let mut index = ScanIndex::new(&cloud.points, INDEX_VOXEL);
            let mut scratch = expand::Scratch::new(std::mem::take(&mut self.masks));
            // Only the primitives a point of this scan could reach (exact:
            // see `primindex`), in id order.
            let (voxels, side) = index.voxels();
            near = self.index.near_voxels(cloud.origin, voxels, side);
            for &id in &near {
                let Ok(k) = self.primitives.binary_search_by_key(&id, |q| q.id) else {
                    continue;
                };
                let prim = &mut self.primitives[k];
                let stamp = k as u32 + 1;
                let taken = expand::expand(
                    &mut scratch,
                    prim,
                    cloud,
                    &mut index,
                    stamp,
                    &mut alive,
                    &mut labels,
                    p,
                    scan,
                );
                if taken > 0 {
                    self.index.update(prim);
                    report.grown.push(prim.id);
                }
            }
            self.masks = scratch.into_masks();
            report.explained_by_expansion = alive[..n].iter().filter(|&&a| !a).count();
        }
        report.time_ms.expansion = clock::now_ms() - te;

        // 2. Detection on the leftover points.
        let td = clock::now_ms();
        let selection = self.pool.select(cloud, n, &alive, p);
        let empty = n == 0;
        let rest = &selection.rest;
        report.sent_to_detection = selection.from_scan;
        report.pool_to_detection = rest.len() - selection.from_scan;
        let pts: Vec<glam::Vec3> = rest.iter().map(|&i| cloud.points[i as usize]).collect();
        let mut policy = CascadePolicy::scenario_leftovers();
        if report.pool_to_detection > 0 {
            policy = policy.pooled();
        }
        // The paper's mode without expansion keeps the paper's cascade.
        if p.expansion && self.primitives.is_empty() {
            policy = policy.on_empty_map();
        }
        let det = Detector::new(p, policy).run_with_rng(
            &pts,
            cloud.origin,
            sensor,
            Rng::derive(p.seed, scan),
        );
        for mut prim in det.primitives {
            let local = prim.id;
            prim.id = self.next_id;
            self.next_id += 1;
            prim.born_scan = scan;
            prim.last_scan = scan;
            for (k, &l) in det.labels.iter().enumerate() {
                if l == local {
                    let i = rest[k] as usize;
                    labels[i] = prim.id;
                    alive[i] = false;
                    report.explained_by_detection += usize::from(i < n);
                }
            }
            report.added.push(prim.id);
            self.index.update(&prim);
            self.primitives.push(prim);
        }
        // 2b. Risers (curbs, steps) between the near-horizontal primitives
        //     this scan reached, as one-shot detection finds them, from the
        //     scan's and the pool's points; the pool holds the pieces too
        //     small to keep.
        near.extend_from_slice(&report.added);
        let held = if self.params.expansion && !empty {
            self.add_risers(
                cloud,
                n,
                &near,
                sensor,
                &mut labels,
                &mut alive,
                &mut report,
            )
        } else {
            Vec::new()
        };
        let p = &self.params;
        report.explained_from_pool = alive[n..].iter().filter(|&&a| !a).count();
        if !empty {
            let seen = Surfaces::new(&self.primitives, &near, |q| surfaces::seen_slack(q, p));
            self.pool
                .carry(cloud, n, &alive, &selection, &held, scan, p, &|w| {
                    seen.holds(w, p)
                });
        }
        report.pool_points = self.pool.len();
        labels.truncate(n);
        report.time_ms.detection = clock::now_ms() - td;

        // 3. Merge primitives that now touch (never in the paper's mode
        //    without expansion, which appends).
        let tm = clock::now_ms();
        if p.expansion {
            let mut changed = report.grown.clone();
            changed.extend_from_slice(&report.added);
            report.merged =
                crate::merge::stats::merge_all(&mut self.primitives, &changed, p, &mut self.index);
            for ev in &report.merged {
                for l in labels.iter_mut().filter(|l| **l == ev.removed) {
                    *l = ev.kept;
                }
                report.grown.retain(|&g| g != ev.removed);
                report.added.retain(|&a| a != ev.removed);
            }
        }
        report.time_ms.merge = clock::now_ms() - tm;

        self.scans += 1;
        report.polygon_count = self.primitives.len();
        report.total_area = self.primitives.iter().map(|q| q.area).sum();
        report.time_ms.total = clock::now_ms() - t0;
        self.last_labels = labels;
        report
    }

    /// Step 2b of [`Scenario::add_cloud`]: the risers between the
    /// near-horizontal primitives among `near` (ids), from the points of
    /// `cloud` (the scan's first `n`, then the pool's), which they take
    /// from the primitive they were labelled with. A riser of `minArea`
    /// becomes a new primitive (the merge then joins it to one an earlier
    /// scan found there); a smaller piece grows the primitive it
    /// continues, or its points are returned (indices into `cloud`), for
    /// the pool to hold: a curb's face lies within the expansion gates of
    /// the road and the sidewalk, so the pool would not keep it, and a
    /// curb seen a few metres at a time between parked cars adds up only
    /// there.
    #[allow(clippy::too_many_arguments)]
    fn add_risers(
        &mut self,
        cloud: &Cloud,
        n: usize,
        near: &[u32],
        sensor: DVec3,
        labels: &mut [u32],
        alive: &mut [bool],
        report: &mut ScanReport,
    ) -> Vec<u32> {
        let (p, scan) = (&self.params, self.scans);
        let index_of =
            |prims: &[Primitive], id: u32| prims.binary_search_by_key(&id, |q| q.id).ok();
        let mut bound = vec![false; self.primitives.len()];
        for &id in near {
            if let Some(k) = index_of(&self.primitives, id) {
                bound[k] = true;
            }
        }
        let prims = &self.primitives;
        let slot = |l: u32| index_of(prims, l);
        let found = crate::detect::riser::find_risers(
            prims,
            &bound,
            &slot,
            labels,
            &cloud.points,
            cloud.origin,
            sensor,
            p,
            0.0,
            Some(sensor.truncate()),
        );
        // Those large enough first, each a new primitive; then the pieces
        // too small to stand alone (a scan sees a few metres of a curb),
        // each taken into the primitive it continues (`merge::mergeable`:
        // a riser in view or one just added) at once, or held in the pool.
        // A small piece never stands alone, not even until the merge step:
        // there it could miss the primitive it continued (merged into
        // another first) and stay, a few centimetres wide.
        let (large, small): (Vec<_>, Vec<_>) =
            found.into_iter().partition(|(r, _)| r.area >= p.min_area);
        let mut ids: Vec<u32> = near.to_vec();
        let mut held = Vec::new();
        for (mut riser, points) in large.into_iter().chain(small) {
            // The slot of the primitive a small piece continues.
            let into = if riser.area < p.min_area {
                let continued = ids.iter().find_map(|&id| {
                    index_of(&self.primitives, id)
                        .filter(|&k| crate::merge::mergeable(&self.primitives[k], &riser, p))
                });
                let Some(k) = continued else {
                    held.extend_from_slice(&points);
                    continue;
                };
                Some(k)
            } else {
                None
            };
            riser.born_scan = scan;
            riser.last_scan = scan;
            let id = match into {
                Some(k) => self.primitives[k].id,
                None => {
                    riser.id = self.next_id;
                    self.next_id += 1;
                    riser.id
                }
            };
            for &i in &points {
                let i = i as usize;
                let old = std::mem::replace(&mut labels[i], id);
                match index_of(&self.primitives, old) {
                    Some(k) => {
                        let q = &mut self.primitives[k];
                        q.support = q.support.saturating_sub(1);
                    }
                    None => report.explained_by_detection += usize::from(i < n),
                }
                alive[i] = false;
            }
            match into {
                Some(k) => {
                    let q = &mut self.primitives[k];
                    crate::merge::stats::absorb(q, &riser, p);
                    self.index.update(q);
                    if !report.added.contains(&id) && !report.grown.contains(&id) {
                        report.grown.push(id);
                    }
                }
                None => {
                    report.added.push(id);
                    ids.push(id);
                    self.index.update(&riser);
                    self.primitives.push(riser);
                }
            }
        }
        held
    }

    /// Move `scan` (world frame, seen from `sensor`) by the last scan's
    /// correction, then align it to the polygons in view and keep the
    /// refined correction (`align.rs`). Returns the moved scan (`None`
    /// when the correction is the identity), the moved sensor and the
    /// report.
    fn align(&mut self, scan: &Cloud, sensor: DVec3) -> (Option<Cloud>, DVec3, Alignment) {
        let p = &self.params;
        let mut report = Alignment::default();
        if !(p.align_scans && p.expansion) {
            return (None, sensor, report);
        }
        report.correction = self.correction.to_cols_array();
        if scan.is_empty() {
            return (None, sensor, report);
        }
        if !self.primitives.is_empty() {
            self.index.ensure(&self.primitives, p);
            let fit = align::align(
                scan,
                sensor,
                &self.correction,
                &self.primitives,
                &self.index,
                p,
            );
            report.pairs = fit.pairs;
            report.constrained = fit.constrained;
            if fit.applied {
                report.applied = true;
                report.shift = fit.shift;
                report.turn = fit.turn.to_degrees();
                self.correction = fit.step * self.correction;
            }
        }
        let moved =
            (self.correction != DMat4::IDENTITY).then(|| scan.transformed(&self.correction));
        let at = self.correction.transform_point3(sensor);
        report.correction = self.correction.to_cols_array();
        (moved, at, report)
    }

    /// The whole state as JSON (parameters included). Restoring it with
    /// [`Scenario::from_json`] and continuing gives exactly the result of
    /// not stopping.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Restore from [`Scenario::to_json`] output. The text is refused
    /// (with a message) unless it is at most [`MAX_SNAPSHOT_BYTES`] long and
    /// describes a state the pipeline could have reached; see
    /// [`snapshot::check`] for what is checked.
    pub fn from_json(text: &str) -> Result<Self> {
        if text.len() > MAX_SNAPSHOT_BYTES {
            return Err(Error::Invalid(format!(
                "not a polyscene snapshot: its text has {} bytes, more than the \
                 {MAX_SNAPSHOT_BYTES} a snapshot may have",
                text.len()
            )));
        }
        serde_json::from_str::<Scenario>(text)
            .map_err(not_a_snapshot)?
            .checked()
    }

    /// [`Scenario::from_json`] for the snapshot already parsed into a JSON
    /// value, with the same checks. The JS binding restores this way:
    /// `JSON.parse` reads the text, so the wasm carries no JSON parser, and
    /// an integer field of 2^53 or more (a `seed` or `maxWork` given in
    /// Rust) reaches it as a float, refused as the wrong type.
    pub fn from_json_value(value: serde_json::Value) -> Result<Self> {
        serde_json::from_value::<Scenario>(value)
            .map_err(not_a_snapshot)?
            .checked()
    }

    /// A deserialised snapshot, if it describes a state the pipeline could
    /// have reached.
    fn checked(self) -> Result<Self> {
        check_params(&self.params)?;
        snapshot::check(&self.primitives, self.next_id, self.scans, &self.params)
            .map_err(|e| Error::Invalid(format!("not a polyscene snapshot: {e}")))?;
        self.pool.validate(self.scans)?;
        crate::cloud::check_rigid(&self.correction).map_err(|e| {
            Error::Invalid(format!(
                "not a polyscene snapshot: its pose correction is no rigid transform: {e}"
            ))
        })?;
        if self.correction.w_axis.truncate().abs().max_element() > crate::cloud::MAX_COORDINATE {
            return Err(Error::Invalid(format!(
                "not a polyscene snapshot: its pose correction moves points by more than {} m",
                crate::cloud::MAX_COORDINATE
            )));
        }
        Ok(self)
    }
}

/// A snapshot serde could not read.
fn not_a_snapshot(e: serde_json::Error) -> Error {
    Error::Invalid(format!("not a polyscene snapshot: {e}"))
}

/// Parameters a scenario can run with: valid, and without a `viewpoint`
/// (each scan's sensor position comes from its pose).
fn check_params(params: &Params) -> Result<()> {
    params.validate()?;
    if params.viewpoint.is_some() {
        return Err(Error::BadOption {
            key: "viewpoint".into(),
            reason: "a scenario takes each scan's sensor position from its pose; \
                     viewpoint is for one-shot detection"
                .into(),
        });
    }
    Ok(())
}
