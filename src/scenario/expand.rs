//! Expansion of an existing primitive with a new scan (the paper's
//! Algorithm 2, first half).
//!
//! 1. *Perpendicular gate*: the scan points within `across` of the plane
//!    near the primitive's grown box (for a riser, between its two edges).
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
/// in wasm especially), with the grown masks kept from the last scan.
#[derive(Default)]
pub(crate) struct Scratch {
    clusterer: Clusterer,
    cand: Vec<u32>,
    q: Vec<DVec2>,
    off: Vec<f32>,
    /// The last scan's masks, and how many of them this scan has passed.
    last: Masks,
    next: usize,
    /// This scan's masks, for the next one.
    kept: Vec<KeptMask>,
}

/// The grown masks of the primitives a scan expanded without changing
/// their outline, in id order, for the next scan: most outlines stay the
/// same from one scan to the next (85 % of expansions on the simulated
/// street), and building their masks again took 0.85 ms of a scan's
/// 9.7 ms of expansion there (BENCHMARKS.md). Derived state, bounded by
/// the primitives in one scan's reach: it never makes two scenarios
/// unequal, and a restored scenario starts without it.
#[derive(Clone, Debug, Default)]
pub(crate) struct Masks(Vec<KeptMask>);

impl PartialEq for Masks {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// A mask with what it was built from.
#[derive(Clone, Debug)]
struct KeptMask {
    id: u32,
    along: f64,
    outline: Vec<DVec2>,
    mask: GrownMask,
}

impl Scratch {
    /// Working memory for a scan, after the scan that kept `last`.
    pub fn new(last: Masks) -> Self {
        Scratch {
            last,
            ..Scratch::default()
        }
    }

    /// The masks to keep for the next scan.
    pub fn into_masks(self) -> Masks {
        Masks(self.kept)
    }

    /// The mask of `prim`'s outline grown by `along`: the last scan's when
    /// it was built from the same, else a new one (the same either way:
    /// [`GrownMask::new`] depends on nothing else). Primitives come in
    /// increasing id order, as the kept masks are stored.
    fn mask(&mut self, prim: &Primitive, along: f64) -> KeptMask {
        let last = &mut self.last.0;
        while self.next < last.len() && last[self.next].id < prim.id {
            self.next += 1;
        }
        if let Some(m) = last.get_mut(self.next) {
            if m.id == prim.id && m.along == along && m.outline == prim.outline {
                self.next += 1;
                return KeptMask {
                    id: m.id,
                    along,
                    outline: std::mem::take(&mut m.outline),
                    mask: std::mem::take(&mut m.mask),
                };
            }
        }
        KeptMask {
            id: prim.id,
            along,
            outline: prim.outline.clone(),
            mask: GrownMask::new(&prim.outline, along, mask_cell(along)),
        }
    }
}

/// The cell of a grown mask of reach `along` (m).
fn mask_cell(along: f64) -> f64 {
    (along * 0.5).clamp(0.05, 1.0)
}

/// Grow `prim` with the live points of `cloud`; marks taken points dead in
/// `alive`, writes `label` into `labels` for them and returns how many.
#[allow(clippy::too_many_arguments)]
#[inline(never)] // inlined into the scan loop, 0.65 kB more wasm (BENCHMARKS.md)
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

    // A riser grows along its length only: its face ends at the two
    // surfaces it joins, and what stands in its plane beyond them is
    // another surface (a car's side a few centimetres in front of a curb).
    let (from, to) = crate::primitive::strip_span(&prim.outline, params.min_width);

