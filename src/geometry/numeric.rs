//! Small numeric helpers the geometry and the rest of the crate share: a
//! unit vector with the sqrt instruction, the ground's range pulling, box
//! growth by selects and two small sorts. A leaf: it imports nothing of the
//! crate, so every geometry module can use it without an import circle
//! through `geometry/mod.rs` (which re-exports these under their old paths).

/// `v.normalize_or_zero()` with the sqrt instruction: glam's (with its
/// `libm` feature) calls a software square root in wasm. Both are correctly
/// rounded, so the bits are the same.
pub(crate) fn unit_or_zero(v: glam::DVec2) -> glam::DVec2 {
    let rcp = 1.0 / v.length_squared().sqrt();
    if rcp.is_finite() && rcp > 0.0 {
        v * rcp
    } else {
        glam::DVec2::ZERO
    }
}

/// The ground's range pulling (one-shot detection): a distance `r` from the
/// viewpoint's foot beyond `range` becomes `2 range - range^2 / r`
/// (continuous and increasing, below `2 range`); nearer ones stay. Points
/// a fixed tolerance `t` apart after pulling are `t (r / range)^2` apart
/// along the line of sight before it, as the gaps between laser rings on
/// the ground grow. Shared by the clustering (`detect::pull_towards`) and
/// the footprint that fills what it bridged ([`Footprint::bridge_towards`](crate::geometry::Footprint::bridge_towards)).
pub(crate) fn pull_range(r: f64, range: f64) -> f64 {
    if r > range {
        (2.0 - range / r) * range
    } else {
        r
    }
}

/// The inverse of [`pull_range`]; infinite from `2 range` on.
pub(crate) fn unpull_range(q: f64, range: f64) -> f64 {
    if q >= 2.0 * range {
        f64::INFINITY
    } else if q > range {
        range * range / (2.0 * range - q)
    } else {
        q
    }
}

/// Grow the box `[lo, hi]` to hold `p`, by comparisons written as selects.
/// (wasm's `f64.min` treats NaN differently, so `f64::min` and `max`
/// become calls to `fmin`/`fmax`, which wasm-opt inlines as a NaN test, a
/// comparison and two selects; these loops run once per point. As selects they
/// compile branch-free, to `minsd`/`maxsd` natively: a branch per
/// coordinate mispredicts often while a box is still growing, which made
/// the clustering's per-cell boxes cost twice as much. NaN coordinates are
/// ignored, as `min`/`max` ignore them.)
#[inline]
pub(crate) fn grow_box<T: BoxCoords>(lo: &mut T, hi: &mut T, p: T) {
    for k in 0..T::DIM {
        let v = p[k];
        lo[k] = if v < lo[k] { v } else { lo[k] };
        hi[k] = if v > hi[k] { v } else { hi[k] };
    }
}

/// Points [`grow_box`] works on: f64 coordinates by index.
pub(crate) trait BoxCoords: Copy + std::ops::IndexMut<usize, Output = f64> {
    /// Number of coordinates.
    const DIM: usize;
}

impl BoxCoords for glam::DVec2 {
    const DIM: usize = 2;
}

impl BoxCoords for glam::DVec3 {
    const DIM: usize = 3;
}

