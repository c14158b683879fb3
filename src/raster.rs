//! A raster of bits and the operations on it that the outlines and masks
//! need: binary dilation by a disk, closing, labelling of 4-connected
//! regions by horizontal runs, and tracing a region's boundary along cell
//! edges. Integer cells only, 64 to a word: nothing here knows about
//! metres, frames or points, which is why it is a top-level module and not
//! part of `geometry` (whose footprint and masks use it). It imports
//! nothing of the crate.

/// A traced region: its outer ring (grid corners) and its cells.
pub(crate) type Traced = (Vec<(i64, i64)>, Vec<bool>);

/// A grid closed for tracing: the closing, the exterior of its largest
/// 4-connected region (the region's holes filled) and how many cells the
/// region encloses that are not in it.
pub(crate) struct Closing {
    closed: BitGrid,
    outside: Vec<bool>,
    enclosed: usize,
}

impl Closing {
    /// Close `grid` with a disk of radius `r` cells and find its largest
    /// 4-connected region. `None` when no cell is set.
    pub(crate) fn new(grid: BitGrid, r: usize) -> Option<Closing> {
        if grid.w == 0 || grid.h == 0 {
            return None;
        }
        let closed = grid.closed(r);
        let (outside, enclosed) = exterior_of_largest_region(&closed)?;
        Some(Closing {
            closed,
            outside,
            enclosed,
        })
    }

    /// The cells to clear so that each hole of at least `min_hole` cells (a
    /// 4-connected component of the cells the region encloses that the
    /// closing left clear) joins the exterior: for each, the region's cells
    /// on the shortest of four straight walks (down, left, up, right) from
    /// the hole to the exterior. Empty, at no cost, when the region
    /// encloses fewer cells.
    pub(crate) fn cuts(&self, min_hole: usize) -> Vec<u32> {
        if self.enclosed < min_hole.max(1) {
            return Vec::new();
        }
        keyholes(&self.closed, &self.outside, min_hole.max(1))
    }

    /// Trace the region with `cuts` made (the other holes filled): its
    /// outer boundary along cell edges, in grid-corner coordinates
    /// (counter-clockwise: the region on the left), and its cells, one
    /// bool per cell, the cut cells among them (a cut leaves no point
    /// outside the polygon's support). Should the cuts split the region,
    /// its largest part is traced.
    pub(crate) fn trace(&self, cuts: &[u32]) -> Option<Traced> {
        let (w, h) = (self.closed.w, self.closed.h);
        let recut;
        let outside = if cuts.is_empty() {
            &self.outside
        } else {
            let mut closed = self.closed.clone();
            for &k in cuts {
                closed.clear(k as usize % w, k as usize / w);
            }
            recut = exterior_of_largest_region(&closed)?.0;
            &recut
        };
        let ring = trace_ring(outside, w, h)?;
        let mut inside: Vec<bool> = outside.iter().map(|&o| !o).collect();
        for &k in cuts {
            inside[k as usize] = true;
        }
        Some((ring, inside))
    }
}

