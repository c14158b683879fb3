//! The two innermost loops of the RANSAC search, written with explicit SIMD.
//!
//! Scoring a hypothesis (an MSAC sum over a prefix of the pool) and listing
//! a plane's inliers in a prefix are where most of a detection's arithmetic
//! goes. Written as plain loops, LLVM vectorises the MSAC sum badly: its
//! eight accumulators come out as a mix of 2- and 4-lane vectors and scalar
//! lanes with branches, about 0.49 ns a point on the benchmark machine. The
//! explicit versions here take 0.29 (SSE2) and 0.15 ns (AVX, chosen at run
//! time); in the wasm build (Node 20), simd128 intrinsics take 0.31 ns
//! where LLVM's own vectorisation took 0.43.
//!
//! **Every version returns the same bits.** The scalar reference fixes the
//! order of every operation: lane `l` of eight accumulates the points
//! `8 j + l` in f32, in order; the lanes are then added in f64, lane 0
//! first, and the tail (under eight points) after them, one point at a time.
//! The vector versions do exactly these IEEE operations (no fused
//! multiply-add, no reassociation), and their `max(w, 0)` keeps the
//! reference's `if w > 0 { w } else { 0 }` (NaN and -0 give +0). The unit
//! tests compare them bit for bit on data with NaNs, zeros and every tail
//! length, so detection gives the same polygons on every machine and in
//! the browser.
#![allow(unsafe_code)]

/// A plane as the kernels use it: `v = n · p + d` for a point `p`.
#[derive(Clone, Copy, Debug)]
pub struct PlaneF32 {
    /// Normal, x.
    pub nx: f32,
    /// Normal, y.
    pub ny: f32,
    /// Normal, z.
    pub nz: f32,
    /// Offset.
    pub d: f32,
}

/// Points as three coordinate arrays of one length, the layout the RANSAC
/// pool keeps them in (a removed point has x = NaN).
#[derive(Clone, Copy, Debug)]
pub struct Points<'a> {
    xs: &'a [f32],
    ys: &'a [f32],
    zs: &'a [f32],
}

impl<'a> Points<'a> {
    /// The points `(xs[i], ys[i], zs[i])`, as many as the shortest array.
    pub fn new(xs: &'a [f32], ys: &'a [f32], zs: &'a [f32]) -> Self {
        let n = xs.len().min(ys.len()).min(zs.len());
        Points {
            xs: &xs[..n],
            ys: &ys[..n],
            zs: &zs[..n],
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.xs.len()
    }

    /// No points?
    pub fn is_empty(&self) -> bool {
        self.xs.is_empty()
    }

    /// The points `range` of these.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Self {
        Points {
            xs: &self.xs[range.clone()],
            ys: &self.ys[range.clone()],
            zs: &self.zs[range],
        }
    }

    /// The points from `i` on.
    fn tail(&self, i: usize) -> Self {
        self.slice(i..self.len())
    }
}

/// MSAC sum over the points `(xs[i], ys[i], zs[i])`: each point with
/// `w = 1 - ((n · p + d) * inv)^2 > 0` adds `w` (a NaN coordinate adds 0).
/// `inv` is one over the inlier distance. The scoring of RANSAC hypotheses
/// (paper Algorithm 1, step 1), as a soft inlier count.
///
/// ```
/// use polyscene::detect::kernels::{msac_sum, PlaneF32, Points};
/// // z = 0; points at heights 0, 0.05 and 0.2, inlier distance 0.1 m.
/// let plane = PlaneF32 { nx: 0.0, ny: 0.0, nz: 1.0, d: 0.0 };
/// let (xs, ys, zs) = ([0.0, 1.0, 2.0], [0.0; 3], [0.0, 0.05, 0.2]);
/// let s = msac_sum(Points::new(&xs, &ys, &zs), plane, 10.0);
/// assert!((s - 1.75).abs() < 1e-6); // 1 + (1 - 0.5^2) + 0
/// ```
pub fn msac_sum(pts: Points, plane: PlaneF32, inv: f32) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            return unsafe { x86::msac_avx(pts, plane, inv) };
        }
        x86::msac_sse2(pts, plane, inv)
    }
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    {
        wasm::msac_simd128(pts, plane, inv)
    }
    #[cfg(not(any(
        target_arch = "x86_64",
        all(target_arch = "wasm32", target_feature = "simd128")
    )))]
    {
        msac_scalar(pts, plane, inv)
    }
}

