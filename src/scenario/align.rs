//! Scan-to-map alignment: before a scan expands the map, its pose is
//! refined so that its points lie on the polygons the map already holds.
//!
//! Poses from odometry drift: a few centimetres and a tenth of a degree a
//! scan, adding up over a drive. Expansion takes a point only within a few
//! centimetres of a polygon's plane (`expandAcross`), so a known wall seen
//! through a drifted pose looks new: it is detected a second time, or its
//! points wait in the pool. Aligning each scan first keeps the map one
//! layer thick. This is the step the paper leaves to its (perfect) poses.
//!
//! The method is point-to-plane Gauss-Newton, the linearised form of
//! Chen and Medioni's ICP, with the map's polygons as the planes:
//! 1. *Prior.* The scan starts at the correction found for the last scan
//!    (drift changes little from one scan to the next).
//! 2. *Sample.* Up to [`SAMPLE`] points of the scan, evenly spaced in scan
//!    order.
//! 3. *Pairs.* Each sampled point is paired with the nearest polygon plane
//!    within the gate whose footprint (the raster of cells that held
//!    support) holds the point's projection. The gate starts at
//!    `alignReach` and halves each iteration down to `expandAcross`;
//!    residuals are weighted with Tukey's biweight at the gate, so a car
//!    that drove off or a bush in front of a wall weighs little.
//! 4. *Step.* The six-parameter update (a small rotation about the sensor
//!    and a translation) solves the weighted normal equations, but only in
//!    the directions the pairs pin down: the 6 x 6 system is diagonalised
//!    and directions with less information than [`MIN_CONSTRAINT`] pairs
//!    keep the prior. A drive along a straight road between facades sees
//!    nothing that fixes the position along the road; the solution does not
//!    wander there (Zhang, Kaess and Singh, "On degeneracy of
//!    optimization-based state estimation problems", ICRA 2016).
//! 5. Iterate until the step is below a tenth of a millimetre (at most
//!    [`ITERATIONS`]).
//! 6. *Polygons at odds with the rest.* While the step is one to apply
//!    (below), the polygon whose pairs change it the most is found by
//!    leaving each out in turn (the rest re-solved from the refined pose,
//!    in the directions the rest pins down); when that change moves some
//!    point of a 50 m scan by more than [`DEADBAND`], the polygon leaves
//!    the fit, which iterates again at the last gate (at most
//!    [`MAX_LEFT_OUT`] polygons a scan). A drifted pose moves the points
//!    on every polygon alike, and the polygons agree on the step; a
//!    polygon fitted a little off from the one scan it was born in (a
//!    car's roof 2.5 degrees off level, on the independent bench) pulls
//!    the scan towards itself alone, and with true poses turned the whole
//!    map by 0.05 degrees. This is a deletion diagnostic, as Cook's
//!    distance is for one observation of a least-squares fit, with each
//!    polygon's pairs as one group. Two polygons off the same way hide
//!    each other: leaving out either, the other still pulls.
//!
//! The result is kept only with at least [`MIN_PAIRS`] pairs and a total
//! step within `alignReach` (a larger one is no refinement but a different
//! answer); and only when it moves some point of a 50 m scan by more than
//! [`DEADBAND`], so that exact poses stay exactly as given.

use super::surfaces::Surfaces;
use crate::cloud::Cloud;
use crate::params::Params;
use crate::primindex::PrimIndex;
use crate::primitive::Primitive;
use glam::{DMat4, DQuat, DVec3};

/// Most scan points used (evenly spaced in scan order).
pub const SAMPLE: usize = 2048;

/// Most Gauss-Newton iterations.
const ITERATIONS: usize = 12;

/// Rotations are measured as the displacement they give at this distance
/// from the sensor (m), so that the six unknowns have one unit.
const LEVER: f64 = 10.0;

/// Most polygons left out of one scan's fit as at odds with the rest.
const MAX_LEFT_OUT: usize = 3;

/// Fewest pairs for a refinement.
pub const MIN_PAIRS: usize = 100;

/// Least information in a direction of the pose (the weight of this many
/// pairs whose planes face it fully) for the step to move along it.
pub const MIN_CONSTRAINT: f64 = 25.0;

/// A refinement that moves no point within 50 m of the sensor by more than
/// this (m) is not applied: expansion's gate (at least 3 cm) absorbs such
/// an error, and below it the fit measures the map's own small errors more
/// than the pose (with exact poses, fits of 1-3 cm at 50 m turned the
/// simulated street's scans by 0.01-0.03 degrees).
pub const DEADBAND: f64 = 0.03;

