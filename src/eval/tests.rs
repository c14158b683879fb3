//! Scenes with known answers: a 20 x 10 m floor and two 3 m walls.

use super::index::{for_each_tile, Aabb, PolyIndex};
use super::*;
use crate::rng::Rng;
use glam::{DVec2, DVec3};

const FLOOR: u32 = 1;
const BACK: u32 = 2;
const SIDE: u32 = 3;

/// The rectangle `corner, corner + e1, corner + e1 + e2, corner + e2`.
fn rect(corner: DVec3, e1: DVec3, e2: DVec3) -> Polygon3 {
    Polygon3::from_world(&[corner, corner + e1, corner + e1 + e2, corner + e2]).unwrap()
}

/// Points at the centres of a `step` grid on the rectangle.
fn grid_on(corner: DVec3, e1: DVec3, e2: DVec3, step: f64) -> Vec<DVec3> {
    let n1 = (e1.length() / step).round() as usize;
    let n2 = (e2.length() / step).round() as usize;
    let mut out = Vec::with_capacity(n1 * n2);
    for i in 0..n1 {
        for j in 0..n2 {
            let (a, b) = ((i as f64 + 0.5) / n1 as f64, (j as f64 + 0.5) / n2 as f64);
            out.push(corner + e1 * a + e2 * b);
        }
    }
    out
}

struct Scene {
    gt: Vec<GtSurface>,
    points: Vec<DVec3>,
    labels: Vec<u32>,
}

/// Floor `x in [0, 20], y in [0, 10], z = 0`, back wall `y = 10`, side wall
/// `x = 0`, both 3 m high; points every 0.1 m on each, plus clutter.
fn room() -> Scene {
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    let parts = [
        (FLOOR, DVec3::ZERO, 20.0 * x, 10.0 * y),
        (BACK, 10.0 * y, 20.0 * x, 3.0 * z),
        (SIDE, 10.0 * y, -10.0 * y, 3.0 * z),
    ];
    let mut scene = Scene {
        gt: Vec::new(),
        points: Vec::new(),
        labels: Vec::new(),
    };
    for (id, c, e1, e2) in parts {
        scene.gt.push(GtSurface {
            id,
            polygon: rect(c, e1, e2),
        });
        let pts = grid_on(c, e1, e2, 0.1);
        scene.labels.extend(std::iter::repeat_n(id, pts.len()));
        scene.points.extend(pts);
    }
    let mut rng = Rng::new(5);
    for _ in 0..500 {
        let p = DVec3::new(
            rng.range(2.0, 18.0),
            rng.range(2.0, 8.0),
            rng.range(0.5, 2.5),
        );
        scene.points.push(p);
        scene.labels.push(CLUTTER);
    }
    scene
}

fn run(scene: &Scene, pred: &[Polygon3]) -> Metrics {
    run_with(scene, pred, &EvalOptions::default())
}

fn run_with(scene: &Scene, pred: &[Polygon3], opts: &EvalOptions) -> Metrics {
    evaluate(
        pred,
        &scene.gt,
        &scene.points,
        &scene.labels,
        scene.points.len(),
        opts,
    )
    .unwrap()
}

fn surface(m: &Metrics, id: u32) -> &SurfaceReport {
    m.surfaces.iter().find(|s| s.id == id).unwrap()
}

fn perfect(scene: &Scene) -> Vec<Polygon3> {
    scene.gt.iter().map(|g| g.polygon.clone()).collect()
}

/// The back wall from `x = x0` to `x = x1`, `z` from 0 to `top`, at `y`.
fn back_wall(x0: f64, x1: f64, top: f64, y: f64) -> Polygon3 {
    rect(DVec3::new(x0, y, 0.0), (x1 - x0) * DVec3::X, top * DVec3::Z)
}

