//! Risers: the short faces between two near-horizontal surfaces a step
//! apart (a curb between a road and a sidewalk, a step, the edge of a low
//! plateau). Such a face is too narrow for a round of the cascade: it is
//! narrower than `minWidth`, and the inlier slabs of the two surfaces
//! take most of its points. But the two surfaces bound it, so where their
//! outlines meet with a step between them and points fill the step, the
//! face is there. One-shot detection adds it as a primitive of its own
//! after its merge pass (or takes it into a primitive on its plane whose
//! outline it meets)
//! ([`CascadePolicy::find_risers`](super::CascadePolicy::find_risers));
//! the scenario after each scan's detection, from the scan's points.
//!
//! One pass over the primitives and the points:
//! 1. Every ordered pair of near-horizontal primitives within 5 degrees of
//!    each other: the upper one's outline (its edges within reach of the
//!    points' box) is sampled every `cell`, and a
//!    sample is kept where the lower one's outline lies within the
//!    larger of the two surfaces' clustering tolerances (in plan; each
//!    scaled as its outline radius is, [`Primitive::cluster_tolerance`]:
//!    one-shot detection's coarse pass traces a sparse sidewalk on cells
//!    three times as wide, and its outline lies as much farther from the
//!    curb) and the upper surface stands between
//!    the lower one's inlier distance and `minWidth` above it (lower steps
//!    are one surface; higher faces are found by the cascade itself). Runs
//!    of kept samples are cut into straight segments.
//! 2. One pass over the points: a point near a segment (in plan) whose
//!    height lies strictly between the two surfaces (beyond twice their
//!    RMS, or a quarter of the lower one's inlier distance) is evidence of
//!    that segment's face.
//! 3. Each segment's face is the line its evidence lies along, within the
//!    non-ground inlier distance (a robust fit: wheels and poles next to a
//!    curb fall away). Faces on one line that overlap or lie within
//!    `2 * alpha` (grown as below) merge, across pairs of surfaces (a curb
//!    runs past several pieces of road, and a far one's outline is jagged).
//!    Each face then runs on along its line past its ends for as long as
//!    the lower surface's outline follows the line (within the reach of
//!    step 1); the points near that whole stretch are its evidence again,
//!    fitted as in this step, and the faces merge once more. A curb goes
//!    on where a tree pit or a driveway pulls the sidewalk's outline back
//!    from it: the road still ends at it. With that rule, every face is
//!    dropped when less than a quarter of its points lie in either half of
//!    the step: one run on from a short, higher surface (a car's bumper
//!    over the curb) holds the curb's points in its foot only. A face
//!    follows the lower surface of the first segment it was found on, so
//!    it runs on along one piece of road.
//! 4. A face is cut where its points leave a gap wider than `2 * alpha`;
//!    a piece is kept when its points cover at least `minOccupancy` of its
//!    length (each point the `cell` after it) and its area (length times
//!    step) is at least `minArea`, or, smaller, when it is at least as long
//!    as the widest gap a piece may hold and the pieces of its face that
//!    long add up to `minArea` (a curb seen between parked cars a few
//!    metres at a time). Each piece's outline is the rectangle between the
//!    two surfaces over its own points (none spans a gap, where nothing was
//!    seen); its points are labelled with it. When the points come
//!    from one sensor whose position is known ([`Spacing`]), the gaps of
//!    steps 3 and 4 and each point's length grow with the square of the
//!    range beyond `groundClusterRange`: a laser ring hits a curb's face
//!    only where it crosses the curb's line, so the runs of points on a
//!    face lie as far apart as the rings do on the ground.
//!
//! [`Primitive::cluster_tolerance`]: crate::primitive::Primitive::cluster_tolerance

use crate::geometry::plane::Moments;
use crate::geometry::polygon::{make_ccw, rings_within, segment_distance_sq, signed_area};
use crate::geometry::{bounds, grow_box, Footprint, Frame, Plane};
use crate::params::Params;
use crate::primitive::{Primitive, NO_PRIMITIVE};
use glam::{DVec2, DVec3, Vec3};

/// Largest angle (degrees) between the two surfaces of a step.
const PARALLEL_DEG: f64 = 5.0;
/// Largest tilt (degrees) from the vertical of a surface's normal for it to
/// bound a riser: near-horizontal surfaces only.
const MAX_TILT_DEG: f64 = 15.0;
/// Evidence lies beyond this many times the surfaces' RMS from both...
const MARGIN_RMS: f64 = 2.0;
/// ...and beyond this share of the lower surface's inlier distance.
const MARGIN_FLOOR: f64 = 0.25;

/// How far apart a face's evidence lies along it: as far as the laser
/// rings lie on the ground, which grows with the square of the range from
/// the sensor's foot beyond `range` (`groundClusterRange`; the ground's
/// range-pulled clustering follows the same law, `geometry::pull_range`).
/// Without a foot (a cloud seen from many poses, or from nowhere known)
/// the spacing is the same everywhere.
#[derive(Clone, Copy)]
struct Spacing {
    /// The plan position of the one sensor the points were seen from;
    /// `None` for a cloud seen from many poses or from nowhere known.
    foot: Option<DVec2>,
    /// `groundClusterRange` (m): within it the spacing is the near one.
    range: f64,
}

impl Spacing {
    /// How many times the near spacing the evidence at plan point `q` may
    /// leave between its runs: `(r / range)^2` at range `r` beyond
    /// `range`, 1 nearer.
    fn scale(&self, q: DVec2) -> f64 {
        let Some(foot) = self.foot else {
            return 1.0;
        };
        ((q - foot).length_squared() / (self.range * self.range)).max(1.0)
    }
}

/// The plan box (world x, y) a riser can lie in: the points' box, grown by
/// the reach. Outline edges outside it are not looked at (the scenario's
/// surfaces run far beyond one scan).
#[derive(Clone, Copy)]
struct Window {
    lo: DVec2,
    hi: DVec2,
}

impl Window {
    fn of(pts: &[Vec3], origin: DVec3, reach: f64) -> Option<Window> {
        if pts.is_empty() {
            return None;
        }
        // One pass over the scan's points: the box grows by selects
        // (`grow_box`), as the other per-point boxes do.
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for q in pts {
            grow_box(&mut lo, &mut hi, q.as_dvec3());
        }
        let grow = DVec2::splat(reach);
        Some(Window {
            lo: (origin + lo).truncate() - grow,
            hi: (origin + hi).truncate() + grow,
        })
    }

    /// Whether the box `lo..hi` meets this one.
    fn meets(&self, lo: DVec2, hi: DVec2) -> bool {
        lo.x <= self.hi.x && hi.x >= self.lo.x && lo.y <= self.hi.y && hi.y >= self.lo.y
    }
}

/// A near-horizontal primitive, seen from above.
struct Surface {
    /// Its plane, normal up.
    plane: Plane,
    /// Outline vertices in plan (world x, y).
    plan: Vec<DVec2>,
    /// Outline vertices in the world.
    ring: Vec<DVec3>,
    lo: DVec2,
    hi: DVec2,
    rms: f64,
    ground: bool,
    /// Its clustering tolerance ([`Primitive::cluster_tolerance`]): its
    /// outline lies within it of the surface's edge.
    tolerance: f64,
    /// Its footprint's cell (m): its outline's resolution.
    cell: f64,
    /// Its points within this distance of it are the surface itself, never
    /// a face's evidence (no segment's margin is smaller).
    noise: f64,
    /// Its outline's edges by plan cell: each edge listed in every cell
    /// within `reach` of it (in the window).
    edges: Option<CellLists>,
}

impl Surface {
    /// Whether the plan point `q` lies within `within` (at most the `reach`
    /// its edges were listed with) of the outline.
    fn near_outline(&self, q: DVec2, within: f64) -> bool {
        let n = self.plan.len();
        self.edges.as_ref().is_some_and(|grid| {
            grid.at(q).iter().any(|&e| {
                let e = e as usize;
                segment_distance_sq(q, self.plan[e], self.plan[(e + 1) % n]) <= within * within
            })
        })
    }
}