/// The reference [`msac_sum`]: plain Rust, the order of operations every
/// vector version keeps.
pub fn msac_scalar(pts: Points, plane: PlaneF32, inv: f32) -> f64 {
    let body = pts.len() / 8 * 8;
    let mut acc = [0f32; 8];
    for i in 0..body {
        acc[i % 8] += msac_term(pts.xs[i], pts.ys[i], pts.zs[i], plane, inv);
    }
    finish(&acc, pts.tail(body), plane, inv)
}

#[inline(always)]
fn msac_term(x: f32, y: f32, z: f32, p: PlaneF32, inv: f32) -> f32 {
    let v = (p.nx * x + p.ny * y + p.nz * z + p.d) * inv;
    let w = 1.0 - v * v;
    if w > 0.0 {
        w
    } else {
        0.0
    }
}

/// The lanes in f64, lane 0 first, then the tail point by point.
#[inline(always)]
fn finish(acc: &[f32; 8], tail: Points, p: PlaneF32, inv: f32) -> f64 {
    let mut c: f64 = acc.iter().map(|&a| a as f64).sum();
    for i in 0..tail.len() {
        c += msac_term(tail.xs[i], tail.ys[i], tail.zs[i], p, inv) as f64;
    }
    c
}

/// Append to `out` the indices `base + i` of the points with
/// `|n · p + d| < t` (NaN coordinates never qualify), in increasing order.
///
/// ```
/// use polyscene::detect::kernels::{inliers, PlaneF32, Points};
/// let plane = PlaneF32 { nx: 0.0, ny: 0.0, nz: 1.0, d: 0.0 };
/// let (xs, ys, zs) = ([0.0; 4], [0.0; 4], [0.0, 0.5, -0.05, f32::NAN]);
/// let mut out = Vec::new();
/// inliers(Points::new(&xs, &ys, &zs), plane, 0.1, 100, &mut out);
/// assert_eq!(out, [100, 102]);
/// ```
pub fn inliers(pts: Points, plane: PlaneF32, t: f32, base: u32, out: &mut Vec<u32>) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            return unsafe { x86::inliers_avx(pts, plane, t, base, out) };
        }
    }
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    {
        return wasm::inliers_simd128(pts, plane, t, base, out);
    }
    #[allow(unreachable_code)]
    inliers_scalar(pts, plane, t, base, out)
}

/// The reference [`inliers`]: 64 tests into a bit mask, then the set bits
/// (inliers are a minority, so most masks are empty).
pub fn inliers_scalar(pts: Points, p: PlaneF32, t: f32, base: u32, out: &mut Vec<u32>) {
    let (n, Points { xs, ys, zs }) = (pts.len(), pts);
    let mut start = 0;
    while start < n {
        let end = n.min(start + 64);
        let mut m = 0u64;
        for i in start..end {
            let v = p.nx * xs[i] + p.ny * ys[i] + p.nz * zs[i] + p.d;
            m |= ((v.abs() < t) as u64) << (i - start);
        }
        push_bits(m, base + start as u32, out);
        start = end;
    }
}