/// Range the deadband is measured at (m).
const DEADBAND_RANGE: f64 = 50.0;

/// What one alignment found.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fit {
    /// The refinement, a world-frame rigid transform (identity when none
    /// was kept).
    pub step: DMat4,
    /// Pairs in the last iteration.
    pub pairs: usize,
    /// How many of the six pose directions the pairs pinned down.
    pub constrained: usize,
    /// Whether `step` is applied (see the module documentation).
    pub applied: bool,
    /// How far the refinement moves the sensor (m).
    pub shift: f64,
    /// Its rotation (rad).
    pub turn: f64,
}

impl Fit {
    fn none(pairs: usize, constrained: usize) -> Self {
        Fit {
            step: DMat4::IDENTITY,
            pairs,
            constrained,
            applied: false,
            shift: 0.0,
            turn: 0.0,
        }
    }
}

/// Refine the placement of the world-frame scan `cloud` (as given, seen
/// from `sensor`), starting from the correction `prior`, against the
/// polygons `prims` (id-sorted, filed in `index`). The refinement turns
/// about the sensor moved by `prior`.
// Matrix code reads as the formulas with indices.
#[allow(clippy::needless_range_loop)]
pub(crate) fn align(
    cloud: &Cloud,
    sensor: DVec3,
    prior: &DMat4,
    prims: &[Primitive],
    index: &PrimIndex,
    params: &Params,
) -> Fit {
    let n = cloud.len();
    if n == 0 || prims.is_empty() {
        return Fit::none(0, 0);
    }
    let reach = params.align_reach;
    let floor = params
        .other
        .expand_across
        .max(params.ground.expand_across)
        .min(reach);
    // The sample, moved by the prior, relative to the moved sensor.
    let at = prior.transform_point3(sensor);
    let every = n.div_ceil(SAMPLE).max(1);
    let world: Vec<DVec3> = (0..n)
        .step_by(every)
        .map(|i| prior.transform_point3(cloud.origin + cloud.points[i].as_dvec3()))
        .collect();
    let ids = index.near_points(world.iter().copied());
    let surfaces = Surfaces::new(prims, &ids, |_| 2.0 * reach + 1.0);
    // Each sample's candidate polygons: within twice the first gate of
    // their plane (a kept step moves a point 10 m from the sensor by at
    // most the first gate; a farther point that leaves this band only
    // loses its pair).
    let mut samples: Vec<DVec3> = Vec::with_capacity(world.len());
    let mut start: Vec<u32> = vec![0];
    let mut cand: Vec<u32> = Vec::new();
    for &w in &world {
        let before = cand.len();
        cand.extend(
            surfaces
                .near(w)
                .filter(|&k| prims[k].plane.signed_distance(w).abs() < 2.0 * reach)
                .map(|k| k as u32),
        );
        if cand.len() > before {
            samples.push(w - at);
            start.push(cand.len() as u32);
        }
    }
    if samples.len() < MIN_PAIRS {
        return Fit::none(0, 0);
    }
    // The running estimate: point s (relative to the sensor) goes to
    // rot * s + shift.
    let mut rot = DQuat::IDENTITY;
    let mut shift = DVec3::ZERO;
    let mut pairs;
    let mut constrained = 0;
    // The polygons left out of the fit (step 6), each paired polygon's
    // place in `parts` (`u32::MAX`: none) and its share of the normal
    // equations, kept in the pass that looks for one at odds.
    let mut left_out = vec![false; prims.len()];
    let mut slot = vec![u32::MAX; prims.len()];
    let mut parts: Vec<(usize, System)> = Vec::new();
    // `checking`: this pass, at the refined pose, keeps each polygon's
    // share and looks for one at odds instead of taking a step; `left`:
    // polygons left out so far; the fit stops at iteration `last`.
    let (mut checking, mut left, mut it, mut last) = (false, 0, 0, ITERATIONS);
    loop {
        let gate = (reach * 0.5f64.powi(it as i32)).max(floor);
        let mut all = System::default();
        for &(k, _) in &parts {
            slot[k] = u32::MAX;
        }
        parts.clear();
        pairs = 0;
        for (j, s) in samples.iter().enumerate() {
            let rel = rot * *s + shift;
            let w = at + rel;
            let mut best: Option<(f64, usize)> = None;
            for &k in &cand[start[j] as usize..start[j + 1] as usize] {
                let k = k as usize;
                let prim = &prims[k];
                let r = prim.plane.signed_distance(w);
                if r.abs() >= gate || best.is_some_and(|(b, _)| b.abs() <= r.abs()) || left_out[k] {
                    continue;
                }
                if prim.footprint.is_set(prim.frame.to_local(w)) {
                    best = Some((r, k));
                }
            }
            let Some((r, k)) = best else {
                continue;
            };
            let normal = prims[k].plane.normal;
            let u = r / gate;
            let weight = (1.0 - u * u) * (1.0 - u * u);
            let a = rel.cross(normal) / LEVER;
            let jac = [a.x, a.y, a.z, normal.x, normal.y, normal.z];
            all.add(weight, &jac, r);
            if checking {
                if slot[k] == u32::MAX {
                    slot[k] = parts.len() as u32;
                    parts.push((k, System::default()));
                }
                parts[slot[k] as usize].1.add(weight, &jac, r);
            }
            pairs += 1;
        }
        if pairs < MIN_PAIRS {
            return Fit::none(pairs, 0);
        }
        if checking {
            // 6. The polygon at odds with the rest leaves the fit, which
            //    goes on at the last gate.
            checking = false;
            let Some(k) = odd_one(&all, &parts) else {
                break;
            };
            left_out[k] = true;
            left += 1;
            last = it + ITERATIONS;
            continue;
        }
        let (x, c) = constrained_solve(all.full(), all.g);
        constrained = c;
        let turn = DVec3::new(x[0], x[1], x[2]) / LEVER;
        let step = DVec3::new(x[3], x[4], x[5]);
        let dq = DQuat::from_scaled_axis(turn);
        rot = (dq * rot).normalize();
        shift = dq * shift + step;
        it += 1;
        let small = step.length() + turn.length() * LEVER < 1e-4;
        if small && gate <= floor || it >= last {
            if left < MAX_LEFT_OUT && kept(rot, shift, reach) {
                checking = true;
                continue;
            }
            break;
        }
    }
    if !kept(rot, shift, reach) {
        return Fit::none(pairs, constrained);
    }
    let angle = rot.angle_between(DQuat::IDENTITY);
    // World: w -> at + rot * (w - at) + shift.
    let step =
        DMat4::from_translation(at + shift) * DMat4::from_quat(rot) * DMat4::from_translation(-at);
    Fit {
        step,
        pairs,
        constrained,
        applied: true,
        shift: shift.length(),
        turn: angle,
    }
}

