//! Observed area of the ground-truth surfaces and how much of it the
//! predictions cover: completeness and the per-surface part of recall.

use super::index::{for_each_tile, Aabb, PolyIndex, TILE};
use super::metrics::{ratio, Completeness, SurfaceReport};
use super::options::{normals_match, EvalOptions};
use super::GtSurface;
use crate::geometry::Polygon3;
use glam::{DVec2, DVec3};

/// Per-surface reports, in the order of `gt`.
pub(crate) fn measure(
    gt: &[GtSurface],
    pred: &[Polygon3],
    points: &[DVec3],
    labels: &[u32],
    opts: &EvalOptions,
) -> Vec<SurfaceReport> {
    let index = PolyIndex::new(pred.iter().collect());
    let per_surface = bin_points(gt, points, labels, opts.cell_size);
    gt.iter()
        .zip(per_surface)
        .map(|(surface, entries)| {
            let n = entries.len();
            let cells = observed_cells(entries);
            cover_surface(surface, n, cells, pred, &index, opts)
        })
        .collect()
}

/// Completeness of all surfaces together (area-weighted).
pub(crate) fn completeness(surfaces: &[SurfaceReport]) -> Completeness {
    let observed_area: f64 = surfaces.iter().map(|s| s.observed_area).sum();
    let covered_area: f64 = surfaces.iter().map(|s| s.covered_area).sum();
    Completeness {
        observed_area,
        covered_area,
        completeness: ratio(covered_area, observed_area),
    }
}

/// A labelled point in its surface's frame, with its raster cell.
type Entry = ((i64, i64), DVec2);

/// For each surface, its labelled points in its frame with their cells.
/// Labels that name no surface (clutter, `u32::MAX`) are skipped.
fn bin_points(gt: &[GtSurface], points: &[DVec3], labels: &[u32], cell: f64) -> Vec<Vec<Entry>> {
    let mut slots: Vec<(u32, usize)> = gt.iter().enumerate().map(|(i, g)| (g.id, i)).collect();
    slots.sort_unstable();
    let mut out = vec![Vec::new(); gt.len()];
    for (&p, &label) in points.iter().zip(labels) {
        let Ok(k) = slots.binary_search_by_key(&label, |s| s.0) else {
            continue;
        };
        let slot = slots[k].1;
        let q = gt[slot].polygon.frame.to_local(p);
        let key = (
            libm::floor(q.x / cell) as i64,
            libm::floor(q.y / cell) as i64,
        );
        out[slot].push((key, q));
    }
    out
}

/// One representative point per occupied cell: the mean of its points
/// (projected on the plane), in cell order.
fn observed_cells(mut entries: Vec<Entry>) -> Vec<DVec2> {
    entries.sort_by_key(|e| e.0);
    let mut cells = Vec::new();
    let mut start = 0;
    while start < entries.len() {
        let key = entries[start].0;
        let run = entries[start..].iter().take_while(|e| e.0 == key).count();
        let sum: DVec2 = entries[start..start + run].iter().map(|e| e.1).sum();
        cells.push(sum / run as f64);
        start += run;
    }
    cells
}

/// Coverage of one surface's observed cells by the predictions.
fn cover_surface(
    surface: &GtSurface,
    points: usize,
    mut cells: Vec<DVec2>,
    pred: &[Polygon3],
    index: &PolyIndex,
    opts: &EvalOptions,
) -> SurfaceReport {
    let frame = &surface.polygon.frame;
    let cos_max = opts.cos_max_angle();
    let matching: Vec<bool> = pred
        .iter()
        .map(|p| normals_match(p.frame.normal, frame.normal, cos_max))
        .collect();
    let (tol_c, tol_f) = (opts.completeness_tolerance, opts.found_tolerance);
    let radius = tol_c.max(tol_f);
    let (mut covered, mut matched) = (0usize, 0usize);
    let mut matched_by = vec![false; pred.len()];
    let (mut world, mut cands) = (Vec::new(), Vec::new());
    for_each_tile(&mut cells, TILE, |tile| {
        world.clear();
        world.extend(tile.iter().map(|&q| frame.to_world(q)));
        index.within_candidates(&Aabb::of(&world), radius, |_| true, &mut cands);
        for &c in &world {
            let (mut is_covered, mut is_matched) = (false, false);
            for &i in &cands {
                let Some(d) = index.distance_within(i, c, radius) else {
                    continue;
                };
                is_covered |= d <= tol_c;
                if matching[i] && d <= tol_f {
                    is_matched = true;
                    matched_by[i] = true;
                }
            }
            covered += usize::from(is_covered);
            matched += usize::from(is_matched);
        }
    });
    let cell_area = opts.cell_size * opts.cell_size;
    let observed_area = cells.len() as f64 * cell_area;
    let matched_coverage = ratio(matched as f64, cells.len() as f64);
    let eligible = observed_area > 0.0 && observed_area >= opts.min_observed_area;
    SurfaceReport {
        id: surface.id,
        points,
        observed_area,
        covered_area: covered as f64 * cell_area,
        completeness: ratio(covered as f64, cells.len() as f64),
        matched_area: matched as f64 * cell_area,
        matched_coverage,
        eligible,
        found: eligible && matched_coverage >= opts.found_coverage,
        matching_predictions: (0..pred.len()).filter(|&i| matched_by[i]).collect(),
    }
}
