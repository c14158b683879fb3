//! Occupancy rasters on a plane and concave outlines traced from them.
//!
//! A [`Footprint`] is a bit grid in a primitive's 2D frame: a cell is set when
//! a support point fell in it. It is what a primitive remembers of *where* it
//! was observed, in memory proportional to its extent (not to its points), and
//! it grows with every scan.
//!
//! The concave outline is a discrete alpha hull: the occupied cells are closed
//! morphologically with a disk of radius `alpha` (dilate, then erode: this is
//! exactly the complement of the union of all empty disks of radius `alpha`,
//! i.e. the alpha hull, on the grid), the largest 4-connected region is kept,
//! its holes are filled, or the large ones joined to the outside by a cut
//! (see [`Footprint::outline_region`]), and its boundary is traced along cell
//! edges. A hole-free 4-connected region of cells has no pinch vertices, so
//! the traced ring is always a simple polygon; it is then simplified
//! (Douglas–Peucker, simplicity kept) within a tolerance. Work is linear in the number of cells
//! in the bounding box, independent of the number of points.
//!
//! Here: the footprint's storage (marking, counting, bridging, the snapshot
//! format) and the mapping between metres and cells around the tracing.
//! The raster work itself (closing, region labelling, boundary tracing) is
//! the crate's bit raster, `crate::raster`; the concave outline method that
//! uses it is [`crate::outline`]. Both outline methods keep a footprint
//! (occupancy, merging and expansion read it), so it stays here.

use super::polygon::{
    is_simple, make_ccw, remove_collinear, signed_area, simplify_within, DouglasPeucker,
};
use crate::raster::{BitGrid, Closing};
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// Most cells the outline tracer works on at once: a larger footprint is
/// traced at a coarser resolution (cells merged 2x2 until it fits).
pub const MAX_TRACE_CELLS: usize = 4_000_000;

/// Most cells a footprint grid holds (2^30, 128 MiB of bits; about 6.5 km a
/// side at 0.2 m cells), and the farthest its corner may lie from the frame
/// origin (2^40 cells). Points beyond are not recorded: memory stays bounded
/// (and the index arithmetic within `usize` on wasm32) whatever the input.
pub const MAX_CELLS: u64 = 1 << 30;
const MAX_OFFSET: i128 = 1 << 40;
/// Longest gap, in cells, that [`Footprint::bridge_towards`] fills.
pub const MAX_TRAIL: usize = 256;

/// A growable occupancy bit grid in a plane's 2D frame.
///
/// Serialised as `{cell, x0, y0, w, h, bits}` with `bits` a hex string (16
/// digits per 64-cell word): JSON numbers above 2^53 would not survive
/// JavaScript's `JSON.parse`. Deserialising checks that the fields are
/// consistent, so a corrupt snapshot is an error rather than a panic later.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "FootprintData")]
pub struct Footprint {
    cell: f64,
    x0: i64,
    y0: i64,
    w: usize,
    h: usize,
    #[serde(with = "hex_words")]
    bits: Vec<u64>,
}

/// The serialised fields of a [`Footprint`], before the consistency check.
#[derive(Deserialize)]
struct FootprintData {
    cell: f64,
    x0: i64,
    y0: i64,
    w: usize,
    h: usize,
    #[serde(with = "hex_words")]
    bits: Vec<u64>,
}

impl TryFrom<FootprintData> for Footprint {
    type Error = String;

    fn try_from(d: FootprintData) -> Result<Self, String> {
        // Grid sizes and offsets far beyond any real footprint (2^31 cells a
        // side, 2^40 cells from the frame origin) would overflow later.
        const SIDE: usize = 1 << 31;
        const OFFSET: u64 = 1 << 40;
        let cells = d.w.checked_mul(d.h);
        let ok = d.cell.is_finite()
            && d.cell >= 1e-3
            && d.w <= SIDE
            && d.h <= SIDE
            && d.x0.unsigned_abs() <= OFFSET
            && d.y0.unsigned_abs() <= OFFSET
            && (d.w == 0) == (d.h == 0)
            && cells.is_some_and(|c| c as u64 <= MAX_CELLS && d.bits.len() == c.div_ceil(64));
        if !ok {
            return Err(format!(
                "inconsistent footprint (cell {}, {} x {} cells at ({}, {}), {} words)",
                d.cell,
                d.w,
                d.h,
                d.x0,
                d.y0,
                d.bits.len()
            ));
        }
        Ok(Footprint {
            cell: d.cell,
            x0: d.x0,
            y0: d.y0,
            w: d.w,
            h: d.h,
            bits: d.bits,
        })
    }
}

/// Serde of `Vec<u64>` as one lowercase hex string, 16 digits per word.
/// Reading also accepts an array of integers (the earlier format).
mod hex_words {
    use serde::de::{Error, SeqAccess, Visitor};
    use serde::{Deserializer, Serializer};
    use std::fmt;

