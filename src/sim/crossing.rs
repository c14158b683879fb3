//! The `crossing` layout: road A along x (driven through) crosses road B
//! along y. Each quadrant has a sidewalk with curbs and either an L-shaped
//! corner building (two facades) or, in one quadrant, a plaza with a
//! free-standing wall at an odd angle; rows of buildings continue along the
//! arms. Road B's +y arm ends in a ramp rising at 6° to 10°.

use super::builder::{Builder, Place, Route, DRIVE_LENGTH};
use super::parts::{self, Building, Row, RowEnd, CURB_HEIGHT};
use super::truth::SurfaceKind;
use glam::{DVec2, DVec3};

/// Where the drive starts on road A (it passes the crossing half-way).
const DRIVE_START: f64 = -100.0;
/// Length of road A's arms, from the centre, metres.
const LONG_ARM: f64 = 230.0;

pub(crate) fn build(b: &mut Builder) -> Route {
    // Half widths: [road A (along x), road B (along y)].
    let h = [b.rng.range(5.2, 6.0), b.rng.range(5.2, 6.0)];
    // Arm lengths from the centre, by direction: +x, +y, -x, -y.
    let arm = [
        LONG_ARM,
        b.rng.range(48.0, 58.0),
        LONG_ARM,
        b.rng.range(90.0, 110.0),
    ];
    let (ha, hb) = (h[0], h[1]);
    let road = [
        (arm[0], -ha),
        (arm[0], ha),
        (hb, ha),
        (hb, arm[1]),
        (-hb, arm[1]),
        (-hb, ha),
        (-arm[2], ha),
        (-arm[2], -ha),
        (-hb, -ha),
        (-hb, -arm[3]),
        (hb, -arm[3]),
        (hb, -ha),
    ]
    .map(|(x, y)| DVec2::new(x, y));
    b.add_flat(SurfaceKind::Road, &road, 0.0);
    ramp(b, hb, arm[1]);
    let plaza = 2 + b.rng.below(2) as u32;
    for k in 0..4u32 {
        quadrant(b, k, h, arm, k == plaza);
    }
    Route {
        x0: DRIVE_START,
        length: DRIVE_LENGTH,
        lane_y: -b.rng.range(1.5, 2.0),
        amp: b.rng.range(0.1, 0.25),
        wavelength: b.rng.range(60.0, 100.0),
        phase: b.rng.range(0.0, std::f64::consts::TAU),
    }
}

/// The ramp continuing road B beyond `y0`, with its two side walls.
fn ramp(b: &mut Builder, half: f64, y0: f64) {
    let slope = b.rng.range(6.0f64, 10.0).to_radians();
    let len = b.rng.range(35.0, 45.0);
    let y1 = y0 + len * libm::cos(slope);
    let top = len * libm::sin(slope);
    let verts = vec![
        DVec3::new(-half, y0, 0.0),
        DVec3::new(half, y0, 0.0),
        DVec3::new(half, y1, top),
        DVec3::new(-half, y1, top),
    ];
    b.add(Some(SurfaceKind::Ramp), verts, DVec3::Z);
    for s in [-1.0, 1.0] {
        let x = s * half;
        let side = vec![
            DVec3::new(x, y0, 0.0),
            DVec3::new(x, y1, 0.0),
            DVec3::new(x, y1, top),
        ];
        b.add(Some(SurfaceKind::Wall), side, DVec3::X * s);
    }
}

