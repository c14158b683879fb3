//! Expansion of an existing primitive with a new scan (the paper's
//! Algorithm 2, first half).
//!
//! 1. *Perpendicular gate*: the scan points within `across` of the plane,
//!    found through the scan's voxel index near the primitive's grown box.
//! 2. *Longitudinal growth*, projected into the primitive's frame: a point
//!    is taken when it lies within `along` of the outline, or within `along`
//!    of a point already taken. The paper reaches this by iterating "offset
//!    the polygon by a step, take the points inside, re-outline"; here the
//!    fixed point is computed directly: the gated points are clustered with
//!    tolerance `along` (linear time) and every cluster that has a point
//!    within `along` of the outline is taken whole, unless it fills the gate
//!    evenly (a slab of a volume, such as a tree beside a car's end: see
//!    [`SLAB_RMS`]). With convex outlines the
//!    paper's extra reach is kept: the hull of old outline and taken points
//!    is grown again until it takes nothing new.
//! 3. *Refit* from running moments (only points within three residual
//!    standard deviations of the plane feed the moments, so crossing
//!    surfaces do not tilt it), the frame follows the plane with the
//!    smallest rotation, the footprint records the new points and the
//!    outline is recomputed (convex: hull of old outline and new points;
//!    concave: from the footprint).
//! 4. The taken points leave the scan: later primitives and the detector
//!    never see them.

use super::index::ScanIndex;
use crate::cloud::Cloud;
use crate::detect::cluster::Clusterer;
use crate::geometry::mask::{GrownMask, Zone};
use crate::geometry::{bounds, convex_hull};
use crate::params::Params;
use crate::primitive::Primitive;
use glam::{DVec2, DVec3};

/// Working memory kept across the primitives of one scan (fresh buffers per
/// primitive cost more in allocation than some primitives' whole growth,
/// in wasm especially).
#[derive(Default)]
pub(crate) struct Scratch {
    clusterer: Clusterer,
    cand: Vec<u32>,
    q: Vec<DVec2>,
    off: Vec<f32>,
}

/// Grow `prim` with the live points of `cloud`; marks taken points dead in
/// `alive`, writes `label` into `labels` for them and returns how many.
#[allow(clippy::too_many_arguments)]
pub(crate) fn expand(
    scratch: &mut Scratch,
    prim: &mut Primitive,
    cloud: &Cloud,
    index: &mut ScanIndex,
    stamp: u32,
    alive: &mut [bool],
    labels: &mut [u32],
    params: &Params,
    scan: u64,
) -> usize {
    let surface = params.surface(prim.ground);
    let (max_across, along) = (surface.expand_across, surface.expand_along);
    // The gate adapts to how flat this primitive really is (the 3 cm floor
    // yields to an expandAcross set below it).
    let across = prim.noise_gate(max_across);
    let n = prim.plane.normal;
    let d_local = prim.plane.offset + n.dot(cloud.origin);
    let verts = prim.vertices();
    let (mut lo, mut hi) = bounds(&verts);
    lo -= DVec3::splat(along + across) + cloud.origin;
    hi += DVec3::splat(along + across) - cloud.origin;

    // 1. Perpendicular gate, over the voxels near the plane in the box; the
    //    box is enlarged while the growth reaches its edge.
    let Scratch {
        clusterer,
        cand,
        q,
        off,
    } = scratch;
    cand.clear();
    q.clear();
    off.clear();
    let mut taken: Vec<bool>;
    let mut inner: Vec<bool>;
    let mut outside: bool;
    let mut guard = 0;
    loop {
        let (nf, df, af) = (n.as_vec3(), d_local as f32, across as f32);
        index.for_each_near_plane(stamp, lo, hi, n, d_local, across, |items| {
            for &i in items {
                if !alive[i as usize] {
                    continue;
                }
                let p = cloud.points[i as usize];
                let d = nf.dot(p) + df;
                if d.abs() >= af {
                    continue;
                }
                cand.push(i);
                off.push(d);
                q.push(prim.frame.to_local(cloud.origin + p.as_dvec3()));
            }
        });
        // 2. Longitudinal growth.
        (taken, inner, outside) = grow(
            &prim.outline,
            q,
            off,
            SLAB_RMS * across,
            along,
            params,
            clusterer,
        );
        // Does the taken region reach the edge of the gathered box?
        let mut tlo = DVec3::splat(f64::INFINITY);
        let mut thi = DVec3::splat(f64::NEG_INFINITY);
        for (k, &t) in taken.iter().enumerate() {
            if t {
                let p = cloud.points[cand[k] as usize].as_dvec3();
                crate::geometry::grow_box(&mut tlo, &mut thi, p);
            }
        }
        let reach = DVec3::splat(along + across);
        guard += 1;
        if guard >= 16 || !(tlo - reach).cmplt(lo).any() && !(thi + reach).cmpgt(hi).any() {
            break;
        }
        // Extend only the sides the growth reached, geometrically (by half
        // the box's size, at least four reaches), so long walls and the ground
        // need few rounds.
        let ext = ((hi - lo) * 0.5).max(reach * 4.0);
        lo = DVec3::select((tlo - reach).cmplt(lo), lo - ext, lo);
        hi = DVec3::select((thi + reach).cmpgt(hi), hi + ext, hi);
    }
    let count = taken.iter().filter(|&&t| t).count();
    if count == 0 {
        return 0;
    }

    // 3. Refit from robust running moments, re-frame, re-outline.
    let cut = across;
    let mut new_q = Vec::with_capacity(count);
    for (k, &t) in taken.iter().enumerate() {
        if !t {
            continue;
        }
        let i = cand[k] as usize;
        alive[i] = false;
        labels[i] = prim.id;
        // Only points inside the outline feed the plane fit: the growth ring
        // holds the edges of crossing surfaces (the top of a car's side under
        // its roof), which would tilt the plane a little more every scan.
        let w = cloud.origin + cloud.points[i].as_dvec3();
        if inner[k] && prim.plane.signed_distance(w).abs() <= cut {
            prim.moments.push(w);
        }
        new_q.push(q[k]);
    }
    let fresh_cells = prim.footprint.mark_all(&new_q);
    if let Some((mut plane, _)) = prim.moments.fit_plane() {
        if plane.normal.dot(prim.plane.normal) < 0.0 {
            plane.normal = -plane.normal;
            plane.offset = -plane.offset;
        }
        prim.plane = plane;
        prim.frame = prim.frame.realigned(&plane);
    }
    // The outline only changes when points were taken outside it (closing
    // is increasing and idempotent: cells inside the closed region leave it
    // unchanged; a hull only grows from points outside it).
    if outside && fresh_cells > 0 {
        prim.reshape(params, &new_q);
    }
    prim.support += count as u64;
    prim.last_scan = scan;
    count
}

