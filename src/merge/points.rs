//! Merging with the points in hand: one-shot detection's final pass over
//! the pieces it found. Labels follow the merges, and a merge that would
//! leave support off its plane or outside its outline is not made.

use super::{boxes_apart, mergeable};
use crate::geometry::bounds;
use crate::geometry::plane::{robust_fit, Moments, Plane};
use crate::geometry::polygon::{contains, signed_area};
use crate::params::Params;
use crate::primitive::{Primitive, NO_PRIMITIVE};
use glam::{DVec2, DVec3, Vec3};

/// Merge primitives that are pieces of one surface (the scenario's rule:
/// near-coplanar, outlines touching or overlapping), then number the
/// survivors 0, 1, ... again, labels included. A round's plane can cut a
/// band out of a surface that crosses it at a small angle, and that band is
/// one of the plane's other clusters; when a later round finds the surface
/// whole, its outline covers the band. And the pieces of a road beyond a
/// gap in its rings touch the road once their own rounds outlined them.
/// For concave outlines (a convex hull of two pieces would cover what lies
/// between them; the caller decides).
///
/// In the order found, a primitive and the newer pieces mergeable with it
/// become one ([`absorb`]); a piece that would lose too much of its support
/// stays apart, and the others merge without it. A merged outline is larger and can touch a
/// piece it did not touch before, so passes repeat until nothing merges;
/// after the first, only groups with a primitive grown in the last pass
/// are looked at. Last, the recesses a larger survivor's outline spans are
/// dropped ([`drop_covered`]).
#[inline(never)]
pub(crate) fn merge_pieces(
    primitives: &mut Vec<Primitive>,
    labels: &mut [u32],
    pts: &[Vec3],
    origin: DVec3,
    p: &Params,
) {
    let n = primitives.len();
    if n < 2 {
        return;
    }
    // The points of each primitive, in increasing order, kept with the
    // labels: a merge then reads its pieces' points, not every label.
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (i, &l) in labels.iter().enumerate() {
        if l != NO_PRIMITIVE {
            members[l as usize].push(i as u32);
        }
    }
    // Each primitive's outline box, kept up to date as it grows: most
    // pairs are told apart by it alone.
    let mut boxes: Vec<(DVec3, DVec3)> = primitives.iter().map(outline_box).collect();
    let mut into: Vec<u32> = (0..n as u32).collect();
    let mut grown = vec![true; n];
    for _ in 0..n {
        let mut next = vec![false; n];
        for first in 0..n {
            if into[first] != first as u32 {
                continue;
            }
            let mut group: Vec<usize> = (first + 1..n)
                .filter(|&j| {
                    into[j] == j as u32
                        && (grown[first] || grown[j])
                        && !boxes_apart(boxes[first], boxes[j], p)
                        && mergeable(&primitives[first], &primitives[j], p)
                })
                .collect();
            if group.is_empty() {
                continue;
            }
            group.push(first);
            let big = group.iter().copied().fold(first, |b, j| {
                if primitives[j].area > primitives[b].area {
                    j
                } else {
                    b
                }
            });
            group.retain(|&j| j != big);
            // A piece that would lose too much support stays apart; the
            // others still merge.
            while !group.is_empty() {
                match absorb(
                    primitives,
                    labels,
                    &mut members,
                    big,
                    &group,
                    pts,
                    origin,
                    p,
                ) {
                    Ok(out) => {
                        boxes[big] = outline_box(&out);
                        primitives[big] = out;
                        for &j in &group {
                            into[j] = big as u32;
                        }
                        next[big] = true;
                        break;
                    }
                    Err(failed) if !failed.is_empty() => group.retain(|j| !failed.contains(j)),
                    Err(_) => break,
                }
            }
        }
        if !next.contains(&true) {
            break;
        }
        grown = next;
    }
    drop_covered(primitives, &mut into, &boxes, p);
    // Survivors in their order, numbered densely; labels follow.
    let mut dense = vec![NO_PRIMITIVE; n];
    let mut k = 0;
    for i in 0..n {
        if into[i] == i as u32 {
            dense[i] = k;
            k += 1;
        }
    }
    if k as usize == n {
        return;
    }
    let mut i = 0;
    primitives.retain(|_| {
        i += 1;
        into[i - 1] == i as u32 - 1
    });
    for (k, q) in primitives.iter_mut().enumerate() {
        q.id = k as u32;
    }
    for l in labels.iter_mut() {
        if *l != NO_PRIMITIVE {
            *l = dense[*l as usize];
        }
    }
}