/// Items listed by the cells of a plan grid (compressed rows): each item
/// in every cell its box meets. Cells are squares of the side asked for,
/// grown so that the grid has at most 512 a side.
struct CellLists {
    lo: DVec2,
    cell: f64,
    w: usize,
    h: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl CellLists {
    /// Per item its box, or `None` (not listed). `None` when nothing is.
    fn new(boxes: &[Option<(DVec2, DVec2)>], cell: f64) -> Option<CellLists> {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &(a, b) in boxes.iter().flatten() {
            (lo, hi) = (lo.min(a), hi.max(b));
        }
        let cell = cell.max((hi - lo).max_element() / 512.0);
        if !(lo.x <= hi.x && lo.y <= hi.y) || cell.is_nan() || cell <= 0.0 {
            return None;
        }
        let side = |extent: f64| (extent / cell) as usize + 1;
        let (w, h) = (side(hi.x - lo.x), side(hi.y - lo.y));
        let mut grid = CellLists {
            lo,
            cell,
            w,
            h,
            start: vec![0; w * h + 1],
            items: Vec::new(),
        };
        for &(a, b) in boxes.iter().flatten() {
            grid.each_cell(a, b, |c, g| g.start[c + 1] += 1);
        }
        for c in 0..w * h {
            grid.start[c + 1] += grid.start[c];
        }
        let mut fill = grid.start.clone();
        grid.items = vec![0; grid.start[w * h] as usize];
        for (k, &(a, b)) in boxes
            .iter()
            .enumerate()
            .filter_map(|(k, b)| Some((k, b.as_ref()?)))
        {
            grid.each_cell(a, b, |c, g| {
                g.items[fill[c] as usize] = k as u32;
                fill[c] += 1;
            });
        }
        Some(grid)
    }

    /// Call `f` with every cell the box `a..b` meets.
    fn each_cell(&mut self, a: DVec2, b: DVec2, mut f: impl FnMut(usize, &mut CellLists)) {
        let (a, b) = ((a - self.lo) / self.cell, (b - self.lo) / self.cell);
        let (x1, y1) = (
            (b.x as usize).min(self.w - 1),
            (b.y as usize).min(self.h - 1),
        );
        for y in (a.y.max(0.0) as usize)..=y1 {
            for x in (a.x.max(0.0) as usize)..=x1 {
                f(y * self.w + x, self);
            }
        }
    }

    /// The items listed in the cell of `q` (none outside the grid).
    fn at(&self, q: DVec2) -> &[u32] {
        let (x, y) = ((q.x - self.lo.x) / self.cell, (q.y - self.lo.y) / self.cell);
        if !(x >= 0.0 && y >= 0.0 && x < self.w as f64 && y < self.h as f64) {
            return &[];
        }
        let c = y as usize * self.w + x as usize;
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

/// The edges of a plan ring that reach into the window, listed by cells,
/// each in every cell within `reach` of it.
fn edge_grid(plan: &[DVec2], reach: f64, window: Window) -> Option<CellLists> {
    let n = plan.len();
    let boxes: Vec<Option<(DVec2, DVec2)>> = (0..n)
        .map(|e| {
            let (a, b) = (plan[e], plan[(e + 1) % n]);
            let lo = a.min(b) - DVec2::splat(reach);
            let hi = a.max(b) + DVec2::splat(reach);
            window
                .meets(lo, hi)
                .then(|| (lo.max(window.lo), hi.min(window.hi)))
        })
        .collect();
    // Cells a few times the reach: fewer entries, few edges each.
    CellLists::new(&boxes, 4.0 * reach)
}

/// A straight piece of the line where an upper surface's outline meets a
/// lower one's, and the points of the face between them.
struct Segment {
    lower: usize,
    upper: usize,
    a: DVec2,
    b: DVec2,
    margin: f64,
    reach: f64,
    face: Vec<u32>,
}

/// A riser before its final checks: its surfaces, its line and its points.
struct Face {
    /// The segment it was first found on (after a merge, the first
    /// member's; after running on, still the one it ran on from): its
    /// surfaces, margin and reach.
    segment: usize,
    lower: Plane,
    upper: Plane,
    /// A point on the line and its unit direction (plan).
    at: DVec2,
    dir: DVec2,
    /// The extent of its points along the line, from `at`.
    lo: f64,
    hi: f64,
    points: Vec<u32>,
}

impl Face {
    /// A face on the line through `at` along `dir`, of the points within
    /// `tol` of it.
    #[allow(clippy::too_many_arguments)]
    fn new(
        segment: usize,
        lower: Plane,
        upper: Plane,
        at: DVec2,
        dir: DVec2,
        mut points: Vec<u32>,
        plan: Plan,
        tol: f64,
    ) -> Face {
        let n = dir.perp();
        points.retain(|&i| n.dot(plan.at(i) - at).abs() <= tol);
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &i| {
                let s = dir.dot(plan.at(i) - at);
                (a.min(s), b.max(s))
            });
        Face {
            segment,
            lower,
            upper,
            at,
            dir,
            lo,
            hi,
            points,
        }
    }
}

/// The points (local to `origin`) seen from above.
#[derive(Clone, Copy)]
struct Plan<'a> {
    pts: &'a [Vec3],
    origin: DVec3,
}

impl Plan<'_> {
    /// Point `i` in plan (world x, y).
    fn at(&self, i: u32) -> DVec2 {
        (self.origin + self.pts[i as usize].as_dvec3()).truncate()
    }
}

/// Add the risers between the near-horizontal `primitives` (numbered from
/// `primitives.len()` on, up to `maxPrimitives`): one-shot detection,
/// where a label is a primitive's index. Their points are labelled with
/// them and leave the support count of the surface they were labelled
/// with. That surface's moments stay: they are the statistics of its
/// robust refit (which trims most points this far off its plane), not a
/// sum over its labels (a primitive that takes a riser in gains the
/// riser's moments, as in a merge). A riser most of whose points lie on the plane of
/// a primitive already there (within the non-ground inlier distance,
/// facing its way within 5 degrees) and whose outline meets that
/// primitive's is part of it (the foot of a wall whose lowest rows its
/// cluster left out, or a curb on the line of a wall that stands on it):
/// it is taken into that primitive ([`absorb`](crate::merge::stats::absorb)),
/// as the merge pass before would have taken a piece, not added over it.
/// `foot`: as for [`find_risers`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_risers(
    primitives: &mut Vec<Primitive>,
    labels: &mut [u32],
    pts: &[Vec3],
    origin: DVec3,
    viewpoint: DVec3,
    p: &Params,
    foot: Option<DVec2>,
) {
    let n = primitives.len();
    let every = vec![true; n];
    let slot = |l: u32| ((l as usize) < n).then_some(l as usize);
    let found = find_risers(
        primitives, &every, &slot, labels, pts, origin, viewpoint, p, p.min_area, foot,
    );
    let cos_parallel = libm::cos(PARALLEL_DEG.to_radians());
    for (r, points) in found {
        let rv = r.vertices();
        let part_of = primitives.iter().position(|q| {
            if q.plane.normal.dot(r.plane.normal).abs() < cos_parallel {
                return false;
            }
            let on = |&&i: &&u32| {
                let w = origin + pts[i as usize].as_dvec3();
                q.plane.signed_distance(w).abs() <= p.other.distance
            };
            if 2 * points.iter().filter(on).count() <= points.len() {
                return false;
            }
            let ring: Vec<DVec2> = rv.iter().map(|&v| q.frame.to_local(v)).collect();
            rings_within(&q.outline, &ring, 0.0)
        });
        if part_of.is_none() && primitives.len() >= p.max_primitives {
            // No room for it; a later one may still be taken into a
            // primitive.
            continue;
        }
        let id = part_of.unwrap_or(primitives.len()) as u32;
        // The points move from the surface they supported, if any.
        for &i in &points {
            let old = std::mem::replace(&mut labels[i as usize], id);
            if let Some(q) = primitives.get_mut(old as usize) {
                q.support = q.support.saturating_sub(1);
            }
        }
        match part_of {
            Some(k) => crate::merge::stats::absorb(&mut primitives[k], &r, p),
            None => primitives.push(Primitive { id, ..r }),
        }
    }
}