/// The outer boundary of the cells not `outside` (a hole-free 4-connected
/// region) along cell edges, counter-clockwise, in grid-corner coordinates.
fn trace_ring(outside: &[bool], w: usize, h: usize) -> Option<Vec<(i64, i64)>> {
    // The region's cells as bits (a row's padding is clear: beyond the
    // grid is outside).
    let region = BitGrid::where_cells_are(outside, false, w, h);
    let stride = region.stride;
    // Directed boundary edges with the region on the left; from each corner
    // exactly one leaves (no pinches), kept at its start corner as the way
    // it leaves (one byte; 0: none): right, up, left or down. A cell's
    // edges are set in the order bottom, right, top, left, cells in
    // row-major order.
    const RIGHT: u8 = 1;
    const UP: u8 = 2;
    const LEFT: u8 = 3;
    const DOWN: u8 = 4;
    let mut way: Vec<u8> = vec![0; (w + 1) * (h + 1)];
    let cid = |x: usize, y: usize| y * (w + 1) + x;
    let mut first = None;
    let none = vec![0u64; stride];
    for y in 0..h {
        let row = region.row(y);
        let below = if y > 0 { region.row(y - 1) } else { &none[..] };
        let above = if y + 1 < h {
            region.row(y + 1)
        } else {
            &none[..]
        };
        for (i, &cells) in row.iter().enumerate() {
            if cells == 0 {
                continue;
            }
            // Bit b: is the cell left (right) of cell b inside?
            let left_in = cells << 1 | if i > 0 { row[i - 1] >> 63 } else { 0 };
            let right_in = cells >> 1 | if i + 1 < stride { row[i + 1] << 63 } else { 0 };
            let bottom = cells & !below[i];
            let right = cells & !right_in;
            let top = cells & !above[i];
            let left = cells & !left_in;
            let mut edged = bottom | right | top | left;
            while edged != 0 {
                let b = edged.trailing_zeros() as usize;
                edged &= edged - 1;
                let (x, bit) = (i * 64 + b, 1u64 << b);
                // bottom edge (region above): left to right
                if bottom & bit != 0 {
                    way[cid(x, y)] = RIGHT;
                    first.get_or_insert(cid(x, y));
                }
                // right edge: bottom to top
                if right & bit != 0 {
                    way[cid(x + 1, y)] = UP;
                }
                // top edge: right to left
                if top & bit != 0 {
                    way[cid(x + 1, y + 1)] = LEFT;
                }
                // left edge: top to bottom
                if left & bit != 0 {
                    way[cid(x, y + 1)] = DOWN;
                }
            }
        }
    }
    let start = first?;
    let mut ring = Vec::new();
    let mut c = start;
    let limit = 4 * w * h + 4;
    loop {
        ring.push(((c % (w + 1)) as i64, (c / (w + 1)) as i64));
        c = match way[c] {
            RIGHT => c + 1,
            UP => c + (w + 1),
            LEFT => c - 1,
            DOWN => c - (w + 1),
            _ => return None,
        };
        if ring.len() > limit {
            return None;
        }
        if c == start {
            break;
        }
    }
    Some(ring)
}

/// The cells of `row` equal to `value`, as bits (cell `x` is bit `x % 64`
/// of word `x / 64`), into `dst`. Eight cells at a time: a bool is one
/// byte, 0 or 1, and multiplying eight such bytes by
/// `0x0102_0408_1020_4080` gathers byte `k` into bit `56 + k`.
fn pack_row(row: &[bool], value: bool, dst: &mut [u64]) {
    let flip = if value { 0 } else { 0xff };
    for (word, cells) in dst.iter_mut().zip(row.chunks(64)) {
        let mut v = 0u64;
        let mut groups = cells.chunks_exact(8);
        for (g, eight) in groups.by_ref().enumerate() {
            let bytes = u64::from_le_bytes(std::array::from_fn(|k| u8::from(eight[k])));
            let got = bytes.wrapping_mul(0x0102_0408_1020_4080) >> 56;
            v |= ((got ^ flip) & 0xff) << (8 * g);
        }
        let done = cells.len() - groups.remainder().len();
        for (k, &c) in groups.remainder().iter().enumerate() {
            v |= u64::from(c == value) << (done + k);
        }
        *word = v;
    }
}

/// The cuts of [`Closing::cuts`]: for each hole of the region `!outside`
/// (a 4-connected component of the cells it encloses that `closed` leaves
/// clear) of at least `min_hole` cells, the region cells of the straight
/// walk from the hole's first cell (row-major) to the exterior that
/// crosses the fewest, in one of the four directions (the first of equally
/// short ones: down, left, up, right).
///
/// Holes are opened one at a time, and what an earlier cut opened counts
/// as exterior for the later walks: its cut, its hole, and the holes it
/// passed through (which need no cut of their own). Each cut joins one
/// new hole to what is already open, so the cuts form a tree and never
/// enclose a part of the region: two cuts from one hole to the exterior
/// would cut off the region between them.
fn keyholes(closed: &BitGrid, outside: &[bool], min_hole: usize) -> Vec<u32> {
    let (w, h) = (closed.w, closed.h);
    const REGION: u8 = 0;
    const OUT: u8 = 1;
    const HOLE: u8 = 2;
    const FOUND: u8 = 3;
    // A hole under `min_hole` cells: filled unless a cut passes it.
    const SMALL: u8 = 4;
    let mut state: Vec<u8> = (0..w * h)
        .map(|k| match (outside[k], closed.get(k % w, k / w)) {
            (true, _) => OUT,
            (false, true) => REGION,
            (false, false) => HOLE,
        })
        .collect();
    let mut cuts = Vec::new();
    for k0 in 0..w * h {
        if state[k0] != HOLE {
            continue;
        }
        let cells = flood(&mut state, k0, w, h, |s| s == HOLE, FOUND);
        if cells.len() < min_hole {
            for &k in &cells {
                state[k] = SMALL;
            }
            continue;
        }
        // A straight walk from (x, y) by (dx, dy) up to what is open (the
        // grid's border cells are all exterior): the region cells it
        // crosses, and the cells of other holes it passes.
        let (x, y) = ((k0 % w) as isize, (k0 / w) as isize);
        let walk = |(dx, dy): (isize, isize)| {
            let (mut region, mut holes) = (Vec::new(), Vec::new());
            let (mut x, mut y) = (x + dx, y + dy);
            while x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h {
                let k = y as usize * w + x as usize;
                match state[k] {
                    OUT => break,
                    REGION => region.push(k as u32),
                    HOLE | SMALL => holes.push(k),
                    _ => {}
                }
                x += dx;
                y += dy;
            }
            (region, holes)
        };
        let Some((cut, passed)) = [(0, -1), (-1, 0), (0, 1), (1, 0)]
            .into_iter()
            .map(walk)
            .min_by_key(|(c, _)| c.len())
        else {
            continue;
        };
        // Open: the hole, the cut and every hole the cut passes.
        for &k in &cells {
            state[k] = OUT;
        }
        for &k in &cut {
            state[k as usize] = OUT;
        }
        for k in passed {
            if state[k] != OUT {
                flood(&mut state, k, w, h, |s| matches!(s, HOLE | SMALL), OUT);
            }
        }
        cuts.extend(cut);
    }
    cuts
}