    pub fn serialize<S: Serializer>(words: &[u64], s: S) -> Result<S::Ok, S::Error> {
        const DIGITS: &[u8; 16] = b"0123456789abcdef";
        let mut out = String::with_capacity(16 * words.len());
        for w in words {
            for k in (0..16).rev() {
                out.push(DIGITS[(w >> (4 * k) & 15) as usize] as char);
            }
        }
        s.serialize_str(&out)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u64>, D::Error> {
        struct Words;
        impl<'de> Visitor<'de> for Words {
            type Value = Vec<u64>;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a hex string of 16 digits per word, or an array of integers")
            }

            fn visit_str<E: Error>(self, v: &str) -> Result<Vec<u64>, E> {
                if v.len() % 16 != 0 || !v.is_ascii() {
                    return Err(E::custom("footprint bits: length not a multiple of 16"));
                }
                v.as_bytes()
                    .chunks_exact(16)
                    .map(|c| {
                        std::str::from_utf8(c)
                            .ok()
                            .and_then(|t| u64::from_str_radix(t, 16).ok())
                            .ok_or_else(|| E::custom("footprint bits: not hexadecimal"))
                    })
                    .collect()
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<u64>, A::Error> {
                let mut out = Vec::new();
                while let Some(w) = seq.next_element::<u64>()? {
                    out.push(w);
                }
                Ok(out)
            }
        }
        d.deserialize_any(Words)
    }
}

impl Footprint {
    /// Empty footprint with square cells of `cell` metres (clamped to >= 1 mm).
    pub fn new(cell: f64) -> Self {
        let cell = if cell.is_finite() {
            cell.max(1e-3)
        } else {
            0.2
        };
        Footprint {
            cell,
            x0: 0,
            y0: 0,
            w: 0,
            h: 0,
            bits: Vec::new(),
        }
    }

    /// Cell size in metres.
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The grid's lower and upper corners in frame coordinates (m); `None`
    /// for an empty grid.
    pub fn extent(&self) -> Option<(DVec2, DVec2)> {
        if self.w == 0 || self.h == 0 {
            return None;
        }
        let lo = DVec2::new(self.x0 as f64, self.y0 as f64) * self.cell;
        let size = DVec2::new(self.w as f64, self.h as f64) * self.cell;
        Some((lo, lo + size))
    }

    #[inline]
    fn index_of(&self, p: DVec2) -> (i64, i64) {
        cell_index(p, 1.0 / self.cell)
    }

    /// Grow the grid to cover cells `lo..=hi`; false (the grid unchanged)
    /// when that would exceed [`MAX_CELLS`] or the offset limit.
    fn grow_to(&mut self, lo: (i64, i64), hi: (i64, i64)) -> bool {
        // i128: cell indices saturate at the i64 range for huge coordinates.
        let (lo, hi) = ((lo.0 as i128, lo.1 as i128), (hi.0 as i128, hi.1 as i128));
        let (x0, y0) = (self.x0 as i128, self.y0 as i128);
        let (w, h) = (self.w as i128, self.h as i128);
        if w > 0 && lo.0 >= x0 && lo.1 >= y0 && hi.0 < x0 + w && hi.1 < y0 + h {
            return true;
        }
        let (mut nx0, mut ny0, mut nx1, mut ny1) = (lo.0, lo.1, hi.0 + 1, hi.1 + 1);
        if w > 0 {
            nx0 = nx0.min(x0);
            ny0 = ny0.min(y0);
            nx1 = nx1.max(x0 + w);
            ny1 = ny1.max(y0 + h);
            // Amortise: leave a quarter of the size as slack on the growing sides.
            // (Both sizes are positive: a shift, not an i128 division.)
            let (sx, sy) = (((nx1 - nx0) >> 2) + 4, ((ny1 - ny0) >> 2) + 4);
            if lo.0 < x0 {
                nx0 -= sx;
            }
            if hi.0 >= x0 + w {
                nx1 += sx;
            }
            if lo.1 < y0 {
                ny0 -= sy;
            }
            if hi.1 >= y0 + h {
                ny1 += sy;
            }
        }
        let fits = (nx1 - nx0) * (ny1 - ny0) <= MAX_CELLS as i128
            && [nx0, ny0, nx1, ny1].iter().all(|v| v.abs() <= MAX_OFFSET);
        if !fits {
            return false;
        }
        let (nx0, ny0) = (nx0 as i64, ny0 as i64);
        let (nw, nh) = ((nx1 as i64 - nx0) as usize, (ny1 as i64 - ny0) as usize);
        let mut bits = vec![0u64; (nw * nh).div_ceil(64)];
        for y in 0..self.h {
            for x in 0..self.w {
                if self.get_local(x, y) {
                    let gx = (self.x0 + x as i64 - nx0) as usize;
                    let gy = (self.y0 + y as i64 - ny0) as usize;
                    let k = gy * nw + gx;
                    bits[k >> 6] |= 1 << (k & 63);
                }
            }
        }
        *self = Footprint {
            cell: self.cell,
            x0: nx0,
            y0: ny0,
            w: nw,
            h: nh,
            bits,
        };
        true
    }

    /// Call `f` with the column of every set cell of row `y`, in order
    /// (a word at a time: empty stretches cost almost nothing).
    #[inline]
    fn row_set_cells(&self, y: usize, mut f: impl FnMut(usize)) {
        let (start, end) = (y * self.w, (y + 1) * self.w);
        let mut k = start;
        while k < end {
            let off = k & 63;
            let take = (64 - off).min(end - k);
            let mut bits = self.bits[k >> 6] >> off;
            if take < 64 {
                bits &= (1u64 << take) - 1;
            }
            while bits != 0 {
                f(k + bits.trailing_zeros() as usize - start);
                bits &= bits - 1;
            }
            k += take;
        }
    }