#[test]
fn perfect_prediction_scores_perfectly() {
    let scene = room();
    let m = run(&scene, &perfect(&scene));
    assert!(m.accuracy.mean.unwrap() < 1e-9, "{m}");
    assert!(m.accuracy.max.unwrap() < 1e-9, "{m}");
    assert!(m.accuracy.median.unwrap() < 1e-9);
    // 200 + 60 + 30 m^2 at 0.1 m: 29 000 grid samples.
    assert_eq!(m.accuracy.area_samples, 29_000);
    assert!((m.accuracy.sampled_area - 290.0).abs() < 1e-6);
    assert_eq!(m.completeness.completeness, 1.0);
    assert!((m.completeness.observed_area - 290.0).abs() < 1e-9, "{m}");
    assert_eq!(m.detection.precision, 1.0);
    assert_eq!(m.detection.recall, 1.0);
    assert_eq!(m.detection.f1, 1.0);
    assert_eq!(m.duplicates.count, 0);
    for (i, s) in m.surfaces.iter().enumerate() {
        assert_eq!(s.matching_predictions, vec![i]);
    }
    for p in &m.predictions {
        assert_eq!(p.surface, Some(scene.gt[p.index].id));
        assert_eq!(p.on_surface_share, 1.0);
    }
}

#[test]
fn a_duplicated_polygon_is_caught() {
    let scene = room();
    let mut pred = perfect(&scene);
    let copy = rect(DVec3::new(5.0, 0.0, 0.05), 10.0 * DVec3::X, 10.0 * DVec3::Y);
    pred.push(copy);
    let m = run(&scene, &pred);
    assert_eq!(m.duplicates.count, 1, "{m}");
    let pair = &m.duplicates.pairs[0];
    assert_eq!((pair.first, pair.second), (0, 3));
    assert!(
        (pair.overlap_area - 100.0).abs() < 1e-6,
        "{}",
        pair.overlap_area
    );
    assert!(pair.angle_deg < 1e-6);
    assert_eq!(m.detection.true_positives, 4);
    assert_eq!(m.detection.precision, 1.0);
    assert_eq!(m.detection.recall, 1.0);
    // Side by side, touching but not overlapping: no duplicate.
    let halves = vec![
        rect(DVec3::ZERO, 10.0 * DVec3::X, 10.0 * DVec3::Y),
        rect(10.0 * DVec3::X, 10.0 * DVec3::X, 10.0 * DVec3::Y),
    ];
    assert_eq!(run(&scene, &halves).duplicates.count, 0);
}

#[test]
fn a_shifted_prediction_is_off_by_the_shift() {
    let scene = room();
    // The back wall moved 0.3 m away from the room: nothing is closer than
    // the back wall itself.
    let m = run(&scene, &[back_wall(0.0, 20.0, 3.0, 10.3)]);
    let p = &m.predictions[0];
    assert!((p.mean_distance.unwrap() - 0.3).abs() < 1e-9, "{m}");
    assert!((p.max_distance.unwrap() - 0.3).abs() < 1e-9);
    assert!((m.accuracy.mean.unwrap() - 0.3).abs() < 1e-9);
    assert!((m.accuracy.median.unwrap() - 0.3).abs() < 1e-9);
    assert!((m.accuracy.max.unwrap() - 0.3).abs() < 1e-9);
    let back = surface(&m, BACK);
    assert_eq!(back.completeness, 0.0);
    assert!(!back.found);
    assert!(!p.true_positive);
    assert_eq!((m.detection.precision, m.detection.recall), (0.0, 0.0));
    // A looser found tolerance finds it.
    let loose = EvalOptions {
        found_tolerance: 0.35,
        on_surface_tolerance: 0.35,
        ..EvalOptions::default()
    };
    let m = run_with(&scene, &[back_wall(0.0, 20.0, 3.0, 10.3)], &loose);
    assert!(surface(&m, BACK).found);
    assert_eq!(m.detection.precision, 1.0);
}

