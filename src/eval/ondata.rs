//! How much of the polygons' area lies near a point of the cloud they were
//! made from: [`on_data`](super::on_data). Needs no ground truth, so it
//! applies to real scans.

use super::options::EvalOptions;
use super::sampling::sample_polygon;
use super::{check_polygon, metrics::ratio};
use crate::geometry::Polygon3;
use glam::DVec3;
use serde::Serialize;

/// Grid spacing (m) of the area samples of [`on_data`](super::on_data).
pub const ON_DATA_SPACING: f64 = 0.05;

/// Most area samples per polygon in [`on_data`](super::on_data): a larger
/// polygon gets a coarser grid (spacing `sqrt(area / ON_DATA_MAX_SAMPLES)`).
pub const ON_DATA_MAX_SAMPLES: usize = 200_000;

/// Share of the polygons' area that has a cloud point within `radius`, as
/// [`on_data`](super::on_data) returns it. Lengths in metres, areas in
/// square metres. Serialises to JSON with `serde_json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OnData {
    /// The distance (m) a point must be within, as given.
    pub radius: f64,
    /// Number of finite cloud points used.
    pub points: usize,
    /// Total outline area (m^2) of the polygons.
    pub area: f64,
    /// The part (m^2) of `area` near a point: the sum of each polygon's
    /// `area * share`.
    pub near_area: f64,
    /// `near_area / area`; 1 when the polygons have no area (nothing lies
    /// off the data), 0 when they have area but there is no point.
    pub share: f64,
    /// One entry per polygon, in input order.
    pub polygons: Vec<PolygonOnData>,
}

/// What [`on_data`](super::on_data) found for one polygon.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PolygonOnData {
    /// Index in the polygon slice.
    pub index: usize,
    /// Outline area (m^2); 0 for an invalid polygon.
    pub area: f64,
    /// Grid spacing (m) of its area samples.
    pub spacing: f64,
    /// Number of samples its share is over: area samples, or outline samples
    /// when the polygon is too small for a grid sample.
    pub samples: usize,
    /// Share of its samples with a point within the radius.
    pub share: f64,
}

/// See [`on_data`](super::on_data).
pub(crate) fn measure(polygons: &[Polygon3], points: &[DVec3], radius: f64) -> OnData {
    let radius_used = if radius >= 0.0 { radius } else { 0.0 };
    let grid = PointGrid::new(points, radius_used);
    let opts = EvalOptions {
        sample_spacing: ON_DATA_SPACING,
        max_samples_per_polygon: ON_DATA_MAX_SAMPLES,
        ..EvalOptions::default()
    };
    let reports: Vec<PolygonOnData> = polygons
        .iter()
        .enumerate()
        .map(|(index, poly)| {
            if check_polygon(poly).is_err() {
                return PolygonOnData {
                    index,
                    area: 0.0,
                    spacing: ON_DATA_SPACING,
                    samples: 0,
                    share: 0.0,
                };
            }
            let samples = sample_polygon(poly, &opts);
            let used = if samples.area.is_empty() {
                &samples.boundary
            } else {
                &samples.area
            };
            let near = used
                .iter()
                .filter(|&&q| grid.any_within(poly.frame.to_world(q)))
                .count();
            PolygonOnData {
                index,
                area: poly.area(),
                spacing: samples.spacing,
                samples: used.len(),
                share: ratio(near as f64, used.len() as f64),
            }
        })
        .collect();
    let area: f64 = reports.iter().map(|r| r.area).sum();
    let near_area: f64 = reports.iter().map(|r| r.area * r.share).sum();
    OnData {
        radius,
        points: grid.points.len(),
        area,
        near_area,
        share: if area > 0.0 { near_area / area } else { 1.0 },
        polygons: reports,
    }
}

/// A cell of the point grid: integer coordinates `floor(p / cell)`.
type Key = (i64, i64, i64);

/// Finite points sorted by cubic cell of side at least the radius, so the
/// points within the radius of a query lie in its cell's 27 neighbours.
/// Sorted, not hashed: deterministic and without allocation per query.
struct PointGrid {
    cell: f64,
    radius_sq: f64,
    /// Any point at all counts (infinite radius).
    unbounded: bool,
    points: Vec<(Key, DVec3)>,
}

