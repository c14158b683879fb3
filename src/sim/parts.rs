//! Scene parts shared by the layouts: buildings along a sidewalk, parked
//! cars, poles and trees.
//!
//! Parts are laid out in a row frame `(u, v)` placed by a [`Place`]: `u` runs
//! along the curb, `v` points away from the road (the curb is at `v = 0`, the
//! road at `v < 0`).

use super::builder::{Builder, Place};
use super::truth::SurfaceKind;
use glam::{DVec2, DVec3};

/// Height of sidewalks above the road, metres.
pub(crate) const CURB_HEIGHT: f64 = 0.15;
/// How far a door is recessed behind its facade, metres.
pub(crate) const DOOR_DEPTH: f64 = 0.3;

/// A recessed door of a facade, in row coordinates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Door {
    pub u0: f64,
    pub u1: f64,
    pub height: f64,
}

/// A building block seen from the road, in row coordinates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Building {
    /// Extent along the curb.
    pub a: f64,
    pub b: f64,
    /// `v` of the facade plane.
    pub front: f64,
    /// Extent behind the facade.
    pub depth: f64,
    /// Ground level (sidewalk top).
    pub z0: f64,
    /// Roof heights (absolute z) at the `a` end and at the `b` end.
    pub left_h: f64,
    pub right_h: f64,
    /// Where the roofline steps from `left_h` to `right_h`, if they differ.
    pub step_u: Option<f64>,
    pub door: Option<Door>,
}

impl Building {
    pub fn back(&self) -> f64 {
        self.front + self.depth
    }
}

/// Add a building's facade (non-convex when it has a door notch or a roof
/// step), its door and door reveals, its roof-step wall and, if `side_walls`,
/// its two side walls. Returns the sidewalk's boundary along it in row
/// coordinates, in increasing `u` (it dips into the door recess).
pub(crate) fn building(
    bld: &mut Builder,
    pl: &Place,
    b: &Building,
    side_walls: bool,
) -> Vec<DVec2> {
    let (a, e, f, z0) = (b.a, b.b, b.front, b.z0);
    let toward_road = pl.dir(0.0, -1.0);
    let mut outline = vec![pl.at(a, f, z0)];
    let mut boundary = vec![DVec2::new(a, f)];
    if let Some(d) = b.door {
        let top = z0 + d.height;
        outline.extend([
            pl.at(d.u0, f, z0),
            pl.at(d.u0, f, top),
            pl.at(d.u1, f, top),
            pl.at(d.u1, f, z0),
        ]);
        let g = f + DOOR_DEPTH;
        boundary.extend([
            DVec2::new(d.u0, f),
            DVec2::new(d.u0, g),
            DVec2::new(d.u1, g),
            DVec2::new(d.u1, f),
        ]);
        let door = vec![
            pl.at(d.u0, g, z0),
            pl.at(d.u1, g, z0),
            pl.at(d.u1, g, top),
            pl.at(d.u0, g, top),
        ];
        bld.add(Some(SurfaceKind::Door), door, toward_road);
        // Reveals: the two jambs and the lintel of the recess.
        bld.add_wall(
            None,
            pl.xy(d.u0, f),
            pl.xy(d.u0, g),
            z0,
            top,
            pl.dir(1.0, 0.0),
        );
        bld.add_wall(
            None,
            pl.xy(d.u1, f),
            pl.xy(d.u1, g),
            z0,
            top,
            pl.dir(-1.0, 0.0),
        );
        let lintel = vec![
            pl.at(d.u0, f, top),
            pl.at(d.u1, f, top),
            pl.at(d.u1, g, top),
            pl.at(d.u0, g, top),
        ];
        bld.add(None, lintel, -DVec3::Z);
    }
    boundary.push(DVec2::new(e, f));
    outline.extend([pl.at(e, f, z0), pl.at(e, f, b.right_h)]);
    if let Some(s) = b.step_u {
        outline.extend([pl.at(s, f, b.right_h), pl.at(s, f, b.left_h)]);
        // The wall of the taller part above the lower roof faces the lower side.
        let (lo, hi) = (b.left_h.min(b.right_h), b.left_h.max(b.right_h));
        let toward = if b.left_h < b.right_h {
            pl.dir(-1.0, 0.0)
        } else {
            pl.dir(1.0, 0.0)
        };
        bld.add_wall(
            Some(SurfaceKind::Facade),
            pl.xy(s, f),
            pl.xy(s, b.back()),
            lo,
            hi,
            toward,
        );
    }
    outline.push(pl.at(a, f, b.left_h));
    bld.add(Some(SurfaceKind::Facade), outline, toward_road);
    if side_walls {
        bld.add_wall(
            Some(SurfaceKind::Facade),
            pl.xy(a, f),
            pl.xy(a, b.back()),
            z0,
            b.left_h,
            pl.dir(-1.0, 0.0),
        );
        bld.add_wall(
            Some(SurfaceKind::Facade),
            pl.xy(e, f),
            pl.xy(e, b.back()),
            z0,
            b.right_h,
            pl.dir(1.0, 0.0),
        );
    }
    boundary
}

