//! The polygons within reach of one scan, filed by coarse cells, so that
//! asking "which polygons could this point lie on" costs what the scan saw,
//! not what the map holds. Two per-scan tests use it: the scan-to-map
//! alignment (`align.rs`), which pairs points with the polygon they lie
//! on, and the pool, which does not keep points that a known polygon holds
//! ([`Surfaces::holds`]).

use crate::geometry::{bounds, floor_i64};
use crate::hash::GridMap;
use crate::params::Params;
use crate::primitive::Primitive;
use glam::DVec3;
use std::cell::Cell;

/// Side of the cells polygons are filed under (m).
const CELL: f64 = 16.0;

/// Most cells a polygon is filed under; a larger one is a candidate for
/// every point.
const MAX_CELLS: i64 = 4096;

/// A cell and the range of [`Surfaces`]'s list that holds its polygons.
type CellRange = ([i64; 3], (u32, u32));

/// Polygons of a scenario (by position in its id-sorted list), filed under
/// every cell that their outline's box, grown by a per-polygon slack,
/// covers.
pub(crate) struct Surfaces<'a> {
    pub prims: &'a [Primitive],
    /// Per cell, the range of `items` that holds its polygons.
    cells: GridMap<[i64; 3], (u32, u32)>,
    items: Vec<u32>,
    wide: Vec<usize>,
    /// The last cell looked up and its range: consecutive points of a scan
    /// mostly share a cell, and the hash lookup was most of a query.
    last: Cell<Option<CellRange>>,
}

impl<'a> Surfaces<'a> {
    /// The polygons `ids` of `prims` (id-sorted), each filed with the slack
    /// `slack(prim)` (m) around its outline's box.
    pub fn new(prims: &'a [Primitive], ids: &[u32], slack: impl Fn(&Primitive) -> f64) -> Self {
        let mut wide = Vec::new();
        // (The primitive index's map type: one copy of the hash map's code
        // in the wasm: 0.25 kB less, gzipped.)
        let mut lists: GridMap<[i64; 3], Vec<u32>> = GridMap::default();
        for &id in ids {
            let Ok(k) = prims.binary_search_by_key(&id, |q| q.id) else {
                continue;
            };
            let prim = &prims[k];
            let (lo, hi) = bounds(&prim.vertices());
            let pad = DVec3::splat(slack(prim));
            let (a, b) = (cell_of(lo - pad), cell_of(hi + pad));
            let count = (0..3).fold(1i64, |c, i| {
                c.saturating_mul(b[i].saturating_sub(a[i]).saturating_add(1))
            });
            if !(lo.is_finite() && hi.is_finite()) || count > MAX_CELLS {
                wide.push(k);
                continue;
            }
            for x in a[0]..=b[0] {
                for y in a[1]..=b[1] {
                    for z in a[2]..=b[2] {
                        lists.entry([x, y, z]).or_default().push(k as u32);
                    }
                }
            }
        }
        // One flat list, each cell's polygons in filing order.
        let mut items = Vec::new();
        let mut cells = GridMap::default();
        cells.reserve(lists.len());
        for (key, list) in lists {
            let from = items.len() as u32;
            items.extend_from_slice(&list);
            cells.insert(key, (from, items.len() as u32));
        }
        Surfaces {
            prims,
            cells,
            items,
            wide,
            last: Cell::new(None),
        }
    }

    /// Positions (in `prims`) of the polygons filed where `w` lies: every
    /// polygon whose grown box holds `w` is among them.
    pub fn near(&self, w: DVec3) -> impl Iterator<Item = usize> + '_ {
        let key = cell_of(w);
        let (from, to) = match self.last.get() {
            Some((k, range)) if k == key => range,
            _ => {
                let range = self.cells.get(&key).copied().unwrap_or((0, 0));
                self.last.set(Some((key, range)));
                range
            }
        };
        self.wide.iter().copied().chain(
            self.items[from as usize..to as usize]
                .iter()
                .map(|&k| k as usize),
        )
    }
}

/// Two expansion gates (`expandAcross`) of `prim`'s kind (m): the slack of
/// [`Surfaces::holds`].
pub(crate) fn seen_slack(prim: &Primitive, params: &Params) -> f64 {
    2.0 * params.surface(prim.ground).expand_across
}

impl Surfaces<'_> {
    /// Is world point `w` on one of these polygons, seen through an
    /// imperfect pose: inside its outline and within two expansion gates of
    /// its plane ([`seen_slack`], the slack these surfaces must be filed
    /// with)? Expansion takes points within one gate; a pose a few
    /// centimetres or a tenth of a degree off puts a surface's points just
    /// beyond it. Left in the pool, such points would add up, scan after
    /// scan, to a second layer of the same surface; so the pool does not
    /// keep them (the scan's detection still sees them, as without a pool).
    pub fn holds(&self, w: DVec3, params: &Params) -> bool {
        self.near(w).any(|k| {
            let prim = &self.prims[k];
            prim.holds(w, seen_slack(prim, params))
        })
    }
}

fn cell_of(p: DVec3) -> [i64; 3] {
    [
        floor_i64(p.x / CELL),
        floor_i64(p.y / CELL),
        floor_i64(p.z / CELL),
    ]
}
