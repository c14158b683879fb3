//! The coarse pass ([`CascadePolicy::coarse_pass`]): a second cascade, at
//! [`SCALE`] times the first one's clustering tolerance, footprint cell,
//! outline radius and sampling voxel, on the points that no primitive
//! explains and that lie too sparsely for the first one.
//!
//! A spinning LiDAR samples a surface ever more sparsely with range and
//! with grazing incidence: a facade 40-100 m down the street, seen along
//! its length, holds a few laser rings half a metre apart, with gaps of a
//! metre along each. At the first pass's scale its points fall apart into
//! fragments (the clustering breaks at every gap wider than its tolerance)
//! and no round finds it. Only points whose neighbourhood is sparse take
//! part: the leftovers of well-sampled surfaces (the laser-ring bands of a
//! facade at a door's or a window's height) would, at this scale, join
//! into horizontal slabs across the surfaces they lie on.
//!
//! [`CascadePolicy::coarse_pass`]: super::CascadePolicy::coarse_pass

use super::{Detection, Detector, PlanePool, Progress, Seen, NO_PRIMITIVE};
use crate::hash::VoxelGrid;
use crate::params::Params;
use crate::primitive::Primitive;
use crate::rng::Rng;
use glam::Vec3;
use std::ops::ControlFlow;

/// How much coarser the second pass is than the first: its clustering
/// tolerance, footprint cell, outline radius and sampling voxel.
pub(crate) const SCALE: f64 = 3.0;
/// [`SCALE`], as an integer.
const SCALE_INT: usize = 3;

/// The stream the coarse pass's generator is derived with.
pub(super) const STREAM: u64 = 0xC0A5;

/// The parameters of the coarse pass: `p` at [`SCALE`] times its
/// clustering tolerances, cells, outline radii and sampling voxel, and
/// `minInliers` over [`SCALE`] (50 with the defaults): a surface seen at
/// grazing incidence is sampled more sparsely along it, and the first
/// pass's count would ask a far facade for the support of one seen face
/// on. (Over `SCALE^2`, for sampling sparser both ways, found more on the
/// own simulator's locations but at precision 0.877 against 0.950.)
pub(super) fn coarser(p: &Params) -> Params {
    let mut q = p.clone();
    q.min_inliers = p.min_inliers.div_ceil(SCALE_INT);
    for s in [&mut q.other, &mut q.ground] {
        s.cluster_tolerance *= SCALE;
        s.cell *= SCALE;
        s.alpha *= SCALE;
    }
    q.sample_radius *= SCALE;
    q
}

/// The points that no primitive explains (`labels`) and that have no more
/// neighbours in the whole cloud, within the clustering tolerance `r`,
/// than a surface sampled at one point per footprint cell `c` would have
/// (pi r^2 / c^2, rounded down: 19 with the defaults). Below that density
/// the first pass's footprint has a hole in most cells, and its clustering
/// breaks. Neighbours are counted in `grid` (the first pass's sampling
/// voxels) when its voxels are `r` to `2 r` wide (the defaults: 1 m and
/// 0.5 m), else in voxels of `r`: in wider ones a sparse point would read
/// ever more points that lie too far.
fn sparse_leftovers(pts: &[Vec3], labels: &[u32], grid: &VoxelGrid, p: &Params) -> Vec<u32> {
    let (r, c) = (p.other.cluster_tolerance, p.other.cell);
    // Counting stops past `most`, which bounds the work in dense places.
    // (Validated parameters: `r` in (0, 1000], `c` at least 0.01 m.)
    let most = (std::f64::consts::PI * (r / c) * (r / c)) as usize;
    let own;
    let grid = if (r..=2.0 * r).contains(&grid.side) {
        grid
    } else {
        own = VoxelGrid::new(pts, r);
        &own
    };
    (0..pts.len())
        .filter(|&i| labels[i] == NO_PRIMITIVE && grid.neighbours_up_to(pts, i, r, most) <= most)
        .map(|i| i as u32)
        .collect()
}

