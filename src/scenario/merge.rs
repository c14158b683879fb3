//! Merging primitives that grew into each other, which the paper lacks: two
//! pieces of one long wall detected in different scans become one primitive
//! once they are near-coplanar and their outlines touch or overlap. The
//! older id survives.

use crate::geometry::polygon::rings_within;
use crate::params::Params;
use crate::primitive::Primitive;
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// One merge: `removed` was absorbed into `kept`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct MergeEvent {
    /// Surviving (older) id.
    pub kept: u32,
    /// Absorbed id, no longer in the scenario.
    pub removed: u32,
}

/// Should `a` and `b` be one primitive?
pub(crate) fn mergeable(a: &Primitive, b: &Primitive, params: &Params) -> bool {
    if a.plane.angle_to(&b.plane) > params.merge_angle.to_radians() {
        return false;
    }
    // The smaller one must lie on the larger one's plane: the RMS distance
    // of its outline vertices and centroid. A centroid test alone is
    // meaningless next to a 3000 m^2 road, where a tenth of a degree of tilt
    // moves the plane by centimetres, and would let a sidewalk (one curb
    // higher) merge in; a maximum would keep a slightly tilted piece apart
    // forever.
    let (av, bv) = (a.vertices(), b.vertices());
    let (big, small, small_v) = if a.area >= b.area {
        (a, b, &bv)
    } else {
        (b, a, &av)
    };
    let ms = small_v
        .iter()
        .copied()
        .chain([small.moments.mean()])
        .map(|p| {
            let d = big.plane.signed_distance(p);
            d * d
        })
        .sum::<f64>()
        / (small_v.len() + 1) as f64;
    // Or each centroid on the other's plane (two slightly tilted pieces of
    // one surface whose far vertices disagree).
    let (ca, cb) = (a.moments.mean(), b.moments.mean());
    let centroids = a.plane.signed_distance(cb).abs() <= params.merge_distance
        && b.plane.signed_distance(ca).abs() <= params.merge_distance;
    if ms.sqrt() > params.merge_distance && !centroids {
        return false;
    }
    let ((alo, ahi), (blo, bhi)) = (bounds(&av), bounds(&bv));
    let pad = DVec3::splat(params.merge_gap + params.merge_distance);
    if (alo - pad).cmpgt(bhi).any() || (blo - pad).cmpgt(ahi).any() {
        return false;
    }
    // The outlines, both in a's frame: touching or overlapping?
    let b_in_a: Vec<DVec2> = bv.iter().map(|&v| a.frame.to_local(v)).collect();
    rings_within(&a.outline, &b_in_a, params.merge_gap)
}

/// Absorb `b` into `a`.
fn absorb(a: &mut Primitive, b: &Primitive, params: &Params) {
    a.moments.merge(&b.moments);
    let old_normal = a.plane.normal;
    if let Some((mut plane, _)) = a.moments.fit_plane() {
        if plane.normal.dot(old_normal) < 0.0 {
            plane.normal = -plane.normal;
            plane.offset = -plane.offset;
        }
        a.plane = plane;
        a.frame = a.frame.realigned(&plane);
    }
    let (fa, fb) = (a.frame, b.frame);
    a.footprint
        .merge_mapped(&b.footprint, |q| fa.to_local(fb.to_world(q)));
    let extra: Vec<DVec2> = params.hull.carried_vertices(&fb, &b.outline, &fa);
    a.reshape(params, &extra);
    a.support += b.support;
    a.born_scan = a.born_scan.min(b.born_scan);
    a.last_scan = a.last_scan.max(b.last_scan);
}

/// Merge until no pair of primitives, one of them in `changed` (ids), is
/// mergeable. `prims` is sorted by id and stays so.
pub(crate) fn merge_all(
    prims: &mut Vec<Primitive>,
    changed: &[u32],
    params: &Params,
) -> Vec<MergeEvent> {
    let mut events = Vec::new();
    let mut dirty: Vec<u32> = changed.to_vec();
    dirty.sort_unstable();
    dirty.dedup();
    while let Some(id) = dirty.first().copied() {
        dirty.remove(0);
        let Some(ia) = prims.iter().position(|p| p.id == id) else {
            continue;
        };
        let partner =
            (0..prims.len()).find(|&j| j != ia && mergeable(&prims[ia], &prims[j], params));
        let Some(ib) = partner else {
            continue;
        };
        // The older (smaller id) survives.
        let (keep, gone) = if prims[ia].id < prims[ib].id {
            (ia, ib)
        } else {
            (ib, ia)
        };
        let b = prims[gone].clone();
        absorb(&mut prims[keep], &b, params);
        let kept_id = prims[keep].id;
        events.push(MergeEvent {
            kept: kept_id,
            removed: b.id,
        });
        prims.remove(gone);
        dirty.retain(|&d| d != b.id);
        // The survivor changed: check it again.
        if let Err(pos) = dirty.binary_search(&kept_id) {
            dirty.insert(pos, kept_id);
        }
    }
    events
}

fn bounds(pts: &[DVec3]) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &p in pts {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    (lo, hi)
}