    // 1. Perpendicular gate, over the voxels near the plane in the box; the
    //    box is enlarged while the growth reaches its edge.
    let mask = scratch.mask(prim, along);
    let Scratch {
        clusterer,
        cand,
        q,
        off,
        ..
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
                let local = prim.frame.to_local(cloud.origin + p.as_dvec3());
                if !(from..=to).contains(&local.y) {
                    continue;
                }
                cand.push(i);
                off.push(d);
                q.push(local);
            }
        });
        // 2. Longitudinal growth.
        (taken, inner, outside) = grow(
            &prim.outline,
            &mask.mask,
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
        scratch.kept.push(mask);
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
    if prim.outline == mask.outline {
        scratch.kept.push(mask);
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
/// `mask` is the outline's [`GrownMask`] by `along`.
///
/// Also returns which points lie inside the outline's cells and whether any
/// point was taken outside them.
#[allow(clippy::too_many_arguments)]
fn grow(
    outline: &[DVec2],
    mask: &GrownMask,
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
    let mut region = Vec::new();
    let mut grown;
    for _ in 0..32 {
        let mask = if first {
            mask
        } else {
            grown = GrownMask::new(&region, along, mask_cell(along));
            &grown
        };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Footprint, Frame, Moments, Plane};

    fn square(id: u32, side: f64) -> Primitive {
        let plane = Plane::from_point_normal(DVec3::ZERO, DVec3::Z);
        let outline = vec![
            DVec2::ZERO,
            DVec2::new(side, 0.0),
            DVec2::new(side, side),
            DVec2::new(0.0, side),
        ];
        Primitive {
            id,
            plane,
            frame: Frame::on_plane(&plane, DVec3::ZERO),
            area: side * side,
            outline,
            support: 100,
            ground: false,
            moments: Moments::new(DVec3::ZERO),
            footprint: Footprint::new(0.2),
            born_scan: 0,
            last_scan: 0,
        }
    }

    /// A kept mask whose cells are all outside: told apart from a built one.
    fn blank(prim: &Primitive, along: f64) -> KeptMask {
        KeptMask {
            id: prim.id,
            along,
            outline: prim.outline.clone(),
            mask: GrownMask::default(),
        }
    }

    #[test]
    fn a_kept_mask_serves_only_the_same_primitive_outline_and_reach() {
        let centre = DVec2::new(1.0, 1.0);
        let (a, b) = (square(3, 2.0), square(5, 2.0));
        // The same id, outline and reach: the kept mask comes back.
        let mut s = Scratch::new(Masks(vec![blank(&a, 0.5), blank(&b, 0.5)]));
        assert!(!s.mask(&a, 0.5).mask.contains(centre));
        assert!(!s.mask(&b, 0.5).mask.contains(centre));
        // Another outline, another reach, another id: built anew.
        let mut s = Scratch::new(Masks(vec![blank(&a, 0.5), blank(&b, 0.5)]));
        assert!(s.mask(&square(3, 2.5), 0.5).mask.contains(centre));
        assert!(s.mask(&b, 0.4).mask.contains(centre));
        let mut s = Scratch::new(Masks(vec![blank(&a, 0.5)]));
        assert!(s.mask(&square(4, 2.0), 0.5).mask.contains(centre));
        // Passed ids are dropped: a primitive asked for after a later one
        // (not the id order expansion keeps) gets a new mask.
        let mut s = Scratch::new(Masks(vec![blank(&a, 0.5), blank(&b, 0.5)]));
        assert!(!s.mask(&b, 0.5).mask.contains(centre));
        assert!(s.mask(&a, 0.5).mask.contains(centre));
    }

    /// Expands `prim` with a grid of points 0.1 m apart on its plane over
    /// `[0, side]^2`.
    fn expand_with(s: &mut Scratch, prim: &mut Primitive, side: f64) -> usize {
        let n = (side / 0.1) as usize + 1;
        let pts: Vec<f64> = (0..n * n)
            .flat_map(|k| [(k % n) as f64 * 0.1, (k / n) as f64 * 0.1, 0.0])
            .collect();
        let cloud = Cloud::from_flat_f64(&pts, 3).unwrap();
        let mut index = ScanIndex::new(&cloud.points, 1.0);
        let (mut alive, mut labels) = (vec![true; cloud.len()], vec![0; cloud.len()]);
        let p = Params::gpp2();
        expand(
            s,
            prim,
            &cloud,
            &mut index,
            1,
            &mut alive,
            &mut labels,
            &p,
            1,
        )
    }

    #[test]
    fn a_riser_grows_along_its_curb_but_not_up_a_car_side_in_front_of_it() {
        // A curb's face as the riser step makes it: the 15 cm rectangle
        // over 3 m of the plane y = 0 (local x runs along the world's -x,
        // local y is the height): world x from -3 to 0.
        let plane = Plane::from_point_normal(DVec3::ZERO, DVec3::Y);
        let outline = vec![
            DVec2::ZERO,
            DVec2::new(3.0, 0.0),
            DVec2::new(3.0, 0.15),
            DVec2::new(0.0, 0.15),
        ];
        let mut prim = Primitive {
            plane,
            frame: Frame::on_plane(&plane, DVec3::ZERO),
            area: 0.45,
            outline,
            ..square(1, 1.0)
        };
        // The face, on to x = -6 m, and a car's side 1 cm in front of it
        // (within the 3 cm gate), from 0.3 m up to 1.5 m over x = -5..-1 m.
        let mut pts = Vec::new();
        for i in 0..=60 {
            for k in 1..=7 {
                pts.extend([-0.1 * i as f64, 0.0, k as f64 * 0.02]);
            }
        }
        let face = pts.len() / 3;
        for i in 10..=50 {
            for k in 0..=24 {
                pts.extend([-0.1 * i as f64, -0.01, 0.3 + k as f64 * 0.05]);
            }
        }
        let cloud = Cloud::from_flat_f64(&pts, 3).unwrap();
        let mut index = ScanIndex::new(&cloud.points, 1.0);
        let (mut alive, mut labels) = (vec![true; cloud.len()], vec![0; cloud.len()]);
        let mut s = Scratch::new(Masks::default());
        let p = Params::gpp2();
        let taken = expand(
            &mut s,
            &mut prim,
            &cloud,
            &mut index,
            1,
            &mut alive,
            &mut labels,
            &p,
            1,
        );
        // All of the face, none of the car.
        assert_eq!(taken, face);
        assert!(alive[face..].iter().all(|&a| a));
        // Still a 15 cm strip, now 6 m long (to the centre of the last
        // 0.2 m footprint cell).
        let (lo, hi) = prim.outline.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &v| (lo.min(v), hi.max(v)),
        );
        assert!(hi.y - lo.y < 0.2, "{:?}", prim.outline);
        assert!((5.8..6.2).contains(&(hi.x - lo.x)), "{:?}", prim.outline);
    }

    #[test]
    fn a_scan_keeps_the_masks_of_the_outlines_it_left_unchanged() {
        // Points inside the outline: it stays, and so does its mask.
        let mut prim = square(3, 2.0);
        let mut s = Scratch::new(Masks::default());
        assert!(expand_with(&mut s, &mut prim, 1.9) > 0);
        assert_eq!(prim.outline, square(3, 2.0).outline);
        let kept = s.into_masks();
        assert_eq!(kept.0.len(), 1);
        assert_eq!(kept.0[0].outline, prim.outline);
        // Points beyond it: the outline grows and the old mask is dropped.
        let mut s = Scratch::new(kept);
        assert!(expand_with(&mut s, &mut prim, 3.0) > 0);
        assert_ne!(prim.outline, square(3, 2.0).outline);
        assert!(s.into_masks().0.is_empty());
    }
}