/// How a row of buildings ends.
#[derive(Clone, Copy, Debug)]
pub(crate) enum RowEnd {
    /// A building flush with the end.
    Open,
    /// A gap (closed by a fence) next to a neighbouring building whose back
    /// is at this `v`.
    Gap(f64),
    /// A building flush with the end, reaching back at least to this `v`.
    MinBack(f64),
}

/// A row of buildings along a curb, `u0 ≤ u ≤ u1`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Row {
    pub u0: f64,
    pub u1: f64,
    /// Minimum sidewalk width (facades stand at least this far from the curb).
    pub sidewalk: f64,
    pub lead: RowEnd,
    pub trail: RowEnd,
}

enum Lot {
    Building(Building),
    Gap { a: f64, b: f64 },
}

/// Random door for a facade spanning `a..b`, if it is wide enough.
pub(crate) fn random_door(bld: &mut Builder, a: f64, b: f64) -> Option<Door> {
    let w = bld.rng.range(1.0, 1.4);
    if b - a < w + 3.2 {
        return None;
    }
    let u0 = bld.rng.range(a + 1.5, b - 1.5 - w);
    Some(Door {
        u0,
        u1: u0 + w,
        height: bld.rng.range(2.1, 2.4),
    })
}

/// Add a row of buildings separated by gaps (each gap floored by the
/// sidewalk and closed at the back by a fence) and return the sidewalk's
/// boundary along the row in row coordinates, in increasing `u`.
pub(crate) fn row(bld: &mut Builder, pl: &Place, row: &Row) -> Vec<DVec2> {
    let z0 = CURB_HEIGHT;
    let len = row.u1 - row.u0;
    if len <= 0.0 {
        return Vec::new();
    }
    // Plan widths: (is_gap, width), then scale them to fit exactly.
    let mut plan: Vec<(bool, f64)> = Vec::new();
    if len < 12.0 {
        plan.push((false, len));
    } else {
        if matches!(row.lead, RowEnd::Gap(_)) {
            plan.push((true, bld.rng.range(2.0, 6.0)));
        }
        let trail_gap = matches!(row.trail, RowEnd::Gap(_));
        loop {
            plan.push((false, bld.rng.range(9.0, 24.0)));
            let total: f64 =
                plan.iter().map(|p| p.1).sum::<f64>() + if trail_gap { 4.0 } else { 0.0 };
            if total >= len {
                break;
            }
            plan.push((true, bld.rng.range(1.5, 6.0)));
        }
        if trail_gap {
            plan.push((true, bld.rng.range(2.0, 6.0)));
        }
    }
    let scale = len / plan.iter().map(|p| p.1).sum::<f64>();
    // Realise the lots.
    let mut lots = Vec::with_capacity(plan.len());
    let mut u = row.u0;
    let last = plan.len() - 1;
    for (i, &(gap, w)) in plan.iter().enumerate() {
        let end = if i == last { row.u1 } else { u + w * scale };
        if gap {
            lots.push(Lot::Gap { a: u, b: end });
        } else {
            let front = row.sidewalk + bld.rng.range(0.0, 2.5);
            let mut depth = bld.rng.range(9.0, 16.0);
            if let (0, RowEnd::MinBack(m)) = (i, row.lead) {
                depth = depth.max(m - front + 0.5);
            }
            if let RowEnd::MinBack(m) = row.trail {
                if i == last {
                    depth = depth.max(m - front + 0.5);
                }
            }
            let h = z0 + bld.rng.range(6.0, 22.0);
            let step = bld.rng.uniform() < 0.45;
            let door = if bld.rng.uniform() < 0.85 {
                random_door(bld, u, end)
            } else {
                None
            };
            let mut b = Building {
                a: u,
                b: end,
                front,
                depth,
                z0,
                left_h: h,
                right_h: h,
                step_u: None,
                door,
            };
            if step {
                set_step(bld, &mut b);
            }
            lots.push(Lot::Building(b));
        }
        u = end;
    }
    // Every row shows at least one door and one stepped roofline if it can.
    let buildings = || {
        lots.iter().filter_map(|l| match l {
            Lot::Building(b) => Some(b),
            Lot::Gap { .. } => None,
        })
    };
    let widest = buildings()
        .enumerate()
        .max_by(|x, y| (x.1.b - x.1.a).total_cmp(&(y.1.b - y.1.a)))
        .map(|(i, _)| i);
    let need_door = buildings().all(|b| b.door.is_none());
    let need_step = buildings().all(|b| b.step_u.is_none());
    if let Some(wi) = widest {
        if let Some(Lot::Building(b)) = lots
            .iter_mut()
            .filter(|l| matches!(l, Lot::Building(_)))
            .nth(wi)
        {
            if need_door {
                b.door = random_door(bld, b.a, b.b);
            }
            if need_step {
                set_step(bld, b);
            }
        }
    }
    // Emit.
    let mut boundary = Vec::new();
    for i in 0..lots.len() {
        match &lots[i] {
            Lot::Building(b) => boundary.extend(building(bld, pl, b, true)),
            Lot::Gap { a, b } => {
                let back_of = |j: Option<usize>, end: RowEnd| match j.and_then(|j| lots.get(j)) {
                    Some(Lot::Building(n)) => n.back(),
                    _ => match end {
                        RowEnd::Gap(v) => v,
                        _ => row.sidewalk + 9.0,
                    },
                };
                let left = back_of(i.checked_sub(1), row.lead);
                let right = back_of(Some(i + 1), row.trail);
                let vg = left.min(right);
                boundary.push(DVec2::new(*a, vg));
                boundary.push(DVec2::new(*b, vg));
                let fence = z0 + bld.rng.range(1.8, 2.5);
                bld.add_wall(
                    Some(SurfaceKind::Wall),
                    pl.xy(*a, vg),
                    pl.xy(*b, vg),
                    z0,
                    fence,
                    pl.dir(0.0, -1.0),
                );
            }
        }
    }
    boundary
}

