//! A small deterministic hasher for integer grid keys (the std default is
//! randomly seeded and slower). Maps built with it are only ever looked up,
//! never iterated to produce results, so output does not depend on it.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Multiply-rotate hasher for fixed-size integer keys.
#[derive(Default, Clone, Copy)]
pub struct GridHasher(u64);

impl Hasher for GridHasher {
    #[inline]
    fn finish(&self) -> u64 {
        // Final avalanche (the splitmix64 mixer): the multiply alone leaves
        // the low bits depending only on the key's low bits (the x cell of a
        // packed key), and the table indexes buckets by the low bits, so
        // every cell of one x column would probe the same group.
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    #[inline]
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7C_C1_B7_27_22_0A_95);
    }
    #[inline]
    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }
    #[inline]
    fn write_u32(&mut self, v: u32) {
        self.write_u64(v as u64);
    }
    #[inline]
    fn write_i32(&mut self, v: i32) {
        self.write_u64(v as u32 as u64);
    }
    #[inline]
    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
}

/// `HashMap` with [`GridHasher`].
pub type GridMap<K, V> = HashMap<K, V, BuildHasherDefault<GridHasher>>;

/// Pack a 3D cell index into one key.
#[inline]
pub fn key3(x: i64, y: i64, z: i64) -> u64 {
    let m = (1u64 << 21) - 1;
    ((x as u64) & m) | (((y as u64) & m) << 21) | (((z as u64) & m) << 42)
}

/// Pack a 2D cell index into one key.
#[inline]
pub fn key2(x: i64, y: i64) -> u64 {
    ((x as u64) & 0xFFFF_FFFF) | ((y as u64) << 32)
}

/// `floor(x)` as an integer, exact for |x| < 2^63 (saturating beyond, NaN
/// gives 0). Much cheaper than `libm::floor` on targets without a rounding
/// instruction, and identical on every platform.
#[inline]
pub fn floor_i64(x: f64) -> i64 {
    let i = x as i64;
    if (i as f64) > x {
        // Saturating: `x as i64` already saturated for x below i64::MIN.
        i.saturating_sub(1)
    } else {
        i
    }
}

/// Point indices grouped by cell (compressed rows): the points of cell `c`
/// are `items[start[c]..start[c + 1]]`, in increasing index order. The
/// buffers are kept when refilled.
#[derive(Clone, Debug, Default)]
pub struct Buckets {
    /// Row starts, `cells + 1` of them.
    pub start: Vec<u32>,
    /// Point indices, grouped by cell.
    pub items: Vec<u32>,
}

impl Buckets {
    /// Group the points by `cell_of` (one cell id below `cells` per point).
    pub fn new(cell_of: &[u32], cells: usize) -> Self {
        let mut b = Buckets::default();
        b.fill(cell_of, cells);
        b
    }

    /// [`Buckets::new`] into the existing buffers (a counting sort).
    pub fn fill(&mut self, cell_of: &[u32], cells: usize) {
        self.start.clear();
        self.start.resize(cells + 1, 0);
        for &c in cell_of {
            self.start[c as usize + 1] += 1;
        }
        for i in 0..cells {
            self.start[i + 1] += self.start[i];
        }
        // Place with start[c] as the cursor of cell c, then shift the starts
        // back: no second buffer.
        self.items.clear();
        self.items.resize(cell_of.len(), 0);
        for (i, &c) in cell_of.iter().enumerate() {
            let at = &mut self.start[c as usize];
            self.items[*at as usize] = i as u32;
            *at += 1;
        }
        for c in (1..=cells).rev() {
            self.start[c] = self.start[c - 1];
        }
        self.start[0] = 0;
    }

    /// Number of cells.
    pub fn cells(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// Range of cell `c` in `items`.
    #[inline]
    pub fn range(&self, c: usize) -> std::ops::Range<usize> {
        self.start[c] as usize..self.start[c + 1] as usize
    }

    /// The points of cell `c`.
    #[inline]
    pub fn of(&self, c: usize) -> &[u32] {
        &self.items[self.range(c)]
    }
}

/// Points assigned to cubic voxels (see [`voxelise`]).
pub struct Voxels {
    /// Voxel id of each point; ids in first-seen order.
    pub cell_of: Vec<u32>,
    /// Integer coordinates of each voxel id.
    pub coords: Vec<[i64; 3]>,
    /// Further voxels whose packed key ([`key3`]) wraps onto an earlier
    /// voxel's (coordinates 2^21 voxels apart): they share its id.
    pub aliased: Vec<[i64; 3]>,
    /// Packed key to voxel id.
    pub map: GridMap<u64, u32>,
}

/// Assign `pts` to voxels of side `voxel`. Consecutive points of a scan
/// are mostly neighbours along a ring, in one voxel: the last voxel is
/// remembered and the map skipped for repeats.
pub fn voxelise(pts: &[glam::Vec3], voxel: f64) -> Voxels {
    let inv = 1.0 / voxel;
    let mut out = Voxels {
        cell_of: Vec::with_capacity(pts.len()),
        coords: Vec::new(),
        aliased: Vec::new(),
        map: GridMap::default(),
    };
    let mut last = ([i64::MAX; 3], 0u32);
    for p in pts {
        let c = [
            floor_i64(p.x as f64 * inv),
            floor_i64(p.y as f64 * inv),
            floor_i64(p.z as f64 * inv),
        ];
        if c != last.0 {
            let next = out.coords.len() as u32;
            let id = *out.map.entry(key3(c[0], c[1], c[2])).or_insert(next);
            if id == next {
                out.coords.push(c);
            } else if out.coords[id as usize] != c {
                out.aliased.push(c);
            }
            last = (c, id);
        }
        out.cell_of.push(last.1);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{floor_i64, Buckets};

    #[test]
    fn buckets_group_indices_by_cell_in_order() {
        let mut b = Buckets::new(&[2, 0, 2, 1, 0, 2], 4);
        assert_eq!(b.cells(), 4);
        assert_eq!(b.of(0), &[1, 4]);
        assert_eq!(b.of(1), &[3]);
        assert_eq!(b.of(2), &[0, 2, 5]);
        assert!(b.of(3).is_empty());
        b.fill(&[1, 1], 2);
        assert_eq!((b.of(0), b.of(1)), (&[][..], &[0, 1][..]));
        b.fill(&[], 0);
        assert_eq!(b.cells(), 0);
    }

    #[test]
    fn floor_matches_libm() {
        for &x in &[
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.999,
            -2.999,
            1e12 + 0.5,
            -1e12 - 0.5,
            7.0 / 3.0,
        ] {
            assert_eq!(floor_i64(x), libm::floor(x) as i64, "{x}");
        }
        assert_eq!(floor_i64(f64::NAN), 0);
    }
}
