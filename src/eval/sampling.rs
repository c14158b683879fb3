//! Dense samples of a polygon: a grid of cell centres inside it (each stands
//! for `spacing^2` of area) and points along its outline.

use super::options::EvalOptions;
use crate::geometry::polygon::signed_area;
use crate::geometry::Polygon3;
use glam::DVec2;

/// Polygons with fewer grid cells than this get a finer grid (down to a tenth
/// of the spacing), so that small polygons still get area samples.
const MIN_SAMPLES: f64 = 16.0;

/// Samples of one polygon, in its frame's 2D coordinates.
#[derive(Clone, Debug, Default)]
pub(crate) struct PolygonSamples {
    /// Grid spacing (m): each area sample stands for `spacing^2` of area.
    pub spacing: f64,
    /// Cell centres inside the outline (even-odd rule).
    pub area: Vec<DVec2>,
    /// Points along the outline, every vertex included.
    pub boundary: Vec<DVec2>,
}

impl PolygonSamples {
    /// Area (m^2) one area sample stands for.
    pub fn weight(&self) -> f64 {
        self.spacing * self.spacing
    }
}

/// Grid and outline samples of `poly` at the options' spacing, adapted to
/// its size (see [`EvalOptions::max_samples_per_polygon`]).
pub(crate) fn sample_polygon(poly: &Polygon3, opts: &EvalOptions) -> PolygonSamples {
    let max = opts.max_samples_per_polygon;
    let mut spacing = area_spacing(
        signed_area(&poly.ring).abs(),
        opts.sample_spacing,
        max as f64,
    );
    let mut area = Vec::new();
    // A self-intersecting ring can hold more cells than its signed area says:
    // coarsen until the grid fits in twice the cap.
    for _ in 0..64 {
        if grid_samples(&poly.ring, spacing, max.saturating_mul(2), &mut area) {
            break;
        }
        area.clear();
        spacing *= 2.0;
    }
    let perimeter = ring_perimeter(&poly.ring);
    let step = opts.sample_spacing.max(perimeter / max as f64);
    PolygonSamples {
        spacing,
        area,
        boundary: boundary_samples(&poly.ring, step),
    }
}

/// Grid spacing for a polygon of `area`: `spacing`, coarsened so that the grid
/// has at most `max` cells, refined (to at most ten times finer) so that it
/// has at least [`MIN_SAMPLES`].
fn area_spacing(area: f64, spacing: f64, max: f64) -> f64 {
    let cells = area / (spacing * spacing);
    if cells > max {
        libm::sqrt(area / max)
    } else if area > 0.0 && cells < MIN_SAMPLES {
        libm::sqrt(area / MIN_SAMPLES).max(0.1 * spacing)
    } else {
        spacing
    }
}

/// Append the centres `((i + 1/2) s, (j + 1/2) s)` that lie inside `ring`
/// (even-odd rule, by scanlines) to `out`. Returns `false`, with `out`
/// partially filled, when more than `limit` points or rows would be needed.
pub(crate) fn grid_samples(ring: &[DVec2], s: f64, limit: usize, out: &mut Vec<DVec2>) -> bool {
    if ring.len() < 3 {
        return true;
    }
    let (lo, hi) = ring
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let first = libm::ceil(lo.y / s - 0.5);
    let last = libm::floor(hi.y / s - 0.5);
    if last - first >= limit as f64 {
        return false;
    }
    let rows = if last >= first {
        (last - first) as usize + 1
    } else {
        0
    };
    let mut crossings = Vec::new();
    for row in 0..rows {
        let y = (first + row as f64 + 0.5) * s;
        row_crossings(ring, y, &mut crossings);
        for pair in crossings.chunks_exact(2) {
            let i0 = libm::ceil(pair[0] / s - 0.5);
            let i1 = libm::ceil(pair[1] / s - 0.5) - 1.0;
            if i1 < i0 {
                continue;
            }
            if out.len() as f64 + (i1 - i0 + 1.0) > limit as f64 {
                return false;
            }
            let count = (i1 - i0 + 1.0) as usize;
            out.extend((0..count).map(|k| DVec2::new((i0 + k as f64 + 0.5) * s, y)));
        }
    }
    true
}

/// Sorted x of the crossings of the horizontal line at `y` with the ring's
/// edges (half-open rule, as in [`crate::geometry::polygon::contains`]).
fn row_crossings(ring: &[DVec2], y: f64, out: &mut Vec<f64>) {
    out.clear();
    let n = ring.len();
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        if (a.y > y) != (b.y > y) {
            out.push(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
        }
    }
    out.sort_by(f64::total_cmp);
}

fn ring_perimeter(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    (0..n).map(|i| (ring[(i + 1) % n] - ring[i]).length()).sum()
}

/// Points along the closed ring at most `step` apart, every vertex included.
fn boundary_samples(ring: &[DVec2], step: f64) -> Vec<DVec2> {
    let n = ring.len();
    let mut out = Vec::new();
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let m = libm::ceil((b - a).length() / step).max(1.0) as usize;
        out.extend((0..m).map(|k| a + (b - a) * (k as f64 / m as f64)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(w: f64, h: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(w, 0.0),
            DVec2::new(w, h),
            DVec2::new(0.0, h),
        ]
    }

    #[test]
    fn grid_counts_match_area() {
        let mut out = Vec::new();
        assert!(grid_samples(&rect(2.0, 1.0), 0.1, 1000, &mut out));
        assert_eq!(out.len(), 200);
        // A triangle: about half of the square's cells.
        let tri = vec![DVec2::ZERO, DVec2::new(10.0, 0.0), DVec2::new(0.0, 10.0)];
        out.clear();
        assert!(grid_samples(&tri, 0.1, 100_000, &mut out));
        assert!(
            (out.len() as f64 * 0.01 - 50.0).abs() < 0.6,
            "{}",
            out.len()
        );
        assert!(!grid_samples(
            &rect(100.0, 100.0),
            0.1,
            1000,
            &mut Vec::new()
        ));
    }

    #[test]
    fn spacing_adapts_to_size() {
        assert_eq!(area_spacing(100.0, 0.1, 200_000.0), 0.1);
        let s = area_spacing(1.0e4, 0.1, 200_000.0);
        assert!((1.0e4 / (s * s) - 200_000.0).abs() < 1e-6);
        assert!((area_spacing(1e-6, 0.1, 200_000.0) - 0.01).abs() < 1e-15);
        assert_eq!(area_spacing(0.0, 0.1, 200_000.0), 0.1);
    }

    #[test]
    fn boundary_includes_vertices() {
        let b = boundary_samples(&rect(1.0, 0.5), 0.1);
        assert_eq!(b.len(), 30);
        assert!(b.contains(&DVec2::new(1.0, 0.5)));
    }
}