/// Stable insertion sort: for the short lists (scan-line crossings, three
/// eigenvalues, a sensor's rings) that would otherwise each instantiate the
/// standard library's sort, several kilobytes of wasm apiece. Same order as
/// `sort_by` with the same comparison.
pub(crate) fn insertion_sort_by<T: Copy>(
    v: &mut [T],
    mut cmp: impl FnMut(&T, &T) -> std::cmp::Ordering,
) {
    for i in 1..v.len() {
        let x = v[i];
        let mut j = i;
        while j > 0 && cmp(&v[j - 1], &x) == std::cmp::Ordering::Greater {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
    }
}

/// Heapsort by `cmp`: O(n log n), in place, and a few hundred bytes of wasm
/// where the library's sorts cost kilobytes per element type. Not stable:
/// for a comparator under which equal elements are identical (a total order
/// on the values, as `f64::total_cmp` on coordinates), the result is that of
/// any other sort.
pub(crate) fn heap_sort_by<T: Copy>(
    v: &mut [T],
    mut cmp: impl FnMut(&T, &T) -> std::cmp::Ordering,
) {
    use std::cmp::Ordering::Less;
    // Move v[root] down the max-heap v[..end].
    let mut sift = |v: &mut [T], mut root: usize, end: usize| loop {
        let mut child = 2 * root + 1;
        if child >= end {
            break;
        }
        if child + 1 < end && cmp(&v[child], &v[child + 1]) == Less {
            child += 1;
        }
        if cmp(&v[root], &v[child]) != Less {
            break;
        }
        v.swap(root, child);
        root = child;
    };
    for root in (0..v.len() / 2).rev() {
        sift(v, root, v.len());
    }
    for end in (1..v.len()).rev() {
        v.swap(0, end);
        sift(v, 0, end);
    }
}

/// `floor(x)` as an integer, exact for |x| < 2^63 (saturating beyond, NaN
/// gives 0). Much cheaper than `libm::floor` on targets without a rounding
/// instruction (baseline x86_64), and identical on every platform: wasm has
/// one (`f64.floor`, then a saturating conversion), and uses it.
#[inline]
pub fn floor_i64(x: f64) -> i64 {
    #[cfg(target_arch = "wasm32")]
    {
        x.floor() as i64
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        let i = x as i64;
        if (i as f64) > x {
            // Saturating: `x as i64` already saturated for x below i64::MIN.
            i.saturating_sub(1)
        } else {
            i
        }
    }
}

/// `x.clamp(lo, hi)` for `lo <= hi` (NaN stays NaN), without its panic for
/// `lo > hi` (which then gives `lo`). The panic's message writes the floats
/// with `{:?}`, and where the bounds are not constants it kept core's
/// exponent formatting in the wasm.
#[inline]
pub(crate) fn clamp(x: f64, lo: f64, hi: f64) -> f64 {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// The bounding box (low, high corners) of `pts`; infinite corners for
/// none.
pub(crate) fn bounds(pts: &[glam::DVec3]) -> (glam::DVec3, glam::DVec3) {
    let mut lo = glam::DVec3::splat(f64::INFINITY);
    let mut hi = glam::DVec3::splat(f64::NEG_INFINITY);
    for &p in pts {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::{pull_range, unpull_range};

    #[test]
    fn range_pulling_is_continuous_increasing_and_inverted() {
        let range = 20.0;
        assert_eq!(pull_range(10.0, range), 10.0);
        assert_eq!(pull_range(20.0, range), 20.0);
        assert!((pull_range(40.0, range) - 30.0).abs() < 1e-12);
        assert!(pull_range(1e9, range) < 40.0);
        let mut last = 0.0;
        for k in 1..2000 {
            let r = k as f64 * 0.1;
            let q = pull_range(r, range);
            assert!(q > last, "increasing at {r}");
            assert!(
                (unpull_range(q, range) - r).abs() < 1e-9 * r.max(1.0),
                "{r}"
            );
            last = q;
        }
        assert_eq!(unpull_range(40.0, range), f64::INFINITY);
        assert_eq!(unpull_range(-3.0, range), -3.0);
    }

    #[test]
    fn heap_sort_matches_sort_by_on_a_total_order() {
        let mut rng = crate::rng::Rng::new(5);
        for n in [0, 1, 2, 3, 4, 17, 130, 1000] {
            // Few distinct values: many equal (identical) elements.
            let v: Vec<(f64, f64)> = (0..n)
                .map(|_| (rng.below(7) as f64 - 3.0, rng.below(5) as f64 * 0.5))
                .collect();
            let cmp =
                |a: &(f64, f64), b: &(f64, f64)| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1));
            let (mut heap, mut lib) = (v.clone(), v);
            super::heap_sort_by(&mut heap, cmp);
            lib.sort_by(cmp);
            assert_eq!(heap, lib, "n = {n}");
        }
    }

    #[test]
    fn insertion_sort_is_stable_and_matches_sort_by() {
        let mut rng = crate::rng::Rng::new(4);
        for n in [0, 1, 2, 3, 17, 130] {
            // Few distinct keys, so ties are common; the index shows order.
            let v: Vec<(f64, usize)> = (0..n).map(|i| (rng.below(5) as f64, i)).collect();
            let (mut a, mut b) = (v.clone(), v);
            super::insertion_sort_by(&mut a, |x, y| x.0.total_cmp(&y.0));
            b.sort_by(|x, y| x.0.total_cmp(&y.0));
            assert_eq!(a, b, "n = {n}");
        }
    }
}
