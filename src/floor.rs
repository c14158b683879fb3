//! The local floor of a cloud: for detection without a viewpoint, ground is
//! what lies at the bottom of the cloud where it is, not a fixed depth below
//! one sensor position. A road, the sidewalks one curb higher, a ramp and a
//! raised plateau are all ground; a car's roof or bonnet, a table or a low
//! wall's top stand above the floor around them and are not.

use crate::geometry::Plane;
use crate::hash::GridMap;
use glam::{DVec3, Vec3};

/// Side of a floor cell (m): large enough to hold ground points beside
/// most objects (a car is 1.8 m wide), small enough that a 6 degree ramp
/// rises less than [`GROUND_RISE`] across one.
const CELL: f64 = 4.0;
/// Highest a ground point may stand above its cell's floor (m): a curb and
/// a sidewalk (0.15-0.2 m), plus the rise of a ramp or hill across a cell.
pub(crate) const GROUND_RISE: f64 = 0.5;
/// The floor of a cell is its points' height of this rank from the bottom
/// (0: the lowest), or of the rank of the lowest 2 % in a cell of fewer than
/// 400 points: the lowest points, less the odd point below the ground (a
/// reflection, noise).
const RANK: usize = 7;

/// The [`RANK`]` + 1` lowest heights of a cell, ascending, and its count.
#[derive(Clone, Copy)]
struct Lowest {
    n: u32,
    z: [f32; RANK + 1],
}

impl Lowest {
    fn push(&mut self, z: f32) {
        let kept = (self.n as usize).min(RANK + 1);
        self.n += 1;
        if kept == RANK + 1 && z >= self.z[RANK] {
            return;
        }
        // Insert in order, dropping the highest when full.
        let mut i = kept.min(RANK);
        while i > 0 && self.z[i - 1] > z {
            self.z[i] = self.z[i - 1];
            i -= 1;
        }
        self.z[i] = z;
    }

    fn floor(&self) -> f64 {
        let rank = (self.n as usize / 50).min(RANK);
        self.z[rank] as f64
    }
}

/// Floor height per [`CELL`] x [`CELL`] column of the cloud (local
/// coordinates, z up).
pub(crate) struct FloorGrid {
    /// Each cell's lowest heights, its floor read from them on lookup (one
    /// map type instead of two: 0.46 kB less wasm, gzipped).
    lowest: GridMap<(i64, i64), Lowest>,
}

fn key(x: f64, y: f64) -> (i64, i64) {
    (
        crate::geometry::floor_i64(x / CELL),
        crate::geometry::floor_i64(y / CELL),
    )
}

impl FloorGrid {
    /// The floor of `pts` (non-finite points are skipped).
    pub(crate) fn new(pts: &[Vec3]) -> Self {
        let mut lowest: GridMap<(i64, i64), Lowest> = GridMap::default();
        for p in pts {
            if p.is_finite() {
                lowest
                    .entry(key(p.x as f64, p.y as f64))
                    .or_insert(Lowest {
                        n: 0,
                        z: [f32::INFINITY; RANK + 1],
                    })
                    .push(p.z);
            }
        }
        FloorGrid { lowest }
    }

    /// The floor under `(x, y)`, if its cell holds points.
    pub(crate) fn at(&self, x: f64, y: f64) -> Option<f64> {
        self.lowest.get(&key(x, y)).map(Lowest::floor)
    }

    /// Does `p` stand on the floor (at most [`GROUND_RISE`] above it)?
    pub(crate) fn on_floor(&self, p: DVec3) -> bool {
        self.at(p.x, p.y).is_some_and(|f| p.z - f <= GROUND_RISE)
    }
}

/// Could a sensor have stood at `p` (the points' coordinates): points
/// within 10 m of it horizontally, and `p` between 0.3 m and 5 m above
/// their floor (a LiDAR on a robot, a car's roof or a tripod)? A cloud in
/// its sensor's own frame has its sensor at the origin; a world-frame map's
/// origin is usually elsewhere, or on the ground. One pass over the points,
/// without the floor grid.
pub(crate) fn sensor_could_stand_at(pts: &[Vec3], p: DVec3) -> bool {
    const RADIUS: f64 = 10.0;
    let mut lowest = Lowest {
        n: 0,
        z: [f32::INFINITY; RANK + 1],
    };
    for q in pts {
        let (dx, dy) = (q.x as f64 - p.x, q.y as f64 - p.y);
        if dx * dx + dy * dy <= RADIUS * RADIUS && q.z.is_finite() {
            lowest.push(q.z);
        }
    }
    lowest.n > 0 && (0.3..=5.0).contains(&(p.z - lowest.floor()))
}

/// How a plane is told to be ground (ground planes get their own inlier
/// distance, clustering tolerance and outline radius).
#[derive(Clone, Copy)]
pub(crate) enum GroundRule<'g> {
    /// Near-horizontal and `groundDepth` below the viewpoint's height.
    BelowViewpoint,
    /// Near-horizontal and on the cloud's local floor.
    LocalFloor(&'g FloorGrid),
}

