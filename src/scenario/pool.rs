//! The pool of unexplained points: what no primitive explained in the last
//! `poolScans` scans, in the world frame, one point per voxel of side
//! `poolVoxel`, at most `poolMaxPoints` of them.
//!
//! A surface that comes into view a little at a time (a far facade, the end
//! of a car, a curb seen along a drive, a ramp at grazing range) gives each
//! scan too few points for detection: the plane has fewer than `minInliers`
//! inliers, or its laser rings lie farther apart than the clustering
//! tolerance. Carried over a few scans, those points add up. Per scan
//! (see `Scenario::add_cloud`):
//!
//! 1. [`Pool::join`]: the scan and the pool become one cloud; expansion runs
//!    over both, so a primitive that grows towards old unexplained points
//!    takes them (they were seen, never counted);
//! 2. [`Pool::select`]: detection gets every live point of the scan and the
//!    live pool points in voxels the scan's live points do not reach (there
//!    the scan's points are the newer evidence of the same place);
//! 3. [`Pool::carry`]: after detection, the pool becomes the scan's live
//!    points, one a voxel (the first in scan order), then the pool's points
//!    detection saw and left, while younger than `poolScans` scans; newest
//!    first, cut at `poolMaxPoints`.
//!
//! So the pool's size is bounded by the cap and, in practice, by the
//! unexplained surface seen in the last `poolScans` scans at one point a
//! voxel: it follows the mapped area's clutter, not the number of scans.
//!
//! Coordinates are whole millimetres (integers, exact in snapshots and the
//! same for a drive translated by whole metres), stored relative to an
//! anchor so that snapshots stay short. The voxel grid is anchored at the
//! world origin.

use crate::cloud::Cloud;
use crate::error::{Error, Result};
use crate::geometry::floor_i64;
use crate::hash::GridMap;
use crate::params::Params;
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// Unexplained points of the last scans (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub(crate) struct Pool {
    /// World millimetres the stored coordinates are relative to (a whole
    /// number of metres).
    anchor: [i64; 3],
    /// Per point, x, y, z in millimetres from `anchor`, flat.
    mm: Vec<i64>,
    /// Per point, the scan that saw it; newest first.
    seen: Vec<u64>,
}

/// Which points of a joined cloud go to detection, and what the pool keeps
/// of them afterwards (see [`Pool::select`]).
pub(crate) struct Selection {
    /// Indices into the joined cloud: the scan's live points, then the pool
    /// points detection sees.
    pub rest: Vec<u32>,
    /// How many of `rest` are the scan's.
    pub from_scan: usize,
    /// Per scan point of `rest`: its world millimetres and its voxel's
    /// number (voxels numbered in first-seen order).
    scan_mm: Vec<[i64; 3]>,
    voxel_of: Vec<u32>,
    voxels: usize,
}

/// Millimetres of an origin (whole metres for every cloud the scenario
/// makes).
fn origin_mm(origin: DVec3) -> [i64; 3] {
    origin.to_array().map(mm)
}

impl Pool {
    /// Points held.
    pub(crate) fn len(&self) -> usize {
        self.seen.len()
    }

    /// World millimetres of point `k`.
    fn world_mm(&self, k: usize) -> [i64; 3] {
        [0, 1, 2].map(|a| self.anchor[a] + self.mm[3 * k + a])
    }

    /// `cloud` followed by the pool's points (relative to the cloud's
    /// origin), or `None` when the pool is empty (use `cloud` itself).
    pub(crate) fn join(&self, cloud: &Cloud) -> Option<Cloud> {
        if self.seen.is_empty() {
            return None;
        }
        let o = origin_mm(cloud.origin);
        let mut points = Vec::with_capacity(cloud.len() + self.len());
        points.extend_from_slice(&cloud.points);
        for k in 0..self.len() {
            let w = self.world_mm(k);
            let local = [0, 1, 2].map(|a| ((w[a] - o[a]) as f64 / 1000.0) as f32);
            points.push(Vec3::from_array(local));
        }
        Some(Cloud {
            origin: cloud.origin,
            points,
        })
    }

    /// The detection input of a joined cloud (`n` scan points, then the
    /// pool's) after expansion: every live scan point, and each live pool
    /// point whose voxel holds no live scan point.
    pub(crate) fn select(
        &self,
        cloud: &Cloud,
        n: usize,
        alive: &[bool],
        params: &Params,
    ) -> Selection {
        let mut rest: Vec<u32> = (0..n as u32).filter(|&i| alive[i as usize]).collect();
        let from_scan = rest.len();
        let mut sel = Selection {
            rest: Vec::new(),
            from_scan,
            scan_mm: Vec::new(),
            voxel_of: Vec::new(),
            voxels: 0,
        };
        // (Without the pool's points joined, as for an empty scan, there is
        // nothing of it to select.)
        if !enabled(params) || cloud.len() != n + self.len() {
            sel.rest = rest;
            return sel;
        }
        let grid = Grid::new(params);
        let o = origin_mm(cloud.origin);
        let mut ids: GridMap<[i64; 3], u32> = GridMap::default();
        ids.reserve(from_scan);
        sel.scan_mm.reserve(from_scan);
        sel.voxel_of.reserve(from_scan);
        for &i in &rest {
            let p = cloud.points[i as usize].to_array();
            let w = [0, 1, 2].map(|a| o[a] + mm(p[a] as f64));
            let next = ids.len() as u32;
            sel.voxel_of.push(*ids.entry(grid.voxel(w)).or_insert(next));
            sel.scan_mm.push(w);
        }
        sel.voxels = ids.len();
        for k in 0..self.len() {
            let i = n + k;
            if alive[i] && !ids.contains_key(&grid.voxel(self.world_mm(k))) {
                rest.push(i as u32);
            }
        }
        sel.rest = rest;
        sel
    }