/// The risers between the near-horizontal primitives marked in `bound`,
/// in the order found, each with its points (indices into `pts`, local
/// to `origin`). `labels` give each point's primitive, or
/// [`NO_PRIMITIVE`]; `slot` turns a label into an index of `primitives`
/// (`None`: a primitive not among them, whose points are no evidence).
/// Points of a riser can hold a label of another one found here (the
/// caller labels them in order, the last riser keeping them). A riser
/// smaller than `min_area` is left out unless it is at least `2 * alpha`
/// long (times the [`Spacing`] at its middle) and the pieces of its face
/// that long add up to `min_area` (step 4 of the module documentation). `foot`: the plan
/// position of the one sensor the points were seen from, if known, which
/// sets how far apart their evidence may lie ([`Spacing`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn find_risers(
    primitives: &[Primitive],
    bound: &[bool],
    slot: &dyn Fn(u32) -> Option<usize>,
    labels: &[u32],
    pts: &[Vec3],
    origin: DVec3,
    viewpoint: DVec3,
    p: &Params,
    min_area: f64,
    foot: Option<DVec2>,
) -> Vec<(Primitive, Vec<u32>)> {
    let spacing = Spacing {
        foot,
        range: p.ground_cluster_range,
    };
    // The farthest two outlines can lie apart and still meet: the largest
    // clustering tolerance of the surfaces (a surface traced on coarser
    // cells has a coarser outline).
    let reach = primitives
        .iter()
        .zip(bound)
        .filter(|(_, &b)| b)
        .map(|(q, _)| q.cluster_tolerance(p))
        .fold(0.0, f64::max);
    let Some(window) = Window::of(pts, origin, reach) else {
        return Vec::new();
    };
    let surfaces = surfaces(primitives, bound, window, reach, p);
    if surfaces.iter().flatten().count() < 2 {
        return Vec::new();
    }
    let mut segments = segments(&surfaces, window, p);
    if segments.is_empty() {
        return Vec::new();
    }
    gather_evidence(&mut segments, &surfaces, slot, labels, pts, origin);
    let tol = p.other.distance;
    let mut faces: Vec<Face> = segments
        .iter()
        .enumerate()
        .filter_map(|(k, s)| fit_face(k, s, &surfaces, pts, origin, tol))
        .collect();
    merge_faces(&mut faces, pts, origin, tol, 2.0 * p.other.alpha, spacing);
    // Step 3, on along the lower surface's edge.
    let (mut more, owner) = run_on_edges(&faces, &segments, &surfaces, window);
    if !more.is_empty() {
        gather_evidence(&mut more, &surfaces, slot, labels, pts, origin);
        for (s, &k) in more.iter().zip(&owner) {
            if let Some(face) = fit_face(faces[k].segment, s, &surfaces, pts, origin, tol) {
                faces[k] = face;
            }
        }
        merge_faces(&mut faces, pts, origin, tol, 2.0 * p.other.alpha, spacing);
    }
    // Step 4. A face seen in pieces (a curb behind parked cars) is one
    // surface: a piece too small alone is kept when it is at least as long
    // as the gaps `split` allows and such pieces of its face add up to
    // `min_area`.
    let mut out = Vec::new();
    let plan = Plan { pts, origin };
    for face in &faces {
        if !fills_step(face, plan) {
            continue;
        }
        let found: Vec<(Primitive, Vec<u32>, bool)> =
            split(face, pts, origin, 2.0 * p.other.alpha, spacing)
                .iter()
                .filter_map(|piece| riser(face, piece, plan, viewpoint, p, spacing))
                .collect();
        let total: f64 = found.iter().filter(|f| f.2).map(|f| f.0.area).sum();
        out.extend(
            found
                .into_iter()
                .filter(|(r, _, long)| r.area >= min_area || *long && total >= min_area)
                .map(|(r, points, _)| (r, points)),
        );
    }
    out
}

/// The near-horizontal primitives marked in `bound` (normal turned up)
/// that reach into the window, by index.
fn surfaces(
    primitives: &[Primitive],
    bound: &[bool],
    window: Window,
    reach: f64,
    p: &Params,
) -> Vec<Option<Surface>> {
    let cos_tilt = libm::cos(MAX_TILT_DEG.to_radians());
    primitives
        .iter()
        .zip(bound)
        .map(|(q, &b)| {
            let mut plane = q.plane;
            if !b || plane.normal.z.abs() < cos_tilt {
                return None;
            }
            if plane.normal.z < 0.0 {
                plane = Plane {
                    normal: -plane.normal,
                    offset: -plane.offset,
                };
            }
            let ring = q.vertices();
            let plan: Vec<DVec2> = ring.iter().map(|v| v.truncate()).collect();
            let (lo, hi) = bounds(&ring);
            let (lo, hi) = (lo.truncate(), hi.truncate());
            if plan.len() < 3 || !window.meets(lo, hi) {
                return None;
            }
            // Only the part in the window matters.
            let (lo, hi) = (lo.max(window.lo), hi.min(window.hi));
            Some(Surface {
                plane,
                ring,
                lo,
                hi,
                rms: q.rms(),
                ground: q.ground,
                tolerance: q.cluster_tolerance(p),
                cell: q.footprint.cell(),
                noise: MARGIN_FLOOR * p.ground.distance.min(p.other.distance),
                edges: edge_grid(&plan, reach, window),
                plan,
            })
        })
        .collect()
}

/// Step 1: the straight pieces of the lines where an upper outline meets a
/// lower one a step below.
fn segments(surfaces: &[Option<Surface>], window: Window, p: &Params) -> Vec<Segment> {
    let cos_parallel = libm::cos(PARALLEL_DEG.to_radians());
    let mut out = Vec::new();
    for (ui, u) in surfaces.iter().enumerate() {
        let Some(u) = u else { continue };
        for (li, l) in surfaces.iter().enumerate() {
            let Some(l) = l else { continue };
            if ui == li || u.plane.normal.dot(l.plane.normal) < cos_parallel {
                continue;
            }
            let (su, sl) = (p.surface(u.ground), p.surface(l.ground));
            let reach = u.tolerance.max(l.tolerance);
            if u.lo.x > l.hi.x + reach
                || l.lo.x > u.hi.x + reach
                || u.lo.y > l.hi.y + reach
                || l.lo.y > u.hi.y + reach
            {
                continue;
            }
            let (lowest, highest) = (sl.distance, p.min_width);
            // The step is linear in plan: over the box where samples can be
            // kept it lies between its values at the corners. Most pairs
            // (pieces of one road) never stand a step apart.
            let (blo, bhi) = (u.lo.max(l.lo - reach), u.hi.min(l.hi + reach));
            let steps = [blo, DVec2::new(blo.x, bhi.y), DVec2::new(bhi.x, blo.y), bhi]
                .map(|q| l.plane.signed_distance(q.extend(height(&u.plane, q))));
            if steps.iter().all(|&d| d < lowest) || steps.iter().all(|&d| d > highest) {
                continue;
            }
            let margin = (MARGIN_RMS * u.rms.max(l.rms)).max(MARGIN_FLOOR * sl.distance);
            // Samples along the upper outline, each kept or not.
            let mut samples: Vec<(DVec2, bool)> = Vec::new();
            let n = u.ring.len();
            for k in 0..n {
                let (a, b) = (u.ring[k], u.ring[(k + 1) % n]);
                let (pa, pb) = (a.truncate(), b.truncate());
                if !window.meets(pa.min(pb), pa.max(pb)) {
                    // Out of the window: one sample, not kept, ends a run.
                    samples.push((pa, false));
                    continue;
                }
                // Rounded, not ceiled: outline edges run along the footprint's
                // cells, so their lengths are often whole cells, where a
                // ceiling would turn on rounding error.
                let count = ((b - a).length() / su.cell).round().max(1.0) as usize;
                for j in 0..count {
                    let q = a.lerp(b, j as f64 / count as f64);
                    let step = l.plane.signed_distance(q);
                    let plan = q.truncate();
                    let kept = step >= lowest
                        && step <= highest
                        && plan.x >= l.lo.x - reach
                        && plan.x <= l.hi.x + reach
                        && plan.y >= l.lo.y - reach
                        && plan.y <= l.hi.y + reach
                        && l.near_outline(plan, reach);
                    samples.push((plan, kept));
                }
            }
            for run in runs(&samples) {
                for (a, b) in straight_pieces(&run, p.other.distance) {
                    out.push(Segment {
                        lower: li,
                        upper: ui,
                        a,
                        b,
                        margin,
                        reach,
                        face: Vec::new(),
                    });
                }
            }
        }
    }
    out
}