/// The world box of a primitive's outline vertices. Not inlined: each of
/// its two call sites would carry a copy of the vertex code (0.3 kB of the
/// gzipped wasm).
#[inline(never)]
fn outline_box(q: &Primitive) -> (DVec3, DVec3) {
    bounds(&q.vertices())
}

/// Drop the survivors of the merge (`into[i] == i`) that are recesses in
/// a larger survivor: wholly within its outline, near-parallel to it
/// (`mergeAngle`), behind its plane (on average, against its normal:
/// below a near-horizontal one, away from the viewpoint for the others)
/// and closer to it than two planes RANSAC can tell apart (the RMS
/// distance of their outline vertices within `Params::layer_distance`).
/// The merge keeps them apart because the larger one has no support where
/// they lie: a tree pit's soil 10 cm below the sidewalk around it, a door
/// set into a facade. Outlines have no holes, so the larger one's outline
/// spans the recess, and the two would draw one place twice, a few
/// centimetres apart; the larger one already draws it within that
/// distance, in front. The piece is dropped (`into` set past every index)
/// and its points lose their label. A piece in front (a traffic island
/// above the road around it, a sign on a wall) stays: the larger polygon,
/// behind it, does not stand in for it. `boxes`: each outline's box.
fn drop_covered(primitives: &[Primitive], into: &mut [u32], boxes: &[(DVec3, DVec3)], p: &Params) {
    let n = primitives.len();
    let max_angle = p.merge_angle.to_radians();
    for s in 0..n {
        if into[s] != s as u32 {
            continue;
        }
        let small = &primitives[s];
        let vs = small.vertices();
        let covered = (0..n).any(|b| {
            let big = &primitives[b];
            b != s
                && into[b] == b as u32
                && big.area > small.area
                && !boxes_apart(boxes[s], boxes[b], p)
                && big.plane.angle_to(&small.plane) <= max_angle
                && {
                    let (sum, sq) = vs.iter().fold((0.0, 0.0), |(s, q), &v| {
                        let d = big.plane.signed_distance(v);
                        (s + d, q + d * d)
                    });
                    sum < 0.0 && sq <= p.layer_distance().powi(2) * vs.len() as f64
                }
                && vs
                    .iter()
                    .all(|&v| contains(&big.outline, big.frame.to_local(v)))
        });
        if covered {
            into[s] = u32::MAX;
        }
    }
}