#[test]
fn half_a_wall_is_half_complete() {
    let scene = room();
    let m = run(&scene, &[back_wall(0.0, 10.0, 3.0, 10.0)]);
    let back = surface(&m, BACK);
    // 40 of 80 cell columns, plus the column whose points reach 0.1 m past
    // the edge when rounding lets it.
    assert!((0.5..=41.0 / 80.0).contains(&back.completeness), "{m}");
    assert!(back.found);
    assert_eq!(m.detection.precision, 1.0);
    let m = run(&scene, &[back_wall(0.0, 8.0, 3.0, 10.0)]);
    let back = surface(&m, BACK);
    assert!((back.completeness - 0.4).abs() < 0.02, "{m}");
    assert!(!back.found);
    let m = run(&scene, &[back_wall(0.0, 12.0, 3.0, 10.0)]);
    assert!((surface(&m, BACK).completeness - 0.6).abs() < 0.02);
    assert!(surface(&m, BACK).found);
    assert!((m.detection.recall - 1.0 / 3.0).abs() < 1e-12);
}

#[test]
fn an_overhang_is_as_far_as_it_reaches() {
    let scene = room();
    // The back wall 2 m too tall: its top edge is 2 m from the wall's.
    let m = run(&scene, &[back_wall(0.0, 20.0, 5.0, 10.0)]);
    assert!((m.accuracy.max.unwrap() - 2.0).abs() < 1e-9, "{m}");
    // Area-weighted mean: 3/5 at 0, 2/5 uniform in [0, 2] -> 0.4.
    assert!((m.accuracy.mean.unwrap() - 0.4).abs() < 1e-3, "{m}");
    let p = &m.predictions[0];
    assert!((p.on_surface_share - 3.15 / 5.0).abs() < 0.015);
    assert!(p.true_positive);
    assert_eq!(surface(&m, BACK).completeness, 1.0);
}

#[test]
fn compactness_of_three_quads() {
    let scene = room();
    let pred = perfect(&scene);
    let m = evaluate(
        &pred,
        &scene.gt,
        &scene.points,
        &scene.labels,
        1000,
        &EvalOptions::default(),
    )
    .unwrap();
    let k = &m.compactness;
    assert_eq!((k.polygons, k.vertices), (3, 12));
    assert_eq!(k.polygon_bytes, 12 * 12 + 3 * 16);
    assert_eq!(k.input_bytes, 12_000);
    assert_eq!(k.ratio, Some(192.0 / 12_000.0));
    assert_eq!(Compactness::new(&[], 0).ratio, None);
}

#[test]
fn empty_inputs_are_well_defined() {
    let scene = room();
    let m = run(&scene, &[]);
    assert_eq!(m.accuracy.mean, None);
    assert_eq!(m.accuracy.max, None);
    assert_eq!(m.accuracy.area_samples, 0);
    assert_eq!(
        (m.detection.precision, m.detection.recall, m.detection.f1),
        (0.0, 0.0, 0.0)
    );
    assert_eq!(m.detection.eligible_surfaces, 3);
    assert_eq!(m.completeness.completeness, 0.0);
    // Predictions but no ground truth at all.
    let pred = perfect(&scene);
    let m = evaluate(&pred, &[], &[], &[], 0, &EvalOptions::default()).unwrap();
    assert_eq!(m.accuracy.max, None);
    assert_eq!(m.detection.precision, 0.0);
    assert_eq!(m.detection.eligible_surfaces, 0);
    assert_eq!(m.compactness.ratio, None);
    // Surfaces never observed are not eligible.
    let m = evaluate(&pred, &scene.gt, &[], &[], 0, &EvalOptions::default()).unwrap();
    assert_eq!(
        (m.completeness.observed_area, m.detection.eligible_surfaces),
        (0.0, 0)
    );
    assert!(m.accuracy.max.unwrap() < 1e-9);
    // Degenerate predictions: no vertex, a segment, a point.
    let mut bad = pred[0].clone();
    bad.ring.clear();
    let mut segment = pred[0].clone();
    segment.ring.truncate(2);
    let mut dot = pred[0].clone();
    dot.ring.truncate(1);
    let m = run(&scene, &[bad, segment, dot]);
    assert_eq!(m.accuracy.area_samples, 0);
    assert!(m.accuracy.max.unwrap() < 1e-9);
    assert_eq!(m.detection.true_positives, 0);
    let text = m.to_string();
    assert!(text.contains("precision") && text.contains("surface"));
    let json = serde_json::to_string(&m).unwrap();
    assert!(json.contains("\"mean\":null"));
}