/// The runs of consecutive kept samples of a closed ring of samples.
fn runs(samples: &[(DVec2, bool)]) -> Vec<Vec<DVec2>> {
    let n = samples.len();
    let Some(start) = samples.iter().position(|s| !s.1) else {
        // All kept: one run around the ring.
        let mut all: Vec<DVec2> = samples.iter().map(|s| s.0).collect();
        if let Some(&first) = all.first() {
            all.push(first);
        }
        return vec![all];
    };
    let mut out = Vec::new();
    let mut run: Vec<DVec2> = Vec::new();
    for k in 1..=n {
        let (q, kept) = samples[(start + k) % n];
        if kept {
            run.push(q);
        } else if !run.is_empty() {
            out.push(std::mem::take(&mut run));
        }
    }
    out.retain(|r| r.len() >= 2);
    out
}

/// A polyline cut into straight pieces (Douglas-Peucker within `tol`).
fn straight_pieces(run: &[DVec2], tol: f64) -> Vec<(DVec2, DVec2)> {
    if run.len() < 2 {
        return Vec::new();
    }
    let mut keep = vec![false; run.len()];
    keep[0] = true;
    keep[run.len() - 1] = true;
    let mut stack = vec![(0usize, run.len() - 1)];
    while let Some((i, j)) = stack.pop() {
        // Samples along cell edges often lie equally far from a chord:
        // the first of them wins unless another is farther by a
        // micrometre, so that rounding error (a map far from its origin)
        // picks the same one.
        let (mut worst, mut at) = (tol, None);
        for k in i + 1..j {
            let d = segment_distance_sq(run[k], run[i], run[j]).sqrt();
            if d > worst + 1e-6 {
                (worst, at) = (d, Some(k));
            }
        }
        if let Some(k) = at {
            keep[k] = true;
            stack.push((i, k));
            stack.push((k, j));
        }
    }
    let corners: Vec<DVec2> = run
        .iter()
        .zip(&keep)
        .filter_map(|(&q, &k)| k.then_some(q))
        .collect();
    corners
        .windows(2)
        .filter(|w| w[0] != w[1])
        .map(|w| (w[0], w[1]))
        .collect()
}

/// Step 2: each point near a segment, strictly between its two surfaces,
/// joins the segment's face. Points of non-horizontal primitives are not
/// evidence.
fn gather_evidence(
    segments: &mut [Segment],
    surfaces: &[Option<Surface>],
    slot: &dyn Fn(u32) -> Option<usize>,
    labels: &[u32],
    pts: &[Vec3],
    origin: DVec3,
) {
    // The segments listed by plan cell, each in every cell within its
    // reach: a point looks at its cell's.
    let reach = segments.iter().map(|s| s.reach).fold(0.0, f64::max);
    let boxes: Vec<Option<(DVec2, DVec2)>> = segments
        .iter()
        .map(|s| {
            let r = DVec2::splat(s.reach);
            Some((s.a.min(s.b) - r, s.a.max(s.b) + r))
        })
        .collect();
    let Some(grid) = CellLists::new(&boxes, 4.0 * reach) else {
        return;
    };
    // The heights evidence can have: between the lowest lower surface and
    // the highest upper one near any segment (planes tilt by up to
    // MAX_TILT_DEG over a segment's reach).
    // tan(MAX_TILT_DEG), as a constant: libm's tangent or sine would be
    // new code in the wasm.
    let slope = 0.267_949_192_431_122_7;
    let (mut zlo, mut zhi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in segments.iter() {
        let (Some(lo), Some(up)) = (&surfaces[s.lower], &surfaces[s.upper]) else {
            continue;
        };
        for q in [s.a, s.b] {
            zlo = zlo.min(height(&lo.plane, q) - s.reach * slope);
            zhi = zhi.max(height(&up.plane, q) + s.reach * slope);
        }
    }
    for (i, (pt, &l)) in pts.iter().zip(labels).enumerate() {
        let w = origin + pt.as_dvec3();
        if !(w.z > zlo && w.z < zhi) {
            continue;
        }
        let list = grid.at(w.truncate());
        if list.is_empty() {
            continue;
        }
        if l != NO_PRIMITIVE {
            // Points of a non-horizontal primitive, and those within noise
            // of the near-horizontal one they support, are no evidence.
            match slot(l).and_then(|k| surfaces[k].as_ref()) {
                Some(s) if s.plane.signed_distance(w).abs() > s.noise => {}
                _ => continue,
            }
        }
        for &k in list {
            let s = &segments[k as usize];
            if segment_distance_sq(w.truncate(), s.a, s.b) > s.reach * s.reach {
                continue;
            }
            let (Some(lo), Some(up)) = (&surfaces[s.lower], &surfaces[s.upper]) else {
                continue;
            };
            if lo.plane.signed_distance(w) > s.margin && up.plane.signed_distance(w) < -s.margin {
                segments[k as usize].face.push(i as u32);
            }
        }
    }
}

/// Step 3: the line a segment's evidence lies along (within `tol`).
fn fit_face(
    k: usize,
    s: &Segment,
    surfaces: &[Option<Surface>],
    pts: &[Vec3],
    origin: DVec3,
    tol: f64,
) -> Option<Face> {
    let (lower, upper) = (surfaces[s.lower].as_ref()?, surfaces[s.upper].as_ref()?);
    let plan = Plan { pts, origin };
    let mut dir = (s.b - s.a).try_normalize()?;
    let normal = dir.perp();
    // The offset of the face from the outline's line: the median.
    let mut across: Vec<f64> = s
        .face
        .iter()
        .map(|&i| normal.dot(plan.at(i) - s.a))
        .collect();
    if across.len() < 3 {
        return None;
    }
    crate::geometry::heap_sort_by(&mut across, f64::total_cmp);
    let mut at = s.a + normal * across[across.len() / 2];
    let mut points: Vec<u32> = Vec::new();
    for _ in 0..2 {
        let n = dir.perp();
        points = s
            .face
            .iter()
            .copied()
            .filter(|&i| n.dot(plan.at(i) - at).abs() <= tol)
            .collect();
        (at, dir) = line_fit(plan, &points, dir)?;
    }
    let face = Face::new(k, lower.plane, upper.plane, at, dir, points, plan, tol);
    (face.points.len() >= 3).then_some(face)
}

/// Step 3, on along the lower surface's edge: a face runs on past its
/// ends along its line as far as the lower surface's outline stays within
/// the reach of its segment, sampled every cell of that surface's
/// footprint (a curb goes on where a tree pit or a driveway pulls the
/// upper surface's outline back from it, and the road still ends at it).
/// Each face that runs on gives a segment on its line from end to end,
/// with the face's index, whose evidence is fitted again as the first
/// segments' was.
fn run_on_edges(
    faces: &[Face],
    segments: &[Segment],
    surfaces: &[Option<Surface>],
    window: Window,
) -> (Vec<Segment>, Vec<usize>) {
    let (mut out, mut owner) = (Vec::new(), Vec::new());
    for (k, f) in faces.iter().enumerate() {
        let s = &segments[f.segment];
        let Some(lower) = &surfaces[s.lower] else {
            continue;
        };
        if f.points.is_empty() {
            continue;
        }
        let step = lower.cell;
        let [a, b] = [(f.lo, -f.dir), (f.hi, f.dir)].map(|(end, dir)| {
            let mut q = f.at + f.dir * end;
            while window.meets(q + dir * step, q + dir * step)
                && lower.near_outline(q + dir * step, s.reach)
            {
                q += dir * step;
            }
            q
        });
        if a != f.at + f.dir * f.lo || b != f.at + f.dir * f.hi {
            out.push(Segment {
                lower: s.lower,
                upper: s.upper,
                a,
                b,
                margin: s.margin,
                reach: s.reach,
                face: Vec::new(),
            });
            owner.push(k);
        }
    }
    (out, owner)
}

/// Whether a face's points fill its step: at least a quarter of them lie
/// in each half of it. A face run on along a curb from a short, higher
/// surface (a car's bumper over it) holds the curb's points in its foot
/// only.
fn fills_step(face: &Face, plan: Plan) -> bool {
    let up = face
        .points
        .iter()
        .filter(|&&i| {
            let w = plan.origin + plan.pts[i as usize].as_dvec3();
            let foot = height(&face.lower, w.truncate());
            w.z - foot >= 0.5 * (height(&face.upper, w.truncate()) - foot)
        })
        .count();
    let n = face.points.len();
    4 * up >= n && 4 * up <= 3 * n
}

/// Least-squares line through the points `idx` in plan: its centroid and
/// direction (turned to agree with `hint`).
fn line_fit(plan: Plan, idx: &[u32], hint: DVec2) -> Option<(DVec2, DVec2)> {
    let q: Vec<DVec2> = idx.iter().map(|&i| plan.at(i)).collect();
    if q.len() < 2 {
        return None;
    }
    let c = q.iter().copied().sum::<DVec2>() / q.len() as f64;
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for v in &q {
        let d = *v - c;
        xx += d.x * d.x;
        xy += d.x * d.y;
        yy += d.y * d.y;
    }
    // The major axis of the scatter: the eigenvector of its larger
    // eigenvalue (along x when the points spread equally every way).
    let half = 0.5 * (xx - yy);
    let big = 0.5 * (xx + yy) + (half * half + xy * xy).sqrt();
    let v = if xx >= yy {
        DVec2::new(big - yy, xy)
    } else {
        DVec2::new(xy, big - xx)
    };
    let dir = v.try_normalize().unwrap_or(DVec2::X);
    Some((c, if dir.dot(hint) < 0.0 { -dir } else { dir }))
}

/// Step 3, across segments: faces on one line (within 5 degrees and `tol`)
/// between the same heights (each surface within `tol` of the other's at
/// the joined face's centre) whose extents overlap or lie within `gap`
/// (times the `spacing` at the gap's middle, as in [`split`]) become one.
fn merge_faces(
    faces: &mut Vec<Face>,
    pts: &[Vec3],
    origin: DVec3,
    tol: f64,
    gap: f64,
    spacing: Spacing,
) {
    let cos_parallel = libm::cos(PARALLEL_DEG.to_radians());
    let plan = Plan { pts, origin };
    // Groups of faces joined pairwise (union-find, smallest index as root),
    // each fitted once.
    let mut root: Vec<usize> = (0..faces.len()).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    for i in 0..faces.len() {
        for j in i + 1..faces.len() {
            if on_one_line(&faces[i], &faces[j], tol, gap, spacing, cos_parallel) {
                let (a, b) = (find(&mut root, i), find(&mut root, j));
                root[a.max(b)] = a.min(b);
            }
        }
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); faces.len()];
    for i in 0..faces.len() {
        let r = find(&mut root, i);
        members[r].push(i);
    }
    let mut next = Vec::new();
    for (r, group) in members.iter().enumerate() {
        match group.len() {
            0 => {}
            1 => {
                let f = &mut faces[r];
                let points = std::mem::take(&mut f.points);
                next.push(Face { points, ..*f });
            }
            _ => {
                let mut points: Vec<u32> = group
                    .iter()
                    .flat_map(|&k| faces[k].points.iter().copied())
                    .collect();
                points.sort_unstable();
                points.dedup();
                let f = &faces[r];
                if let Some((at, dir)) = line_fit(plan, &points, f.dir) {
                    next.push(Face::new(
                        f.segment, f.lower, f.upper, at, dir, points, plan, tol,
                    ));
                }
            }
        }
    }
    *faces = next;
}