    /// The pool after scan `scan`: the scan's points still alive, one a
    /// voxel, then the pool points of `sel` still alive and younger than
    /// `poolScans` scans, cut at `poolMaxPoints`. A point for which `known`
    /// is true (it lies on a known polygon, a little off its plane) is not
    /// kept (see `Surfaces::holds` in `scenario/surfaces.rs`).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn carry(
        &mut self,
        cloud: &Cloud,
        n: usize,
        alive: &[bool],
        sel: &Selection,
        scan: u64,
        params: &Params,
        known: &dyn Fn(DVec3) -> bool,
    ) {
        let (age, cap) = (params.pool_scans as u64, params.pool_max_points);
        let anchor = origin_mm(cloud.origin);
        let mut mm = Vec::new();
        let mut seen = Vec::new();
        if enabled(params) {
            let mut kept = vec![false; sel.voxels];
            for (j, &i) in sel.rest[..sel.from_scan].iter().enumerate() {
                if seen.len() >= cap {
                    break;
                }
                let v = sel.voxel_of[j] as usize;
                if alive[i as usize] && !kept[v] && !known(cloud.world(i as usize)) {
                    kept[v] = true;
                    let w = sel.scan_mm[j];
                    mm.extend((0..3).map(|a| w[a] - anchor[a]));
                    seen.push(scan);
                }
            }
            for &i in &sel.rest[sel.from_scan..] {
                let (i, k) = (i as usize, i as usize - n);
                if seen.len() >= cap {
                    break;
                }
                if alive[i] && scan.saturating_sub(self.seen[k]) < age && !known(cloud.world(i)) {
                    let w = self.world_mm(k);
                    mm.extend((0..3).map(|a| w[a] - anchor[a]));
                    seen.push(self.seen[k]);
                }
            }
        }
        *self = Pool { anchor, mm, seen };
    }

    /// Check a restored pool: lengths agree, no point is from a scan not
    /// yet made (`scans` made so far), ages are newest first, and every
    /// coordinate lies within the accepted range.
    pub(crate) fn validate(&self, scans: u64) -> Result<()> {
        let bad = |what: &str| {
            Err(Error::Invalid(format!(
                "not a polyscene snapshot: pool {what}"
            )))
        };
        if self.mm.len() != 3 * self.seen.len() {
            return bad("coordinates and ages differ in length");
        }
        if self.seen.iter().any(|&s| s >= scans) || self.seen.windows(2).any(|w| w[0] < w[1]) {
            return bad("ages out of order or from a later scan");
        }
        let limit = (crate::cloud::MAX_COORDINATE * 1000.0) as i64;
        let out = |v: i64| !(-limit..=limit).contains(&v);
        if self.anchor.iter().any(|&a| out(a))
            || self.mm.iter().any(|&v| out(v))
            || (0..self.len()).any(|k| self.world_mm(k).iter().any(|&v| out(v)))
        {
            return bad("coordinates out of range");
        }
        Ok(())
    }
}

/// Is there a pool? Not with `poolScans` or `poolMaxPoints` 0, nor in the
/// paper's mode without expansion (each scan detected anew and appended).
fn enabled(params: &Params) -> bool {
    params.expansion && params.pool_scans > 0 && params.pool_max_points > 0
}

/// Metres to whole millimetres, halves rounded up (a floor, native in
/// wasm and cheap natively; `f64::round` is a library call in both).
#[inline]
fn mm(metres: f64) -> i64 {
    floor_i64(metres * 1000.0 + 0.5)
}

/// Voxels of a side in whole millimetres.
#[derive(Clone, Copy)]
struct Grid {
    side: i64,
    inv: f64,
}

impl Grid {
    fn new(params: &Params) -> Self {
        let side = mm(params.pool_voxel).max(1);
        Grid {
            side,
            inv: 1.0 / side as f64,
        }
    }

    /// The voxel holding world millimetres `w`: `w.div_euclid(side)` per
    /// axis, by a multiply and a one-step correction (an integer division
    /// per coordinate cost more than the rest of the pool's work).
    #[inline]
    fn voxel(self, w: [i64; 3]) -> [i64; 3] {
        w.map(|c| {
            let mut q = floor_i64(c as f64 * self.inv);
            if q * self.side > c {
                q -= 1;
            } else if (q + 1) * self.side <= c {
                q += 1;
            }
            q
        })
    }
}