/// `primitives[big]` with the pieces `group` absorbed, or the pieces that
/// would lose too much support when the merge would break the detection
/// contract (support near its plane, inside its outline; none named when
/// the outline fails or `big` itself would lose too much). The largest keeps its plane and frame; the pieces'
/// points on that plane mark its footprint, and one outline trace follows.
/// Each piece must keep nine tenths of its support within the inlier
/// distance of the plane and inside the new raster region, and so must the
/// largest (the larger footprint's trace can simplify another way). A
/// piece may lose more, up to half, off the plane when those points are a
/// strip of another surface that tilted its fit (a car's end face beside
/// its side, a door's jamb): without them it lies on the plane. The points
/// that do not stay lose their label. Labels (and `members`, the points
/// of each primitive in increasing order) are changed only on success.
#[allow(clippy::too_many_arguments)]
fn absorb(
    primitives: &[Primitive],
    labels: &mut [u32],
    members: &mut [Vec<u32>],
    big: usize,
    group: &[usize],
    pts: &[Vec3],
    origin: DVec3,
    p: &Params,
) -> Result<Primitive, Vec<usize>> {
    let n = primitives.len();
    let world = |i: usize| origin + pts[i].as_dvec3();
    let mut out = primitives[big].clone();
    let threshold = p.surface(out.ground).distance;
    // The pieces' points, with their coordinates in `big`'s frame when they
    // lie on its plane.
    let mut taken: Vec<(usize, Option<DVec2>)> = Vec::new();
    let (mut total, mut bad) = (vec![0usize; n], vec![0usize; n]);
    // In increasing order, as the labels hold them: the moments removed
    // below sum in that order.
    let mut pieces: Vec<u32> = Vec::new();
    for &j in group {
        pieces.extend_from_slice(&members[j]);
    }
    pieces.sort_unstable();
    for i in pieces.into_iter().map(|i| i as usize) {
        let (l, w) = (labels[i] as usize, world(i));
        let on = out.plane.signed_distance(w).abs() < threshold;
        total[l] += 1;
        bad[l] += !on as usize;
        taken.push((i, on.then(|| out.frame.to_local(w))));
    }
    let mut marks: Vec<DVec2> = taken.iter().filter_map(|t| t.1).collect();
    // A piece traced on coarser cells than the parameters' (one-shot
    // detection's coarse pass) marks its cells whole: its points alone, on
    // `big`'s cells (finer, or as coarse on another grid), would leave the
    // holes its outline closed.
    for &j in group {
        let piece = &primitives[j];
        if piece.footprint.cell() > p.surface(piece.ground).cell {
            marks.extend(piece.footprint.covering_points(out.footprint.cell(), |q| {
                out.frame.to_local(piece.frame.to_world(q))
            }));
        }
    }
    out.footprint.mark_all(&marks);
    let (ring, region) = out
        .footprint
        .outline_region(out.alpha(p), p.simplify, p.max_vertices, p.min_area)
        .ok_or_else(Vec::new)?;
    let mut kept = Vec::with_capacity(taken.len());
    for &(i, q) in &taken {
        let stay = q.is_some_and(|q| region.contains(q));
        bad[labels[i] as usize] += (q.is_some() && !stay) as usize;
        kept.push(stay);
    }
    // A piece with too many points off the plane or outside the region may
    // still be one surface with a strip of another that tilted it
    // (`strip_tilted`); the strip then loses its label.
    // The strip test fits the points within the larger piece's own noise
    // of its plane (expansion's gate), where a strip's points near the
    // plane weigh least.
    let gate = out.noise_gate(threshold);
    let failed: Vec<usize> = group
        .iter()
        .copied()
        .filter(|&j| {
            10 * bad[j] > total[j]
                && !strip_tilted(
                    &primitives[j],
                    &members[j],
                    bad[j],
                    pts,
                    origin,
                    &out.plane,
                    threshold,
                    gate,
                    p,
                )
        })
        .collect();
    if !failed.is_empty() {
        return Err(failed);
    }
    // `out` is `big` with the pieces' cells added (same frame): when the
    // region holds all of `big`'s cells it holds all of its points.
    let keeps_own = primitives[big]
        .footprint
        .cell_centres()
        .iter()
        .all(|&c| region.contains(c));
    let mut own_out = Vec::new();
    if !keeps_own {
        let own = members[big].len();
        for &i in &members[big] {
            let i = i as usize;
            if !region.contains(out.frame.to_local(world(i))) {
                own_out.push(i);
            }
        }
        if 10 * own_out.len() > own {
            return Err(Vec::new());
        }
    }
    out.area = signed_area(&ring);
    out.outline = ring;
    out.footprint.retain_region(&region);
    let mut gone = Moments::new(out.moments.reference);
    for &i in &own_out {
        labels[i] = NO_PRIMITIVE;
    }
    let mut now = std::mem::take(&mut members[big]);
    now.retain(|&i| labels[i as usize] == big as u32);
    // The pieces' points that stay, in increasing order as `taken` holds
    // them: merged into `big`'s in one pass (sorting the two runs again
    // took 10 ms of a 1.2M-point location's merge pass).
    let mut joined = Vec::with_capacity(taken.len());
    for (&(i, _), &stay) in taken.iter().zip(&kept) {
        if stay {
            labels[i] = big as u32;
            out.support += 1;
            joined.push(i as u32);
        } else {
            labels[i] = NO_PRIMITIVE;
            gone.push(world(i));
        }
    }
    for &i in &own_out {
        gone.push(world(i));
    }
    out.support = out.support.saturating_sub(own_out.len() as u64);
    members[big] = merge_sorted(&now, &joined);
    for &j in group {
        members[j].clear();
    }
    for &j in group {
        out.moments.merge(&primitives[j].moments);
    }
    out.moments.remove(&gone);
    Ok(out)
}