/// Whether two faces lie on one line (within 5 degrees and `tol`) between
/// the same heights (each surface within `tol` of the other's at their
/// middle), with extents that overlap or lie within `gap` times the
/// `spacing` at the gap's middle.
fn on_one_line(
    f: &Face,
    g: &Face,
    tol: f64,
    gap: f64,
    spacing: Spacing,
    cos_parallel: f64,
) -> bool {
    // A face without points has no extent (and an infinite gap).
    if !(f.lo <= f.hi && g.lo <= g.hi)
        || f.dir.dot(g.dir).abs() < cos_parallel
        || f.dir.perp().dot(g.at - f.at).abs() > tol
        || g.dir.perp().dot(f.at - g.at).abs() > tol
    {
        return false;
    }
    let mid = (f.at + g.at) * 0.5;
    if (height(&f.lower, mid) - height(&g.lower, mid)).abs() > tol
        || (height(&f.upper, mid) - height(&g.upper, mid)).abs() > tol
    {
        return false;
    }
    // g's extent along f's line, and the gap between the two extents
    // (negative where they overlap), allowed as wide as the evidence may
    // leave at its middle (`Spacing`).
    let ends = [g.at + g.dir * g.lo, g.at + g.dir * g.hi].map(|q| f.dir.dot(q - f.at));
    let (g0, g1) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
    let (a, b) = if g0 > f.hi { (f.hi, g0) } else { (g1, f.lo) };
    b - a <= gap * spacing.scale(f.at + f.dir * (0.5 * (a + b)))
}

/// The height of a near-horizontal plane over the plan point `q`.
fn height(plane: &Plane, q: DVec2) -> f64 {
    -(plane.normal.x * q.x + plane.normal.y * q.y + plane.offset) / plane.normal.z
}

/// Step 4: a face's points, cut where they leave a gap wider than `gap`
/// (times the [`Spacing`] at the gap's middle) along its line; each piece
/// in order along it.
fn split(face: &Face, pts: &[Vec3], origin: DVec3, gap: f64, spacing: Spacing) -> Vec<Vec<u32>> {
    let along: Vec<f64> = face
        .points
        .iter()
        .map(|&i| {
            face.dir
                .dot((origin + pts[i as usize].as_dvec3()).truncate() - face.at)
        })
        .collect();
    // The cuts: the starts of the gaps wider than allowed between the
    // sorted positions; a point's piece is the number of cuts below it.
    let mut sorted = along.clone();
    crate::geometry::heap_sort_by(&mut sorted, f64::total_cmp);
    let cuts: Vec<f64> = sorted
        .windows(2)
        .filter(|w| w[1] - w[0] > gap * spacing.scale(face.at + face.dir * (0.5 * (w[0] + w[1]))))
        .map(|w| w[0])
        .collect();
    let mut out: Vec<Vec<u32>> = vec![Vec::new(); cuts.len() + 1];
    for (&i, &s) in face.points.iter().zip(&along) {
        out[cuts.partition_point(|&c| c < s)].push(i);
    }
    out
}