/// The weighted normal equations of point-to-plane pairs: `h` in its
/// upper triangle, `g` the gradient.
#[derive(Clone, Copy, Default)]
struct System {
    h: [[f64; 6]; 6],
    g: [f64; 6],
}

// Matrix code reads as the formulas with indices.
#[allow(clippy::needless_range_loop)]
impl System {
    /// `h` made whole from its upper triangle.
    fn full(&self) -> [[f64; 6]; 6] {
        let mut h = self.h;
        for p in 0..6 {
            for q in 0..p {
                h[p][q] = h[q][p];
            }
        }
        h
    }

    /// Add one pair: weight, Jacobian row and residual.
    #[inline(never)] // two callers; inlined, 64 bytes more wasm
    fn add(&mut self, weight: f64, jac: &[f64; 6], r: f64) {
        for p in 0..6 {
            self.g[p] += weight * jac[p] * r;
            for q in p..6 {
                self.h[p][q] += weight * jac[p] * jac[q];
            }
        }
    }
}

/// Whether the refinement `rot`, `shift` is one to apply: finite, within
/// `reach` (a larger step is no refinement but a different answer), and
/// moving some point within [`DEADBAND_RANGE`] of the sensor by more than
/// [`DEADBAND`].
fn kept(rot: DQuat, shift: DVec3, reach: f64) -> bool {
    let angle = rot.angle_between(DQuat::IDENTITY);
    shift.is_finite()
        && angle.is_finite()
        && shift.length() + angle * LEVER <= reach
        && motion(shift, angle) > DEADBAND
}

/// The most a step of `shift` and a turn of `angle` (radians) about the
/// sensor moves a point within [`DEADBAND_RANGE`] of it (m).
fn motion(shift: DVec3, angle: f64) -> f64 {
    shift.length() + angle * DEADBAND_RANGE
}