/// Set `to` on cell `k0` and on every cell 4-connected to it through cells
/// whose state is `from`; returns them.
fn flood(
    state: &mut [u8],
    k0: usize,
    w: usize,
    h: usize,
    from: impl Fn(u8) -> bool,
    to: u8,
) -> Vec<usize> {
    state[k0] = to;
    let mut cells = vec![k0];
    let mut i = 0;
    while let Some(&k) = cells.get(i) {
        i += 1;
        for j in neighbours(k, w, h) {
            if from(state[j]) {
                state[j] = to;
                cells.push(j);
            }
        }
    }
    cells
}

/// The 4-neighbours of cell `k` of a `w` x `h` grid.
fn neighbours(k: usize, w: usize, h: usize) -> impl Iterator<Item = usize> {
    let (x, y) = (k % w, k / w);
    [
        (x > 0).then(|| k - 1),
        (x + 1 < w).then(|| k + 1),
        (y > 0).then(|| k - w),
        (y + 1 < h).then(|| k + w),
    ]
    .into_iter()
    .flatten()
}

/// The cells outside the largest 4-connected region of `closed` (the first
/// in row-major order of equally large ones) with its holes filled: those
/// reachable from the grid's border without crossing the region; and how
/// many cells it encloses that are not in it. `None` when no cell is set.
fn exterior_of_largest_region(closed: &BitGrid) -> Option<(Vec<bool>, usize)> {
    let (w, h) = (closed.w, closed.h);
    // Largest 4-connected region (first found wins ties: row-major order),
    // then its holes filled: everything not reachable from the border
    // through non-region cells belongs to it. Both on horizontal runs of
    // cells joined by union-find (rows overlap in a column: 4-connected),
    // which costs a pass over the cells plus work per run, not per cell.
    let (row_start, runs) = closed.runs();
    let root = connect_runs(&row_start, &runs);
    let mut size = vec![0usize; runs.len()];
    for (k, &(x0, x1)) in runs.iter().enumerate() {
        size[root[k] as usize] += (x1 - x0) as usize;
    }
    // Roots are each component's first run in row-major order, so the
    // strict comparison keeps the first of equally large regions.
    let mut best: Option<usize> = None;
    for k in 0..runs.len() {
        if root[k] as usize == k && best.is_none_or(|b| size[k] > size[b]) {
            best = Some(k);
        }
    }
    let best = best? as u32;
    // The gaps between the region's runs, row by row.
    let mut gap_start = Vec::with_capacity(h + 1);
    let mut gaps: Vec<(u32, u32)> = Vec::new();
    for y in 0..h {
        gap_start.push(gaps.len() as u32);
        let mut x = 0u32;
        for k in row_start[y] as usize..row_start[y + 1] as usize {
            if root[k] != best {
                continue;
            }
            let (x0, x1) = runs[k];
            if x0 > x {
                gaps.push((x, x0));
            }
            x = x1;
        }
        if (x as usize) < w {
            gaps.push((x, w as u32));
        }
    }
    gap_start.push(gaps.len() as u32);
    let gap_root = connect_runs(&gap_start, &gaps);
    let mut open = vec![false; gaps.len()];
    for y in 0..h {
        for k in gap_start[y] as usize..gap_start[y + 1] as usize {
            let (x0, x1) = gaps[k];
            if y == 0 || y + 1 == h || x0 == 0 || x1 as usize == w {
                open[gap_root[k] as usize] = true;
            }
        }
    }
    let mut outside = vec![false; w * h];
    let mut enclosed = 0;
    for y in 0..h {
        for k in gap_start[y] as usize..gap_start[y + 1] as usize {
            let (x0, x1) = gaps[k];
            if open[gap_root[k] as usize] {
                outside[y * w + x0 as usize..y * w + x1 as usize].fill(true);
            } else {
                enclosed += (x1 - x0) as usize;
            }
        }
    }
    Some((outside, enclosed))
}