/// Step 4: the riser primitive of a piece of a face, if its points cover
/// enough of it, its points (those of the piece within the inlier distance
/// of its plane), and whether it is at least as long as the widest gap
/// [`split`] leaves within it (`2 * alpha` times the [`Spacing`] at its
/// middle).
fn riser(
    face: &Face,
    piece: &[u32],
    plan: Plan,
    viewpoint: DVec3,
    p: &Params,
    spacing: Spacing,
) -> Option<(Primitive, Vec<u32>, bool)> {
    let Plan { pts, origin } = plan;
    let world = |i: u32| origin + pts[i as usize].as_dvec3();
    let (at, dir) = line_fit(plan, piece, face.dir)?;
    // Upright between the two surfaces, along the line.
    let up = (face.lower.normal + face.upper.normal).normalize_or_zero();
    let normal = dir.extend(0.0).cross(up).normalize_or_zero();
    if normal == DVec3::ZERO {
        return None;
    }
    let centre = at.extend(height(&face.lower, at));
    let plane = Plane::from_point_normal(centre, normal).oriented(viewpoint);
    let tol = p.other.distance;
    let kept: Vec<u32> = piece
        .iter()
        .copied()
        .filter(|&i| plane.signed_distance(world(i)).abs() < tol)
        .collect();
    let mut along: Vec<f64> = kept
        .iter()
        .map(|&i| dir.dot(world(i).truncate() - at))
        .collect();
    let s0 = along.iter().copied().fold(f64::INFINITY, f64::min);
    let s1 = along.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if s1.is_nan() || s1 <= s0 {
        return None;
    }
    let cell = p.other.cell;
    // The share of its extent (at least a cell) that its points cover,
    // each the `cell` after it times the spacing at its range.
    let len = (s1 - s0).max(cell);
    crate::geometry::heap_sort_by(&mut along, f64::total_cmp);
    let (mut covered, mut end) = (0.0, s0);
    for s in along {
        let b = s + cell * spacing.scale(at + dir * s);
        let (a, b) = (s.max(end), b.min(s0 + len));
        if b > a {
            covered += b - a;
            end = b;
        }
    }
    let occupancy = covered / len;
    if occupancy < p.min_occupancy {
        return None;
    }
    // The rectangle between the two surfaces over the extent of its points:
    // each end's foot on the line, moved along `up` onto either surface.
    let foot = |s: f64, surface: &Plane| {
        let q = centre + dir.extend(0.0) * s;
        q - up * (surface.signed_distance(q) / surface.normal.dot(up))
    };
    let corners = [
        foot(s0, &face.lower),
        foot(s1, &face.lower),
        foot(s1, &face.upper),
        foot(s0, &face.upper),
    ];
    let mut moments = Moments::new(centre.round());
    for &i in &kept {
        moments.push(world(i));
    }
    let frame = Frame::on_plane(&plane, moments.mean());
    let mut outline: Vec<DVec2> = corners.iter().map(|&c| frame.to_local(c)).collect();
    make_ccw(&mut outline);
    let area = signed_area(&outline);
    if area.is_nan() {
        return None;
    }
    let long = s1 - s0 >= 2.0 * p.other.alpha * spacing.scale(at + dir * (0.5 * (s0 + s1)));
    let mut footprint = Footprint::new(cell);
    let local: Vec<DVec2> = kept.iter().map(|&i| frame.to_local(world(i))).collect();
    footprint.mark_all(&local);
    let riser = Primitive {
        id: 0,
        plane,
        frame,
        outline,
        area,
        support: kept.len() as u64,
        ground: false,
        moments,
        footprint,
        born_scan: 0,
        last_scan: 0,
    };
    Some((riser, kept, long))
}

#[cfg(test)]
mod tests {
    use crate::cloud::Cloud;
    use crate::detect::{detect, CascadePolicy, Detector, NO_PRIMITIVE};
    use crate::params::Params;
    use glam::DVec3;

    /// A road (z = 0, y < 0) and a sidewalk `step` higher (y > 0), 20 m
    /// along x, sampled every 0.1 m, and `face` points on the step at
    /// y = 0, evenly along x and strictly between the two heights.
    fn curb(step: f64, face: usize) -> Vec<f32> {
        let mut pts = Vec::new();
        for i in 0..200 {
            let x = i as f64 * 0.1 + 0.05;
            for j in 0..50 {
                pts.extend([x, -5.0 + j as f64 * 0.1 + 0.05, 0.0]);
            }
            for j in 0..30 {
                pts.extend([x, j as f64 * 0.1 + 0.05, step]);
            }
        }
        for k in 0..face {
            let x = (k as f64 + 0.5) * 20.0 / face as f64;
            let z = step * (0.3 + 0.4 * ((k % 3) as f64 / 2.0));
            pts.extend([x, 0.0, z]);
        }
        pts.into_iter().map(|v| v as f32).collect()
    }

    /// The tests' sensor, on the road 3 m from the curb, and the
    /// parameters that know it.
    const VIEWPOINT: [f64; 3] = [10.0, -3.0, 1.8];

    fn seen_from_the_road() -> (Params, DVec3) {
        let p = Params {
            viewpoint: Some(VIEWPOINT),
            ..Params::gpp2()
        };
        (p, DVec3::from_array(VIEWPOINT))
    }

    /// One-shot detection without its riser step.
    fn no_risers() -> CascadePolicy {
        CascadePolicy {
            find_risers: false,
            ..CascadePolicy::one_shot()
        }
    }

    /// A wall on the curb's line (y = 0) from the road up to 5 m, its
    /// `columns` every 0.1 m along x from 0, its rows every 0.05 m.
    fn wall(columns: usize) -> Vec<f32> {
        let mut pts = Vec::new();
        for i in 0..columns {
            for j in 0..=100 {
                pts.extend([i as f32 * 0.1 + 0.05, 0.0, j as f32 * 0.05]);
            }
        }
        pts
    }

    fn run(pts: &[f32], policy: CascadePolicy) -> (Cloud, crate::detect::Detection) {
        let cloud = Cloud::from_flat(pts, 3).unwrap();
        let (p, viewpoint) = seen_from_the_road();
        let det = Detector::new(&p, policy).run(&cloud.points, cloud.origin, viewpoint);
        (cloud, det)
    }

    #[test]
    fn a_curb_between_road_and_sidewalk_is_a_riser() {
        let pts = curb(0.15, 300);
        let (cloud, det) = run(&pts, CascadePolicy::one_shot());
        assert_eq!(det.primitives.len(), 3, "road, sidewalk and curb");
        let r = &det.primitives[2];
        // Upright at y = 0, facing the sensor (on the road side).
        assert!((r.plane.normal - DVec3::new(0.0, -1.0, 0.0)).length() < 0.01);
        let v = r.vertices();
        let (lo, hi) = v
            .iter()
            .fold((DVec3::splat(1e9), DVec3::splat(-1e9)), |(a, b), &q| {
                (a.min(q), b.max(q))
            });
        assert!(lo.y.abs() < 0.01 && hi.y.abs() < 0.01, "{lo} {hi}");
        assert!(lo.z.abs() < 0.01 && (hi.z - 0.15).abs() < 0.01, "{lo} {hi}");
        assert!(lo.x < 0.1 && hi.x > 19.9, "{lo} {hi}");
        assert!((r.area - 3.0).abs() < 0.05, "{}", r.area);
        // Its points are the face's, taken from the surfaces they were on.
        let face: Vec<usize> = (0..cloud.len())
            .filter(|&i| cloud.world(i).y == 0.0)
            .collect();
        assert!(face.iter().all(|&i| det.labels[i] == 2));
        assert_eq!(r.support, 300);
        for (k, q) in det.primitives.iter().enumerate() {
            let n = det.labels.iter().filter(|&&l| l == k as u32).count() as u64;
            assert_eq!(q.support, n);
        }
        // Without the rule, no round finds it (too narrow).
        assert_eq!(run(&pts, no_risers()).1.primitives.len(), 2);
        // And the public one-shot detection has it.
        let (p, _) = seen_from_the_road();
        assert_eq!(detect(&cloud, &p).unwrap().primitives.len(), 3);
    }

    #[test]
    fn surfaces_traced_on_coarse_cells_meet_within_their_own_tolerance() {
        // The road's points stop 0.75 m short of the curb (y = 0), so its
        // outline and the sidewalk's lie more than 0.5 m apart: beyond the
        // clustering tolerance (0.5 m) of surfaces traced on the usual
        // cells, within that of a sidewalk traced on cells three times as
        // wide (one-shot detection's coarse pass), whose outline is as
        // coarse.
        let (mut road, mut sidewalk, mut face) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..200 {
            let x = i as f32 * 0.1 + 0.05;
            for j in 0..43 {
                road.extend([x, -5.0 + j as f32 * 0.1 + 0.05, 0.0]);
            }
            for j in 0..30 {
                sidewalk.extend([x, j as f32 * 0.1 + 0.05, 0.15]);
            }
            face.extend([x, 0.0, 0.045 + 0.03 * (i % 3) as f32]);
        }
        let (p, viewpoint) = seen_from_the_road();
        let surface = |pts: &[f32], traced_with: &Params| {
            let cloud = Cloud::from_flat(pts, 3).unwrap();
            let mut det =
                Detector::new(traced_with, no_risers()).run(&cloud.points, cloud.origin, viewpoint);
            assert_eq!(det.primitives.len(), 1);
            det.primitives.remove(0)
        };
        let all: Vec<f32> = [&road[..], &sidewalk[..], &face[..]].concat();
        let cloud = Cloud::from_flat(&all, 3).unwrap();
        let labels = vec![NO_PRIMITIVE; cloud.len()];
        let risers = |sidewalk_traced_with: &Params| {
            let surfaces = [surface(&road, &p), surface(&sidewalk, sidewalk_traced_with)];
            super::find_risers(
                &surfaces,
                &[true, true],
                &|_| None,
                &labels,
                &cloud.points,
                cloud.origin,
                viewpoint,
                &p,
                p.min_area,
                None,
            )
        };
        assert!(risers(&p).is_empty());
        let found = risers(&crate::detect::coarse::coarser(&p));
        assert_eq!(found.len(), 1);
        assert!((found[0].0.area - 3.0).abs() < 0.05, "{}", found[0].0.area);
    }