impl GroundRule<'_> {
    /// Is `plane` ground: near-horizontal, and below the viewpoint by
    /// `depth` or, with a floor, on it as `on_floor` judges?
    fn is_ground(
        &self,
        plane: &Plane,
        viewpoint: DVec3,
        (min_cos, depth): (f64, f64),
        on_floor: impl FnOnce(&FloorGrid) -> bool,
    ) -> bool {
        match self {
            GroundRule::BelowViewpoint => plane.is_ground_below(viewpoint, min_cos, depth),
            GroundRule::LocalFloor(grid) => plane.normal.z.abs() >= min_cos && on_floor(grid),
        }
    }

    /// Is `plane` ground? On a floor, judged where it passes over `at` (a
    /// hypothesis, drawn near `at`); below the viewpoint, under the
    /// viewpoint itself. The flag picks a hypothesis's inlier distance and
    /// clustering tolerance; judged under `at` below a viewpoint too, the
    /// bench's crossing drives lost a plateau (BENCHMARKS.md). `viewpoint`
    /// and `at` in the plane's coordinates, which are the floor's.
    pub(crate) fn at_point(
        &self,
        plane: &Plane,
        viewpoint: DVec3,
        at: DVec3,
        min_cos: f64,
        depth: f64,
    ) -> bool {
        self.is_ground(plane, viewpoint, (min_cos, depth), |grid| {
            let n = plane.normal;
            let z = -(n.x * at.x + n.y * at.y + plane.offset) / n.z;
            grid.on_floor(DVec3::new(at.x, at.y, z))
        })
    }

    /// Is `plane` (world coordinates) ground, judged on its support `pts`
    /// (local coordinates, the floor's): most of them on the floor? Below
    /// the viewpoint, the depth is taken where the support lies (`centre`,
    /// world), under the viewpoint's height: a plane fitted a few degrees
    /// off level (a car's roof from a few laser rings) passes metres below
    /// a sensor 20 m away.
    pub(crate) fn of_support(
        &self,
        plane: &Plane,
        viewpoint: DVec3,
        centre: DVec3,
        pts: &[Vec3],
        min_cos: f64,
        depth: f64,
    ) -> bool {
        let above = DVec3::new(centre.x, centre.y, viewpoint.z);
        self.is_ground(plane, above, (min_cos, depth), |grid| {
            2 * pts.iter().filter(|p| grid.on_floor(p.as_dvec3())).count() >= pts.len()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A road at z = 0 over 40 m x 40 m, a sidewalk at 0.15 m beside it, a
    /// car roof at 1.5 m with its side down to 0.3 m.
    fn scene() -> Vec<Vec3> {
        let mut pts = Vec::new();
        for i in 0..200 {
            for j in 0..200 {
                let (x, y) = (i as f32 * 0.2, j as f32 * 0.2);
                let z = if y > 30.0 { 0.15 } else { 0.0 };
                pts.push(Vec3::new(x, y, z));
            }
        }
        for i in 0..20 {
            for j in 0..9 {
                pts.push(Vec3::new(10.0 + i as f32 * 0.2, 10.0 + j as f32 * 0.2, 1.5));
            }
            for k in 0..6 {
                pts.push(Vec3::new(10.0 + i as f32 * 0.2, 10.0, 0.3 + k as f32 * 0.2));
            }
        }
        pts
    }

    #[test]
    fn road_and_sidewalk_are_on_the_floor_a_roof_is_not() {
        let g = FloorGrid::new(&scene());
        assert!(g.on_floor(DVec3::new(5.0, 5.0, 0.0)));
        assert!(g.on_floor(DVec3::new(5.0, 35.0, 0.15)));
        assert!(!g.on_floor(DVec3::new(11.0, 11.0, 1.5)));
        assert!(!g.on_floor(DVec3::new(500.0, 5.0, 0.0)), "no floor there");
    }

    #[test]
    fn the_floor_ignores_a_few_points_below_the_ground() {
        let mut pts = scene();
        for i in 0..5 {
            pts.push(Vec3::new(1.0 + i as f32 * 0.1, 1.0, -3.0));
        }
        let g = FloorGrid::new(&pts);
        assert_eq!(g.at(1.0, 1.0), Some(0.0));
        let mut l = Lowest {
            n: 0,
            z: [f32::INFINITY; RANK + 1],
        };
        for z in [5.0, 3.0, 4.0, 1.0, 2.0] {
            l.push(z);
        }
        assert_eq!(l.floor(), 1.0, "under 50 points: the lowest");
        for k in 0..500 {
            l.push(10.0 + k as f32);
        }
        assert_eq!(
            l.floor(),
            10.0 + 2.0,
            "the 8th lowest: 1..5, then 10, 11, 12"
        );
    }

    #[test]
    fn a_sensor_stands_above_the_floor_not_on_it() {
        let pts = scene();
        assert!(sensor_could_stand_at(&pts, DVec3::new(20.0, 20.0, 1.8)));
        assert!(!sensor_could_stand_at(&pts, DVec3::new(20.0, 20.0, 0.0)));
        assert!(!sensor_could_stand_at(&pts, DVec3::new(20.0, 20.0, 30.0)));
        assert!(!sensor_could_stand_at(&pts, DVec3::new(-500.0, 0.0, 1.8)));
    }
}
