//! Accuracy (one-sided Hausdorff distance) and the per-prediction part of
//! precision, from one pass over dense samples of each prediction.

use super::index::{for_each_tile, Aabb, Candidate, PolyIndex, TILE};
use super::metrics::{Accuracy, PredictionReport};
use super::options::{normals_match, EvalOptions};
use super::sampling::sample_polygon;
use super::GtSurface;
use crate::geometry::{Frame, Polygon3};
use glam::{DVec2, DVec3};

/// Distances of one prediction's samples and its on-surface counts.
struct Measured {
    report: PredictionReport,
    /// Distance of every area sample that found a surface.
    distances: Vec<f64>,
    /// Area one area sample stands for.
    weight: f64,
    boundary_samples: usize,
}

/// Reusable buffers for the per-tile work.
#[derive(Default)]
struct Scratch {
    world: Vec<DVec3>,
    nearest: Vec<Candidate>,
    within: Vec<usize>,
}

/// Measure every prediction against the ground truth.
pub(crate) fn measure(
    pred: &[Polygon3],
    gt: &[GtSurface],
    opts: &EvalOptions,
) -> (Accuracy, Vec<PredictionReport>) {
    let index = PolyIndex::new(gt.iter().map(|g| &g.polygon).collect());
    let measured: Vec<Measured> = pred
        .iter()
        .enumerate()
        .map(|(i, p)| measure_one(i, p, gt, &index, opts))
        .collect();
    let accuracy = summarize(&measured);
    (accuracy, measured.into_iter().map(|m| m.report).collect())
}

/// World points of a tile of 2D samples, and their box.
fn to_world(frame: &Frame, tile: &[DVec2], world: &mut Vec<DVec3>) -> Aabb {
    world.clear();
    world.extend(tile.iter().map(|&q| frame.to_world(q)));
    Aabb::of(world)
}

fn measure_one(
    index: usize,
    poly: &Polygon3,
    gt: &[GtSurface],
    gt_index: &PolyIndex,
    opts: &EvalOptions,
) -> Measured {
    let mut samples = sample_polygon(poly, opts);
    let (frame, cos_max, tol) = (&poly.frame, opts.cos_max_angle(), opts.on_surface_tolerance);
    let same_normal = |g: usize| normals_match(frame.normal, gt[g].polygon.frame.normal, cos_max);
    let mut on_surface = vec![0usize; gt.len()];
    let mut distances = Vec::with_capacity(samples.area.len());
    let mut max: Option<f64> = None;
    let mut s = Scratch::default();
    for_each_tile(&mut samples.area, TILE, |tile| {
        let region = to_world(frame, tile, &mut s.world);
        gt_index.nearest_candidates(&region, &mut s.nearest);
        gt_index.within_candidates(&region, tol, same_normal, &mut s.within);
        for &p in &s.world {
            if let Some((_, d)) = gt_index.nearest(p, &s.nearest) {
                distances.push(d);
                max = Some(max.map_or(d, |m: f64| m.max(d)));
            }
            for &g in &s.within {
                if gt_index.distance_within(g, p, tol).is_some() {
                    on_surface[g] += 1;
                }
            }
        }
    });
    for_each_tile(&mut samples.boundary, TILE, |tile| {
        let region = to_world(frame, tile, &mut s.world);
        gt_index.nearest_candidates(&region, &mut s.nearest);
        for &p in &s.world {
            if let Some((_, d)) = gt_index.nearest(p, &s.nearest) {
                max = Some(max.map_or(d, |m: f64| m.max(d)));
            }
        }
    });
    let n = samples.area.len();
    let (surface, share) = best_surface(gt, &on_surface, n);
    let mean =
        (!distances.is_empty()).then(|| distances.iter().sum::<f64>() / distances.len() as f64);
    Measured {
        report: PredictionReport {
            index,
            area: poly.area(),
            vertices: poly.ring.len(),
            spacing: samples.spacing,
            samples: n,
            mean_distance: mean,
            max_distance: max,
            surface,
            on_surface_share: share,
            true_positive: share > opts.true_positive_share,
        },
        distances,
        weight: samples.weight(),
        boundary_samples: samples.boundary.len(),
    }
}

/// The surface holding most samples (first on ties) and its share of `n`.
fn best_surface(gt: &[GtSurface], on_surface: &[usize], n: usize) -> (Option<u32>, f64) {
    let mut best: Option<(usize, usize)> = None;
    for (g, &count) in on_surface.iter().enumerate() {
        if count > 0 && best.is_none_or(|(_, c)| count > c) {
            best = Some((g, count));
        }
    }
    match best {
        Some((g, count)) if n > 0 => (Some(gt[g].id), count as f64 / n as f64),
        _ => (None, 0.0),
    }
}

/// Area-weighted statistics over every prediction's samples.
fn summarize(measured: &[Measured]) -> Accuracy {
    let mut weighted: Vec<(f64, f64)> = measured
        .iter()
        .flat_map(|m| m.distances.iter().map(move |&d| (d, m.weight)))
        .collect();
    let total: f64 = weighted.iter().map(|&(_, w)| w).sum();
    let sum: f64 = weighted.iter().map(|&(d, w)| d * w).sum();
    let max = measured
        .iter()
        .filter_map(|m| m.report.max_distance)
        .fold(None, |acc: Option<f64>, d| {
            Some(acc.map_or(d, |a| a.max(d)))
        });
    Accuracy {
        area_samples: weighted.len(),
        boundary_samples: measured.iter().map(|m| m.boundary_samples).sum(),
        sampled_area: total,
        mean: (total > 0.0).then(|| sum / total),
        median: weighted_median(&mut weighted),
        max,
    }
}

/// The smallest value at which the cumulative weight reaches half the total.
fn weighted_median(values: &mut [(f64, f64)]) -> Option<f64> {
    values.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = values.iter().map(|&(_, w)| w).sum();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let mut cumulative = 0.0;
    for &(d, w) in values.iter() {
        cumulative += w;
        if cumulative >= 0.5 * total {
            return Some(d);
        }
    }
    values.last().map(|&(d, _)| d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weighted_median_uses_weights() {
        let mut v = vec![(3.0, 1.0), (1.0, 1.0), (2.0, 1.0)];
        assert_eq!(weighted_median(&mut v), Some(2.0));
        let mut v = vec![(1.0, 1.0), (5.0, 10.0)];
        assert_eq!(weighted_median(&mut v), Some(5.0));
        assert_eq!(weighted_median(&mut []), None);
    }
}