/// Is `piece` (its points `members`, `bad` of them off `plane`, at
/// `threshold` or more, or on it but outside the new region) one surface
/// with a strip of another that tilted its fit (a car's end face beside its
/// side, a door's jamb)? Under half of its points lie off `plane`, at most
/// a tenth on it but outside the new region, and its points within `gate`
/// of `plane`, fitted alone (robustly, as shaping fits), stay within
/// `mergeDistance` of it across the piece's outline (the sine of the angle
/// between the two planes times the outline's reach from those points'
/// centroid).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn strip_tilted(
    piece: &Primitive,
    members: &[u32],
    bad: usize,
    pts: &[Vec3],
    origin: DVec3,
    plane: &Plane,
    threshold: f64,
    gate: f64,
    p: &Params,
) -> bool {
    let total = members.len();
    let mut on = 0;
    let mut near = Vec::new();
    for &i in members {
        let w = origin + pts[i as usize].as_dvec3();
        let d = plane.signed_distance(w).abs();
        if d < threshold {
            on += 1;
            if d <= gate {
                near.push(w);
            }
        }
    }
    // `bad` counts the points off the plane and those on it outside the
    // region.
    let outside = bad - (total - on);
    if 2 * on < total || 10 * outside > total {
        return false;
    }
    let Some(fit) = robust_fit(&near, piece.moments.reference) else {
        return false;
    };
    let c = piece.frame.to_local(fit.moments.mean());
    let reach_sq = piece
        .outline
        .iter()
        .fold(0.0f64, |r, &q| r.max((q - c).length_squared()));
    // Squared: sine^2 = 1 - cosine^2.
    let cos = fit.plane.normal.dot(plane.normal);
    (1.0 - cos * cos) * reach_sq <= p.merge_distance * p.merge_distance
}