/// The polygon most at odds with the rest, from the normal equations at
/// the refined pose (`all`) and each paired polygon's share of them
/// (`parts`, by index into the polygons): the one whose pairs, left out
/// and the rest re-solved from there, change the step the most, when
/// that change moves some point within [`DEADBAND_RANGE`] by more than
/// [`DEADBAND`]. A drifted pose moves the points on every polygon alike,
/// so the polygons agree on the step and none changes it much; a polygon
/// fitted a little off from the one scan it was born in (a car's roof 2.5
/// degrees off level) pulls the scan towards itself alone. A direction
/// only that polygon pins down keeps its value: nothing else gainsays it.
fn odd_one(all: &System, parts: &[(usize, System)]) -> Option<usize> {
    let mut worst: Option<(f64, usize)> = None;
    for (k, part) in parts {
        let mut rest = *all;
        for p in 0..6 {
            rest.g[p] -= part.g[p];
            for q in p..6 {
                rest.h[p][q] -= part.h[p][q];
            }
        }
        let (x, _) = constrained_solve(rest.full(), rest.g);
        let change = motion(
            DVec3::new(x[3], x[4], x[5]),
            DVec3::new(x[0], x[1], x[2]).length() / LEVER,
        );
        if change > DEADBAND && worst.is_none_or(|(w, _)| change > w) {
            worst = Some((change, *k));
        }
    }
    worst.map(|(_, k)| k)
}

/// The Gauss-Newton step `x = -H⁺ g` restricted to the eigen-directions of
/// the symmetric `h` whose eigenvalue is at least [`MIN_CONSTRAINT`];
/// returns it and how many directions that is.
fn constrained_solve(h: [[f64; 6]; 6], g: [f64; 6]) -> ([f64; 6], usize) {
    let (values, vectors) = jacobi6(h);
    let mut x = [0.0; 6];
    let mut used = 0;
    for k in 0..6 {
        if values[k] < MIN_CONSTRAINT || values[k].is_nan() {
            continue;
        }
        let v = vectors[k];
        let along = (0..6).map(|i| v[i] * g[i]).sum::<f64>() / values[k];
        for i in 0..6 {
            x[i] -= along * v[i];
        }
        used += 1;
    }
    (x, used)
}

/// Eigenvalues and unit eigenvectors of a symmetric 6 x 6 matrix, by
/// cyclic Jacobi rotations (deterministic, accurate to rounding).
#[allow(clippy::needless_range_loop)]
fn jacobi6(mut a: [[f64; 6]; 6]) -> ([f64; 6], [[f64; 6]; 6]) {
    let mut v = [[0.0f64; 6]; 6];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..64 {
        let off: f64 = (0..6)
            .flat_map(|p| (p + 1..6).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q] * a[p][q])
            .sum();
        let diag: f64 = (0..6).map(|p| a[p][p] * a[p][p]).sum();
        if off <= 1e-30 * diag || off.is_nan() {
            break;
        }
        for p in 0..6 {
            for q in p + 1..6 {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                // The smaller root of t^2 + 2 theta t - 1 = 0 (signum(0) = 1).
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..6 {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for k in 0..6 {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    // Column k of `v` is the eigenvector of a[k][k].
    let mut values = [0.0; 6];
    let mut vectors = [[0.0; 6]; 6];
    for k in 0..6 {
        values[k] = a[k][k];
        for i in 0..6 {
            vectors[k][i] = v[i][k];
        }
    }
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_diagonalises_a_symmetric_matrix() {
        let mut m = [[0.0; 6]; 6];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = 1.0 / (1.0 + i as f64 + j as f64) + if i == j { 2.0 } else { 0.0 };
            }
        }
        let (values, vectors) = jacobi6(m);
        for k in 0..6 {
            let v = vectors[k];
            let norm: f64 = v.iter().map(|x| x * x).sum();
            assert!((norm - 1.0).abs() < 1e-12);
            for i in 0..6 {
                let mv: f64 = (0..6).map(|j| m[i][j] * v[j]).sum();
                assert!((mv - values[k] * v[i]).abs() < 1e-10, "M v = λ v");
            }
        }
    }

    #[test]
    fn unconstrained_directions_do_not_move() {
        // Information only on the translation along z (a floor): the step
        // moves along z and nowhere else.
        let mut h = [[0.0; 6]; 6];
        h[5][5] = 1000.0;
        let g = [3.0, -2.0, 1.0, 4.0, 5.0, 20.0];
        let (x, used) = constrained_solve(h, g);
        assert_eq!(used, 1);
        assert_eq!(&x[..5], &[0.0; 5]);
        assert!((x[5] + 0.02).abs() < 1e-12);
    }
}