/// Run the coarse pass after `first`'s rounds and add what it finds to
/// `out` (labels, primitives numbered on, steps, work); `progress` counts
/// its rounds on from the first pass's. The flag: stopped by `progress`.
pub(super) fn pass(
    first: &Detector,
    out: &mut Detection,
    seen: Seen,
    grid: &VoxelGrid,
    rng: Rng,
    progress: &mut dyn FnMut(&Progress) -> ControlFlow<()>,
) -> bool {
    let pts = seen.pts;
    let p = first.params;
    let room = p.max_primitives.saturating_sub(out.primitives.len());
    if room == 0 {
        return false;
    }
    let q = Params {
        max_primitives: room,
        max_work: p.max_work.saturating_sub(out.work),
        ..coarser(p)
    };
    let sparse = sparse_leftovers(pts, &out.labels, grid, p);
    if sparse.len() < q.min_inliers {
        return false;
    }
    let points: Vec<Vec3> = sparse.iter().map(|&i| pts[i as usize]).collect();
    let (rounds, found) = (out.steps.len(), out.primitives.len());
    let sub = Seen {
        pts: &points,
        ..seen
    };
    let sub_grid = PlanePool::grid(&points, q.sample_radius);
    let (more, stopped, _) = Detector {
        sensors: first.sensors,
        ..Detector::new(&q, first.policy)
    }
    .rounds(sub, sub_grid, rng, &mut |at| {
        progress(&Progress {
            round: rounds + at.round,
            points_left: at.points_left,
            points: pts.len(),
            primitives: found + at.primitives,
        })
    });
    let base = found as u32;
    for (&i, &l) in sparse.iter().zip(&more.labels) {
        if l != NO_PRIMITIVE {
            out.labels[i as usize] = base + l;
        }
    }
    out.primitives
        .extend(more.primitives.into_iter().map(|q| Primitive {
            id: base + q.id,
            ..q
        }));
    out.steps.extend(more.steps);
    out.work += more.work;
    stopped
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points of the vertical patch y = `y`, x in `x0..x1`, z in 0..2, every
    /// `step` metres.
    fn grid(x0: f64, x1: f64, y: f64, step: f64) -> Vec<Vec3> {
        let mut out = Vec::new();
        let mut x = x0;
        while x < x1 {
            let mut z = 0.0;
            while z < 2.0 {
                out.push(Vec3::new(x as f32, y as f32, z as f32));
                z += step;
            }
            x += step;
        }
        out
    }

    /// Only the leftovers of a sparsely seen surface take part: not those
    /// of a dense one, nor a band of a dense surface a primitive explains
    /// the rest of.
    #[test]
    fn the_coarse_pass_takes_the_sparse_leftovers_only() {
        let p = Params::gpp2();
        let sparse = grid(0.0, 10.0, 0.0, 0.5);
        let dense = grid(20.0, 24.0, 0.0, 0.05);
        let explained = grid(30.0, 34.0, 0.0, 0.05);
        let pts = [sparse.clone(), dense.clone(), explained.clone()].concat();
        let mut labels = vec![NO_PRIMITIVE; pts.len()];
        let from = sparse.len() + dense.len();
        // All of the third patch but the band between z = 1 and 1.2 m.
        for (i, q) in pts.iter().enumerate().skip(from) {
            if !(1.0..1.2).contains(&q.z) {
                labels[i] = 0;
            }
        }
        let want: Vec<u32> = (0..sparse.len() as u32).collect();
        // On the sampling voxels (1 m), and on voxels narrower or much
        // wider than the clustering tolerance, which it then does not
        // count in.
        for side in [p.sample_radius, 0.3, 5.0] {
            let left = sparse_leftovers(&pts, &labels, &PlanePool::grid(&pts, side), &p);
            assert_eq!(left, want, "voxels of {side} m");
        }
    }
}
