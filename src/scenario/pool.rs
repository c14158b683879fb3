//! The pool of unexplained points: what no primitive explained in the last
//! `poolScans` scans, in the world frame, one point per voxel of side
//! `poolVoxel` (and one held point a voxel, below), at most
//! `poolMaxPoints` of them.
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
//!    the scan's points are the newer evidence of the same place), but not
//!    the held points (below);
//! 3. [`Pool::carry`]: after detection and the riser step, the pool becomes
//!    the scan's live points, one a voxel (the first in scan order), then
//!    the pool's points detection saw and left, while younger than
//!    `poolScans` scans; newest first, cut at `poolMaxPoints`. The points of
//!    a riser's piece too small to keep are *held*: kept although expansion
//!    took them into the road or the sidewalk (a curb's face lies within
//!    their gates), for the riser step alone, which runs on the scan's and
//!    the pool's points, so that a curb seen a few metres at a time between
//!    parked cars adds up to a riser.
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
    /// The points held for the riser step (ascending positions): pieces of
    /// a curb's face too small to keep. Detection does not see them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    held: Vec<u64>,
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

/// World millimetres of point `i` of `cloud`, whose origin is `o`
/// ([`origin_mm`]).
fn point_mm(cloud: &Cloud, o: [i64; 3], i: usize) -> [i64; 3] {
    let p = cloud.points[i].to_array();
    [0, 1, 2].map(|a| o[a] + mm(p[a] as f64))
}