/// Give a building a stepped roofline, if it is wide enough.
fn set_step(bld: &mut Builder, b: &mut Building) {
    let w = b.b - b.a;
    if w < 8.0 {
        return;
    }
    let s = b.a + w * bld.rng.range(0.3, 0.7);
    let dh = bld.rng.range(3.0, 8.0);
    let lower = (b.left_h - dh).max(b.z0 + 4.0);
    if b.left_h - lower < 2.0 {
        b.right_h = b.left_h + dh;
    } else if bld.rng.uniform() < 0.5 {
        b.right_h = lower;
    } else {
        b.left_h = lower;
    }
    b.step_u = Some(s);
}

/// Park cars along the curb (on the road side, `v < 0`) for `u0..u1`: boxes
/// of about 4.5 × 1.8 m from 0.3 m to about 1.5 m above the road.
pub(crate) fn park_cars(bld: &mut Builder, pl: &Place, u0: f64, u1: f64) {
    let mut u = u0 + bld.rng.range(0.0, 6.0);
    loop {
        if bld.rng.uniform() < 0.25 {
            u += bld.rng.range(4.0, 10.0);
            if u > u1 {
                break;
            }
            continue;
        }
        let len = bld.rng.range(4.2, 4.8);
        if u + len > u1 {
            break;
        }
        let width = bld.rng.range(1.7, 1.9);
        let top = bld.rng.range(1.4, 1.6);
        let off = bld.rng.range(0.2, 0.4);
        let yaw = bld.rng.range(-0.03, 0.03);
        let centre = DVec2::new(u + len / 2.0, -off - width / 2.0);
        let car = Place::rotation(yaw, centre);
        let (l, w) = (len / 2.0, width / 2.0);
        let footprint: Vec<DVec2> = [(-l, -w), (l, -w), (l, w), (-l, w)]
            .iter()
            .map(|&(x, y)| {
                let p = car.xy(x, y);
                pl.xy(p.x, p.y)
            })
            .collect();
        bld.add_box(Some(SurfaceKind::Vehicle), &footprint, 0.3, top);
        u += len + bld.rng.range(0.8, 3.0);
    }
}

/// Poles and trees on the sidewalk near the curb for `u0..u1`, at least one
/// of each when the stretch is long enough.
pub(crate) fn furniture(bld: &mut Builder, pl: &Place, u0: f64, u1: f64) {
    let z0 = CURB_HEIGHT;
    let mut u = u0 + bld.rng.range(1.0, 6.0);
    let mut i = 0;
    while u <= u1 {
        let pole = match i {
            0 => true,
            1 => false,
            _ => bld.rng.uniform() < 0.35,
        };
        if pole {
            let v = bld.rng.range(0.35, 0.6);
            let r = bld.rng.range(0.08, 0.14);
            let h = bld.rng.range(4.0, 8.0);
            bld.pole(pl.at(u, v, z0), r, h);
        } else {
            let v = bld.rng.range(0.6, 1.0);
            let r = bld.rng.range(0.12, 0.25);
            let h = bld.rng.range(2.4, 3.4);
            let crown = bld.rng.range(1.4, 2.2);
            bld.tree(pl.at(u, v, z0), r, h, crown);
        }
        i += 1;
        u += bld.rng.range(7.0, 15.0);
    }
}
