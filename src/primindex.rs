//! A spatial index over a scenario's primitives, so that a scan costs what
//! the sensor sees, not what the map holds: expansion visits only the
//! primitives a scan point could reach, merging tests only the pairs whose
//! boxes could touch.
//!
//! Each primitive is filed, by id, under every cell of a uniform 3D grid
//! (cells of [`CELL`] metres, keyed by their integer coordinates in a hash
//! map) that its *reach box* overlaps: a box that holds every point the
//! primitive's expansion could take, and its outline's bounding box grown by
//! the merge test's padding. A primitive whose reach box is not finite, or
//! covers more than [`MAX_CELLS`] cells, is kept in a short list that every
//! query returns. The index is updated whenever a primitive is added, grows,
//! absorbs another or is removed, and is rebuilt from the primitives after a
//! snapshot is restored (it is derived state, never serialised).
//!
//! Why pruning is exact (the outputs stay bit-for-bit the same):
//! - *Expansion* (`scenario/expand.rs`) takes a point only if it lies in
//!   the first round's grown mask of the outline (inside or in the ring;
//!   every later round and every box enlargement needs a point taken in the
//!   first) and within `across` of the plane. The mask's grid spans the
//!   outline's 2D box grown by `along` plus three of its cells, and a cell
//!   is at most `max(1 m, extent / 700)` (`geometry/mask.rs` coarsens to 2M
//!   cells). The reach box holds that 2D box, grown by one more metre, at
//!   every height within `across` (plus the frame's distance from the
//!   plane): a primitive none of whose cells holds a scan point would take
//!   nothing, and `expand` would change nothing.
//! - *Merging* (`merge::mergeable`) is false when the outlines' bounding
//!   boxes, one grown by the merge padding, are apart. The reach box holds
//!   the outline's bounding box grown by that padding plus a metre, so a
//!   pair that can merge shares a cell of the query around one outline box.

use crate::geometry::{bounds, floor_i64};
use crate::hash::GridMap;
use crate::params::Params;
use crate::primitive::Primitive;
use glam::{DVec2, DVec3};

/// Side of the grid's cells (m): about the size of a facade; a scan of a
/// 120 m-range sensor covers a few hundred.
pub const CELL: f64 = 16.0;

/// Most cells a primitive is filed under; larger ones (a road merged over
/// kilometres) go to the list every query returns.
pub const MAX_CELLS: u64 = 512;

/// Slack added to every reach (m), for rounding in the f32 scan
/// coordinates and the raster grids.
const SLACK: f64 = 1.0;

/// The distances that make a reach box, from the parameters.
#[derive(Clone, Copy, Debug, Default)]
struct Reach {
    /// Largest `expandAlong` of the two surface kinds (m).
    along: f64,
    /// Largest `expandAcross` (m).
    across: f64,
    /// The merge test's box padding (m).
    merge: f64,
}

impl Reach {
    fn of(params: &Params) -> Self {
        Reach {
            along: params.ground.expand_along.max(params.other.expand_along),
            // `expand` clamps its gate to at least 3 cm.
            across: (params.ground.expand_across)
                .max(params.other.expand_across)
                .max(0.03),
            merge: params.merge_box_pad(),
        }
    }
}

/// Where one primitive is filed.
#[derive(Clone, Debug, PartialEq)]
enum Entry {
    /// Under the cells `lo..=hi`.
    Cells([i64; 3], [i64; 3]),
    /// In the list every query returns.
    Big,
}

/// The index. See the module documentation.
#[derive(Clone, Debug, Default)]
pub struct PrimIndex {
    built: bool,
    reach: Reach,
    cells: GridMap<[i64; 3], Vec<u32>>,
    big: Vec<u32>,
    entries: GridMap<u32, Entry>,
}