    #[inline]
    fn get_local(&self, x: usize, y: usize) -> bool {
        let k = y * self.w + x;
        self.bits[k >> 6] >> (k & 63) & 1 == 1
    }

    /// Is the cell containing `p` set?
    pub fn is_set(&self, p: DVec2) -> bool {
        let (ix, iy) = self.index_of(p);
        let (x, y) = (ix - self.x0, iy - self.y0);
        x >= 0
            && y >= 0
            && (x as usize) < self.w
            && (y as usize) < self.h
            && self.get_local(x as usize, y as usize)
    }

    /// Set the cells of all `points` (frame coordinates, metres); returns
    /// how many cells were newly set. Non-finite points are ignored.
    pub fn mark_all(&mut self, points: &[DVec2]) -> usize {
        let inv = 1.0 / self.cell;
        // The cells of the points' box corners bound every point's cell
        // (the cell index is monotone in the coordinate).
        let (mut plo, mut phi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &p in points {
            if p.is_finite() {
                super::numeric::grow_box(&mut plo, &mut phi, p);
            }
        }
        if plo.x > phi.x {
            return 0;
        }
        // When the grid cannot grow that far, the points outside it are left out.
        let _ = self.grow_to(cell_index(plo, inv), cell_index(phi, inv));
        let (x0, y0, w, h) = (self.x0, self.y0, self.w as u64, self.h as u64);
        let mut fresh = 0;
        for &p in points {
            if !p.is_finite() {
                continue;
            }
            let (x, y) = cell_index(p, inv);
            // Exact: |cell index| < 2^63 and |x0| is bounded, so the
            // wrapped difference is in 0..w only when the true one is.
            let (x, y) = (x.wrapping_sub(x0) as u64, y.wrapping_sub(y0) as u64);
            if x >= w || y >= h {
                continue;
            }
            let k = y as usize * self.w + x as usize;
            fresh += (self.bits[k >> 6] >> (k & 63) & 1 == 0) as usize;
            self.bits[k >> 6] |= 1 << (k & 63);
        }
        fresh
    }

    /// Clear the set cells outside `region` (traced from this footprint):
    /// afterwards the footprint holds exactly the cells of the points the
    /// region contains.
    pub fn retain_region(&mut self, region: &Region) {
        for y in 0..self.h {
            for x in 0..self.w {
                if self.get_local(x, y)
                    && !region.contains(self.centre(self.x0 + x as i64, self.y0 + y as i64))
                {
                    let k = y * self.w + x;
                    self.bits[k >> 6] &= !(1 << (k & 63));
                }
            }
        }
    }

    /// Number of set cells.
    pub fn count(&self) -> usize {
        self.bits.iter().map(|b| b.count_ones() as usize).sum()
    }

    /// Area of the set cells in square metres.
    pub fn occupied_area(&self) -> f64 {
        self.count() as f64 * self.cell * self.cell
    }

    /// Area of the blocks of 2 x 2 cells (aligned on even cell indices)
    /// that hold a set cell, in square metres: the occupied area at twice
    /// the cell size.
    pub fn occupied_block_area(&self) -> f64 {
        if self.w == 0 || self.h == 0 {
            return 0.0;
        }
        let (w, h) = (self.w as i64, self.h as i64);
        let (bx0, by0) = (self.x0.div_euclid(2), self.y0.div_euclid(2));
        let (bx1, by1) = (
            (self.x0 + w - 1).div_euclid(2),
            (self.y0 + h - 1).div_euclid(2),
        );
        let set = |x: i64, y: i64| {
            let (x, y) = (x - self.x0, y - self.y0);
            (0..w).contains(&x) && (0..h).contains(&y) && self.get_local(x as usize, y as usize)
        };
        let mut blocks = 0usize;
        for by in by0..=by1 {
            for bx in bx0..=bx1 {
                let (x, y) = (2 * bx, 2 * by);
                blocks +=
                    (set(x, y) || set(x + 1, y) || set(x, y + 1) || set(x + 1, y + 1)) as usize;
            }
        }
        blocks as f64 * 4.0 * self.cell * self.cell
    }

    /// Centres of the set cells (frame coordinates), in row-major order.
    pub fn cell_centres(&self) -> Vec<DVec2> {
        let mut out = Vec::new();
        for y in 0..self.h {
            for x in 0..self.w {
                if self.get_local(x, y) {
                    out.push(self.centre(self.x0 + x as i64, self.y0 + y as i64));
                }
            }
        }
        out
    }

    /// Bridge the gaps between laser rings that the ground's clustering
    /// bridged: from each set cell farther than `range` from `foot`, walk
    /// towards `foot`; when a set cell lies within the clustering's reach
    /// (back along the line of sight to where the distance after pulling,
    /// `geometry::pull_range`, is `tol` less), set the cells in between.
    /// Only gaps with set cells on both sides are filled, never the area in
    /// front of the nearest points, and only those at least `narrowest`
    /// wide (an outline's closing fills the narrower ones). Each walk is at
    /// most [`MAX_TRAIL`] cells; the walks read the cells as they were
    /// before. Returns how many cells were newly set.
    // Not inlined: it runs once per ground candidate of one-shot detection,
    // and its code stays out of the shape step it is called from.
    #[inline(never)]
    pub fn bridge_towards(&mut self, foot: DVec2, range: f64, tol: f64, narrowest: f64) -> usize {
        if !(range > 0.0 && tol > 0.0 && foot.is_finite()) {
            return 0;
        }
        let step = self.cell;
        // NaN and negative widths start at the nearest possible gap.
        let first = ((narrowest / step).ceil() as usize).clamp(2, MAX_TRAIL + 1);
        let mut fill: Vec<DVec2> = Vec::new();
        for y in 0..self.h {
            self.row_set_cells(y, |x| {
                let c = self.centre(self.x0 + x as i64, self.y0 + y as i64);
                let d = foot - c;
                // std sqrt: one instruction in wasm, the same bits everywhere.
                let r = d.length_squared().sqrt();
                if r.is_nan() || r <= range {
                    return;
                }
                // Not past the foot, whatever the tolerance.
                let back =
                    super::numeric::unpull_range(super::numeric::pull_range(r, range) - tol, range)
                        .max(0.0);
                let reach = ((r - back) / step) as usize;
                let u = d * (step / r);
                if let Some(j) =
                    (first..=reach.min(MAX_TRAIL)).find(|&j| self.is_set(c + u * j as f64))
                {
                    fill.extend((1..j).map(|i| c + u * i as f64));
                }
            });
        }
        // Between two set cells: inside the grid, which does not grow.
        self.mark_all(&fill)
    }

    fn centre(&self, ix: i64, iy: i64) -> DVec2 {
        DVec2::new((ix as f64 + 0.5) * self.cell, (iy as f64 + 0.5) * self.cell)
    }

    /// Bytes held by the grid.
    pub fn heap_bytes(&self) -> usize {
        self.bits.len() * 8
    }

    /// Concave outline (see the module docs): closing radius `alpha` metres,
    /// simplification `tolerance` metres, at most `max_vertices` vertices,
    /// holes of at least `min_hole` square metres left out (see
    /// [`Footprint::outline_region`]). Counter-clockwise, simple; `None` when
    /// nothing is set.
    pub fn outline(
        &self,
        alpha: f64,
        tolerance: f64,
        max_vertices: usize,
        min_hole: f64,
    ) -> Option<Vec<DVec2>> {
        self.outline_region(alpha, tolerance, max_vertices, min_hole)
            .map(|(r, _)| r)
    }

    /// [`Footprint::outline`] together with the raster region it traces, to
    /// test which points the outline was made from.
    ///
    /// A hole the closing leaves inside the region (no point within `alpha`
    /// of its cells) of at least `min_hole` square metres is area where
    /// nothing was seen, and the outline leaves it out: the region is cut
    /// along the shortest of four straight walks of cells (along the grid's
    /// axes) from the hole to its edge, and the ring runs in along one side
    /// of the cut, around the hole and out along the other: a slit one cell
    /// wide, or two where the traced ring is moved in by half a cell (not
    /// where that would collapse a part one cell wide, as on most outlines
    /// of real scans). A polygon is one simple ring, and stays so. Only
    /// an outline that fits `max_vertices` at `tolerance` with its holes
    /// left out gets them: a hole never costs the outer shape its
    /// resolution. The region's cells, for the point tests, hold the cuts'
    /// cells.
    pub fn outline_region(
        &self,
        alpha: f64,
        tolerance: f64,
        max_vertices: usize,
        min_hole: f64,
    ) -> Option<(Vec<DVec2>, Region)> {
        if self.count() == 0 {
            return None;
        }
        // Work grid: the occupied bounding box plus a margin for the closing,
        // coarsened until it fits the cell budget.
        let (mut lx, mut ly, mut hx, mut hy) = (usize::MAX, usize::MAX, 0, 0);
        for y in 0..self.h {
            let mut any = false;
            self.row_set_cells(y, |x| {
                lx = lx.min(x);
                hx = hx.max(x);
                any = true;
            });
            if any {
                ly = ly.min(y);
                hy = y;
            }
        }
        let mut factor = 1usize;
        loop {
            let r = ((alpha.max(0.0) / (self.cell * factor as f64)).ceil() as usize).min(4096);
            let m = r + 2;
            let gw = (hx - lx) / factor + 1 + 2 * m;
            let gh = (hy - ly) / factor + 1 + 2 * m;
            if gw * gh > MAX_TRACE_CELLS && factor < 1 << 12 {
                factor *= 2;
                continue;
            }
            let mut grid = BitGrid::new(gw, gh);
            for y in ly..=hy {
                let gy = (y - ly) / factor + m;
                self.row_set_cells(y, |x| grid.set((x - lx) / factor + m, gy));
            }
            let closing = Closing::new(grid, r)?;
            let cs = self.cell * factor as f64;
            let ox = (self.x0 + lx as i64) as f64 * self.cell - m as f64 * cs;
            let oy = (self.y0 + ly as i64) as f64 * self.cell - m as f64 * cs;
            let ring_of = |corners: Vec<(i64, i64)>| {
                let mut ring: Vec<DVec2> = corners
                    .into_iter()
                    .map(|(x, y)| DVec2::new(ox + x as f64 * cs, oy + y as f64 * cs))
                    .collect();
                make_ccw(&mut ring);
                remove_collinear(&mut ring);
                if ring.len() < 3 {
                    return None;
                }
                // The traced ring runs along the outer edges of the boundary
                // cells, half a cell beyond the points on average: move it in
                // by half a cell (through the boundary cells' centres),
                // unless that would collapse a one-cell-wide part or, in
                // rounding, the whole ring: a region one cell wide everywhere
                // (a curb's face seen along one laser ring) insets to a line,
                // which rounding left as a ring of area 1e-17 that passes as
                // simple. An inset that keeps a region keeps at least half a
                // cell's area (a 2 x 2 block of cells insets to one cell).
                let inset = inset_rectilinear(&ring, 0.5 * cs);
                if is_simple(&inset) && signed_area(&inset) >= 0.5 * cs * cs {
                    ring = inset;
                }
                Some(ring)
            };
            let tolerance = tolerance.max(0.0);
            // NaN and negative sizes cut no hole, nor does a hole of no cells.
            let min_hole = if min_hole >= 0.0 {
                ((min_hole / (cs * cs)).ceil() as usize).max(1)
            } else {
                usize::MAX
            };
            let trace = |cuts: &[u32]| {
                closing
                    .trace(cuts)
                    .and_then(|(c, inside)| Some((ring_of(c)?, inside)))
            };
            // First with every hole filled; the cuts only if that fits.
            let (ring, inside) = trace(&[])?;
            let mut splits = DouglasPeucker::new(&ring, tolerance);
            let (mut out, inside) = match splits.within(tolerance, max_vertices) {
                None => (splits.raised(tolerance, max_vertices), inside),
                Some(filled) => {
                    let cuts = closing.cuts(min_hole);
                    let cut = if cuts.is_empty() { None } else { trace(&cuts) };
                    cut.and_then(|(r, i)| Some((simplify_within(&r, tolerance, max_vertices)?, i)))
                        .unwrap_or((filled, inside))
                }
            };
            make_ccw(&mut out);
            let region = Region {
                inv: 1.0 / self.cell,
                base: (self.x0 + lx as i64, self.y0 + ly as i64),
                shift: factor.trailing_zeros(),
                margin: m as i64,
                w: gw,
                h: gh,
                inside,
            };
            return Some((out, region));
        }
    }

    /// Copy another footprint's set cells into this one, mapping each set
    /// cell centre through `map` (used when merging primitives with different
    /// frames).
    pub fn merge_mapped(&mut self, other: &Footprint, map: impl Fn(DVec2) -> DVec2) {
        let pts: Vec<DVec2> = other.cell_centres().into_iter().map(map).collect();
        let _ = self.mark_all(&pts);
    }

    /// Points that cover this footprint's set cells whole for a footprint
    /// of cell `cell` (finer, or as fine on another grid), each mapped
    /// through `map`: n x n a cell, no farther apart than half of `cell`.
    /// [`Footprint::merge_mapped`]'s cell centres alone would leave holes
    /// in a finer raster.
    pub fn covering_points(&self, cell: f64, map: impl Fn(DVec2) -> DVec2) -> Vec<DVec2> {
        let n = (self.cell / cell).ceil() as usize + 1;
        let step = self.cell / n as f64;
        let mut out = Vec::new();
        for c in self.cell_centres() {
            let corner = c - DVec2::splat(0.5 * (self.cell - step));
            for k in 0..n * n {
                out.push(map(
                    corner + DVec2::new((k % n) as f64, (k / n) as f64) * step
                ));
            }
        }
        out
    }
}

/// The raster region a concave outline was traced from (before
/// simplification): the outline is within the simplification tolerance of
/// this region's boundary.
#[derive(Clone, Debug)]
pub struct Region {
    /// Inverse of the footprint's cell side.
    inv: f64,
    base: (i64, i64),
    /// Footprint cells per region cell: `1 << shift` (a power of two).
    shift: u32,
    margin: i64,
    w: usize,
    h: usize,
    inside: Vec<bool>,
}

/// The footprint cell of `p` for cells of side `1 / inv` (every footprint
/// and region lookup goes through here, so they agree to the last bit).
#[inline]
fn cell_index(p: DVec2, inv: f64) -> (i64, i64) {
    (
        super::numeric::floor_i64(p.x * inv),
        super::numeric::floor_i64(p.y * inv),
    )
}

impl Region {
    /// Does the footprint cell under `p` belong to the region? Uses the
    /// footprint's own cell indexing, so it agrees exactly with `mark_all`.
    pub fn contains(&self, p: DVec2) -> bool {
        let (ix, iy) = cell_index(p, self.inv);
        // An arithmetic shift is floor division by the power of two.
        let x = ((ix - self.base.0) >> self.shift) + self.margin;
        let y = ((iy - self.base.1) >> self.shift) + self.margin;
        x >= 0
            && y >= 0
            && (x as usize) < self.w
            && (y as usize) < self.h
            && self.inside[y as usize * self.w + x as usize]
    }
}

/// Offset a counter-clockwise rectilinear ring inwards by `d` (each edge
/// moves along its left normal; vertices move along the miter).
fn inset_rectilinear(ring: &[DVec2], d: f64) -> Vec<DVec2> {
    let n = ring.len();
    let left = |e: DVec2| DVec2::new(-e.y, e.x);
    (0..n)
        .map(|i| {
            let prev = ring[(i + n - 1) % n];
            let cur = ring[i];
            let next = ring[(i + 1) % n];
            let a = left(super::numeric::unit_or_zero(cur - prev));
            let b = left(super::numeric::unit_or_zero(next - cur));
            cur + (a + b) * d
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polygon::{contains, distance, is_simple, signed_area};

    #[test]
    fn huge_extents_are_bounded_not_a_crash() {
        // Regression: points 30 km apart at 0.2 m cells asked for 2e10 cells,
        // which overflowed usize on wasm32 and indexed out of bounds.
        let mut fp = Footprint::new(0.2);
        let pts: Vec<DVec2> = (0..60)
            .flat_map(|i| (0..60).map(move |j| DVec2::new(i as f64 * 500.0, j as f64 * 500.0)))
            .collect();
        fp.mark_all(&pts);
        assert!((fp.w as u64) * (fp.h as u64) <= MAX_CELLS);
        // What fits is kept; huge and saturating coordinates are harmless.
        fp.mark_all(&[DVec2::new(1e300, -1e300), DVec2::new(f64::MAX, 0.0)]);
        let mut small = Footprint::new(0.2);
        assert_eq!(
            small.mark_all(&[DVec2::new(1.0, 1.0), DVec2::new(1e300, 1.0)]),
            0
        );
        assert_eq!(small.mark_all(&[DVec2::new(1.0, 1.0)]), 1);
        assert!(small.is_set(DVec2::new(1.0, 1.0)));
        let _ = small.outline(0.5, 0.1, 64, f64::INFINITY);
    }

    #[test]
    fn a_strip_one_cell_wide_keeps_its_area() {
        // A laser ring across a curb's face: points along one row of cells.
        // The half-cell inset takes the ring to a line; at some rows of
        // these 120 m, rounding left that line a ring of area ~1e-17 that
        // passed as simple. The outline is the traced strip instead.
        for row in -300..300 {
            let y = row as f64 * 0.2 + 0.0137;
            let mut fp = Footprint::new(0.2);
            let pts: Vec<DVec2> = (0..9)
                .map(|i| DVec2::new(-26.7565 + 0.0247 * i as f64, y))
                .collect();
            fp.mark_all(&pts);
            let ring = fp.outline(0.5, 0.1, 64, f64::INFINITY).unwrap();
            assert!(is_simple(&ring), "{ring:?}");
            assert!(signed_area(&ring) >= 0.039, "{y}: {ring:?}");
        }
    }

    #[test]
    fn block_area_counts_the_blocks_of_two_by_two_cells_with_support() {
        assert_eq!(Footprint::new(0.2).occupied_block_area(), 0.0);
        // Rows of points 0.45 m apart on 0.2 m cells: a laser ring pattern.
        // About 1 cell row in 2.25 is set, but 8 block rows of 9.
        let mut fp = Footprint::new(0.2);
        let pts: Vec<DVec2> = (0..8)
            .flat_map(|r| {
                (0..40).map(move |i| DVec2::new(0.05 + 0.1 * i as f64, 0.07 + 0.45 * r as f64))
            })
            .collect();
        fp.mark_all(&pts);
        let cells = fp.occupied_area();
        assert!((cells - 8.0 * 20.0 * 0.04).abs() < 1e-9, "{cells}");
        // Rows in cells 0, 2, 4, 7, 9, 11, 13, 16: blocks 0-6 and 8; x in
        // cells 0-19: blocks 0-9.
        let blocks = fp.occupied_block_area();
        assert!((blocks - 8.0 * 10.0 * 0.16).abs() < 1e-9, "{blocks}");
        // Negative cell indices align the same way (floor division).
        let mut neg = Footprint::new(0.2);
        neg.mark_all(&[DVec2::new(-0.1, -0.1), DVec2::new(-0.3, -0.3)]);
        assert!((neg.occupied_block_area() - 0.16).abs() < 1e-12);
        neg.mark_all(&[DVec2::new(0.1, 0.1)]);
        assert!((neg.occupied_block_area() - 0.32).abs() < 1e-12);
    }

    #[test]
    fn bridges_only_gaps_between_rings_that_the_range_allows() {
        // Foot at the origin, range 20 m, tolerance 0.5 m: at 60 m the
        // reach is 0.5 * 3600 / (400 + 30) = 4.19 m.
        let at = |x: f64| DVec2::new(x, 0.1);
        let mut fp = Footprint::new(0.2);
        // Ring pairs 3 m apart (bridged) at 60 m, 6 m apart (not) at 40 m
        // (reach 1.90 m), and a lone point at 30 m.
        fp.mark_all(&[at(57.1), at(60.1), at(34.1), at(40.1), at(30.1)]);
        let before = fp.count();
        let fresh = fp.bridge_towards(DVec2::ZERO, 20.0, 0.5, 0.0);
        assert_eq!(fresh, 14, "the cells strictly between 57.1 and 60.1");
        assert_eq!(fp.count(), before + 14);
        for x in [57.3, 58.5, 59.9] {
            assert!(fp.is_set(at(x)), "{x}");
        }
        for x in [56.9, 35.0, 39.9, 29.9, 60.3] {
            assert!(!fp.is_set(at(x)), "{x}");
        }
        // Gaps narrower than asked for are left.
        let mut narrow = Footprint::new(0.2);
        narrow.mark_all(&[at(57.1), at(60.1)]);
        assert_eq!(narrow.bridge_towards(DVec2::ZERO, 20.0, 0.5, 3.1), 0);
        assert_eq!(narrow.bridge_towards(DVec2::ZERO, 20.0, 0.5, 2.9), 14);
        // Inside the range nothing is bridged, and bad arguments are no-ops.
        let mut near = Footprint::new(0.2);
        near.mark_all(&[at(10.1), at(11.1)]);
        assert_eq!(near.bridge_towards(DVec2::ZERO, 20.0, 0.5, 0.0), 0);
        assert_eq!(fp.bridge_towards(DVec2::NAN, 20.0, 0.5, 0.0), 0);
        assert_eq!(fp.bridge_towards(DVec2::ZERO, 0.0, 0.5, 0.0), 0);
        assert_eq!(fp.bridge_towards(DVec2::ZERO, 20.0, f64::NAN, 0.0), 0);
        let mut nan = Footprint::new(0.2);
        nan.mark_all(&[at(57.1), at(60.1)]);
        assert_eq!(nan.bridge_towards(DVec2::ZERO, 20.0, 0.5, f64::NAN), 14);
    }

    #[test]
    fn serialises_words_as_hex_and_rejects_inconsistent_grids() {
        let mut fp = Footprint::new(0.25);
        // Cells spread over many words, so that high bits are set.
        let pts: Vec<DVec2> = (0..300)
            .map(|i| DVec2::new((i % 37) as f64 * 0.25, (i / 37) as f64 * 0.5))
            .collect();
        fp.mark_all(&pts);
        assert!(fp.bits.iter().any(|&w| w > 1 << 53));
        let text = serde_json::to_string(&fp).unwrap();
        assert!(text.contains("\"bits\":\""), "{text}");
        let back: Footprint = serde_json::from_str(&text).unwrap();
        assert_eq!(back, fp);
        // The earlier format: an array of integers.
        let mut v = serde_json::to_value(&fp).unwrap();
        v["bits"] = serde_json::json!(fp.bits);
        assert_eq!(serde_json::from_value::<Footprint>(v.clone()).unwrap(), fp);
        // Inconsistent or corrupt grids are refused.
        for (key, bad) in [
            ("bits", serde_json::json!("00ff")),
            ("bits", serde_json::json!("zz".repeat(8 * fp.bits.len()))),
            ("bits", serde_json::json!([1, 2])),
            ("w", serde_json::json!(1u64 << 40)),
            ("h", serde_json::json!(0)),
            ("cell", serde_json::json!(0.0)),
            ("x0", serde_json::json!(i64::MIN)),
        ] {
            let mut b = v.clone();
            b[key] = bad.clone();
            assert!(
                serde_json::from_value::<Footprint>(b).is_err(),
                "{key} = {bad}"
            );
        }
    }

    fn grid_points(f: impl Fn(f64, f64) -> bool, step: f64, n: usize) -> Vec<DVec2> {
        let mut v = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let p = DVec2::new((i as f64 + 0.5) * step, (j as f64 + 0.5) * step);
                if f(p.x, p.y) {
                    v.push(p);
                }
            }
        }
        v
    }

    #[test]
    fn l_shape_outline_leaves_the_missing_corner_out() {
        // L: 10 x 10 square minus the [5,10] x [5,10] quadrant.
        let pts = grid_points(|x, y| !(x > 5.0 && y > 5.0), 0.1, 101);
        let mut fp = Footprint::new(0.1);
        fp.mark_all(&pts);
        let ring = fp.outline(0.3, 0.05, 200, f64::INFINITY).unwrap();
        assert!(is_simple(&ring));
        assert!(signed_area(&ring) > 0.0);
        assert!(
            !contains(&ring, DVec2::new(8.0, 8.0)),
            "missing corner covered"
        );
        assert!(contains(&ring, DVec2::new(2.0, 8.0)));
        let a = signed_area(&ring);
        assert!((a - 75.0).abs() < 3.0, "area {a}");
        assert!(ring.len() <= 12, "{} vertices", ring.len());
    }

    #[test]
    fn closing_bridges_gaps_narrower_than_two_alpha() {
        // Two strips 0.6 m apart: alpha 0.4 joins them, alpha 0.2 does not.
        let pts = grid_points(|_, y| !(2.0..=2.6).contains(&y), 0.05, 100);
        let mut fp = Footprint::new(0.05);
        fp.mark_all(&pts);
        let joined = fp.outline(0.4, 0.02, 100, f64::INFINITY).unwrap();
        assert!(contains(&joined, DVec2::new(2.0, 2.3)));
        let split = fp.outline(0.2, 0.02, 100, f64::INFINITY).unwrap();
        assert!(!contains(&split, DVec2::new(2.0, 2.3)));
        assert!(is_simple(&split));
    }

    #[test]
    fn holes_are_filled_and_growth_keeps_cells() {
        let ring_pts = grid_points(|x, y| !(x > 3.0 && x < 6.0 && y > 3.0 && y < 6.0), 0.1, 91);
        let mut fp = Footprint::new(0.1);
        fp.mark_all(&ring_pts[..ring_pts.len() / 2]);
        let before = fp.count();
        fp.mark_all(&ring_pts[ring_pts.len() / 2..]);
        assert!(fp.count() > before);
        assert!(fp.is_set(DVec2::new(0.05, 0.05)));
        let o = fp.outline(0.0, 0.0, 1000, f64::INFINITY).unwrap();
        assert!(contains(&o, DVec2::new(4.5, 4.5)), "hole not filled");
        assert!(is_simple(&o));
        // A hole smaller than `min_hole` is filled too.
        assert_eq!(fp.outline(0.0, 0.0, 1000, 10.0).unwrap(), o);
    }

    #[test]
    fn a_hole_of_min_hole_or_more_is_left_out_through_a_slit() {
        // A 9 x 9 m square of points with a 3 x 3 m hole: nothing seen there.
        let pts = grid_points(|x, y| !(x > 3.0 && x < 6.0 && y > 3.0 && y < 6.0), 0.1, 91);
        let mut fp = Footprint::new(0.1);
        fp.mark_all(&pts);
        for alpha in [0.0, 0.5] {
            let o = fp.outline(alpha, 0.05, 1000, 5.0).unwrap();
            assert!(is_simple(&o), "alpha {alpha}: {o:?}");
            assert!(
                !contains(&o, DVec2::new(4.5, 4.5)),
                "alpha {alpha}: hole kept"
            );
            // The square (9 m between the outer points' cells' centres) less
            // the hole (3.1 m a side after the inset) and a slit 0.2 m wide
            // across the 3 m to the edge; the closing rounds the hole's
            // corners (alpha 0.5: up to (4 - pi) * 0.25 = 0.21 m^2 back).
            let a = signed_area(&o);
            let want = 81.0 - 3.1 * 3.1 - 3.0 * 0.2;
            assert!(
                a > want - 0.1 && a < want + 0.5,
                "alpha {alpha}: {a} against {want}"
            );
            // Every point lies on or in the outline but the 30 along the slit.
            let off = pts.iter().filter(|&&p| distance(&o, p) > 1e-9).count();
            assert!(off <= 31, "{off} points off the outline");
        }
        // The region, for the point tests, holds every point.
        let (_, region) = fp.outline_region(0.0, 0.05, 1000, 5.0).unwrap();
        assert!(pts.iter().all(|&p| region.contains(p)));
    }

    #[test]
    fn holes_are_cut_only_when_the_outline_keeps_its_resolution() {
        // A 20 x 4 m strip with five 1 x 1 m holes: cutting them takes about
        // 45 vertices. In 30 the outer shape would have to coarsen, so none
        // is cut and the strip keeps its corners.
        let hole = |x: f64, y: f64| (1.0..2.0).contains(&(x % 4.0)) && y > 1.5 && y < 2.5;
        let pts: Vec<DVec2> = grid_points(|x, y| y < 4.0 && x < 20.0 && !hole(x, y), 0.1, 201);
        let mut fp = Footprint::new(0.1);
        fp.mark_all(&pts);
        let cut = |o: &[DVec2]| {
            (0..5)
                .filter(|&i| !contains(o, DVec2::new(4.0 * i as f64 + 1.5, 2.0)))
                .count()
        };
        let all = fp.outline(0.0, 0.05, 1000, 0.5).unwrap();
        assert_eq!(cut(&all), 5);
        assert!(all.len() > 30, "{} vertices", all.len());
        let few = fp.outline(0.0, 0.05, 30, 0.5).unwrap();
        assert_eq!(cut(&few), 0);
        assert_eq!(few, fp.outline(0.0, 0.05, 30, f64::INFINITY).unwrap());
        for c in [(0.0, 0.0), (20.0, 0.0), (20.0, 4.0), (0.0, 4.0)] {
            let c = DVec2::new(c.0, c.1);
            let d = few
                .iter()
                .map(|v| v.distance(c))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 0.2, "corner {c} is {d} m from the outline's vertices");
        }
    }

    #[test]
    fn diagonal_touching_cells_never_make_a_pinch() {
        // A checkerboard: every outline must still be simple.
        let pts = grid_points(|x, y| ((x as i64) + (y as i64)) % 2 == 0, 1.0, 9);
        let mut fp = Footprint::new(1.0);
        fp.mark_all(&pts);
        for alpha in [0.0, 0.5, 1.0, 2.0] {
            for min_hole in [0.0, 1.0, f64::INFINITY] {
                if let Some(o) = fp.outline(alpha, 0.0, 1000, min_hole) {
                    assert!(is_simple(&o), "alpha {alpha} min_hole {min_hole}");
                }
            }
        }
    }
}