    #[test]
    fn a_curb_seen_in_pieces_between_tree_pits_is_kept_in_pieces() {
        // A road (z = 0, y < 0) and a sidewalk 0.15 m higher (y > 0) along
        // 30 m. Every 6 m a tree pit 2.6 m long pulls the sidewalk back
        // to y = 1.5, and the curb's face is seen only between two pits,
        // over 3 m (parked cars hide the rest): a piece of 0.45 m^2, under
        // `minArea` (1.5 m^2) alone. The road ends at the curb all along.
        let scene = |pieces: usize| {
            let mut pts: Vec<f32> = Vec::new();
            for i in 0..300 {
                let x = i as f32 * 0.1 + 0.05;
                for j in 0..50 {
                    pts.extend([x, -5.0 + j as f32 * 0.1 + 0.05, 0.0]);
                }
                let pit = (x - 3.2).rem_euclid(6.0) < 2.6;
                for j in 0..30 {
                    let y = j as f32 * 0.1 + 0.05;
                    if !pit || y > 1.5 {
                        pts.extend([x, y, 0.15]);
                    }
                }
            }
            for k in 0..pieces {
                for m in 0..60 {
                    let x = k as f32 * 6.0 + m as f32 * 0.05 + 0.025;
                    pts.extend([x, 0.0, 0.045 + 0.03 * (m % 3) as f32]);
                }
            }
            pts
        };
        let risers = |pts: &[f32]| -> Vec<f64> {
            let (_, det) = run(pts, CascadePolicy::one_shot());
            det.primitives
                .iter()
                .filter(|q| q.plane.normal.z.abs() < 0.1)
                .map(|q| q.area)
                .collect()
        };
        // Five pieces: one face, 2.25 m^2 in all, kept as its pieces (no
        // polygon spans the gaps, where nothing was seen).
        let all = risers(&scene(5));
        assert_eq!(all.len(), 5, "{all:?}");
        assert!(all.iter().all(|a| (a - 0.45).abs() < 0.02), "{all:?}");
        // One piece alone is too small.
        assert!(risers(&scene(1)).is_empty());
    }

    #[test]
    fn a_curb_does_not_run_on_under_a_higher_surface_beside_it() {
        // The curb of `curb` (0.15 m, its face seen all along) and, on the
        // sidewalk at its edge, the top of a box 0.35 m high (x 8-12 m,
        // y 0-1.5 m) whose front overhangs the curb (nothing seen on it).
        // The box's top and the road meet a step of 0.35 m apart, and the
        // road's outline runs on along the curb, but only the foot of that
        // step holds points: one riser, the curb.
        let mut pts = curb(0.15, 400);
        for i in 0..40 {
            for j in 0..15 {
                pts.extend([8.05 + i as f32 * 0.1, 0.05 + j as f32 * 0.1, 0.35]);
            }
        }
        let (_, det) = run(&pts, CascadePolicy::one_shot());
        let risers: Vec<_> = det
            .primitives
            .iter()
            .filter(|q| q.plane.normal.z.abs() < 0.1)
            .collect();
        assert_eq!(risers.len(), 1, "{}", risers.len());
        let top = risers[0]
            .vertices()
            .iter()
            .map(|v| v.z)
            .fold(f64::MIN, f64::max);
        assert!((top - 0.15).abs() < 0.01, "{top}");
    }

    #[test]
    fn a_riser_in_the_foot_of_a_primitive_already_there_is_not_added() {
        // A wall stands on the curb's line (y = 0) from the road up to
        // 5 m, its rows every 0.05 m (found first, the largest surface);
        // say its cluster left out the rows between the road and the
        // sidewalk, which fill the step. They are the wall's foot, inside
        // its outline: no riser over it.
        let pts = [curb(0.15, 0), wall(200)].concat();
        let cloud = Cloud::from_flat(&pts, 3).unwrap();
        let (p, viewpoint) = seen_from_the_road();
        let mut det = Detector::new(&p, no_risers()).run(&cloud.points, cloud.origin, viewpoint);
        let wall = det
            .primitives
            .iter()
            .position(|q| q.plane.normal.z.abs() < 0.1);
        assert!(
            wall.is_some() && det.primitives.len() == 3,
            "road, sidewalk, wall"
        );
        for i in 0..cloud.len() {
            let w = cloud.world(i);
            if w.y == 0.0 && w.z > 0.01 && w.z < 0.14 {
                det.labels[i] = NO_PRIMITIVE;
            }
        }
        super::add_risers(
            &mut det.primitives,
            &mut det.labels,
            &cloud.points,
            cloud.origin,
            viewpoint,
            &p,
            None,
        );
        assert_eq!(det.primitives.len(), 3);
    }

    #[test]
    fn a_riser_on_the_plane_of_a_wall_it_meets_joins_the_wall() {
        // The curb's face is seen along its 20 m, and a wall 5 m long
        // stands on its line (y = 0, x 0-5 m, from the road up), found
        // before the risers with its rows below the sidewalk left out of
        // its support. The riser runs the curb's length, most of its points
        // beyond the wall: it is not added over the wall's foot (two
        // polygons on one plane, one over the other) but taken into the
        // wall, which now runs on along the curb. A wall 0.3 m behind the
        // curb's line, or one on it from 1 m up (its outline does not meet
        // the riser's), leaves the riser a primitive of its own.
        let ground = curb(0.15, 0);
        let face = &curb(0.15, 400)[ground.len()..];
        let (p, viewpoint) = seen_from_the_road();
        let detect = |pts: &[f32]| {
            let c = Cloud::from_flat(pts, 3).unwrap();
            Detector::new(&p, no_risers()).run(&c.points, c.origin, viewpoint)
        };
        let road = detect(&ground);
        assert_eq!(road.primitives.len(), 2);
        let reach = |q: &crate::primitive::Primitive| {
            q.vertices().iter().map(|v| v.x).fold(f64::MIN, f64::max)
        };
        let run = |wall_pts: &[f32]| {
            let all: Vec<f32> = [&ground[..], face, wall_pts].concat();
            let cloud = Cloud::from_flat(&all, 3).unwrap();
            let wall = detect(wall_pts);
            assert_eq!(wall.primitives.len(), 1);
            let mut prims = road.primitives.clone();
            prims.extend(wall.primitives.iter().cloned());
            let mut labels = road.labels.clone();
            labels.extend(std::iter::repeat_n(NO_PRIMITIVE, face.len() / 3));
            for (k, &l) in wall.labels.iter().enumerate() {
                let low = wall_pts[3 * k + 2] < 0.14;
                if l == 0 && low {
                    prims[2].support -= 1;
                }
                labels.push(if l == 0 && !low { 2 } else { NO_PRIMITIVE });
            }
            let before = prims[2].clone();
            assert!(reach(&before) < 5.5);
            super::add_risers(
                &mut prims,
                &mut labels,
                &cloud.points,
                cloud.origin,
                viewpoint,
                &p,
                None,
            );
            for (k, q) in prims.iter().enumerate() {
                let n = labels.iter().filter(|&&l| l == k as u32).count() as u64;
                assert_eq!(q.support, n, "primitive {k}");
            }
            (prims, labels, cloud, before)
        };
        let (prims, labels, cloud, before) = run(&wall(50));
        assert_eq!(prims.len(), 3);
        assert!(reach(&prims[2]) > 19.5, "{}", reach(&prims[2]));
        assert!(prims[2].area > before.area + 1.0);
        let face_at = |i: usize| {
            let w = cloud.world(i);
            w.y == 0.0 && w.x > 6.0 && w.z > 0.01 && w.z < 0.14
        };
        assert!((0..cloud.len()).filter(|&i| face_at(i)).count() > 200);
        assert!((0..cloud.len())
            .filter(|&i| face_at(i))
            .all(|i| labels[i] == 2));
        let moved = |dy: f32, from_z: f32| -> Vec<f32> {
            let w = wall(50);
            let keep = |c: &[f32]| c[2] >= from_z;
            let rows = w.chunks_exact(3).filter(|c| keep(c));
            rows.flat_map(|c| [c[0], c[1] + dy, c[2]]).collect()
        };
        for (what, pts) in [("behind", moved(0.3, 0.15)), ("up", moved(0.0, 1.0))] {
            let (prims, _, _, before) = run(&pts);
            assert_eq!(prims.len(), 4, "a wall {what}");
            assert_eq!(prims[2].area, before.area, "a wall {what}");
        }
    }