/// The union of two increasing lists with no element in both, increasing.
fn merge_sorted(a: &[u32], b: &[u32]) -> Vec<u32> {
    let mut out = vec![0u32; a.len() + b.len()];
    let (mut i, mut j) = (0, 0);
    for slot in &mut out {
        // Take from `a` while it has the smaller head (or `b` is done).
        let from_a = j == b.len() || a.get(i).is_some_and(|&x| x < b[j]);
        *slot = if from_a { a[i] } else { b[j] };
        i += usize::from(from_a);
        j += usize::from(!from_a);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::floor::GroundRule;
    use crate::geometry::polygon::distance;
    use crate::primitive::{shape, ShapeRules};

    #[test]
    fn two_increasing_lists_merge_in_order() {
        assert_eq!(
            merge_sorted(&[1, 4, 9], &[2, 3, 10, 11]),
            [1, 2, 3, 4, 9, 10, 11]
        );
        assert_eq!(merge_sorted(&[5, 6], &[]), [5, 6]);
        assert_eq!(merge_sorted(&[], &[0, 7]), [0, 7]);
    }

    /// Points of a vertical patch in the plane y = `tilt` * z, x in `x0..x1`,
    /// z in 0..2, on a grid of 5 cm shifted by `shift`.
    fn patch(x0: f64, x1: f64, tilt: f64, shift: f64) -> Vec<Vec3> {
        let mut out = Vec::new();
        let mut x = x0 + shift;
        while x < x1 {
            let mut z = shift;
            while z < 2.0 {
                out.push(Vec3::new(x as f32, (tilt * z) as f32, z as f32));
                z += 0.05;
            }
            x += 0.05;
        }
        out
    }

    /// The primitive shaped from `pts` seen from `view`, every point kept.
    fn shaped_whole(pts: &[Vec3], p: &Params, view: DVec3) -> Primitive {
        let rules = ShapeRules::default();
        let s = shape(DVec3::ZERO, pts, p, view, GroundRule::BelowViewpoint, rules).unwrap();
        assert!(s.kept.iter().all(|&k| k));
        s.primitive
    }

    /// Primitives shaped from patches, labelled as detection would.
    fn pieces(patches: &[&[Vec3]], p: &Params) -> (Vec<Primitive>, Vec<u32>, Vec<Vec3>) {
        let view = DVec3::new(2.0, -6.0, 1.5);
        let mut prims = Vec::new();
        let mut labels = Vec::new();
        for (id, pts) in patches.iter().enumerate() {
            let mut prim = shaped_whole(pts, p, view);
            prim.id = id as u32;
            prims.push(prim);
            labels.extend(std::iter::repeat_n(id as u32, pts.len()));
        }
        (prims, labels, patches.concat())
    }

    /// Two primitives shaped from two patches.
    fn two(a: &[Vec3], b: &[Vec3], p: &Params) -> (Vec<Primitive>, Vec<u32>, Vec<Vec3>) {
        pieces(&[a, b], p)
    }

    /// A far part of a facade found by one-shot detection's coarse pass
    /// (cells and outline radius three times the first pass's) merges into
    /// the near part the first pass found: its points alone, on the near
    /// part's finer cells, lie a metre apart and would not hold together.
    #[test]
    fn a_piece_on_coarser_cells_merges_whole() {
        let p = Params::gpp2();
        let mut coarse = p.clone();
        coarse.other.cell *= 3.0;
        coarse.other.alpha *= 3.0;
        let near = patch(0.0, 14.0, 0.0, 0.0);
        let mut far = Vec::new();
        for i in 0..8 {
            for k in 0..3 {
                far.push(Vec3::new(14.05 + i as f32, 0.0, 0.1 + 0.9 * k as f32));
            }
        }
        let view = DVec3::new(2.0, -6.0, 1.5);
        let mut prims = Vec::new();
        for (id, (pts, q)) in [(&near, &p), (&far, &coarse)].into_iter().enumerate() {
            prims.push(Primitive {
                id: id as u32,
                ..shaped_whole(pts, q, view)
            });
        }
        assert!(prims[1].footprint.cell() > prims[0].footprint.cell());
        let pts = [near.clone(), far.clone()].concat();
        let mut labels: Vec<u32> = (0..pts.len()).map(|i| (i >= near.len()) as u32).collect();
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 1);
        assert!(labels.iter().all(|&l| l == 0));
        assert_eq!(prims[0].support, pts.len() as u64);
        // The near part (14 m x 2 m) and the far one (7 m x 1.8 m between
        // its outer points), less the half-cell inset.
        assert!(prims[0].area > 36.0, "{}", prims[0].area);
    }

    /// A door set 15 cm into a facade (away from the viewpoint at y = -6):
    /// the facade has no points where the door is, so the two are not
    /// merged, but the facade's outline (no holes) spans the door. The
    /// door's piece is dropped and its points lose their label; the facade
    /// is unchanged. A panel 15 cm in front of the facade stays.
    #[test]
    fn a_recess_the_larger_outline_spans_is_dropped() {
        let p = Params::gpp2();
        let in_door = |v: &Vec3| v.x > 3.0 && v.x < 4.5 && v.z > 0.2 && v.z < 1.8;
        let wall: Vec<Vec3> = patch(0.0, 8.0, 0.0, 0.0)
            .into_iter()
            .filter(|v| !in_door(v))
            .collect();
        for (depth, kept) in [(0.15, 1), (-0.15, 2)] {
            let door: Vec<Vec3> = patch(3.0, 4.5, 0.0, 0.025)
                .into_iter()
                .filter(in_door)
                .map(|v| v + Vec3::new(0.0, depth, 0.0))
                .collect();
            let (mut prims, mut labels, pts) = two(&wall, &door, &p);
            assert!(prims[0].plane.normal.y < 0.0);
            assert!(!mergeable(&prims[0], &prims[1], &p));
            let before = prims.clone();
            merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
            assert_eq!(prims.len(), kept, "door at {depth} m");
            assert_eq!(prims[0].area, before[0].area);
            assert_eq!(prims[0].support, wall.len() as u64);
            assert!(labels[..wall.len()].iter().all(|&l| l == 0));
            let door_label = if kept == 1 { NO_PRIMITIVE } else { 1 };
            assert!(labels[wall.len()..].iter().all(|&l| l == door_label));
        }
    }

    #[test]
    fn overlapping_pieces_of_one_surface_merge_and_keep_the_contract() {
        let p = Params::gpp2();
        let (a, b) = (patch(0.0, 4.0, 0.0, 0.0), patch(3.0, 7.0, 0.0, 0.025));
        let (mut prims, mut labels, pts) = two(&a, &b, &p);
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 1);
        let q = &prims[0];
        assert_eq!(q.id, 0);
        assert!(labels.iter().all(|&l| l == 0));
        assert_eq!(q.support, pts.len() as u64);
        // 7 m x 2 m, outlined through the boundary cells' centres.
        assert!(q.area > 12.0 && q.area < 14.1, "area {}", q.area);
        for w in &pts {
            let w = w.as_dvec3();
            assert!(q.plane.signed_distance(w).abs() < p.other.distance);
            let out = distance(&q.outline, q.frame.to_local(w));
            assert!(out <= q.footprint.cell() + p.simplify + 1e-9);
        }
    }

    /// The first and the third piece lie 3 m apart; the second overlaps
    /// the first and touches the third. Once the first has absorbed the
    /// second, its outline touches the third: one primitive in the end.
    #[test]
    fn a_merged_outline_takes_in_the_pieces_it_touches_once_grown() {
        let p = Params::gpp2();
        let a = patch(0.0, 4.0, 0.0, 0.0);
        let b = patch(3.0, 7.0, 0.0, 0.025);
        let c = patch(7.0, 10.0, 0.0, 0.0125);
        let (mut prims, mut labels, pts) = pieces(&[&a, &b, &c], &p);
        assert!(!mergeable(&prims[0], &prims[2], &p));
        assert!(mergeable(&prims[1], &prims[2], &p));
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 1);
        assert!(labels.iter().all(|&l| l == 0));
        assert_eq!(prims[0].support, pts.len() as u64);
        // 10 m x 2 m, outlined through the boundary cells' centres.
        assert!(
            prims[0].area > 18.0 && prims[0].area < 20.1,
            "area {}",
            prims[0].area
        );
    }

    #[test]
    fn pieces_tilted_away_from_the_larger_plane_stay_apart() {
        let p = Params::gpp2();
        // 6 degrees apart (within `mergeAngle`), but the smaller's far edge
        // lies 0.2 m off the larger's plane.
        let (a, b) = (patch(0.0, 5.0, 0.0, 0.0), patch(4.0, 7.0, 0.105, 0.025));
        let (mut prims, mut labels, pts) = two(&a, &b, &p);
        let before = (prims.clone(), labels.clone());
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 2);
        assert_eq!(labels, before.1);
        assert_eq!(prims[1].area, before.0[1].area);
    }

    /// A piece that would lose its support to the larger plane (4 degrees
    /// off it: mergeable, but its upper part lies beyond the inlier
    /// distance) does not keep the others from merging with it.
    #[test]
    fn a_piece_that_stays_apart_does_not_block_the_others() {
        let p = Params::gpp2();
        let a = patch(0.0, 5.0, 0.0, 0.0);
        let tilted = patch(4.0, 7.0, 0.07, 0.025);
        let c = patch(-3.0, 1.0, 0.0, 0.025);
        let (mut prims, mut labels, pts) = pieces(&[&a, &tilted, &c], &p);
        assert!(mergeable(&prims[0], &prims[1], &p));
        assert!(mergeable(&prims[0], &prims[2], &p));
        let tilted_area = prims[1].area;
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 2);
        // 8 m x 2 m, outlined through the boundary cells' centres.
        assert!(
            prims[0].area > 14.0 && prims[0].area < 16.1,
            "area {}",
            prims[0].area
        );
        assert_eq!(prims[1].area, tilted_area);
        let (na, nt) = (a.len(), tilted.len());
        assert!(labels[..na].iter().all(|&l| l == 0));
        assert!(labels[na..na + nt].iter().all(|&l| l == 1));
        assert!(labels[na + nt..].iter().all(|&l| l == 0));
    }

    /// A car's side (the plane y = 0, seen from y < 0) found whole, and a
    /// second piece of it that took in a strip of the car's end face (x =
    /// 6, running into the car): the strip tilts the piece's plane, and
    /// more than a tenth of its points lie beyond the inlier distance of the
    /// side's.
    /// The piece merges into the side; the strip's points off the side's
    /// plane lose their label, the rest join the side.
    #[test]
    fn a_piece_tilted_by_a_strip_of_another_surface_merges_without_it() {
        let p = Params::gpp2();
        let side = patch(0.0, 6.0, 0.0, 0.0);
        // The side's points with some noise across it (up to 4 cm: it is
        // what lets the robust fit keep a strip a few centimetres off).
        let mut piece: Vec<Vec3> = patch(3.0, 6.0, 0.0, 0.025)
            .into_iter()
            .enumerate()
            .map(|(i, v)| v + Vec3::new(0.0, 0.02 * ((i * 7) % 5) as f32 - 0.04, 0.0))
            .collect();
        let mut y = 0.01;
        while y < 0.2 {
            for k in 0..80 {
                piece.push(Vec3::new(6.0, y as f32, 0.0125 + 0.025 * k as f32));
            }
            y += 0.01;
        }
        // What shaping keeps of it, as detection would hand it on.
        let view = DVec3::new(2.0, -6.0, 1.5);
        loop {
            let rules = ShapeRules::default();
            let s = shape(
                DVec3::ZERO,
                &piece,
                &p,
                view,
                GroundRule::BelowViewpoint,
                rules,
            )
            .unwrap();
            if s.kept.iter().all(|&k| k) {
                break;
            }
            let mut kept = s.kept.iter();
            piece.retain(|_| *kept.next().unwrap());
        }
        let (mut prims, mut labels, pts) = two(&side, &piece, &p);
        let off = |v: &Vec3| v.y.abs() >= p.other.distance as f32;
        let n_off = piece.iter().filter(|v| off(v)).count();
        assert!(10 * n_off > piece.len(), "{n_off} of {}", piece.len());
        assert!(2 * n_off < piece.len());
        let tilt = prims[0].plane.angle_to(&prims[1].plane).to_degrees();
        assert!(tilt > 1.0, "{tilt}");
        assert!(mergeable(&prims[0], &prims[1], &p));
        let plane = prims[0].plane;
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 1);
        assert_eq!(prims[0].plane, plane);
        assert_eq!(prims[0].support, (pts.len() - n_off) as u64);
        for (v, &l) in pts.iter().zip(&labels) {
            assert_eq!(l == NO_PRIMITIVE, off(v), "{v}");
        }
    }

    #[test]
    fn pieces_apart_by_more_than_the_merge_gap_stay_apart() {
        let p = Params::gpp2();
        let (a, b) = (patch(0.0, 4.0, 0.0, 0.0), patch(5.0, 8.0, 0.0, 0.0));
        let (mut prims, mut labels, pts) = two(&a, &b, &p);
        merge_pieces(&mut prims, &mut labels, &pts, DVec3::ZERO, &p);
        assert_eq!(prims.len(), 2);
        assert!(labels[..a.len()].iter().all(|&l| l == 0));
        assert!(labels[a.len()..].iter().all(|&l| l == 1));
    }

    /// One wall seen twice through poses 9 cm apart: overlapping layers
    /// closer than the inlier distance are one surface. 15 cm apart they
    /// are one surface only where both were seen at the same place: a
    /// window recessed 15 cm in a facade, where the facade has no support,
    /// stays two, and so does a layer beside the wall rather than over it
    /// (a step, not a layer). 25 cm apart, beyond twice the inlier
    /// distance, they stay two.
    #[test]
    fn overlapping_layers_within_the_inlier_distance_merge() {
        let p = Params::gpp2();
        let shifted = |pts: Vec<Vec3>, dy: f32| -> Vec<Vec3> {
            pts.into_iter()
                .map(|q| q + Vec3::new(0.0, dy, 0.0))
                .collect()
        };
        let a = patch(0.0, 6.0, 0.0, 0.0);
        let b = shifted(patch(1.0, 4.0, 0.0, 0.025), 0.09);
        let (prims, _, _) = two(&a, &b, &p);
        assert!(mergeable(&prims[0], &prims[1], &p));
        let c = shifted(patch(1.0, 4.0, 0.0, 0.025), 0.15);
        let (prims, _, _) = two(&a, &c, &p);
        assert!(mergeable(&prims[0], &prims[1], &p), "seen twice, 15 cm");
        let c = shifted(patch(1.0, 4.0, 0.0, 0.025), 0.25);
        let (prims, _, _) = two(&a, &c, &p);
        assert!(!mergeable(&prims[0], &prims[1], &p), "seen twice, 25 cm");
        // The facade around a window (x 1-4 m, z 0.5-1.5 m), and the window
        // 15 cm behind it.
        let in_window = |q: &Vec3| (0.95..4.05).contains(&q.x) && (0.45..1.55).contains(&q.z);
        let facade: Vec<Vec3> = a.iter().copied().filter(|q| !in_window(q)).collect();
        let window: Vec<Vec3> = shifted(patch(1.0, 4.0, 0.0, 0.025), 0.15)
            .into_iter()
            .filter(|q| (0.5..1.5).contains(&q.z))
            .collect();
        let (prims, _, _) = two(&facade, &window, &p);
        // The facade's outline has no holes: the window lies inside it.
        let window_centre = prims[0].frame.to_local(prims[1].moments.mean());
        assert!(crate::geometry::polygon::contains(
            &prims[0].outline,
            window_centre
        ));
        assert!(!mergeable(&prims[0], &prims[1], &p), "a recessed window");
        let d = shifted(patch(6.2, 9.0, 0.0, 0.025), 0.09);
        let (prims, _, _) = two(&a, &d, &p);
        assert!(!mergeable(&prims[0], &prims[1], &p));
    }

    /// Ground keeps to the ground's inlier distance (`groundDistance`,
    /// 8 cm): a plaza or sidewalk 9 cm above the road that borders it on two
    /// sides (its outline's corners on the road's edges) is a step, not a
    /// layer of the road, and stays apart; a piece of road seen again 9 cm
    /// higher through a drifting pose, over the road, still merges.
    #[test]
    fn ground_a_step_above_the_road_beside_it_stays_apart() {
        let p = Params::gpp2();
        let grid = |x: (f64, f64), y: (f64, f64), z: f64, keep: &dyn Fn(f64, f64) -> bool| {
            let mut out = Vec::new();
            let mut u = x.0 + 0.05;
            while u < x.1 {
                let mut v = y.0 + 0.05;
                while v < y.1 {
                    if keep(u, v) {
                        out.push(Vec3::new(u as f32, v as f32, z as f32));
                    }
                    v += 0.1;
                }
                u += 0.1;
            }
            out
        };
        // An L of road 2 m wide around the plaza's corner.
        let road = grid((0.0, 10.0), (0.0, 10.0), 0.0, &|u, v| u < 2.0 || v < 2.0);
        let plaza = grid((2.0, 10.0), (2.0, 10.0), 0.09, &|_, _| true);
        let (prims, _, _) = two(&road, &plaza, &p);
        assert!(prims[0].ground && prims[1].ground);
        assert!(!mergeable(&prims[0], &prims[1], &p), "a plaza 9 cm up");
        let again = grid((0.0, 10.0), (0.0, 2.0), 0.09, &|_, _| true);
        let (prims, _, _) = two(&road, &again, &p);
        assert!(mergeable(&prims[0], &prims[1], &p), "the road seen again");
    }

    /// A road strip whose plane leans 2 degrees across its width (as a
    /// strip one ring wide can be fitted), and beside it a piece of
    /// sidewalk 15 cm up, of about its size, where the strip's plane
    /// extended passes through the sidewalk: the sidewalk's outline lies
    /// within `mergeDistance` of that plane, but the strip's does not lie
    /// on the sidewalk's, and they stay apart. Two level pieces of about
    /// one size that touch still merge, and so does a piece leaning 3
    /// degrees beside one four times its size, on whose plane it lies
    /// though the larger one's outline is far off its own.
    #[test]
    fn a_leaning_strip_and_a_piece_of_its_size_a_curb_up_stay_apart() {
        let p = Params::gpp2();
        let lean = 2f64.to_radians().tan();
        let grid = |x: (f64, f64), z: &dyn Fn(f64) -> f64| {
            let mut out = Vec::new();
            let mut u = x.0 + 0.05;
            while u < x.1 {
                let mut v = 0.05;
                while v < 11.0 {
                    out.push(Vec3::new(u as f32, v as f32, z(u) as f32));
                    v += 0.1;
                }
                u += 0.1;
            }
            out
        };
        let strip = grid((-0.6, 3.3), &|u| lean * u);
        let sidewalk = grid((3.4, 5.6), &|_| 0.15);
        let (prims, _, _) = two(&strip, &sidewalk, &p);
        assert!(prims[0].area < 2.0 * prims[1].area);
        // The sidewalk on the strip's plane, by the RMS distance.
        let on =
            |a: &Primitive, b: &Primitive| crate::merge::mean_square(&a.vertices(), a, b).sqrt();
        assert!(on(&prims[1], &prims[0]) < p.merge_distance);
        assert!(!mergeable(&prims[0], &prims[1], &p));
        let (a, b) = (grid((0.0, 3.9), &|_| 0.0), grid((4.0, 6.0), &|_| 0.0));
        let (prims, _, _) = two(&a, &b, &p);
        assert!(mergeable(&prims[0], &prims[1], &p));
        let lean = 3f64.to_radians().tan();
        let road = grid((-6.0, 2.0), &|_| 0.0);
        let piece = grid((2.0, 4.0), &|u| lean * (u - 2.0));
        let (prims, _, _) = two(&road, &piece, &p);
        assert!(prims[0].area > 3.5 * prims[1].area);
        assert!(on(&prims[1], &prims[0]) < p.merge_distance);
        assert!(on(&prims[0], &prims[1]) > p.layer_distance());
        assert!(mergeable(&prims[0], &prims[1], &p));
    }
}
