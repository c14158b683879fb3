//! Merging from running statistics: the scenario's merge after every scan.

use super::{merge_kind, Kind, MergeEvent};
use crate::params::Params;
use crate::primitive::Primitive;
use glam::DVec2;

/// Absorb `b` (the newer) into `a`, which keeps its id. Pieces join
/// statistics and refit. For a layer (one surface seen again through a pose
/// error) the newer layer's plane and statistics stand for the surface from
/// now on, so that the map follows the poses as they come and the next
/// scans grow it; the older footprint joins it.
fn absorb(a: &mut Primitive, b: &Primitive, kind: Kind, params: &Params) {
    let (support, born, last) = (
        a.support + b.support,
        a.born_scan.min(b.born_scan),
        a.last_scan.max(b.last_scan),
    );
    // `other` is the primitive whose footprint and outline join `a`'s.
    let other = match kind {
        Kind::Pieces => {
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
            b.clone()
        }
        Kind::Layers => std::mem::replace(
            a,
            Primitive {
                id: a.id,
                ..b.clone()
            },
        ),
    };
    let (fa, fo) = (a.frame, other.frame);
    a.footprint
        .merge_mapped(&other.footprint, |q| fa.to_local(fo.to_world(q)));
    let extra: Vec<DVec2> = params.hull.carried_vertices(&fo, &other.outline, &fa);
    a.reshape(params, &extra);
    a.support = support;
    a.born_scan = born;
    a.last_scan = last;
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
        let partner = (0..prims.len())
            .filter(|&j| j != ia)
            .find_map(|j| Some((j, merge_kind(&prims[ia], &prims[j], params)?)));
        let Some((ib, kind)) = partner else {
            continue;
        };
        // The older (smaller id) survives.
        let (keep, gone) = if prims[ia].id < prims[ib].id {
            (ia, ib)
        } else {
            (ib, ia)
        };
        let b = prims[gone].clone();
        absorb(&mut prims[keep], &b, kind, params);
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
