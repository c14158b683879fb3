//! The `street` layout: a straight road along +x with a sidewalk, a curb and
//! a row of buildings on each side, parked cars, poles and trees.

use super::builder::{Builder, Place, Route, DRIVE_LENGTH};
use super::parts::{self, Row, RowEnd, CURB_HEIGHT};
use super::truth::SurfaceKind;
use glam::DVec2;

/// Road beyond each end of the drive, metres (more than the sensor's range).
const MARGIN: f64 = 125.0;

pub(crate) fn build(b: &mut Builder) -> Route {
    let half = b.rng.range(5.2, 6.0);
    let (x0, x1) = (-MARGIN, DRIVE_LENGTH + MARGIN);
    let road = [
        DVec2::new(x0, -half),
        DVec2::new(x1, -half),
        DVec2::new(x1, half),
        DVec2::new(x0, half),
    ];
    b.add_flat(SurfaceKind::Road, &road, 0.0);
    // Left side: u = x, v = y - half. Right side: u = -x, v = -y - half.
    let sides = [
        (Place::quarter(0, DVec2::new(0.0, half)), x0, x1),
        (Place::quarter(2, DVec2::new(0.0, -half)), -x1, -x0),
    ];
    for (pl, u0, u1) in sides {
        side(b, &pl, u0, u1);
    }
    Route {
        x0: 0.0,
        length: DRIVE_LENGTH,
        lane_y: -b.rng.range(1.5, 2.0),
        amp: b.rng.range(0.15, 0.35),
        wavelength: b.rng.range(50.0, 90.0),
        phase: b.rng.range(0.0, std::f64::consts::TAU),
    }
}

/// Curb, buildings, sidewalk, parked cars and street furniture of one side.
fn side(b: &mut Builder, pl: &Place, u0: f64, u1: f64) {
    b.add_wall(
        Some(SurfaceKind::Curb),
        pl.xy(u0, 0.0),
        pl.xy(u1, 0.0),
        0.0,
        CURB_HEIGHT,
        pl.dir(0.0, -1.0),
    );
    let sidewalk = b.rng.range(3.5, 5.0);
    let boundary = parts::row(
        b,
        pl,
        &Row {
            u0,
            u1,
            sidewalk,
            lead: RowEnd::Open,
            trail: RowEnd::Open,
        },
    );
    let mut ring = vec![pl.xy(u0, 0.0), pl.xy(u1, 0.0)];
    ring.extend(boundary.iter().rev().map(|p| pl.xy(p.x, p.y)));
    b.add_flat(SurfaceKind::Sidewalk, &ring, CURB_HEIGHT);
    parts::park_cars(b, pl, u0 + 3.0, u1 - 3.0);
    parts::furniture(b, pl, u0 + 1.0, u1 - 1.0);
}
