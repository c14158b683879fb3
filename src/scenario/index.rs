//! A voxel index of one scan, so a primitive only examines the points near
//! its plane and outline: per primitive the work is proportional to the
//! voxels its grown bounding box crosses near its plane, never to the whole
//! scan.

use crate::hash::{Buckets, VoxelIds};
use glam::{DVec3, Vec3};

/// Points of a scan bucketed by cubic voxels.
pub struct ScanIndex {
    voxel: f64,
    /// Per voxel: the last visit stamp (see `for_each_near_plane`).
    visited: Vec<u32>,
    ids: VoxelIds,
    buckets: Buckets,
    lo: [i64; 3],
    hi: [i64; 3],
    /// With hashed ids: dense occupancy bits over the voxel box `lo..=hi`
    /// (when it has at most `MAX_DENSE` voxels), a cheap test before each
    /// hash lookup. Empty with dense ids, which are as cheap.
    occ: Vec<u64>,
    dims: [usize; 3],
    /// Every occupied voxel's integer coordinates.
    voxels: Vec<[i64; 3]>,
}

/// Largest voxel box that gets a dense occupancy bitmap (16 Mbit = 2 MB).
const MAX_DENSE: usize = 1 << 24;

impl ScanIndex {
    /// Index `pts` (local coordinates) with voxels of side `voxel` metres.
    pub fn new(pts: &[Vec3], voxel: f64) -> Self {
        let v = crate::hash::voxelise(pts, voxel);
        let cells = v.coords.len();
        let buckets = Buckets::new(&v.cell_of, cells);
        // The box counts every voxel, also those whose packed key wraps onto
        // another's (coordinates 2^21 voxels apart).
        let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
        for c in v.coords.iter().chain(&v.aliased) {
            for k in 0..3 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
        let (mut occ, mut dims) = (Vec::new(), [0usize; 3]);
        if !pts.is_empty() && matches!(v.ids, VoxelIds::Map(_)) {
            let d = [0, 1, 2].map(|k| (hi[k] - lo[k] + 1) as u128);
            if d[0] * d[1] * d[2] <= MAX_DENSE as u128 {
                dims = d.map(|x| x as usize);
                occ = vec![0u64; (dims[0] * dims[1] * dims[2]).div_ceil(64)];
                for c in v.coords.iter().chain(&v.aliased) {
                    let c = [c[0] - lo[0], c[1] - lo[1], c[2] - lo[2]];
                    let k = (c[2] as usize * dims[1] + c[1] as usize) * dims[0] + c[0] as usize;
                    occ[k >> 6] |= 1 << (k & 63);
                }
            }
        }
        let mut voxels = v.coords;
        voxels.extend_from_slice(&v.aliased);
        ScanIndex {
            voxel,
            voxels,
            visited: vec![0; cells],
            ids: v.ids,
            buckets,
            lo,
            hi,
            occ,
            dims,
        }
    }

    /// The voxels that hold points: integer coordinates `c`, the voxel
    /// spanning `c * side ..= (c + 1) * side` in local coordinates.
    pub fn voxels(&self) -> (&[[i64; 3]], f64) {
        (&self.voxels, self.voxel)
    }

    /// Might voxel `c` hold points? (False only when it surely does not.)
    #[inline]
    fn maybe_occupied(&self, c: [i64; 3]) -> bool {
        if self.occ.is_empty() {
            return true;
        }
        let r = [c[0] - self.lo[0], c[1] - self.lo[1], c[2] - self.lo[2]];
        let k = (r[2] as usize * self.dims[1] + r[1] as usize) * self.dims[0] + r[0] as usize;
        self.occ[k >> 6] >> (k & 63) & 1 == 1
    }

    /// Call `f` with the point indices of every voxel that intersects the box
    /// `[lo, hi]` and may hold points within `gate` of the plane
    /// `n · p + d = 0` (local coordinates), skipping voxels already visited
    /// with the same `stamp` (so a growing box costs each voxel once). The
    /// loop runs over the two axes the plane is least aligned with and
    /// solves for the third, so a plane costs about its area in voxels, not
    /// the box's volume.
    #[allow(clippy::too_many_arguments)]
    pub fn for_each_near_plane(
        &mut self,
        stamp: u32,
        lo: DVec3,
        hi: DVec3,
        n: DVec3,
        d: f64,
        gate: f64,
        mut f: impl FnMut(&[u32]),
    ) {
        if self.ids.is_empty() {
            return;
        }
        let v = self.voxel;
        let clamp = |x: f64, k: usize| -> i64 {
            crate::geometry::floor_i64(x / v).clamp(self.lo[k], self.hi[k])
        };
        let (blo, bhi) = (
            [clamp(lo.x, 0), clamp(lo.y, 1), clamp(lo.z, 2)],
            [clamp(hi.x, 0), clamp(hi.y, 1), clamp(hi.z, 2)],
        );
        if lo.x > (self.hi[0] + 1) as f64 * v
            || lo.y > (self.hi[1] + 1) as f64 * v
            || lo.z > (self.hi[2] + 1) as f64 * v
            || hi.x < self.lo[0] as f64 * v
            || hi.y < self.lo[1] as f64 * v
            || hi.z < self.lo[2] as f64 * v
        {
            return;
        }
        let na = n.to_array();
        // Solve along the axis with the largest normal component.
        let k = if na[0].abs() >= na[1].abs() && na[0].abs() >= na[2].abs() {
            0
        } else if na[1].abs() >= na[2].abs() {
            1
        } else {
            2
        };
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let slack = gate + v * 3f64.sqrt() * 0.5;
        for a in blo[i]..=bhi[i] {
            for b in blo[j]..=bhi[j] {
                let (ca, cb) = ((a as f64 + 0.5) * v, (b as f64 + 0.5) * v);
                // n_k * x_k = -(d + n_i * ca + n_j * cb) +- slack
                let rest = d + na[i] * ca + na[j] * cb;
                let (x0, x1) = ((-rest - slack) / na[k], (-rest + slack) / na[k]);
                let (x0, x1) = (x0.min(x1), x0.max(x1));
                let c0 = crate::geometry::floor_i64(x0 / v).max(blo[k]);
                let c1 = crate::geometry::floor_i64(x1 / v).min(bhi[k]);
                for c in c0..=c1 {
                    let mut idx = [0i64; 3];
                    idx[i] = a;
                    idx[j] = b;
                    idx[k] = c;
                    if !self.maybe_occupied(idx) {
                        continue;
                    }
                    if let Some(cell) = self.ids.get(idx) {
                        if self.visited[cell as usize] == stamp {
                            continue;
                        }
                        self.visited[cell as usize] = stamp;
                        f(self.buckets.of(cell as usize));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voxels_whose_keys_wrap_are_still_found() {
        // 2^21 voxels apart, the packed keys of (0, 0, 0) and (2^21, 0, 0)
        // coincide: the far voxel must still be in the index's box and
        // occupancy, and visiting it yields its point.
        let far = (1u64 << 21) as f32;
        let pts = vec![Vec3::new(0.5, 0.5, 0.5), Vec3::new(far + 0.5, 0.5, 0.5)];
        let mut index = ScanIndex::new(&pts, 1.0);
        let mut seen = Vec::new();
        let x = far as f64 + 0.5;
        index.for_each_near_plane(
            1,
            DVec3::new(x - 1.0, -1.0, -1.0),
            DVec3::new(x + 1.0, 2.0, 2.0),
            DVec3::X,
            -x,
            0.1,
            |items| seen.extend_from_slice(items),
        );
        assert!(seen.contains(&1), "{seen:?}");
    }
}
