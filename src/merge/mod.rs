//! Merging primitives that are pieces of one surface, which the paper
//! lacks: two pieces of one long wall detected in different scans, or two
//! clusters of one plane in one detection, become one primitive once they
//! are near-coplanar and their outlines touch or overlap.
//!
//! One test ([`mergeable`]) and two ways to absorb, by what is at hand:
//! - [`stats`]: from the primitives' running statistics alone (moments and
//!   footprints), as the scenario must, since it keeps no points. The older
//!   id survives.
//! - [`points`]: with the support points in hand (one-shot detection), so
//!   that the merged primitive keeps the detection contract (every support
//!   point near its plane and inside its outline) and the labels follow.

pub(crate) mod points;
pub(crate) mod stats;

use crate::geometry::bounds;
use crate::geometry::polygon::{distance, rings_within};
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

/// Should `a` and `b` be one primitive? Their planes within `mergeAngle`,
/// and either
/// - the smaller one on the larger one's plane (or each centroid on the
///   other's plane) within `mergeDistance`, and their outlines within
///   `mergeGap` of each other (pieces of one surface that grew together);
/// - or the smaller one lying over the larger one (three quarters of its
///   outline vertices inside the larger's outline, or within `mergeGap` of
///   it) within twice the inlier distance of non-ground planes
///   (`Params::layer_distance`): layers closer than RANSAC tells planes
///   apart, such as one surface seen again through a pose a few
///   centimetres off. Beyond the inlier distance (`groundDistance` when
///   both are ground: a sidewalk 9 cm above the road that borders it on
///   two sides has most of its outline's vertices within `mergeGap` of the
///   road's outline, and is a step; with the defaults `groundDistance`
///   equals `mergeDistance`, so every ground layer needs this), half of
///   the smaller's support must lie where the larger has support too.
///
/// How far one lies from the other's plane is the RMS distance of its
/// outline vertices and centroid. When the larger has under twice the
/// smaller's area, neither plane is the better reference: the distance is
/// taken both ways and the larger counts.
pub fn mergeable(a: &Primitive, b: &Primitive, params: &Params) -> bool {
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
    let (big, big_v, small, small_v) = if a.area >= b.area {
        (a, &av, b, &bv)
    } else {
        (b, &bv, a, &av)
    };
    let mut ms = mean_square(small_v, small, big);
    // Two pieces of about one size: neither plane is the better reference
    // (a strip one ring wide has a tilt across it that its points hardly
    // fix, and extended over a piece beside it, such a plane can pass
    // through a surface a curb higher), so each is judged on the other's.
    if big.area < 2.0 * small.area {
        ms = ms.max(mean_square(big_v, big, small));
    }
    // Or each centroid on the other's plane (two slightly tilted pieces of
    // one surface whose far vertices disagree).
    let (ca, cb) = (a.moments.mean(), b.moments.mean());
    let centroids = a.plane.signed_distance(cb).abs() <= params.merge_distance
        && b.plane.signed_distance(ca).abs() <= params.merge_distance;
    let close = ms.sqrt() <= params.merge_distance || centroids;
    let layered = !close && ms.sqrt() <= params.layer_distance();
    // Layers farther apart than the inlier distance (the ground's for two
    // ground pieces) are one surface only where both were seen at the same
    // place, which two real surfaces cannot be (the nearer hides the
    // farther): a window recessed in a facade lies where the facade has no
    // support.
    let seen_twice = ms.sqrt() <= params.surface(a.ground && b.ground).distance;
    if !close && !layered {
        return false;
    }
    if boxes_apart(bounds(&av), bounds(&bv), params) {
        return false;
    }
    if layered {
        return most_within(small_v, big, params.merge_gap)
            && (seen_twice || seen_on_both(small, big));
    }
    // The outlines, both in a's frame: touching or overlapping?
    let b_in_a: Vec<DVec2> = bv.iter().map(|&v| a.frame.to_local(v)).collect();
    rings_within(&a.outline, &b_in_a, params.merge_gap)
}

/// The mean square distance from `to`'s plane of `of`'s outline vertices
/// (`vertices`, world) and centroid.
fn mean_square(vertices: &[DVec3], of: &Primitive, to: &Primitive) -> f64 {
    vertices
        .iter()
        .copied()
        .chain([of.moments.mean()])
        .map(|p| {
            let d = to.plane.signed_distance(p);
            d * d
        })
        .sum::<f64>()
        / (vertices.len() + 1) as f64
}

/// Do at least three quarters of `vertices` (world) lie within `gap` of
/// `big`'s outline region (inside it, or within `gap` of its boundary)?
/// Each test reads every edge of `big`'s outline (a road's has hundreds),
/// so a vertex beyond the outline's box by more than `gap` is passed over,
/// and the count stops once the answer is known.
fn most_within(vertices: &[DVec3], big: &Primitive, gap: f64) -> bool {
    let (lo, hi) = big
        .outline
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    // The margin also covers the rounding of the distance's closest point
    // (an ulp or so of the outline's largest coordinate).
    let far = lo.abs().max(hi.abs()).max_element();
    let pad = DVec2::splat(gap * (1.0 + 1e-9) + 1e-9 * (1.0 + far));
    let (lo, hi) = (lo - pad, hi + pad);
    let need = (3 * vertices.len()).div_ceil(4);
    let (mut inside, mut left) = (0, vertices.len());
    for &v in vertices {
        if inside >= need || inside + left < need {
            break;
        }
        left -= 1;
        let q = big.frame.to_local(v);
        if q.cmpge(lo).all() && q.cmple(hi).all() && distance(&big.outline, q) <= gap {
            inside += 1;
        }
    }
    inside >= need
}

/// Are two outlines' bounding boxes (world, from their vertices) farther
/// apart than any [`mergeable`] pair can be? A cheap test first: a pass
/// over many pieces rejects most pairs with it, before the vertices of
/// both outlines are computed.
pub(crate) fn boxes_apart(a: (DVec3, DVec3), b: (DVec3, DVec3), params: &Params) -> bool {
    let pad = DVec3::splat(params.merge_box_pad());
    (a.0 - pad).cmpgt(b.1).any() || (b.0 - pad).cmpgt(a.1).any()
}

/// Does most of `small`'s support lie where `big` has support too? At
/// least half of `small`'s footprint cells, mapped into `big`'s frame, land
/// on a set cell of `big`'s footprint.
fn seen_on_both(small: &Primitive, big: &Primitive) -> bool {
    let cells = small.footprint.cell_centres();
    let on_big = cells
        .iter()
        .filter(|&&q| {
            big.footprint
                .is_set(big.frame.to_local(small.frame.to_world(q)))
        })
        .count();
    !cells.is_empty() && 2 * on_big >= cells.len()
}