/// The index is derived from the primitives (rebuilt on demand): two
/// scenarios with equal primitives behave the same whatever their indices
/// hold, so it never makes them unequal.
impl PartialEq for PrimIndex {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The grid cell of a world point.
#[inline]
fn cell_of(p: DVec3) -> [i64; 3] {
    [
        floor_i64(p.x / CELL),
        floor_i64(p.y / CELL),
        floor_i64(p.z / CELL),
    ]
}

/// Cells `lo..=hi` of a box, or `None` when it is not finite or spans more
/// than `max` cells.
fn cell_range(lo: DVec3, hi: DVec3, max: u64) -> Option<([i64; 3], [i64; 3])> {
    if !(lo.is_finite() && hi.is_finite()) || lo.cmpgt(hi).any() {
        return None;
    }
    let (a, b) = (cell_of(lo), cell_of(hi));
    let mut count: u64 = 1;
    for k in 0..3 {
        count = count.saturating_mul(b[k].saturating_sub(a[k]).saturating_add(1) as u64);
    }
    (count <= max).then_some((a, b))
}

fn each_cell(lo: [i64; 3], hi: [i64; 3], mut f: impl FnMut([i64; 3])) {
    for x in lo[0]..=hi[0] {
        for y in lo[1]..=hi[1] {
            for z in lo[2]..=hi[2] {
                f([x, y, z]);
            }
        }
    }
}

/// The primitive's reach box (see the module documentation), or `None`
/// when it cannot be bounded (no outline, non-finite values, a frame off
/// its plane).
fn reach_box(prim: &Primitive, r: &Reach) -> Option<(DVec3, DVec3)> {
    let f = &prim.frame;
    if prim.outline.len() < 3 || f.normal.dot(prim.plane.normal) < 1.0 - 1e-9 {
        return None;
    }
    let (mut lo2, mut hi2) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for &q in &prim.outline {
        lo2 = lo2.min(q);
        hi2 = hi2.max(q);
    }
    let size = hi2 - lo2 + DVec2::splat(2.0 * r.along);
    let mask_cell = (size.max_element() / 700.0).max(1.0);
    let grow = r.along + 3.0 * mask_cell + SLACK;
    let (lo2, hi2) = (lo2 - DVec2::splat(grow), hi2 + DVec2::splat(grow));
    let h = r.across + prim.plane.signed_distance(f.origin).abs() + SLACK;
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for q in [lo2, DVec2::new(hi2.x, lo2.y), hi2, DVec2::new(lo2.x, hi2.y)] {
        let w = f.to_world(q);
        for p in [w - f.normal * h, w + f.normal * h] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    // The outline's own box grown by the merge padding (the corners above
    // hold the outline, but `grow` may be smaller than that padding).
    let (vlo, vhi) = bounds(&prim.vertices());
    let pad = DVec3::splat(r.merge + SLACK);
    Some((lo.min(vlo - pad), hi.max(vhi + pad)))
}

impl PrimIndex {
    /// Build the index over `prims` if it is not built (a new scenario, or
    /// one restored from a snapshot).
    pub fn ensure(&mut self, prims: &[Primitive], params: &Params) {
        if self.built {
            return;
        }
        *self = PrimIndex {
            built: true,
            reach: Reach::of(params),
            ..PrimIndex::default()
        };
        for p in prims {
            self.update(p);
        }
    }

    /// File `prim` again after it was added or changed.
    /// Does nothing before [`PrimIndex::ensure`] (which files them all).
    pub fn update(&mut self, prim: &Primitive) {
        if !self.built {
            return;
        }
        self.remove(prim.id);
        let entry =
            match reach_box(prim, &self.reach).and_then(|(lo, hi)| cell_range(lo, hi, MAX_CELLS)) {
                Some((lo, hi)) => {
                    each_cell(lo, hi, |c| self.cells.entry(c).or_default().push(prim.id));
                    Entry::Cells(lo, hi)
                }
                None => {
                    if let Err(at) = self.big.binary_search(&prim.id) {
                        self.big.insert(at, prim.id);
                    }
                    Entry::Big
                }
            };
        self.entries.insert(prim.id, entry);
    }

    /// Forget the primitive `id` (absorbed, or about to be filed again).
    pub fn remove(&mut self, id: u32) {
        match self.entries.remove(&id) {
            Some(Entry::Cells(lo, hi)) => each_cell(lo, hi, |c| {
                if let Some(v) = self.cells.get_mut(&c) {
                    if let Some(at) = v.iter().position(|&x| x == id) {
                        v.swap_remove(at);
                    }
                    if v.is_empty() {
                        self.cells.remove(&c);
                    }
                }
            }),
            Some(Entry::Big) => self.big.retain(|&x| x != id),
            None => {}
        }
    }

    /// Ids (sorted) of the primitives filed under any of `cells`, and of
    /// the big ones.
    fn gather(&self, cells: impl Iterator<Item = [i64; 3]>) -> Vec<u32> {
        let mut ids = self.big.clone();
        for c in cells {
            if let Some(v) = self.cells.get(&c) {
                ids.extend_from_slice(v);
            }
        }
        ids.sort_unstable();
        ids.dedup();
        ids
    }

    /// Every primitive whose expansion could take a point of a cloud
    /// (sorted ids; a superset, never missing one), from the cloud's
    /// occupied voxels (a few times fewer than its points): `voxels` are integer
    /// coordinates of cubes of side `side` in the frame whose origin is
    /// world point `origin`. Every cell a voxel's cube touches counts (and
    /// those within a micrometre of it, for the rounding of the voxel
    /// coordinates).
    pub fn near_voxels(&self, origin: DVec3, voxels: &[[i64; 3]], side: f64) -> Vec<u32> {
        let mut keys: Vec<[i64; 3]> = Vec::new();
        let eps = DVec3::splat(1e-6);
        for c in voxels {
            let lo = origin + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * side;
            let (a, b) = (cell_of(lo - eps), cell_of(lo + DVec3::splat(side) + eps));
            each_cell(a, b, |k| keys.push(k));
        }
        keys.sort_unstable();
        keys.dedup();
        self.gather(keys.into_iter())
    }

    /// Every primitive whose expansion could take one of the world points
    /// `points` (sorted ids; a superset, never missing one).
    pub fn near_points(&self, points: impl Iterator<Item = DVec3>) -> Vec<u32> {
        let mut keys: Vec<[i64; 3]> = Vec::new();
        let mut last = None;
        for p in points {
            let c = cell_of(p);
            // Consecutive points of a scan mostly share a cell.
            if last != Some(c) {
                keys.push(c);
                last = Some(c);
            }
        }
        keys.sort_unstable();
        keys.dedup();
        self.gather(keys.into_iter())
    }

    /// Every primitive that `mergeable` could pair with `prim` (sorted
    /// ids, `prim`'s own included; a superset, never missing one). All of
    /// them when the query box is not finite or too large.
    pub fn near_primitive(&self, prim: &Primitive) -> Option<Vec<u32>> {
        let (lo, hi) = bounds(&prim.vertices());
        let pad = DVec3::splat(self.reach.merge + SLACK);
        let max = (self.entries.len() as u64).max(MAX_CELLS);
        let (a, b) = cell_range(lo - pad, hi + pad, max)?;
        let mut keys = Vec::new();
        each_cell(a, b, |c| keys.push(c));
        Some(self.gather(keys.into_iter()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_ranges_refuse_unbounded_and_huge_boxes() {
        let lo = DVec3::new(-1.0, -1.0, -1.0);
        assert_eq!(
            cell_range(lo, DVec3::new(1.0, 1.0, 1.0), 8),
            Some(([-1, -1, -1], [0, 0, 0]))
        );
        assert_eq!(cell_range(lo, DVec3::new(1e9, 1.0, 1.0), 512), None);
        assert_eq!(
            cell_range(lo, DVec3::new(f64::INFINITY, 1.0, 1.0), 512),
            None
        );
        assert_eq!(cell_range(DVec3::ONE, lo, 512), None);
    }
}
