//! Property-based tests of the core (proptest, fixed seed): random and
//! degenerate clouds (empty, one to three points, collinear, coplanar,
//! duplicates, tiny and huge coordinates within the bound), options within
//! their documented ranges (`src/params/table.rs`), rigid poses and snapshot
//! round trips. Whatever the input: no panic; labels one per point, each
//! naming a primitive that exists; outlines simple with finite vertices;
//! the same input and seed give the same result; a restored snapshot goes
//! on exactly as the original.
#![cfg(not(target_arch = "wasm32"))]

use glam::{DMat4, DQuat, DVec3, EulerRot};
use polyscene::cloud::Cloud;
use polyscene::detect::{detect, NO_PRIMITIVE};
use polyscene::geometry::polygon::is_simple;
use polyscene::internals::Rng;
use polyscene::params::{HullKind, Params};
use polyscene::primitive::Primitive;
use polyscene::scenario::Scenario;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// A fixed seed and a case count that keeps the file well under a minute
/// in release.
fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x5ca1ab1e),
        failure_persistence: None,
        ..Config::default()
    }
}

fn unit() -> impl Strategy<Value = DVec3> {
    (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(x, y, z)| {
        let v = DVec3::new(x, y, z);
        if v.length() > 1e-3 {
            v.normalize()
        } else {
            DVec3::Z
        }
    })
}

/// Clouds, in metres; each kind shifted by an offset from none to 1e8 m.
fn cloud() -> impl Strategy<Value = Vec<DVec3>> {
    let scale = prop_oneof![Just(1e-3), Just(1.0), Just(50.0), Just(1e5)];
    let kind = prop_oneof![
        // Empty.
        1 => Just(Vec::new()),
        // One to three points.
        1 => proptest::collection::vec((-50.0f64..50.0, -50.0f64..50.0, -50.0f64..50.0), 1..=3)
            .prop_map(|v| v.into_iter().map(DVec3::from).collect()),
        // Collinear.
        1 => (unit(), 2usize..600, 0.001f64..0.5)
            .prop_map(|(d, n, s)| { (0..n).map(|i| d * (i as f64 * s)).collect() }),
        // Duplicates of one point.
        1 => (unit(), 1usize..800).prop_map(|(p, n)| vec![p * 3.0; n]),
        // Coplanar (a noisy grid), maybe with a second plane and clutter.
        6 => (
            unit(),
            unit(),
            5usize..80,
            5usize..80,
            0.02f64..0.3,
            0.0f64..0.01,
            any::<u64>(),
            any::<bool>(),
            0usize..100,
        )
            .prop_map(|(n, n2, a, b, step, noise, seed, second, clutter)| {
                let mut rng = Rng::new(seed);
                let mut pts = Vec::new();
                for n in if second { vec![n, n2] } else { vec![n] } {
                    let u = n.any_orthonormal_vector();
                    let v = n.cross(u);
                    for i in 0..a {
                        for j in 0..b {
                            let w = u * (i as f64 * step) + v * (j as f64 * step);
                            pts.push(w + n * (rng.gaussian() * noise));
                        }
                    }
                }
                for _ in 0..clutter {
                    let r = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                    pts.push(r * 20.0 - DVec3::splat(10.0));
                }
                pts
            }),
        // Random points at a scale.
        1 => (
            scale,
            proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), 0..400)
        )
            .prop_map(|(s, v)| v.into_iter().map(|p| DVec3::from(p) * s).collect()),
    ];
    let offset = prop_oneof![
        3 => Just(DVec3::ZERO),
        1 => (-1e8f64..1e8, -1e8f64..1e8, -1e3f64..1e3).prop_map(DVec3::from),
    ];
    (kind, offset).prop_map(|(pts, o)| pts.into_iter().map(|p| p + o).collect())
}

/// Options within their documented ranges, over a preset.
fn params() -> impl Strategy<Value = Params> {
    (
        (
            any::<bool>(),
            any::<bool>(),
            any::<u64>(),
            3usize..300,
            1usize..300,
        ),
        (
            0.005f64..1.0,
            0.005f64..1.0,
            0.02f64..3.0,
            0.02f64..3.0,
            0.05f64..5.0,
        ),
        (
            4usize..200,
            0.0f64..5.0,
            0.0f64..1.0,
            0.005f64..0.3,
            0.005f64..0.3,
        ),
        (
            0.02f64..4.0,
            0.02f64..4.0,
            0.5f64..30.0,
            0.005f64..0.5,
            0.0f64..2.0,
        ),
        (any::<bool>(), 0.0f64..1.0),
    )
        .prop_map(
            |(
                (gpp1, convex, seed, min_inliers, max_hypotheses),
                (distance, ground_distance, tol, ground_tol, sample_radius),
                (max_vertices, min_area, min_width, across, ground_across),
                (along, ground_along, merge_angle, merge_distance, merge_gap),
                (expansion, min_occupancy),
            )| {
                let mut p = if gpp1 { Params::gpp1() } else { Params::gpp2() };
                p.hull = if convex {
                    HullKind::Convex
                } else {
                    HullKind::Concave
                };
                p.seed = seed;
                p.min_inliers = min_inliers;
                p.max_hypotheses = max_hypotheses;
                p.other.distance = distance;
                p.ground.distance = ground_distance;
                p.other.cluster_tolerance = tol;
                p.ground.cluster_tolerance = ground_tol;
                p.sample_radius = sample_radius;
                p.max_vertices = max_vertices;
                p.min_area = min_area;
                p.min_width = min_width;
                p.other.expand_across = across;
                p.ground.expand_across = ground_across;
                p.other.expand_along = along;
                p.ground.expand_along = ground_along;
                p.merge_angle = merge_angle;
                p.merge_distance = merge_distance;
                p.merge_gap = merge_gap;
                p.expansion = expansion;
                p.min_occupancy = min_occupancy;
                p
            },
        )
}