/// A raster of bits, row by row, each row padded to whole 64-bit words
/// (padding bits always clear). Morphology on it works on 64 cells at a
/// time with plain integer operations, as fast in wasm as natively.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct BitGrid {
    w: usize,
    h: usize,
    stride: usize,
    words: Vec<u64>,
}

impl BitGrid {
    /// All clear, `w` by `h` cells.
    pub(crate) fn new(w: usize, h: usize) -> Self {
        let stride = w.div_ceil(64);
        BitGrid {
            w,
            h,
            stride,
            words: vec![0; stride * h],
        }
    }

    /// From one bool per cell, row-major.
    pub(crate) fn from_bools(cells: &[bool], w: usize, h: usize) -> Self {
        BitGrid::where_cells_are(cells, true, w, h)
    }

    /// The cells of `cells` (one bool per cell, row-major) equal to `value`.
    fn where_cells_are(cells: &[bool], value: bool, w: usize, h: usize) -> Self {
        let mut g = BitGrid::new(w, h);
        if w == 0 {
            return g;
        }
        let stride = g.stride;
        for (row, words) in cells
            .chunks(w)
            .take(h)
            .zip(g.words.chunks_exact_mut(stride))
        {
            pack_row(row, value, words);
        }
        g
    }

    /// One bool per cell, row-major.
    pub(crate) fn to_bools(&self) -> Vec<bool> {
        let mut out = vec![false; self.w * self.h];
        for y in 0..self.h {
            for (x0, x1) in self.row_runs(y) {
                out[y * self.w + x0 as usize..y * self.w + x1 as usize].fill(true);
            }
        }
        out
    }

    #[inline]
    pub(crate) fn get(&self, x: usize, y: usize) -> bool {
        self.words[y * self.stride + x / 64] >> (x % 64) & 1 == 1
    }

    #[inline]
    pub(crate) fn clear(&mut self, x: usize, y: usize) {
        self.words[y * self.stride + x / 64] &= !(1 << (x % 64));
    }

    #[inline]
    pub(crate) fn set(&mut self, x: usize, y: usize) {
        self.words[y * self.stride + x / 64] |= 1 << (x % 64);
    }

    fn row(&self, y: usize) -> &[u64] {
        &self.words[y * self.stride..(y + 1) * self.stride]
    }

    /// Mask of the valid bits of a row's last word.
    fn tail_mask(&self) -> u64 {
        match self.w % 64 {
            0 => !0,
            k => (1 << k) - 1,
        }
    }

    /// Morphological closing by a disk of radius `r` cells: dilation, then
    /// erosion (the dilation of the complement, complemented). The
    /// complement of the union of all empty disks of radius `r`.
    pub(crate) fn closed(self, r: usize) -> BitGrid {
        if r > 0 {
            let mut outside = dilate_bits(&self, r as f64);
            outside.invert();
            let mut closed = dilate_bits(&outside, r as f64);
            closed.invert();
            closed
        } else {
            self
        }
    }

    /// Flip every cell (padding stays clear).
    fn invert(&mut self) {
        let tail = self.tail_mask();
        for row in self.words.chunks_exact_mut(self.stride.max(1)) {
            for v in row.iter_mut() {
                *v = !*v;
            }
            if let Some(last) = row.last_mut() {
                *last &= tail;
            }
        }
    }

