//! Exact culling of polygons for batches of nearby query points.
//!
//! Queries come in tiles (a few metres of samples or cells at a time). For a
//! tile with bounding box `T` and a polygon with bounding box `B`, every query
//! point `p` in `T` satisfies `dist(p, polygon) >= dist(T, B)` (a lower bound)
//! and, the distance to a set being 1-Lipschitz,
//! `dist(p, polygon) <= dist(centre(T), polygon) + half_diagonal(T)` (an upper
//! bound). Polygons whose lower bound exceeds the smallest upper bound can
//! never be the nearest and are dropped; the rest are visited in order of
//! their lower bound, so a query stops as soon as the bound passes the best
//! exact distance found. Nothing is approximated: the nearest polygon is
//! always found (bounds get a 1e-9 relative margin against rounding).

use crate::geometry::Polygon3;
use glam::{DVec2, DVec3};

/// An axis-aligned box in world coordinates; empty when `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (contains nothing, infinitely far from everything).
    pub fn empty() -> Self {
        Aabb {
            min: DVec3::splat(f64::INFINITY),
            max: DVec3::splat(f64::NEG_INFINITY),
        }
    }

    /// Smallest box holding all `points`.
    pub fn of(points: &[DVec3]) -> Self {
        let mut b = Aabb::empty();
        for &p in points {
            b.min = b.min.min(p);
            b.max = b.max.max(p);
        }
        b
    }

    /// Does the box hold no point?
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// Squared distance from `p` to the box (0 inside).
    #[inline]
    pub fn point_distance_sq(&self, p: DVec3) -> f64 {
        (self.min - p)
            .max(p - self.max)
            .max(DVec3::ZERO)
            .length_squared()
    }

    /// Distance between two boxes (0 when they touch or overlap).
    pub fn box_distance(&self, other: &Aabb) -> f64 {
        if self.is_empty() || other.is_empty() {
            return f64::INFINITY;
        }
        (self.min - other.max)
            .max(other.min - self.max)
            .max(DVec3::ZERO)
            .length()
    }

    /// Centre of the box.
    pub fn centre(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Half the length of the diagonal.
    pub fn half_diagonal(&self) -> f64 {
        0.5 * (self.max - self.min).length()
    }
}

/// `x` plus a margin for rounding: box distances are computed differently
/// from polygon distances and may exceed them by a few ulps.
#[inline]
fn slack(x: f64) -> f64 {
    x + 1e-9 * (1.0 + x)
}

/// A polygon that may be the nearest to a tile's points, with the tile's
/// lower bound on the distance to it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Candidate {
    /// Lower bound (m) on the distance from any point of the tile.
    pub lower: f64,
    /// Index of the polygon in the indexed slice.
    pub index: usize,
}

/// Bounding boxes of a list of polygons, for culling.
pub(crate) struct PolyIndex<'a> {
    polys: Vec<&'a Polygon3>,
    boxes: Vec<Aabb>,
}

impl<'a> PolyIndex<'a> {
    /// Index `polys`; polygons without vertices get an empty box and are
    /// never returned.
    pub fn new(polys: Vec<&'a Polygon3>) -> Self {
        let boxes = polys.iter().map(|p| Aabb::of(&p.vertices())).collect();
        PolyIndex { polys, boxes }
    }

    /// Polygons that can be the nearest to some point of `tile`, sorted by
    /// their lower bound (ties by index), into `out`.
    pub fn nearest_candidates(&self, tile: &Aabb, out: &mut Vec<Candidate>) {
        out.clear();
        let (centre, radius) = (tile.centre(), tile.half_diagonal());
        let mut best_upper = f64::INFINITY;
        for (index, b) in self.boxes.iter().enumerate() {
            if b.is_empty() {
                continue;
            }
            let lower = tile.box_distance(b);
            if lower > slack(best_upper) {
                continue;
            }
            let upper = self.polys[index].distance(centre) + radius;
            best_upper = best_upper.min(upper);
            out.push(Candidate { lower, index });
        }
        out.retain(|c| c.lower <= slack(best_upper));
        out.sort_by(|a, b| a.lower.total_cmp(&b.lower).then(a.index.cmp(&b.index)));
    }

    /// Exact nearest polygon to `p` among `cands` (from
    /// [`nearest_candidates`](Self::nearest_candidates) of a tile holding `p`):
    /// its index and distance (on ties, the first visited).
    pub fn nearest(&self, p: DVec3, cands: &[Candidate]) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for c in cands {
            let bound = slack(best.map_or(f64::INFINITY, |b| b.1));
            if c.lower > bound {
                break;
            }
            let box_sq = self.boxes[c.index].point_distance_sq(p);
            if box_sq > bound * bound {
                continue;
            }
            let d = self.polys[c.index].distance(p);
            if best.is_none_or(|b| d < b.1) {
                best = Some((c.index, d));
            }
        }
        best
    }

    /// Polygons whose box is within `radius` of `tile` and that pass
    /// `keep`, in index order, into `out`.
    pub fn within_candidates(
        &self,
        tile: &Aabb,
        radius: f64,
        keep: impl Fn(usize) -> bool,
        out: &mut Vec<usize>,
    ) {
        out.clear();
        out.extend(
            (0..self.boxes.len())
                .filter(|&i| tile.box_distance(&self.boxes[i]) <= slack(radius) && keep(i)),
        );
    }

    /// Exact distance from `p` to polygon `index` when it may be within
    /// `radius` (box test first), else `None`.
    #[inline]
    pub fn distance_within(&self, index: usize, p: DVec3, radius: f64) -> Option<f64> {
        let r = slack(radius);
        if self.boxes[index].point_distance_sq(p) > r * r {
            return None;
        }
        let d = self.polys[index].distance(p);
        (d <= radius).then_some(d)
    }
}

/// Tile side (m) used to batch queries.
pub(crate) const TILE: f64 = 4.0;

/// Sort `points` (2D, in some frame) by the square tile of side `tile` they
/// fall in (row-major, stable) and call `visit` with each tile's points.
pub(crate) fn for_each_tile(points: &mut [DVec2], tile: f64, mut visit: impl FnMut(&[DVec2])) {
    let key = |p: &DVec2| {
        (
            libm::floor(p.y / tile) as i64,
            libm::floor(p.x / tile) as i64,
        )
    };
    points.sort_by_key(key);
    let mut start = 0;
    while start < points.len() {
        let k = key(&points[start]);
        let len = points[start..].iter().take_while(|p| key(p) == k).count();
        visit(&points[start..start + len]);
        start += len;
    }
}
