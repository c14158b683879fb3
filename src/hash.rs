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

#[cfg(test)]
mod tests {
    use super::floor_i64;

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