/// Quadrant `k` (a quarter turn `k` from the `+x, +y` quadrant): curbs,
/// corner building or plaza, rows of buildings, sidewalk, cars, furniture.
///
/// Quadrant-local coordinates `(qx, qy)`: the local x-road (half width `hy`)
/// runs along `qx`, the local y-road (half width `hx`) along `qy`.
fn quadrant(b: &mut Builder, k: u32, h: [f64; 2], arm: [f64; 4], plaza: bool) {
    let z0 = CURB_HEIGHT;
    let q = Place::quarter(k, DVec2::ZERO);
    let (hx, hy) = (h[((k + 1) % 2) as usize], h[(k % 2) as usize]);
    let (lx, ly) = (arm[k as usize], arm[((k + 1) % 4) as usize]);
    // Row frames: along the x-road u = qx, v = qy - hy; along the y-road
    // u = -qy, v = qx - hx (a quarter turn clockwise, so v points away).
    let xr = q.after(&Place::quarter(0, DVec2::new(0.0, hy)));
    let yr = q.after(&Place::quarter(3, DVec2::new(hx, 0.0)));
    b.add_wall(
        Some(SurfaceKind::Curb),
        xr.xy(hx, 0.0),
        xr.xy(lx, 0.0),
        0.0,
        z0,
        xr.dir(0.0, -1.0),
    );
    b.add_wall(
        Some(SurfaceKind::Curb),
        yr.xy(-ly, 0.0),
        yr.xy(-hy, 0.0),
        0.0,
        z0,
        yr.dir(0.0, -1.0),
    );
    let swx = b.rng.range(3.5, 5.0);
    let swy = b.rng.range(3.5, 5.0);
    let mut outline = vec![q.xy(hx, hy), q.xy(lx, hy)];
    let to_x = |p: &DVec2| xr.xy(p.x, p.y);
    let to_y = |p: &DVec2| yr.xy(p.x, p.y);
    if plaza {
        let p = b.rng.range(18.0, 24.0);
        let bx = parts::row(
            b,
            &xr,
            &Row {
                u0: hx + p,
                u1: lx,
                sidewalk: swx,
                lead: RowEnd::MinBack(p),
                trail: RowEnd::Open,
            },
        );
        let by = parts::row(
            b,
            &yr,
            &Row {
                u0: -ly,
                u1: -(hy + p),
                sidewalk: swy,
                lead: RowEnd::Open,
                trail: RowEnd::MinBack(p),
            },
        );
        outline.extend(bx.iter().rev().map(to_x));
        outline.push(q.xy(hx + p, hy + p));
        outline.extend(by.iter().rev().map(to_y));
        free_wall(b, &q, DVec2::new(hx + p / 2.0 + 1.5, hy + p / 2.0 + 1.5));
    } else {
        let fx = swx + b.rng.range(0.0, 2.0);
        let fy = swy + b.rng.range(0.0, 2.0);
        let (cx, cy) = (hx + fy, hy + fx);
        let dx = b.rng.range(9.0, 13.0);
        let dy = b.rng.range(9.0, 13.0);
        let la = b.rng.range(14.0, 24.0).min(lx - cx - 15.0);
        let lb = b.rng.range(14.0, 24.0).min(ly - cy - 15.0);
        let top = z0 + b.rng.range(8.0, 22.0);
        // Facade along the x-road, in the x-row frame.
        let door = parts::random_door(b, cx, cx + la);
        let fa = Building {
            a: cx,
            b: cx + la,
            front: fx,
            depth: dx,
            z0,
            left_h: top,
            right_h: top,
            step_u: None,
            door,
        };
        let ba = parts::building(b, &xr, &fa, false);
        // Facade along the y-road, in the y-row frame.
        let door = parts::random_door(b, -(cy + lb), -cy);
        let fb = Building {
            a: -(cy + lb),
            b: -cy,
            front: fy,
            depth: dy,
            z0,
            left_h: top,
            right_h: top,
            step_u: None,
            door,
        };
        let bb = parts::building(b, &yr, &fb, false);
        // The two end walls of the L.
        b.add_wall(
            Some(SurfaceKind::Facade),
            xr.xy(cx + la, fx),
            xr.xy(cx + la, fx + dx),
            z0,
            top,
            xr.dir(1.0, 0.0),
        );
        b.add_wall(
            Some(SurfaceKind::Facade),
            yr.xy(-(cy + lb), fy),
            yr.xy(-(cy + lb), fy + dy),
            z0,
            top,
            yr.dir(-1.0, 0.0),
        );
        let bx = parts::row(
            b,
            &xr,
            &Row {
                u0: cx + la,
                u1: lx,
                sidewalk: swx,
                lead: RowEnd::Gap(fx + dx),
                trail: RowEnd::Open,
            },
        );
        let by = parts::row(
            b,
            &yr,
            &Row {
                u0: -ly,
                u1: -(cy + lb),
                sidewalk: swy,
                lead: RowEnd::Open,
                trail: RowEnd::Gap(fy + dy),
            },
        );
        outline.extend(bx.iter().rev().map(to_x));
        outline.extend(ba.iter().rev().map(to_x));
        outline.extend(bb.iter().rev().map(to_y));
        outline.extend(by.iter().rev().map(to_y));
    }
    outline.push(q.xy(hx, ly));
    b.add_flat(SurfaceKind::Sidewalk, &outline, z0);
    parts::park_cars(b, &xr, hx + 6.0, lx - 3.0);
    parts::park_cars(b, &yr, -ly + 3.0, -(hy + 6.0));
    parts::furniture(b, &xr, hx + 3.0, lx - 1.0);
    parts::furniture(b, &yr, -ly + 1.0, -(hy + 3.0));
    // A traffic-light pole at the corner.
    b.pole(q.at(hx + 0.6, hy + 0.6, z0), 0.12, 5.5);
}

/// A free-standing wall, 0.3 m thick, at 20° to 35° to the quadrant's x
/// axis, centred at `centre` (quadrant-local): its two long faces are ground
/// truth, its end faces are not.
fn free_wall(b: &mut Builder, q: &Place, centre: DVec2) {
    let angle = b.rng.range(20.0f64, 35.0).to_radians();
    let half = b.rng.range(4.0, 5.0);
    let t = 0.15;
    let top = CURB_HEIGHT + b.rng.range(2.2, 3.0);
    let w = q.after(&Place::rotation(angle, centre));
    let c = [(-half, -t), (half, -t), (half, t), (-half, t)].map(|(u, v)| w.xy(u, v));
    let z0 = CURB_HEIGHT;
    b.add_wall(
        Some(SurfaceKind::Wall),
        c[0],
        c[1],
        z0,
        top,
        w.dir(0.0, -1.0),
    );
    b.add_wall(None, c[1], c[2], z0, top, w.dir(1.0, 0.0));
    b.add_wall(
        Some(SurfaceKind::Wall),
        c[2],
        c[3],
        z0,
        top,
        w.dir(0.0, 1.0),
    );
    b.add_wall(None, c[3], c[0], z0, top, w.dir(-1.0, 0.0));
}