#[test]
fn bad_inputs_are_errors() {
    let scene = room();
    let pred = perfect(&scene);
    let opts = EvalOptions::default();
    let short = &scene.labels[1..];
    assert!(evaluate(&pred, &scene.gt, &scene.points, short, 0, &opts).is_err());
    let mut points = scene.points.clone();
    points[7].y = f64::NAN;
    let err = evaluate(&pred, &scene.gt, &points, &scene.labels, 0, &opts).unwrap_err();
    assert_eq!(err, Error::NonFinite { point: 7 });
    let mut nan = pred.clone();
    nan[1].ring[2].x = f64::INFINITY;
    assert!(evaluate(&nan, &scene.gt, &[], &[], 0, &opts).is_err());
    let mut skew = pred.clone();
    skew[0].frame.u = DVec3::new(1.0, 1.0, 0.0);
    assert!(evaluate(&skew, &scene.gt, &[], &[], 0, &opts).is_err());
    let mut twice = scene.gt.clone();
    twice[1].id = FLOOR;
    assert!(evaluate(&pred, &twice, &[], &[], 0, &opts).is_err());
    let mut clutter = scene.gt.clone();
    clutter[0].id = CLUTTER;
    assert!(evaluate(&pred, &clutter, &[], &[], 0, &opts).is_err());
    for bad in [
        EvalOptions {
            sample_spacing: 0.0,
            ..opts.clone()
        },
        EvalOptions {
            completeness_tolerance: f64::NAN,
            ..opts.clone()
        },
        EvalOptions {
            found_coverage: 1.5,
            ..opts.clone()
        },
        EvalOptions {
            max_normal_angle_deg: 91.0,
            ..opts.clone()
        },
        EvalOptions {
            max_samples_per_polygon: 0,
            ..opts.clone()
        },
    ] {
        assert!(matches!(
            evaluate(&pred, &scene.gt, &[], &[], 0, &bad),
            Err(Error::BadOption { .. })
        ));
    }
}

#[test]
fn large_polygons_are_sampled_coarser_and_results_repeat() {
    let scene = room();
    let opts = EvalOptions {
        max_samples_per_polygon: 5000,
        ..EvalOptions::default()
    };
    let a = run_with(&scene, &perfect(&scene), &opts);
    assert!(
        a.predictions[0].samples <= 5000,
        "{}",
        a.predictions[0].samples
    );
    assert!(a.predictions[0].spacing > 0.1);
    assert_eq!(a.predictions[2].spacing, 0.1);
    assert!((a.accuracy.sampled_area - 290.0).abs() < 2.0);
    let b = run_with(&scene, &perfect(&scene), &opts);
    assert_eq!(a, b);
}

/// Random planar polygons in a 60 m box with random orientations.
fn random_polygons(rng: &mut Rng, n: usize) -> Vec<Polygon3> {
    (0..n)
        .map(|_| {
            let c = DVec3::new(
                rng.range(0.0, 60.0),
                rng.range(0.0, 60.0),
                rng.range(0.0, 20.0),
            );
            let e1 = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            let e2 = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            let (s1, s2) = (rng.range(0.5, 8.0), rng.range(0.5, 8.0));
            // A triangle or a quadrilateral, convex.
            let mut v = vec![c, c + e1 * s1, c + (e1 + e2) * s1.min(s2)];
            if rng.uniform() < 0.5 {
                v.push(c + e2 * s2);
            }
            Polygon3::from_world(&v).unwrap_or_else(|| rect(c, DVec3::X, DVec3::Y))
        })
        .collect()
}