    /// The runs `[x0, x1)` of set cells of row `y`, left to right.
    fn row_runs(&self, y: usize) -> impl Iterator<Item = (u32, u32)> + '_ {
        let row = self.row(y);
        // First set (want = true) or clear (want = false) cell at or after x.
        let find = move |x: usize, want: bool| -> usize {
            let mut i = x / 64;
            if i >= row.len() {
                return self.w;
            }
            let flip = if want { 0 } else { !0 };
            let mut v = (row[i] ^ flip) & (!0u64 << (x % 64));
            loop {
                if v != 0 {
                    return (i * 64 + v.trailing_zeros() as usize).min(self.w);
                }
                i += 1;
                if i >= row.len() {
                    return self.w;
                }
                v = row[i] ^ flip;
            }
        };
        let mut x = 0;
        std::iter::from_fn(move || {
            let x0 = find(x, true);
            if x0 >= self.w {
                return None;
            }
            let x1 = find(x0, false);
            x = x1;
            Some((x0 as u32, x1 as u32))
        })
    }

    /// Horizontal runs of set cells, row by row: the runs of row `y` are
    /// `runs[start[y]..start[y + 1]]`.
    fn runs(&self) -> (Vec<u32>, Vec<(u32, u32)>) {
        let mut start = Vec::with_capacity(self.h + 1);
        let mut runs = Vec::new();
        for y in 0..self.h {
            start.push(runs.len() as u32);
            runs.extend(self.row_runs(y));
        }
        start.push(runs.len() as u32);
        (start, runs)
    }
}

/// `dst = src` grown by one cell left and right (within `tail` in the last
/// word).
fn widen_row(src: &[u64], dst: &mut [u64], tail: u64) {
    let n = src.len();
    for i in 0..n {
        let left = if i > 0 { src[i - 1] >> 63 } else { 0 };
        let right = if i + 1 < n { src[i + 1] << 63 } else { 0 };
        dst[i] = src[i] | src[i] << 1 | src[i] >> 1 | left | right;
    }
    if let Some(last) = dst.last_mut() {
        *last &= tail;
    }
}

/// Binary dilation by a disk of `radius` cells (centre to centre), exact:
/// a cell is set when a set cell lies `dy` rows away and at most
/// `reach(dy) = max { dx : dx^2 + dy^2 <= radius^2 }` columns away. Each
/// source row is widened one column at a time (`reach(0)` passes of a few
/// word operations) and each widening ORed into the rows whose `dy` needs
/// it: `O(cells / 64 * radius)` word operations.
fn dilate_bits(grid: &BitGrid, radius: f64) -> BitGrid {
    let (w, h, stride) = (grid.w, grid.h, grid.stride);
    let mut out = BitGrid::new(w, h);
    if w == 0 || h == 0 {
        return out;
    }
    // A radius beyond the grid's diagonal reaches every cell: capping it at
    // w + h changes nothing.
    let radius = if radius.is_nan() {
        0.0
    } else {
        radius.max(0.0).min((w + h) as f64)
    };
    let r = radius.floor() as usize;
    let lim = radius * radius;
    // reach[dy] for the dy that stay inside the grid (every dy <= r has
    // reach >= 0); the square root is a first guess, made exact below.
    let reach: Vec<usize> = (0..=r.min(h))
        .map(|dy| {
            let dy2 = (dy * dy) as f64;
            let mut dx = (lim - dy2).max(0.0).sqrt() as u64;
            while ((dx + 1) * (dx + 1)) as f64 + dy2 <= lim {
                dx += 1;
            }
            while dx > 0 && (dx * dx) as f64 + dy2 > lim {
                dx -= 1;
            }
            // Widening a row more than its width changes nothing.
            (dx as usize).min(w)
        })
        .collect();
    let tail = grid.tail_mask();
    let (mut cur, mut next) = (vec![0u64; stride], vec![0u64; stride]);
    for y in 0..h {
        let src = grid.row(y);
        if src.iter().all(|&v| v == 0) {
            continue;
        }
        cur.copy_from_slice(src);
        // reach is non-increasing in dy: walk dy from r down to 0 while the
        // widening grows from 0 to reach[0].
        let mut k = 0;
        for dy in (0..=r.min(h)).rev() {
            while k < reach[dy] {
                widen_row(&cur, &mut next, tail);
                std::mem::swap(&mut cur, &mut next);
                k += 1;
            }
            for ty in [y.checked_sub(dy), (dy > 0).then_some(y + dy)]
                .into_iter()
                .flatten()
            {
                if ty < h {
                    let dst = &mut out.words[ty * stride..(ty + 1) * stride];
                    for (d, &c) in dst.iter_mut().zip(&cur) {
                        *d |= c;
                    }
                }
            }
        }
    }
    out
}