/// A rigid pose: any rotation, a translation within 1e6 m.
fn pose() -> impl Strategy<Value = DMat4> {
    (
        -3.2f64..3.2,
        -1.6f64..1.6,
        -3.2f64..3.2,
        prop_oneof![
            Just(DVec3::ZERO),
            (-1e6f64..1e6, -1e6f64..1e6, -1e3f64..1e3).prop_map(DVec3::from)
        ],
    )
        .prop_map(|(a, b, c, t)| {
            DMat4::from_rotation_translation(DQuat::from_euler(EulerRot::ZYX, a, b, c), t)
        })
}

/// A small rigid motion: centimetres and hundredths of a radian.
fn nudge() -> impl Strategy<Value = DMat4> {
    (-0.02f64..0.02, (-0.1f64..0.1, -0.1f64..0.1, -0.02f64..0.02)).prop_map(|(a, t)| {
        DMat4::from_rotation_translation(DQuat::from_rotation_z(a), DVec3::from(t))
    })
}

/// Outlines simple, vertices and planes finite.
fn check_primitives(prims: &[Primitive]) -> Result<(), TestCaseError> {
    for p in prims {
        prop_assert!(
            p.plane.normal.is_finite() && p.plane.offset.is_finite(),
            "plane of {}",
            p.id
        );
        prop_assert!(
            p.outline.iter().all(|q| q.is_finite()),
            "outline of {}",
            p.id
        );
        prop_assert!(
            is_simple(&p.outline),
            "outline of {} not simple: {:?}",
            p.id,
            p.outline
        );
        prop_assert!(
            p.area.is_finite() && p.area > 0.0,
            "area of {}: {}",
            p.id,
            p.area
        );
    }
    Ok(())
}

/// Labels: one per point, each NO_PRIMITIVE or the id of a primitive.
fn check_labels(labels: &[u32], n: usize, prims: &[Primitive]) -> Result<(), TestCaseError> {
    prop_assert_eq!(labels.len(), n);
    for &l in labels {
        prop_assert!(
            l == NO_PRIMITIVE || prims.iter().any(|p| p.id == l),
            "label {} names no primitive",
            l
        );
    }
    Ok(())
}

fn flat(pts: &[DVec3]) -> Vec<f32> {
    pts.iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect()
}

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn detection_is_total_consistent_and_deterministic(pts in cloud(), params in params()) {
        let Ok(cloud) = Cloud::from_flat(&flat(&pts), 3) else {
            return Ok(());
        };
        let a = detect(&cloud, &params);
        let b = detect(&cloud, &params);
        let (a, b) = match (a, b) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(a), Err(b)) => {
                prop_assert_eq!(a.to_string(), b.to_string());
                return Ok(());
            }
            _ => return Err(TestCaseError::fail("one run failed, the other did not")),
        };
        check_primitives(&a.primitives)?;
        check_labels(&a.labels, cloud.len(), &a.primitives)?;
        prop_assert_eq!(&a.primitives, &b.primitives);
        prop_assert_eq!(&a.labels, &b.labels);
    }
}

proptest! {
    #![proptest_config(config(400))]

    #[test]
    fn scenario_is_total_consistent_and_restores_exactly(
        base in (cloud(), pose()),
        moves in proptest::collection::vec((cloud(), pose(), nudge(), any::<bool>()), 1..4),
        last in (cloud(), pose()),
        params in params(),
    ) {
        // Mostly the first cloud again, seen through a nudged pose (so
        // primitives grow and merge), sometimes another cloud and pose.
        let scans: Vec<(Vec<DVec3>, DMat4)> = std::iter::once(base.clone())
            .chain(moves.into_iter().map(|(c, p, n, again)| {
                if again { (base.0.clone(), base.1 * n) } else { (c, p) }
            }))
            .collect();
        let mut sc = Scenario::new(params).unwrap();
        for (pts, pose) in &scans {
            let before = sc.to_json();
            match sc.add_scan(&flat(pts), 3, pose) {
                Ok(report) => {
                    prop_assert_eq!(report.polygon_count, sc.primitives().len());
                    check_primitives(sc.primitives())?;
                    check_labels(sc.last_labels(), pts.len(), sc.primitives())?;
                }
                // A refused scan leaves the scenario as it was.
                Err(_) => prop_assert_eq!(sc.to_json(), before),
            }
        }
        // Round trip, then the same scan on both: the same outcome.
        let json = sc.to_json();
        let mut back = Scenario::from_json(&json).unwrap();
        prop_assert_eq!(back.primitives(), sc.primitives());
        prop_assert_eq!(back.to_json(), json);
        let (pts, pose) = &last;
        let a = sc.add_scan(&flat(pts), 3, pose);
        let b = back.add_scan(&flat(pts), 3, pose);
        match (a, b) {
            (Ok(mut a), Ok(mut b)) => {
                a.time_ms = Default::default();
                b.time_ms = Default::default();
                prop_assert_eq!(a, b);
                prop_assert_eq!(sc.to_json(), back.to_json());
                check_primitives(sc.primitives())?;
                check_labels(sc.last_labels(), pts.len(), sc.primitives())?;
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
            _ => return Err(TestCaseError::fail("one scenario refused the scan, the other did not")),
        }
    }
}