impl PointGrid {
    fn new(points: &[DVec3], radius: f64) -> Self {
        // Smallest cell side, so that keys stay small for a tiny radius.
        let cell = if radius.is_finite() {
            radius.max(1e-6)
        } else {
            1.0
        };
        let mut grid = PointGrid {
            cell,
            radius_sq: radius * radius,
            unbounded: radius.is_infinite(),
            points: Vec::new(),
        };
        grid.points = points
            .iter()
            .filter(|p| p.is_finite())
            .map(|&p| (grid.key(p), p))
            .collect();
        grid.points.sort_by_key(|e| e.0);
        grid
    }

    fn key(&self, p: DVec3) -> Key {
        let c = |x: f64| libm::floor(x / self.cell) as i64;
        (c(p.x), c(p.y), c(p.z))
    }

    /// Is a point within the radius of `q` (3D distance, inclusive)?
    fn any_within(&self, q: DVec3) -> bool {
        if self.unbounded || self.points.is_empty() {
            return self.unbounded && !self.points.is_empty();
        }
        let (x, y, z) = self.key(q);
        for dx in -1..=1 {
            for dy in -1..=1 {
                let (cx, cy) = (x.saturating_add(dx), y.saturating_add(dy));
                let lo = (cx, cy, z.saturating_sub(1));
                let hi = (cx, cy, z.saturating_add(1));
                let start = self.points.partition_point(|e| e.0 < lo);
                let hit = self.points[start..]
                    .iter()
                    .take_while(|e| e.0 <= hi)
                    .any(|e| e.1.distance_squared(q) <= self.radius_sq);
                if hit {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::on_data;
    use crate::rng::Rng;

    /// The rectangle `[0, w] x [0, h]` at height `z`.
    fn rect(w: f64, h: f64, z: f64) -> Polygon3 {
        Polygon3::from_world(&[
            DVec3::new(0.0, 0.0, z),
            DVec3::new(w, 0.0, z),
            DVec3::new(w, h, z),
            DVec3::new(0.0, h, z),
        ])
        .unwrap()
    }

    /// Points at the centres of a `step` grid on `[x0, x1] x [y0, y1]` at
    /// height `z`.
    fn grid(x: (f64, f64), y: (f64, f64), z: f64, step: f64) -> Vec<DVec3> {
        let nx = ((x.1 - x.0) / step).round() as usize;
        let ny = ((y.1 - y.0) / step).round() as usize;
        let mut out = Vec::with_capacity(nx * ny);
        for i in 0..nx {
            for j in 0..ny {
                out.push(DVec3::new(
                    x.0 + (i as f64 + 0.5) * step,
                    y.0 + (j as f64 + 0.5) * step,
                    z,
                ));
            }
        }
        out
    }

    #[test]
    fn on_data_half_covered_square() {
        // Points on the half x <= 5 of a 10 x 10 m square: the area near a
        // point is that half plus a band of about the radius beyond it.
        let points = grid((0.0, 5.0), (0.0, 10.0), 0.0, 0.05);
        let r = on_data(&[rect(10.0, 10.0, 0.0)], &points, 0.2);
        let expected = (5.0 - 0.025 + 0.2) / 10.0;
        assert!((r.share - expected).abs() < 0.005, "{}", r.share);
        assert!((r.area - 100.0).abs() < 1e-9);
        assert!((r.near_area - r.share * 100.0).abs() < 1e-9);
        assert_eq!(r.points, points.len());
        assert_eq!(r.polygons.len(), 1);
        assert_eq!(r.polygons[0].share, r.share);
        assert_eq!(r.polygons[0].spacing, ON_DATA_SPACING);
        assert_eq!(r.polygons[0].samples, 40_000);
    }

    #[test]
    fn on_data_fully_covered_square() {
        let points = grid((0.0, 4.0), (0.0, 3.0), 0.05, 0.1);
        let r = on_data(&[rect(4.0, 3.0, 0.0)], &points, 0.2);
        assert_eq!(r.share, 1.0);
        assert!((r.near_area - 12.0).abs() < 1e-9);
    }

    #[test]
    fn on_data_distance_is_3d() {
        // Points 0.5 m above the plane, right over the polygon.
        let points = grid((0.0, 4.0), (0.0, 3.0), 0.5, 0.1);
        let poly = [rect(4.0, 3.0, 0.0)];
        assert_eq!(on_data(&poly, &points, 0.2).share, 0.0);
        assert_eq!(on_data(&poly, &points, 0.49).share, 0.0);
        assert_eq!(on_data(&poly, &points, 0.51).share, 1.0);
    }

    #[test]
    fn on_data_names_the_overhanging_polygon() {
        // A 2 x 2 m square on the data and a 6 x 1 m strip off it.
        let strip = Polygon3::from_world(&[
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(16.0, 0.0, 0.0),
            DVec3::new(16.0, 1.0, 0.0),
            DVec3::new(10.0, 1.0, 0.0),
        ])
        .unwrap();
        let points = grid((0.0, 2.0), (0.0, 2.0), 0.0, 0.1);
        let r = on_data(&[rect(2.0, 2.0, 0.0), strip], &points, 0.2);
        assert_eq!(r.polygons[0].share, 1.0);
        assert_eq!(r.polygons[1].share, 0.0);
        assert_eq!(r.polygons[1].index, 1);
        assert!((r.polygons[1].area - 6.0).abs() < 1e-9);
        assert!((r.share - 0.4).abs() < 1e-12);
    }

    #[test]
    fn on_data_is_total() {
        let square = rect(1.0, 1.0, 0.0);
        let on = [DVec3::new(0.5, 0.5, 0.0)];
        // No polygons: nothing lies off the data.
        let r = on_data(&[], &on, 0.2);
        assert_eq!((r.share, r.area, r.polygons.len()), (1.0, 0.0, 0));
        // Polygons but no points (non-finite points are dropped).
        let r = on_data(std::slice::from_ref(&square), &[], 0.2);
        assert_eq!((r.share, r.points), (0.0, 0));
        let r = on_data(std::slice::from_ref(&square), &[DVec3::NAN], 0.2);
        assert_eq!((r.share, r.points), (0.0, 0));
        // Negative or NaN radius: 0; infinite: any point.
        for radius in [-1.0, f64::NAN, 0.0] {
            let r = on_data(std::slice::from_ref(&square), &on, radius);
            assert!(r.share < 0.01, "{radius}: {}", r.share);
        }
        let far = [DVec3::new(1e6, 0.0, 0.0)];
        let r = on_data(std::slice::from_ref(&square), &far, f64::INFINITY);
        assert_eq!(r.share, 1.0);
        // An invalid polygon counts with no area.
        let mut bad = square.clone();
        bad.frame.normal = DVec3::NAN;
        let r = on_data(&[bad, square.clone()], &on, 2.0);
        assert_eq!((r.polygons[0].area, r.polygons[0].share), (0.0, 0.0));
        assert_eq!(r.share, 1.0);
        // Too small for a grid sample: its outline samples count.
        let tiny = rect(0.002, 0.002, 0.0);
        let r = on_data(&[tiny], &[DVec3::new(0.1, 0.0, 0.0)], 0.2);
        assert!(r.polygons[0].samples > 0);
        assert_eq!(r.share, 1.0);
    }

    #[test]
    fn on_data_grid_matches_brute_force() {
        let mut rng = Rng::new(3);
        let mut pt = |s: f64| DVec3::new(rng.range(-s, s), rng.range(-s, s), rng.range(-s, s));
        let points: Vec<DVec3> = (0..400).map(|_| pt(2.0)).collect();
        let queries: Vec<DVec3> = (0..2000).map(|_| pt(2.5)).collect();
        for radius in [0.0, 0.05, 0.2, 0.37, 1.0, 10.0] {
            let grid = PointGrid::new(&points, radius);
            for &q in &queries {
                let brute = points
                    .iter()
                    .any(|p| p.distance_squared(q) <= radius * radius);
                assert_eq!(grid.any_within(q), brute, "radius {radius} at {q}");
            }
        }
    }
}