/// The block structure of every vector [`inliers`]: 64-point masks (one
/// bit-listing loop per 64 points: its exit is the branch that
/// mispredicts), then 8-point ones, then the reference for the tail.
/// `mask8(o)` has bit `l` set when point `o + l` is an inlier; it is only
/// called with `o + 8 <= pts.len()`.
#[cfg(any(
    target_arch = "x86_64",
    all(target_arch = "wasm32", target_feature = "simd128")
))]
#[inline(always)]
fn list_blocks(
    pts: Points,
    p: PlaneF32,
    t: f32,
    base: u32,
    out: &mut Vec<u32>,
    mask8: impl Fn(usize) -> u64,
) {
    let (n, mut o) = (pts.len(), 0);
    while o + 64 <= n {
        let mut m = 0u64;
        for j in 0..8 {
            m |= mask8(o + 8 * j) << (8 * j);
        }
        push_bits(m, base + o as u32, out);
        o += 64;
    }
    while o + 8 <= n {
        push_bits(mask8(o), base + o as u32, out);
        o += 8;
    }
    inliers_scalar(pts.tail(o), p, t, base + o as u32, out);
}

#[inline(always)]
fn push_bits(mut m: u64, base: u32, out: &mut Vec<u32>) {
    while m != 0 {
        out.push(base + m.trailing_zeros());
        m &= m - 1;
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{finish, PlaneF32, Points};
    use std::arch::x86_64::*;

    /// [`super::msac_scalar`] with two 4-lane SSE2 accumulators (lanes
    /// 0-3 and 4-7). SSE2 is part of every x86_64 CPU.
    pub fn msac_sse2(pts: Points, p: PlaneF32, inv: f32) -> f64 {
        let (body, Points { xs, ys, zs }) = (pts.len() / 8 * 8, pts);
        let mut acc = [0f32; 8];
        // SAFETY: SSE2 is baseline on x86_64; every load reads 4 floats
        // inside a chunk of 8 of a slice (chunks_exact).
        unsafe {
            let (vx, vy, vz) = (_mm_set1_ps(p.nx), _mm_set1_ps(p.ny), _mm_set1_ps(p.nz));
            let (vd, vi) = (_mm_set1_ps(p.d), _mm_set1_ps(inv));
            let (one, zero) = (_mm_set1_ps(1.0), _mm_setzero_ps());
            let term = |x: *const f32, y: *const f32, z: *const f32| {
                let s = _mm_add_ps(
                    _mm_mul_ps(vx, _mm_loadu_ps(x)),
                    _mm_mul_ps(vy, _mm_loadu_ps(y)),
                );
                let s = _mm_add_ps(s, _mm_mul_ps(vz, _mm_loadu_ps(z)));
                let v = _mm_mul_ps(_mm_add_ps(s, vd), vi);
                // max(w, 0) = if w > 0 { w } else { 0 }: NaN and -0 give +0.
                _mm_max_ps(_mm_sub_ps(one, _mm_mul_ps(v, v)), zero)
            };
            let (mut lo, mut hi) = (zero, zero);
            for ((x, y), z) in xs[..body]
                .chunks_exact(8)
                .zip(ys[..body].chunks_exact(8))
                .zip(zs[..body].chunks_exact(8))
            {
                lo = _mm_add_ps(lo, term(x.as_ptr(), y.as_ptr(), z.as_ptr()));
                hi = _mm_add_ps(hi, term(x[4..].as_ptr(), y[4..].as_ptr(), z[4..].as_ptr()));
            }
            _mm_storeu_ps(acc.as_mut_ptr(), lo);
            _mm_storeu_ps(acc[4..].as_mut_ptr(), hi);
        }
        finish(&acc, pts.tail(body), p, inv)
    }

    /// [`super::msac_scalar`] with one 8-lane AVX accumulator.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[target_feature(enable = "avx")]
    pub unsafe fn msac_avx(pts: Points, p: PlaneF32, inv: f32) -> f64 {
        let (body, Points { xs, ys, zs }) = (pts.len() / 8 * 8, pts);
        let mut acc = [0f32; 8];
        let (vx, vy, vz) = (
            _mm256_set1_ps(p.nx),
            _mm256_set1_ps(p.ny),
            _mm256_set1_ps(p.nz),
        );
        let (vd, vi) = (_mm256_set1_ps(p.d), _mm256_set1_ps(inv));
        let (one, zero) = (_mm256_set1_ps(1.0), _mm256_setzero_ps());
        let mut a = zero;
        for ((x, y), z) in xs[..body]
            .chunks_exact(8)
            .zip(ys[..body].chunks_exact(8))
            .zip(zs[..body].chunks_exact(8))
        {
            // SAFETY: each load reads one chunk of exactly 8 floats.
            let (x, y, z) = unsafe {
                (
                    _mm256_loadu_ps(x.as_ptr()),
                    _mm256_loadu_ps(y.as_ptr()),
                    _mm256_loadu_ps(z.as_ptr()),
                )
            };
            let s = _mm256_add_ps(_mm256_mul_ps(vx, x), _mm256_mul_ps(vy, y));
            let s = _mm256_add_ps(s, _mm256_mul_ps(vz, z));
            let v = _mm256_mul_ps(_mm256_add_ps(s, vd), vi);
            let w = _mm256_sub_ps(one, _mm256_mul_ps(v, v));
            a = _mm256_add_ps(a, _mm256_max_ps(w, zero));
        }
        // SAFETY: `acc` holds exactly 8 floats.
        unsafe { _mm256_storeu_ps(acc.as_mut_ptr(), a) };
        finish(&acc, pts.tail(body), p, inv)
    }

    /// [`super::inliers_scalar`] with one AVX compare per eight points
    /// (blocks as in [`super::list_blocks`]).
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[target_feature(enable = "avx")]
    pub unsafe fn inliers_avx(pts: Points, p: PlaneF32, t: f32, base: u32, out: &mut Vec<u32>) {
        let Points { xs, ys, zs } = pts;
        let (vx, vy, vz) = (
            _mm256_set1_ps(p.nx),
            _mm256_set1_ps(p.ny),
            _mm256_set1_ps(p.nz),
        );
        let (vd, vt) = (_mm256_set1_ps(p.d), _mm256_set1_ps(t));
        let sign = _mm256_set1_ps(-0.0);
        // Bit l of the mask: point `o + l` is an inlier.
        let mask8 = |o: usize| {
            // SAFETY: each load reads a slice of exactly 8 floats (the
            // indexing checks it; `list_blocks` keeps o + 8 <= len).
            let (x, y, z) = unsafe {
                (
                    _mm256_loadu_ps(xs[o..o + 8].as_ptr()),
                    _mm256_loadu_ps(ys[o..o + 8].as_ptr()),
                    _mm256_loadu_ps(zs[o..o + 8].as_ptr()),
                )
            };
            let s = _mm256_add_ps(_mm256_mul_ps(vx, x), _mm256_mul_ps(vy, y));
            let v = _mm256_add_ps(_mm256_add_ps(s, _mm256_mul_ps(vz, z)), vd);
            // |v| < t, ordered: NaN compares false.
            let c = _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(sign, v), vt);
            _mm256_movemask_ps(c) as u32 as u64
        };
        super::list_blocks(pts, p, t, base, out, mask8);
    }
}

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod wasm {
    use super::{finish, PlaneF32, Points};
    use core::arch::wasm32::*;

    /// The first four floats of `s` (which must hold at least four).
    #[inline(always)]
    fn load(s: &[f32]) -> v128 {
        let s = &s[..4];
        // SAFETY: `s` holds four floats; wasm loads need no alignment.
        unsafe { v128_load(s.as_ptr() as *const v128) }
    }

    /// [`super::msac_scalar`] with two 4-lane simd128 accumulators.
    pub fn msac_simd128(pts: Points, p: PlaneF32, inv: f32) -> f64 {
        let (body, Points { xs, ys, zs }) = (pts.len() / 8 * 8, pts);
        let (vx, vy, vz) = (f32x4_splat(p.nx), f32x4_splat(p.ny), f32x4_splat(p.nz));
        let (vd, vi) = (f32x4_splat(p.d), f32x4_splat(inv));
        let (one, zero) = (f32x4_splat(1.0), f32x4_splat(0.0));
        let term = |x: &[f32], y: &[f32], z: &[f32]| {
            let s = f32x4_add(f32x4_mul(vx, load(x)), f32x4_mul(vy, load(y)));
            let s = f32x4_add(s, f32x4_mul(vz, load(z)));
            let v = f32x4_mul(f32x4_add(s, vd), vi);
            // pmax(0, w) = if 0 < w { w } else { 0 }: NaN and -0 give +0.
            f32x4_pmax(zero, f32x4_sub(one, f32x4_mul(v, v)))
        };
        let (mut lo, mut hi) = (zero, zero);
        for ((x, y), z) in xs[..body]
            .chunks_exact(8)
            .zip(ys[..body].chunks_exact(8))
            .zip(zs[..body].chunks_exact(8))
        {
            lo = f32x4_add(lo, term(x, y, z));
            hi = f32x4_add(hi, term(&x[4..], &y[4..], &z[4..]));
        }
        let acc = [
            f32x4_extract_lane::<0>(lo),
            f32x4_extract_lane::<1>(lo),
            f32x4_extract_lane::<2>(lo),
            f32x4_extract_lane::<3>(lo),
            f32x4_extract_lane::<0>(hi),
            f32x4_extract_lane::<1>(hi),
            f32x4_extract_lane::<2>(hi),
            f32x4_extract_lane::<3>(hi),
        ];
        finish(&acc, pts.tail(body), p, inv)
    }

    /// [`super::inliers_scalar`] four tests at a time.
    pub fn inliers_simd128(pts: Points, p: PlaneF32, t: f32, base: u32, out: &mut Vec<u32>) {
        let Points { xs, ys, zs } = pts;
        let (vx, vy, vz) = (f32x4_splat(p.nx), f32x4_splat(p.ny), f32x4_splat(p.nz));
        let (vd, vt) = (f32x4_splat(p.d), f32x4_splat(t));
        // Bit l of the mask: point `o + l` is an inlier (o + 4 <= len).
        let mask4 = |o: usize| {
            let s = f32x4_add(f32x4_mul(vx, load(&xs[o..])), f32x4_mul(vy, load(&ys[o..])));
            let v = f32x4_add(f32x4_add(s, f32x4_mul(vz, load(&zs[o..]))), vd);
            // |v| < t: NaN compares false.
            i32x4_bitmask(f32x4_lt(f32x4_abs(v), vt)) as u64
        };
        let mask8 = |o: usize| mask4(o) | mask4(o + 4) << 4;
        super::list_blocks(pts, p, t, base, out, mask8);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn cloud(n: usize, seed: u64) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let mut rng = Rng::new(seed);
        let mut f = |s: f64| (rng.uniform() * 2.0 - 1.0) * s;
        let mut xs: Vec<f32> = (0..n).map(|_| f(20.0) as f32).collect();
        let ys: Vec<f32> = (0..n).map(|_| f(20.0) as f32).collect();
        // Most points near z = 0.5: a plane with many inliers.
        let mut zs: Vec<f32> = (0..n).map(|_| (0.5 + f(0.2)) as f32).collect();
        for i in (3..n).step_by(17) {
            xs[i] = f32::NAN;
        }
        for i in (5..n).step_by(23) {
            zs[i] = -0.0;
        }
        (xs, ys, zs)
    }

    const PLANE: PlaneF32 = PlaneF32 {
        nx: 0.01,
        ny: -0.02,
        nz: 0.999_75,
        d: -0.5,
    };

    #[test]
    fn msac_sum_is_the_reference_bit_for_bit() {
        let (xs, ys, zs) = cloud(4096 + 7, 3);
        let mut positive = 0;
        for len in (0..80).chain([511, 512, 513, 4096, 4103]) {
            for start in [0, 1, 5] {
                let end = (start + len).min(xs.len());
                let (x, y, z) = (&xs[start..end], &ys[start..end], &zs[start..end]);
                let want = msac_scalar(Points::new(x, y, z), PLANE, 10.0);
                let got = msac_sum(Points::new(x, y, z), PLANE, 10.0);
                assert_eq!(got.to_bits(), want.to_bits(), "len {len} start {start}");
                positive += (want > 0.0) as usize;
            }
        }
        // The data is not trivial: most ranges have inliers.
        assert!(positive > 200, "{positive}");
        // A plane at exactly the threshold edge: w = 0 and -0 contribute +0.
        let flat = [0.1f32; 9];
        let edge = PlaneF32 {
            nx: 0.0,
            ny: 0.0,
            nz: 1.0,
            d: 0.0,
        };
        assert_eq!(
            msac_sum(Points::new(&flat, &flat, &flat), edge, 10.0).to_bits(),
            0f64.to_bits()
        );
    }

    /// The SSE2 path runs only on x86_64 CPUs without AVX: test it here.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn sse2_msac_sum_is_the_reference_bit_for_bit() {
        let (xs, ys, zs) = cloud(1000 + 5, 4);
        for len in (0..40).chain([999, 1005]) {
            let (x, y, z) = (&xs[..len], &ys[..len], &zs[..len]);
            let want = msac_scalar(Points::new(x, y, z), PLANE, 10.0);
            let got = x86::msac_sse2(Points::new(x, y, z), PLANE, 10.0);
            assert_eq!(got.to_bits(), want.to_bits(), "len {len}");
        }
    }

    #[test]
    fn msac_sum_counts_a_known_plane() {
        // 100 points exactly on z = 0.5 (weight 1 each), 20 at distance
        // half the threshold (weight 0.75), 30 beyond it (0), 5 NaN.
        let mut pts = Vec::new();
        pts.extend((0..100).map(|i| (i as f32, 0.0, 0.5)));
        pts.extend((0..20).map(|i| (i as f32, 1.0, 0.5 + 0.05)));
        pts.extend((0..30).map(|i| (i as f32, 2.0, 0.5 + 0.2)));
        pts.extend((0..5).map(|_| (f32::NAN, 0.0, 0.5)));
        let xs: Vec<f32> = pts.iter().map(|p| p.0).collect();
        let ys: Vec<f32> = pts.iter().map(|p| p.1).collect();
        let zs: Vec<f32> = pts.iter().map(|p| p.2).collect();
        let plane = PlaneF32 {
            nx: 0.0,
            ny: 0.0,
            nz: 1.0,
            d: -0.5,
        };
        let s = msac_sum(Points::new(&xs, &ys, &zs), plane, 10.0);
        assert!((s - 115.0).abs() < 1e-3, "{s}");
        let mut out = Vec::new();
        inliers(Points::new(&xs, &ys, &zs), plane, 0.1, 1000, &mut out);
        let want: Vec<u32> = (1000..1120).collect();
        assert_eq!(out, want);
    }

    #[test]
    fn inliers_are_the_reference() {
        let (xs, ys, zs) = cloud(4096 + 7, 9);
        for len in (0..140).chain([4096, 4103]) {
            for start in [0, 3] {
                let end = (start + len).min(xs.len());
                let (x, y, z) = (&xs[start..end], &ys[start..end], &zs[start..end]);
                let (mut want, mut got) = (vec![7], vec![7]);
                inliers_scalar(Points::new(x, y, z), PLANE, 0.1, 40, &mut want);
                inliers(Points::new(x, y, z), PLANE, 0.1, 40, &mut got);
                assert_eq!(got, want, "len {len} start {start}");
            }
        }
        let mut all = Vec::new();
        inliers(Points::new(&xs, &ys, &zs), PLANE, 0.1, 0, &mut all);
        assert!(all.len() > 500 && all.len() < 2000, "{}", all.len());
    }
}
