//! Merging from running statistics: the scenario's merge after every scan.

use super::{mergeable, MergeEvent};
use crate::params::Params;
use crate::primindex::PrimIndex;
use crate::primitive::Primitive;
use glam::DVec2;

/// Absorb `b` into `a`.
pub(crate) fn absorb(a: &mut Primitive, b: &Primitive, params: &Params) {
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
/// mergeable. `prims` is sorted by id and stays so; `index` (built over
/// `prims`) names the partners worth testing and follows every merge.
pub(crate) fn merge_all(
    prims: &mut Vec<Primitive>,
    changed: &[u32],
    params: &Params,
    index: &mut PrimIndex,
) -> Vec<MergeEvent> {
    let mut events = Vec::new();
    let mut dirty: Vec<u32> = changed.to_vec();
    dirty.sort_unstable();
    dirty.dedup();
    while let Some(id) = dirty.first().copied() {
        dirty.remove(0);
        let Ok(ia) = prims.binary_search_by_key(&id, |p| p.id) else {
            continue;
        };
        // The first partner in id order; the index leaves out only pairs
        // `mergeable` refuses on their boxes.
        let partner = match index.near_primitive(&prims[ia]) {
            Some(ids) => ids
                .iter()
                .filter_map(|&b| prims.binary_search_by_key(&b, |p| p.id).ok())
                .find(|&j| j != ia && mergeable(&prims[ia], &prims[j], params)),
            None => (0..prims.len()).find(|&j| j != ia && mergeable(&prims[ia], &prims[j], params)),
        };
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
        index.update(&prims[keep]);
        index.remove(b.id);
        prims.remove(gone);
        dirty.retain(|&d| d != b.id);
        // The survivor changed: check it again.
        if let Err(pos) = dirty.binary_search(&kept_id) {
            dirty.insert(pos, kept_id);
        }
    }
    events
}