/// Clusters of at least this many gated points beyond the outline are
/// judged by their spread across the gate.
const SLAB_MIN_POINTS: usize = 20;

/// The RMS distance from the plane, as a share of the gate's half-width,
/// above which a cluster beyond the outline is a slab of a volume: points
/// spread evenly across the gate have sqrt(1/3) = 0.577 of it, a surface's
/// points (the gate is three times the primitive's own RMS) about 1/3.
const SLAB_RMS: f64 = 0.5;

/// Which of the points `q` are taken: every point within `along` of the
/// region (the outline, then for convex outlines the hull of outline and
/// taken points), and every point chained to those through gaps of at most
/// `along`.
///
/// Only points outside the region need the chaining: a point farther than
/// `along` from the region is farther than `along` from every point inside
/// it, so the clustering runs on the ring within `along` of the region and
/// the points beyond, usually a small share of the candidates.
///
/// Also returns which points lie inside the outline's cells and whether any
/// point was taken outside them.
fn grow(
    outline: &[DVec2],
    q: &[DVec2],
    off: &[f32],
    max_rms: f64,
    along: f64,
    params: &Params,
    clusterer: &mut Clusterer,
) -> (Vec<bool>, Vec<bool>, bool) {
    let mut taken = vec![false; q.len()];
    let mut inner = vec![false; q.len()];
    let mut outside = false;
    if q.is_empty() {
        return (taken, inner, outside);
    }
    let mut first = true;
    let cell = (along * 0.5).clamp(0.05, 1.0);
    let mut region = outline.to_vec();
    for _ in 0..32 {
        let mask = GrownMask::new(&region, along, cell);
        let mut ring: Vec<u32> = Vec::new();
        let mut near: Vec<DVec2> = Vec::new();
        let mut near_idx: Vec<u32> = Vec::new();
        let mut new = 0usize;
        for (k, &p) in q.iter().enumerate() {
            if taken[k] {
                continue;
            }
            match mask.zone(p) {
                Zone::Inside => {
                    taken[k] = true;
                    inner[k] = first;
                    new += 1;
                    outside |= !first;
                }
                Zone::Ring => {
                    ring.push(near.len() as u32);
                    near.push(p);
                    near_idx.push(k as u32);
                }
                Zone::Outside => {
                    near.push(p);
                    near_idx.push(k as u32);
                }
            }
        }
        if !near.is_empty() && !ring.is_empty() {
            let (comp, sizes) = clusterer.clusters(&near, along);
            let mut hit = vec![false; sizes.len()];
            for &r in &ring {
                hit[comp[r as usize] as usize] = true;
            }
            // A cluster that fills the gate evenly is a slab of a volume
            // (a tree beside a car's end), not more of the surface.
            let mut sum = vec![0.0f64; sizes.len()];
            for (j, &c) in comp.iter().enumerate() {
                let d = f64::from(off[near_idx[j] as usize]);
                sum[c as usize] += d * d;
            }
            for (c, h) in hit.iter_mut().enumerate() {
                let n = sizes[c] as usize;
                if *h && n >= SLAB_MIN_POINTS && sum[c] > max_rms * max_rms * n as f64 {
                    *h = false;
                }
            }
            for (j, &c) in comp.iter().enumerate() {
                if hit[c as usize] {
                    taken[near_idx[j] as usize] = true;
                    new += 1;
                    outside = true;
                }
            }
        }
        first = false;
        if new == 0 || !params.hull.grows_by_hull() {
            break;
        }
        let mut pts = outline.to_vec();
        pts.extend(q.iter().zip(&taken).filter_map(|(&p, &t)| t.then_some(p)));
        match convex_hull(&pts) {
            Some(h) => region = h,
            None => break,
        }
    }
    (taken, inner, outside)
}