/// Union-find over runs (as made by [`BitGrid::runs`]): runs in consecutive rows
/// that share a column are joined. Returns each run's root, the lowest run
/// index of its component (its first run in row-major order).
fn connect_runs(start: &[u32], runs: &[(u32, u32)]) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..runs.len() as u32).collect();
    let find = |parent: &mut Vec<u32>, mut a: u32| {
        while parent[a as usize] != a {
            let up = parent[parent[a as usize] as usize];
            parent[a as usize] = up;
            a = up;
        }
        a
    };
    for y in 1..start.len().saturating_sub(1) {
        let (mut i, ie) = (start[y - 1] as usize, start[y] as usize);
        let (mut j, je) = (start[y] as usize, start[y + 1] as usize);
        while i < ie && j < je {
            let (a, b) = (runs[i], runs[j]);
            if a.0 < b.1 && b.0 < a.1 {
                let (ra, rb) = (find(&mut parent, i as u32), find(&mut parent, j as u32));
                if ra != rb {
                    let (lo, hi) = (ra.min(rb), ra.max(rb));
                    parent[hi as usize] = lo;
                }
            }
            // Advance the run that ends first.
            if a.1 <= b.1 {
                i += 1;
            } else {
                j += 1;
            }
        }
    }
    (0..runs.len() as u32)
        .map(|k| find(&mut parent, k))
        .collect()
}