impl Pool {
    /// Points in the pool, held or not.
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
    /// point whose voxel holds no live scan point, but no held one.
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
            let w = point_mm(cloud, o, i as usize);
            let next = ids.len() as u32;
            sel.voxel_of.push(*ids.entry(grid.voxel(w)).or_insert(next));
            sel.scan_mm.push(w);
        }
        sel.voxels = ids.len();
        let mut held = 0;
        for k in 0..self.len() {
            let i = n + k;
            if self.held.get(held) == Some(&(k as u64)) {
                held += 1;
                continue;
            }
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
    /// kept (see `Surfaces::holds` in `scenario/surfaces.rs`). The points
    /// `held` (indices into `cloud`: a riser's piece too small to keep) that
    /// the pool would not keep otherwise are kept whatever `alive` and
    /// `known` say, while younger than `poolScans` scans, one a voxel (a
    /// scan's over an older one).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn carry(
        &mut self,
        cloud: &Cloud,
        n: usize,
        alive: &[bool],
        sel: &Selection,
        held: &[u32],
        scan: u64,
        params: &Params,
        known: &dyn Fn(DVec3) -> bool,
    ) {
        let (age, cap) = (params.pool_scans as u64, params.pool_max_points);
        let anchor = origin_mm(cloud.origin);
        let mut mm = Vec::new();
        let mut seen = Vec::new();
        let mut kept_held = Vec::new();
        if enabled(params) {
            // The held points, the pool's marked by position.
            let mut hold = vec![false; self.len()];
            let mut held_scan = Vec::new();
            for &i in held {
                match (i as usize).checked_sub(n) {
                    Some(k) if k < hold.len() => hold[k] = true,
                    Some(_) => {}
                    None => held_scan.push(i as usize),
                }
            }
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
            let grid = Grid::new(params);
            let mut voxels: GridMap<[i64; 3], u32> = GridMap::default();
            // (A live one is the scan's like any other, kept or thinned
            // above.)
            for &i in &held_scan {
                if alive[i] {
                    continue;
                }
                let w = point_mm(cloud, anchor, i);
                let next = voxels.len() as u32;
                if seen.len() < cap && *voxels.entry(grid.voxel(w)).or_insert(next) == next {
                    kept_held.push(seen.len() as u64);
                    mm.extend((0..3).map(|a| w[a] - anchor[a]));
                    seen.push(scan);
                }
            }
            // The pool's, in its order (newest first): those detection saw
            // and left, and the held ones.
            let mut left = vec![false; self.len()];
            for &i in &sel.rest[sel.from_scan..] {
                left[i as usize - n] = true;
            }
            for k in 0..self.len() {
                let i = n + k;
                if seen.len() >= cap {
                    break;
                }
                let young = scan.saturating_sub(self.seen[k]) < age;
                // One held point a voxel: the scan's newer one wins.
                let hold = hold[k] && !voxels.contains_key(&grid.voxel(self.world_mm(k)));
                if young && (hold || left[k] && alive[i] && !known(cloud.world(i))) {
                    if hold {
                        kept_held.push(seen.len() as u64);
                    }
                    let w = self.world_mm(k);
                    mm.extend((0..3).map(|a| w[a] - anchor[a]));
                    seen.push(self.seen[k]);
                }
            }
        }
        *self = Pool {
            anchor,
            mm,
            seen,
            held: kept_held,
        };
    }

    /// Check a restored pool: lengths agree, no point is from a scan not
    /// yet made (`scans` made so far), ages are newest first, the held
    /// positions ascend and lie among the points, and every coordinate
    /// lies within the accepted range.
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
        if self.held.windows(2).any(|w| w[0] >= w[1])
            || self.held.last().is_some_and(|&h| h >= self.len() as u64)
        {
            return bad("held points out of order or beyond its points");
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

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(pts: &[[f64; 3]]) -> Cloud {
        let flat: Vec<f64> = pts.iter().flatten().copied().collect();
        Cloud::from_flat_f64(&flat, 3).unwrap()
    }

    #[test]
    fn held_points_stay_out_of_detection_while_the_riser_step_holds_them() {
        let p = Params::gpp2();
        let mut pool = Pool::default();
        // Scan 0: three points, all taken by expansion and on a known
        // surface; the riser step holds the first and the third.
        let c = cloud(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
        let dead = [false; 3];
        let sel = pool.select(&c, 3, &dead, &p);
        assert!(sel.rest.is_empty());
        pool.carry(&c, 3, &dead, &sel, &[0, 2], 0, &p, &|_| true);
        assert_eq!((pool.len(), &pool.held[..]), (2, &[0, 1][..]));
        assert_eq!(pool.world_mm(1), [2000, 0, 0]);
        assert!(pool.validate(1).is_ok());
        // Scan 1: one point of its own, then the pool's two, all left by
        // expansion. Detection sees the scan's point, not the held ones.
        let joined = pool.join(&cloud(&[[5.0, 0.0, 0.0]])).unwrap();
        let alive = [true; 3];
        let sel = pool.select(&joined, 1, &alive, &p);
        assert_eq!(sel.rest, vec![0]);
        // The riser step holds the second again, taken by expansion and on
        // a known surface (below x = 3 m) as before; the first, no longer
        // held, leaves with what detection never saw.
        let taken = [true, true, false];
        pool.carry(&joined, 1, &taken, &sel, &[2], 1, &p, &|w| w.x < 3.0);
        assert_eq!((pool.len(), &pool.held[..]), (2, &[1][..]));
        assert_eq!(pool.world_mm(0), [5000, 0, 0]);
        assert_eq!((pool.world_mm(1), pool.seen[1]), ([2000, 0, 0], 0));
        // Held, it still ages out after `poolScans` scans.
        let old = p.pool_scans as u64;
        let joined = pool.join(&cloud(&[[9.0, 0.0, 0.0]])).unwrap();
        let sel = pool.select(&joined, 1, &[false; 3], &p);
        pool.carry(&joined, 1, &[false; 3], &sel, &[2], old, &p, &|_| false);
        assert_eq!(pool.len(), 0);
    }

    #[test]
    fn held_points_are_one_a_voxel_and_never_a_second_copy_of_a_live_one() {
        let p = Params::gpp2();
        let mut pool = Pool::default();
        // Scan 0 holds a point at 2 m.
        let c = cloud(&[[2.0, 0.0, 0.0]]);
        let sel = pool.select(&c, 1, &[false], &p);
        pool.carry(&c, 1, &[false], &sel, &[0], 0, &p, &|_| false);
        assert_eq!(pool.held, vec![0]);
        // Scan 1 holds a point 2 cm from it (the same 0.1 m voxel) and the
        // old one again: the newer is kept. Its other point, held but left
        // by expansion, is kept once, as the scan's live points are.
        let joined = pool
            .join(&cloud(&[[2.02, 0.0, 0.0], [7.0, 0.0, 0.0]]))
            .unwrap();
        let alive = [false, true, false];
        let sel = pool.select(&joined, 2, &alive, &p);
        assert_eq!(sel.rest, vec![1]);
        pool.carry(&joined, 2, &alive, &sel, &[0, 1, 2], 1, &p, &|_| false);
        let kept: Vec<[i64; 3]> = (0..pool.len()).map(|k| pool.world_mm(k)).collect();
        assert_eq!(kept, vec![[7000, 0, 0], [2020, 0, 0]]);
        assert_eq!(pool.held, vec![1]);
    }

    #[test]
    fn a_snapshot_s_held_points_must_be_in_order_and_among_its_points() {
        let mut pool = Pool {
            anchor: [0; 3],
            mm: vec![0; 6],
            seen: vec![1, 0],
            held: vec![0, 1],
        };
        assert!(pool.validate(2).is_ok());
        for held in [vec![1, 0], vec![0, 0], vec![2]] {
            pool.held = held;
            assert!(pool.validate(2).is_err(), "{:?}", pool.held);
        }
    }
}