#[test]
fn culling_always_finds_the_nearest_polygon() {
    let mut rng = Rng::new(11);
    let polys = random_polygons(&mut rng, 80);
    let index = PolyIndex::new(polys.iter().collect());
    // Query tiles of nearby points, as the evaluation does.
    let frame = polys[0].frame;
    let mut pts: Vec<DVec2> = (0..4000)
        .map(|_| DVec2::new(rng.range(-40.0, 80.0), rng.range(-40.0, 80.0)))
        .collect();
    let mut cands = Vec::new();
    let mut checked = 0;
    for_each_tile(&mut pts, 4.0, |tile| {
        let world: Vec<DVec3> = tile
            .iter()
            .map(|&q| frame.to_world(q) + frame.normal * rng.range(-5.0, 5.0))
            .collect();
        index.nearest_candidates(&Aabb::of(&world), &mut cands);
        for &p in &world {
            let brute = polys
                .iter()
                .map(|g| g.distance(p))
                .fold(f64::INFINITY, f64::min);
            let Some((_, d)) = index.nearest(p, &cands) else {
                panic!("{cands:?} {:?} {p}", Aabb::of(&world));
            };
            assert_eq!(d, brute);
            checked += 1;
        }
    });
    assert_eq!(checked, 4000);
}

#[test]
fn report_lists_pairs_surfaces_and_predictions() {
    let scene = room();
    let mut pred = perfect(&scene);
    pred.push(rect(
        DVec3::new(5.0, 0.0, 0.05),
        10.0 * DVec3::X,
        10.0 * DVec3::Y,
    ));
    pred.push(back_wall(0.0, 20.0, 5.0, 10.3));
    let m = run(&scene, &pred);
    let text = m.to_string();
    assert!(text.contains("#0 and #3: overlap 100.00 m^2"), "{text}");
    assert!(text.contains("(4 of 5 predictions)"), "{text}");
    // One row per surface and per prediction, all as wide as their header.
    let lines: Vec<&str> = text.lines().collect();
    let header = lines
        .iter()
        .position(|l| l.trim_start().starts_with("surface"))
        .unwrap();
    assert!(lines[header + 1..header + 4]
        .iter()
        .all(|l| l.len() >= lines[header].len() - 12));
    let json = serde_json::to_value(&m).unwrap();
    assert_eq!(json["duplicates"]["count"], 1);
    assert_eq!(json["predictions"][4]["true_positive"], false);
}

#[test]
fn odd_polygons_neither_panic_nor_hang() {
    let scene = room();
    let mut odd = Vec::new();
    // A bow tie (self-intersecting, signed area 0) 200 m across.
    let mut bowtie = rect(DVec3::ZERO, 200.0 * DVec3::X, 200.0 * DVec3::Y);
    bowtie.ring.swap(2, 3);
    odd.push(bowtie);
    // A 1 km sliver of almost no area, diagonal in its frame.
    odd.push(
        Polygon3::from_world(&[
            DVec3::ZERO,
            DVec3::new(700.0, 700.0, 0.0),
            DVec3::new(700.0, 700.0 + 1e-9, 0.0),
        ])
        .unwrap(),
    );
    // Far from the origin, with a huge outline coordinate.
    let mut far = rect(DVec3::new(1e12, 1e12, 0.0), DVec3::X, DVec3::Y);
    far.ring[2].x = 1e15;
    odd.push(far);
    let opts = EvalOptions {
        max_samples_per_polygon: usize::MAX,
        ..EvalOptions::default()
    };
    let m = run_with(&scene, &odd[..2], &EvalOptions::default());
    assert!(
        m.predictions[0].samples <= 400_000,
        "{}",
        m.predictions[0].samples
    );
    assert!(m.accuracy.max.unwrap().is_finite());
    let m = run_with(
        &scene,
        &odd[2..],
        &EvalOptions {
            max_samples_per_polygon: 1000,
            ..opts
        },
    );
    assert!(m.accuracy.max.unwrap() > 1e11);
    assert!(serde_json::to_string(&m).is_ok());
}