/// Cells whose centre lies within `radius` cells of the centre of a set cell
/// (binary dilation by a disk), one bool per cell: [`dilate_bits`] on the
/// packed grid.
pub(crate) fn dilate_disk(grid: &[bool], w: usize, h: usize, radius: f64) -> Vec<bool> {
    dilate_bits(&BitGrid::from_bools(grid, w, h), radius).to_bools()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cell by cell: the reference the word-wise trace must agree with.
    fn trace_ring_by_cells(outside: &[bool], w: usize, h: usize) -> Option<Vec<(i64, i64)>> {
        let inside = |x: i64, y: i64| -> bool {
            x >= 0
                && y >= 0
                && (x as usize) < w
                && (y as usize) < h
                && !outside[y as usize * w + x as usize]
        };
        let mut next_of: Vec<u32> = vec![u32::MAX; (w + 1) * (h + 1)];
        let cid = |x: i64, y: i64| y as usize * (w + 1) + x as usize;
        let mut first = None;
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                if !inside(x, y) {
                    continue;
                }
                if !inside(x, y - 1) {
                    next_of[cid(x, y)] = cid(x + 1, y) as u32;
                    first.get_or_insert(cid(x, y));
                }
                if !inside(x + 1, y) {
                    next_of[cid(x + 1, y)] = cid(x + 1, y + 1) as u32;
                }
                if !inside(x, y + 1) {
                    next_of[cid(x + 1, y + 1)] = cid(x, y + 1) as u32;
                }
                if !inside(x - 1, y) {
                    next_of[cid(x, y + 1)] = cid(x, y) as u32;
                }
            }
        }
        let start = first?;
        let mut ring = Vec::new();
        let mut c = start;
        loop {
            ring.push(((c % (w + 1)) as i64, (c / (w + 1)) as i64));
            let n = next_of[c];
            if n == u32::MAX || ring.len() > 4 * w * h + 4 {
                return None;
            }
            c = n as usize;
            if c == start {
                return Some(ring);
            }
        }
    }

    #[test]
    fn tracing_word_by_word_gives_the_ring_cell_by_cell_gives() {
        // No cells, no ring.
        for (w, h) in [(0, 0), (0, 3), (3, 0)] {
            assert_eq!(trace_ring(&[], w, h), None);
        }
        // Every byte pattern packs to its bits, at every offset of a row.
        for w in [1usize, 7, 8, 9, 63, 64, 65, 130] {
            for pattern in 0..256u32 {
                let row: Vec<bool> = (0..w).map(|x| pattern >> (x % 8) & 1 == 0).collect();
                let mut words = vec![0u64; w.div_ceil(64)];
                pack_row(&row, false, &mut words);
                for (x, &o) in row.iter().enumerate() {
                    assert_eq!(words[x / 64] >> (x % 64) & 1 == 1, !o, "w {w}, x {x}");
                }
                let grid = BitGrid::from_bools(&row, w, 1);
                for (x, &o) in row.iter().enumerate() {
                    assert_eq!(grid.get(x, 0), o, "w {w}, x {x}");
                }
                assert_eq!(words.last().map_or(0, |v| v.count_ones()) as usize, {
                    let tail = w - 64 * (w.div_ceil(64) - 1);
                    row[w - tail..].iter().filter(|&&o| !o).count()
                });
            }
        }
        // Blobs, with pinches and cells on the grid's border, as the
        // largest region's exterior and as raw random cells.
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        for case in 0..300 {
            // Every fourth grid a whole number of words wide.
            let w = match case % 4 {
                0 => 64 * (1 + (next() % 3) as usize),
                _ => 1 + (next() % 150) as usize,
            };
            let h = 1 + (next() % 40) as usize;
            let fill = next() % 100;
            let cells: Vec<bool> = (0..w * h).map(|_| next() % 100 < fill).collect();
            let grid = BitGrid::from_bools(&cells, w, h);
            let raw: Vec<bool> = cells.iter().map(|&c| !c).collect();
            for outside in [exterior_of_largest_region(&grid).map(|(o, _)| o), Some(raw)]
                .into_iter()
                .flatten()
            {
                assert_eq!(
                    trace_ring(&outside, w, h),
                    trace_ring_by_cells(&outside, w, h),
                    "case {case}, {w} x {h}"
                );
            }
        }
    }

    /// Exact squared Euclidean distance (in cells) from every cell to the nearest
    /// set cell (Felzenszwalb–Huttenlocher, separable, linear time).
    fn sq_edt(grid: &[bool], w: usize, h: usize) -> Vec<f64> {
        const INF: f64 = 1e20;
        let mut d: Vec<f64> = grid.iter().map(|&b| if b { 0.0 } else { INF }).collect();
        let n = w.max(h);
        let (mut f, mut out, mut v, mut z) = (
            vec![0.0; n],
            vec![0.0; n],
            vec![0usize; n],
            vec![0.0; n + 1],
        );
        for x in 0..w {
            for y in 0..h {
                f[y] = d[y * w + x];
            }
            edt_1d(&f[..h], &mut out[..h], &mut v, &mut z);
            for y in 0..h {
                d[y * w + x] = out[y];
            }
        }
        for y in 0..h {
            f[..w].copy_from_slice(&d[y * w..(y + 1) * w]);
            edt_1d(&f[..w], &mut out[..w], &mut v, &mut z);
            d[y * w..(y + 1) * w].copy_from_slice(&out[..w]);
        }
        d
    }

    fn edt_1d(f: &[f64], out: &mut [f64], v: &mut [usize], z: &mut [f64]) {
        let n = f.len();
        if n == 0 {
            return;
        }
        let mut k = 0usize;
        v[0] = 0;
        z[0] = f64::NEG_INFINITY;
        z[1] = f64::INFINITY;
        for q in 1..n {
            let mut s;
            loop {
                let p = v[k];
                s = ((f[q] + (q * q) as f64) - (f[p] + (p * p) as f64))
                    / (2.0 * (q as f64 - p as f64));
                if s <= z[k] && k > 0 {
                    k -= 1;
                } else {
                    break;
                }
            }
            if s <= z[k] {
                // k == 0 and the new parabola dominates from the start.
                v[0] = q;
                z[0] = f64::NEG_INFINITY;
                z[1] = f64::INFINITY;
                continue;
            }
            k += 1;
            v[k] = q;
            z[k] = s;
            z[k + 1] = f64::INFINITY;
        }
        k = 0;
        for (q, o) in out.iter_mut().enumerate() {
            while z[k + 1] < q as f64 {
                k += 1;
            }
            let p = v[k];
            let dq = q as f64 - p as f64;
            *o = dq * dq + f[p];
        }
    }

    /// The cell-by-cell flood fills the run-based labelling replaced: the
    /// largest 4-connected region (first in row-major order on ties) with
    /// its holes filled.
    fn region_by_flood_fill(closed: &[bool], w: usize, h: usize) -> Option<Vec<bool>> {
        let nbrs = |x: usize, y: usize| {
            let mut v = Vec::new();
            if x > 0 {
                v.push((x - 1, y));
            }
            if x + 1 < w {
                v.push((x + 1, y));
            }
            if y > 0 {
                v.push((x, y - 1));
            }
            if y + 1 < h {
                v.push((x, y + 1));
            }
            v
        };
        let mut label = vec![0u32; w * h];
        let (mut best, mut best_size, mut next) = (0u32, 0usize, 1u32);
        for sy in 0..h {
            for sx in 0..w {
                if !closed[sy * w + sx] || label[sy * w + sx] != 0 {
                    continue;
                }
                let mut size = 0;
                label[sy * w + sx] = next;
                let mut stack = vec![(sx, sy)];
                while let Some((x, y)) = stack.pop() {
                    size += 1;
                    for (nx, ny) in nbrs(x, y) {
                        if closed[ny * w + nx] && label[ny * w + nx] == 0 {
                            label[ny * w + nx] = next;
                            stack.push((nx, ny));
                        }
                    }
                }
                if size > best_size {
                    (best, best_size) = (next, size);
                }
                next += 1;
            }
        }
        if best_size == 0 {
            return None;
        }
        let mut outside = vec![false; w * h];
        let mut stack = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let border = x == 0 || y == 0 || x + 1 == w || y + 1 == h;
                if border && label[y * w + x] != best && !outside[y * w + x] {
                    outside[y * w + x] = true;
                    stack.push((x, y));
                }
            }
        }
        while let Some((x, y)) = stack.pop() {
            for (nx, ny) in nbrs(x, y) {
                if label[ny * w + nx] != best && !outside[ny * w + nx] {
                    outside[ny * w + nx] = true;
                    stack.push((nx, ny));
                }
            }
        }
        Some(outside.into_iter().map(|o| !o).collect())
    }

    #[test]
    fn run_labelling_matches_flood_fill() {
        let mut rng = crate::rng::Rng::new(11);
        let mut holes = 0;
        for case in 0..300 {
            let (w, h) = (1 + rng.below(40), 1 + rng.below(40));
            let fill = 20 + rng.below(60);
            let grid: Vec<bool> = (0..w * h).map(|_| rng.below(100) < fill).collect();
            let expected = region_by_flood_fill(&grid, w, h);
            let got = exterior_of_largest_region(&BitGrid::from_bools(&grid, w, h))
                .map(|(outside, _)| outside.into_iter().map(|o| !o).collect::<Vec<bool>>());
            if let Some(e) = &expected {
                holes += (0..w * h).filter(|&k| e[k] && !grid[k]).count();
            }
            assert_eq!(got, expected, "case {case}: {w}x{h}");
        }
        assert!(holes > 0, "no case had a hole to fill");
    }

    #[test]
    fn edt_matches_brute_force() {
        let (w, h) = (13, 9);
        let grid: Vec<bool> = (0..w * h).map(|k| k % 7 == 0 || k == 50).collect();
        let d = sq_edt(&grid, w, h);
        for (k, &dk) in d.iter().enumerate() {
            let (x, y) = ((k % w) as f64, (k / w) as f64);
            let best = (0..w * h)
                .filter(|&j| grid[j])
                .map(|j| {
                    let (a, b) = ((j % w) as f64, (j / w) as f64);
                    (a - x) * (a - x) + (b - y) * (b - y)
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!(dk, best);
        }
    }

    #[test]
    fn disk_dilation_matches_the_distance_transform() {
        // Widths below, at and across the 64-bit word boundary, sparse and
        // dense grids, radii from none to beyond the grid.
        let mut rng = crate::rng::Rng::new(9);
        for (w, h) in [(23, 17), (64, 9), (65, 12), (130, 7), (1, 40), (200, 1)] {
            for fill in [2, 30] {
                let grid: Vec<bool> = (0..w * h).map(|_| rng.below(100) < fill).collect();
                let d = sq_edt(&grid, w, h);
                for radius in [0.0, 1.0, 1.5, 2.0, 3.7, 6.0, 70.5, 1e9] {
                    let dil = dilate_disk(&grid, w, h, radius);
                    for k in 0..w * h {
                        assert_eq!(
                            dil[k],
                            d[k] <= radius * radius,
                            "{w}x{h} fill {fill} radius {radius} cell {k}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn cuts_through_another_hole_cut_nothing_off() {
        // A wide hole B near the region's bottom edge and a smaller hole A
        // above it, whose shortest way out runs down through B. B's own
        // cut runs down from its first cell: two cuts from B to the edge
        // used to cut off the strip of region between them.
        let (w, h) = (60, 60);
        let hole_a = |x: usize, y: usize| (26..33).contains(&x) && (23..31).contains(&y);
        let hole_b = |x: usize, y: usize| (10..46).contains(&x) && (8..21).contains(&y);
        let region = |x: usize, y: usize| {
            (5..55).contains(&x) && (5..55).contains(&y) && !hole_a(x, y) && !hole_b(x, y)
        };
        let mut grid = BitGrid::new(w, h);
        for y in 0..h {
            for x in 0..w {
                if region(x, y) {
                    grid.set(x, y);
                }
            }
        }
        let closing = Closing::new(grid, 0).unwrap();
        let cuts = closing.cuts(20);
        let t = closing.trace(&cuts).unwrap();
        for y in 0..h {
            for x in 0..w {
                let k = y * w + x;
                assert_eq!(t.1[k], region(x, y), "cell ({x}, {y})");
            }
        }
        // B opens through the 3 cells below it, A through the 2 between
        // it and B.
        assert_eq!(cuts.len(), 5, "{cuts:?}");
    }
}