    #[test]
    fn a_riser_needs_a_step_filled_with_points_and_lower_than_min_width() {
        // No points on the step (a sidewalk seen only from above): nothing.
        assert_eq!(
            run(&curb(0.15, 0), CascadePolicy::one_shot())
                .1
                .primitives
                .len(),
            2
        );
        // Points on a quarter of it only: they cover too little of it.
        let mut pts = curb(0.15, 0);
        for k in 0..100 {
            pts.extend([k as f32 * 0.05, 0.0, 0.075]);
        }
        let (_, det) = run(&pts, CascadePolicy::one_shot());
        assert!(
            det.primitives.iter().all(|q| q.plane.normal.z.abs() > 0.9),
            "{}",
            det.primitives.len()
        );
        // A sparse face (100 points, too few for a round) 0.3 m high is a
        // riser; 0.5 m high it is a face `minWidth` (0.4 m) allows a round
        // to find, so the rule leaves it.
        assert_eq!(
            run(&curb(0.3, 100), CascadePolicy::one_shot())
                .1
                .primitives
                .len(),
            3
        );
        assert_eq!(
            run(&curb(0.5, 100), CascadePolicy::one_shot())
                .1
                .primitives
                .len(),
            2
        );
    }

    #[test]
    fn a_far_curb_seen_in_runs_of_points_is_one_riser() {
        // The curb 30-50 m from the sensor's foot (x = -30): its face holds
        // runs of points 0.4 m long every 1.5 m, where laser rings cross
        // it. Gaps of 1.1 m are over `2 * alpha` (1 m), so each run alone
        // would be a piece, far below `minArea`; at these ranges the rings
        // lie 2.25-6.25 times as far apart as within `groundClusterRange`.
        let mut pts = curb(0.15, 0);
        for k in 0..14 {
            for i in 0..9 {
                let x = 0.05 + 1.5 * k as f32 + 0.05 * i as f32;
                pts.extend([x, 0.0, 0.045 + 0.015 * (i % 5) as f32]);
            }
        }
        let cloud = Cloud::from_flat(&pts, 3).unwrap();
        let viewpoint = DVec3::new(-30.0, -3.0, 1.8);
        let p = Params {
            viewpoint: Some(viewpoint.to_array()),
            ..Params::gpp2()
        };
        let run = |policy| Detector::new(&p, policy).run(&cloud.points, cloud.origin, viewpoint);
        let det = run(CascadePolicy::one_shot());
        assert_eq!(det.primitives.len(), 3, "road, sidewalk and curb");
        let v = det.primitives[2].vertices();
        let (lo, hi) = v
            .iter()
            .fold((DVec3::splat(1e9), DVec3::splat(-1e9)), |(a, b), &q| {
                (a.min(q), b.max(q))
            });
        assert!(lo.y.abs() < 0.01 && hi.y.abs() < 0.01, "{lo} {hi}");
        assert!(lo.x < 0.1 && hi.x > 19.9, "one riser end to end: {lo} {hi}");
        // Judged as if seen from everywhere alike, the runs fall apart.
        let alike = CascadePolicy {
            range_pulled_ground: false,
            ..CascadePolicy::one_shot()
        };
        assert_eq!(run(alike).primitives.len(), 2);
    }

    #[test]
    fn far_faces_on_one_line_join_across_the_gaps_the_rings_leave() {
        // A curb's face along y = 0 at x = 20-39: runs of points 1 m long
        // every 2.5 m (gaps of 1.5 m, over `2 * alpha`), each the face of
        // one segment of a jagged outline.
        use super::{merge_faces, Face, Plan, Spacing};
        use crate::geometry::Plane;
        use glam::{DVec2, Vec3};
        let mut pts = Vec::new();
        let mut runs = Vec::new();
        for k in 0..8 {
            let first = pts.len() as u32;
            for i in 0..11 {
                let x = 20.0 + 2.5 * k as f32 + 0.1 * i as f32;
                pts.push(Vec3::new(x, 0.0, 0.05 + 0.01 * (i % 5) as f32));
            }
            runs.push((first..pts.len() as u32).collect::<Vec<u32>>());
        }
        let plan = Plan {
            pts: &pts,
            origin: DVec3::ZERO,
        };
        let lower = Plane::from_point_normal(DVec3::ZERO, DVec3::Z);
        let upper = Plane::from_point_normal(DVec3::new(0.0, 1.0, 0.15), DVec3::Z);
        let faces = || -> Vec<Face> {
            runs.iter()
                .map(|r| {
                    Face::new(
                        0,
                        lower,
                        upper,
                        plan.at(r[0]),
                        DVec2::X,
                        r.clone(),
                        plan,
                        0.08,
                    )
                })
                .collect()
        };
        let joined = |foot: Option<DVec2>| {
            let mut f = faces();
            let spacing = Spacing { foot, range: 20.0 };
            merge_faces(&mut f, &pts, DVec3::ZERO, 0.08, 1.0, spacing);
            f.iter().map(|f| f.points.len()).collect::<Vec<_>>()
        };
        // Seen from the foot, 30-50 m away: one face of every point.
        assert_eq!(joined(Some(DVec2::new(-10.0, 0.0))), vec![88]);
        // From the origin, the gaps whose middles lie 21.75 and 24.25 m
        // away may be 1.18 and 1.47 m wide (the square of the range over
        // 20 m): those two stay, the farther ones join.
        assert_eq!(joined(Some(DVec2::ZERO)), vec![11, 11, 66]);
        // From a foot among them, every gap is within 20 m: too wide.
        assert_eq!(joined(Some(DVec2::new(25.0, 0.0))).len(), 8);
        // Seen from nowhere known, the gaps are too wide everywhere.
        assert_eq!(joined(None).len(), 8);
        // A face without points (no extent: `lo` > `hi`) joins nothing,
        // whichever way round, on a line along no axis.
        let d = DVec2::new(0.6, 0.8);
        let face = |at: f64, lo: f64, hi: f64, points: Vec<u32>| Face {
            segment: 0,
            lower,
            upper,
            at: d * at,
            dir: d,
            lo,
            hi,
            points,
        };
        let empty = face(30.0, f64::INFINITY, f64::NEG_INFINITY, Vec::new());
        let full = face(40.0, 0.0, 1.0, vec![0]);
        let spacing = Spacing {
            foot: Some(DVec2::ZERO),
            range: 20.0,
        };
        let cos = 5f64.to_radians().cos();
        assert!(super::on_one_line(&full, &full, 0.08, 1.0, spacing, cos));
        assert!(!super::on_one_line(&empty, &full, 0.08, 1.0, spacing, cos));
        assert!(!super::on_one_line(&full, &empty, 0.08, 1.0, spacing, cos));
    }

    #[test]
    fn clutter_beside_a_curb_does_not_tilt_it() {
        // A wheel 0.3 m in front of the curb, as high as the step.
        let mut pts = curb(0.15, 300);
        for k in 0..80 {
            let x = 5.0 + (k % 10) as f32 * 0.06;
            let y = -0.25 - (k / 10) as f32 * 0.02;
            pts.extend([x, y, 0.03 + (k % 7) as f32 * 0.015]);
        }
        let (_, det) = run(&pts, CascadePolicy::one_shot());
        let r = det
            .primitives
            .iter()
            .find(|q| q.plane.normal.z.abs() < 0.1)
            .expect("a riser");
        assert!(r.plane.normal.angle_between(DVec3::NEG_Y) < 0.5f64.to_radians());
        assert!(r.plane.offset.abs() < 0.01, "{}", r.plane.offset);
        assert!(det.labels.iter().filter(|&&l| l != NO_PRIMITIVE).count() > 0);
    }
}
