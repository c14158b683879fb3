//! One-shot detection (Algorithm 1) on scenes with known answers.

mod common;

use common::*;
use glam::{DVec2, DVec3};
use polyscene::cloud::Cloud;
use polyscene::detect::detect;
use polyscene::geometry::polygon::contains;
use polyscene::geometry::{Frame, Plane};
use polyscene::internals::Rng;
use polyscene::params::{HullKind, Params};
use polyscene::Error;

fn box_room(rng: &mut Rng) -> Vec<DVec3> {
    // 10 x 8 x 3 m room, sampled every 5 cm with 1 cm noise.
    let mut pts = Vec::new();
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    let s = 0.05;
    rect(&mut pts, DVec3::ZERO, x, y, 10.0, 8.0, s, 0.01, rng); // floor
    rect(
        &mut pts,
        DVec3::new(0.0, 0.0, 3.0),
        x,
        y,
        10.0,
        8.0,
        s,
        0.01,
        rng,
    ); // ceiling
    rect(&mut pts, DVec3::ZERO, x, z, 10.0, 3.0, s, 0.01, rng); // y = 0
    rect(
        &mut pts,
        DVec3::new(0.0, 8.0, 0.0),
        x,
        z,
        10.0,
        3.0,
        s,
        0.01,
        rng,
    ); // y = 8
    rect(&mut pts, DVec3::ZERO, y, z, 8.0, 3.0, s, 0.01, rng); // x = 0
    rect(
        &mut pts,
        DVec3::new(10.0, 0.0, 0.0),
        y,
        z,
        8.0,
        3.0,
        s,
        0.01,
        rng,
    ); // x = 10
    pts
}

#[test]
fn box_room_gives_six_faces() {
    let mut rng = Rng::new(1);
    let pts = box_room(&mut rng);
    let cloud = cloud(&pts);
    for hull in [HullKind::Convex, HullKind::Concave] {
        let p = Params {
            hull,
            viewpoint: Some([5.0, 4.0, 1.8]),
            ..Params::gpp2()
        };
        let det = detect(&cloud, &p).unwrap();
        check_invariants(&cloud, &det, &p);
        assert_eq!(det.primitives.len(), 6, "{hull:?}");
        let centre = DVec3::new(5.0, 4.0, 1.5);
        let mut areas: Vec<f64> = det.primitives.iter().map(|q| q.area).collect();
        areas.sort_by(f64::total_cmp);
        let expect = [24.0, 24.0, 30.0, 30.0, 80.0, 80.0];
        // Faces found later lose the strips within the inlier distance of the
        // faces found before them (each point belongs to one primitive); a
        // concave outline is exact to half a raster cell (perimeter x 0.1 m).
        for (a, e) in areas.iter().zip(expect) {
            assert!(*a > 0.8 * e && *a < 1.06 * e, "{hull:?}: area {a} vs {e}");
        }
        for q in &det.primitives {
            let n = q.plane.normal;
            let axis = n.abs().max_element();
            assert!(axis > 0.999, "normal {n} not axis aligned");
            // Every face's normal points into the room, towards the sensor.
            assert!(q.plane.signed_distance(centre) > 0.0);
        }
        // Only the floor is ground: the ceiling is above the sensor.
        let ground: Vec<f64> = det
            .primitives
            .iter()
            .filter(|q| q.ground)
            .map(|q| q.plane.offset)
            .collect();
        assert_eq!(ground.len(), 1);
        assert!(ground[0].abs() < 0.02);
        // Most points are explained.
        let explained = det.labels.iter().filter(|&&l| l != u32::MAX).count();
        assert!(explained as f64 > 0.95 * pts.len() as f64);
    }
}

#[test]
fn staircase_gives_each_tread_and_riser() {
    // Five steps, 1.2 m deep, 0.5 m high, 4 m wide.
    let mut rng = Rng::new(2);
    let mut pts = Vec::new();
    for k in 0..5 {
        let x0 = k as f64 * 1.2;
        let z0 = k as f64 * 0.5;
        rect(
            &mut pts,
            DVec3::new(x0, 0.0, z0),
            DVec3::X,
            DVec3::Y,
            1.2,
            4.0,
            0.04,
            0.005,
            &mut rng,
        );
        rect(
            &mut pts,
            DVec3::new(x0 + 1.2, 0.0, z0),
            DVec3::Y,
            DVec3::Z,
            4.0,
            0.5,
            0.04,
            0.005,
            &mut rng,
        );
    }
    let cloud = cloud(&pts);
    // A small-scale scene: finer raster and width limits than the street
    // defaults (risers are 0.4 m tall once the treads took their edges).
    let mut p = Params {
        min_area: 1.0,
        min_width: 0.2,
        viewpoint: Some([3.0, 2.0, 5.0]),
        ..Params::gpp2()
    };
    p.other.cell = 0.08;
    p.other.distance = 0.05;
    p.ground.distance = 0.05;
    let det = detect(&cloud, &p).unwrap();
    check_invariants(&cloud, &det, &p);
    // Treads by their orientation: ground is each 4 m column's floor and
    // what lies within 0.5 m of it, so the upper treads are not ground.
    let flat = |q: &&polyscene::primitive::Primitive| q.plane.normal.z.abs() > 0.99;
    let treads: Vec<f64> = det
        .primitives
        .iter()
        .filter(flat)
        .map(|q| -q.plane.offset * q.plane.normal.z.signum())
        .collect();
    let risers = det.primitives.len() - treads.len();
    assert_eq!(treads.len(), 5, "treads at {treads:?}");
    assert_eq!(risers, 5);
    for k in 0..5 {
        let z = k as f64 * 0.5;
        assert!(
            treads.iter().any(|t| (t - z).abs() < 0.02),
            "no tread at {z}: {treads:?}"
        );
    }
}

#[test]
fn coplanar_walls_with_a_gap_stay_two_polygons() {
    let mut rng = Rng::new(3);
    let mut pts = Vec::new();
    rect(
        &mut pts,
        DVec3::ZERO,
        DVec3::X,
        DVec3::Z,
        6.0,
        3.0,
        0.05,
        0.01,
        &mut rng,
    );
    rect(
        &mut pts,
        DVec3::new(9.0, 0.0, 0.0),
        DVec3::X,
        DVec3::Z,
        6.0,
        3.0,
        0.05,
        0.01,
        &mut rng,
    );
    let cloud = cloud(&pts);
    for hull in [HullKind::Convex, HullKind::Concave] {
        let p = Params {
            hull,
            // In front of the gap (at the default, the origin, the sensor
            // would stand in the walls' plane and could see neither).
            viewpoint: Some([7.5, -6.0, 1.5]),
            ..Params::gpp2()
        };
        let det = detect(&cloud, &p).unwrap();
        check_invariants(&cloud, &det, &p);
        assert_eq!(det.primitives.len(), 2, "{hull:?}");
        for q in &det.primitives {
            assert!((q.area - 18.0).abs() < 1.0, "area {}", q.area);
            // Nothing of the gap is covered.
            let gap = q.frame.to_local(DVec3::new(7.5, 0.0, 1.5));
            assert!(!contains(&q.outline, gap));
        }
    }
}

/// A facade bent by 6 degrees (two faces of 4 m x 3 m meeting at a vertical
/// edge): a plane between the two faces holds both within the inlier
/// distance, more points than either face's own plane, and fails the
/// roughness test. Judged as its dominant layer, the candidate gives the
/// face whose plane holds the most of it within its noise, and the other
/// face stays in play for a later round; when the candidate left play
/// with its points, both faces were lost at one of these eight RANSAC
/// seeds.
#[test]
fn a_facade_bent_by_a_few_degrees_gives_both_faces() {
    let mut rng = Rng::new(6);
    let mut pts = Vec::new();
    let half = 3f64.to_radians();
    let faces = [
        DVec3::new(half.cos(), half.sin(), 0.0),
        DVec3::new(-half.cos(), half.sin(), 0.0),
    ];
    let edge = DVec3::new(0.0, 8.0, -1.8);
    for &u in &faces {
        rect(&mut pts, edge, u, DVec3::Z, 4.0, 3.0, 0.05, 0.01, &mut rng);
    }
    let ground = DVec3::new(-10.0, -10.0, -1.8);
    rect(
        &mut pts,
        ground,
        DVec3::X,
        DVec3::Y,
        20.0,
        17.9,
        0.1,
        0.01,
        &mut rng,
    );
    let cloud = cloud(&pts);
    for seed in 1..=8 {
        let det = detect_at_seed(&cloud, seed);
        for &u in &faces {
            let normal = u.cross(DVec3::Z).normalize();
            let middle = edge + u * 2.0 + DVec3::Z * 1.5;
            let face = det.primitives.iter().find(|q| {
                q.plane.normal.dot(normal).abs() > 2f64.to_radians().cos()
                    && contains(&q.outline, q.frame.to_local(middle))
            });
            let area = face.map_or(0.0, |q| q.area);
            // (The face found first takes the band of the other that its
            // plane's slab holds along the edge: 6-9 m^2 of 12 are left.)
            assert!(area > 5.0, "seed {seed}: the face along {u} has {area} m^2");
        }
    }
}

/// A road 10 m wide between two sidewalks a curb (0.15 m) above it, with no
/// curb faces and no viewpoint (a map tile): a plane tilted 0.7 degrees
/// holds the road at one side and a sidewalk at the other within the
/// ground's inlier distance, and more of their points than either surface's
/// own plane. Such a compromise either failed roughness and left play with
/// both surfaces, or passed it (a tilted slab over the road and a sidewalk).
/// When the cascade judged a candidate by roughness alone, a sidewalk was
/// lost at the first of these eight RANSAC seeds.
#[test]
fn a_road_between_two_sidewalks_a_curb_up_gives_three_level_surfaces() {
    let mut rng = Rng::new(8);
    let mut pts = Vec::new();
    // (y from, width, height)
    let surfaces = [(-13.0, 8.0, 0.15), (-5.0, 10.0, 0.0), (5.0, 8.0, 0.15)];
    for &(y, w, z) in &surfaces {
        let at = DVec3::new(0.0, y, z);
        rect(
            &mut pts,
            at,
            DVec3::X,
            DVec3::Y,
            40.0,
            w - 0.1,
            0.1,
            0.01,
            &mut rng,
        );
    }
    let cloud = cloud(&pts);
    let level = 1f64.to_radians().cos();
    for seed in 1..=8 {
        let det = detect_at_seed(&cloud, seed);
        // No polygon spans two heights or leans.
        for q in det.primitives.iter().filter(|q| q.area > 5.0) {
            let z: Vec<f64> = q.outline.iter().map(|&v| q.frame.to_world(v).z).collect();
            let on = |h: f64| z.iter().all(|&z| (z - h).abs() < 0.05);
            let (lo, hi) = z
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), &z| (l.min(z), h.max(z)));
            assert!(
                q.plane.normal.z.abs() > level && (on(0.0) || on(0.15)),
                "seed {seed}: a {} m^2 polygon with normal {} spans heights {lo} to {hi}",
                q.area,
                q.plane.normal
            );
        }
        // Each surface is covered: nine tenths of a grid over it lie in a
        // level polygon at its height.
        for &(y, w, z) in &surfaces {
            let (mut inside, mut all) = (0, 0);
            for i in 0..20 {
                for j in 0..(w as usize) {
                    let at = DVec3::new(1.0 + 2.0 * i as f64, y + 0.5 + j as f64, z);
                    all += 1;
                    inside += usize::from(det.primitives.iter().any(|q| {
                        q.plane.normal.z.abs() > level
                            && q.plane.signed_distance(at).abs() < 0.05
                            && contains(&q.outline, q.frame.to_local(at))
                    }));
                }
            }
            assert!(
                10 * inside >= 9 * all,
                "seed {seed}: the surface at y {y}, z {z} has {inside} of {all} in a polygon"
            );
        }
    }
}

/// Default detection of `cloud` at RANSAC `seed`, its invariants checked.
fn detect_at_seed(cloud: &Cloud, seed: u64) -> polyscene::detect::Detection {
    let p = Params {
        seed,
        ..Params::gpp2()
    };
    let det = detect(cloud, &p).unwrap();
    check_invariants(cloud, &det, &p);
    det
}

/// One plane often holds several surfaces: the sides of cars parked in a
/// row. Every cluster of the round's plane is judged, so all five are found
/// in the round that found the first; the paper's cascade (the largest
/// cluster per round) needs a round for each.
#[test]
fn one_plane_holding_several_surfaces_gives_each_in_one_round() {
    let mut rng = Rng::new(5);
    let mut pts = Vec::new();
    for k in 0..5 {
        rect(
            &mut pts,
            DVec3::new(k as f64 * 6.0, 0.0, 0.3),
            DVec3::X,
            DVec3::Z,
            4.5 - 0.2 * k as f64,
            1.2,
            0.05,
            0.01,
            &mut rng,
        );
    }
    let cloud = cloud(&pts);
    let p = Params {
        viewpoint: Some([12.0, -8.0, 1.8]),
        ..Params::gpp2()
    };
    let det = detect(&cloud, &p).unwrap();
    check_invariants(&cloud, &det, &p);
    assert_eq!(det.primitives.len(), 5);
    assert_eq!(det.steps[0].accepted, 5, "{:?}", det.steps);
    // Largest first, each on its own car side.
    for (k, q) in det.primitives.iter().enumerate() {
        let side = 4.5 - 0.2 * k as f64;
        // The outline runs through the boundary cells' centres: ~0.1 m in.
        let true_area = side * 1.2;
        assert!(
            q.area > 0.75 * true_area && q.area < true_area + 0.3,
            "{k}: area {}",
            q.area
        );
        let centre = q
            .frame
            .to_local(DVec3::new(k as f64 * 6.0 + side / 2.0, 0.0, 0.9));
        assert!(contains(&q.outline, centre), "{k}");
    }
    let paper = polyscene::detect::Detector::new(
        &p,
        polyscene::detect::CascadePolicy::scenario_leftovers(),
    )
    .run(
        &cloud.points,
        cloud.origin,
        DVec3::from_array(p.viewpoint.unwrap()),
    );
    assert_eq!(paper.primitives.len(), 5);
    assert!(paper.steps.iter().all(|s| s.accepted <= 1));
    assert!(paper.steps.len() >= 5);
}

#[test]
fn concave_outline_leaves_the_missing_corner_of_an_l_wall_uncovered() {
    let mut rng = Rng::new(4);
    let f = Frame::on_plane(
        &Plane::from_point_normal(DVec3::ZERO, -DVec3::Y),
        DVec3::ZERO,
    );
    let mut pts = Vec::new();
    // L: 10 x 6 minus the upper-right 5 x 3 block.
    region(
        &mut pts,
        &f,
        DVec2::ZERO,
        DVec2::new(10.0, 6.0),
        0.05,
        0.01,
        &mut rng,
        |q| !(q.x.abs() > 5.0 && q.y > 3.0),
    );
    let cloud = cloud(&pts);
    let p = Params {
        viewpoint: Some([5.0, -6.0, 1.8]),
        ..Params::gpp2()
    };
    let det = detect(&cloud, &p).unwrap();
    check_invariants(&cloud, &det, &p);
    assert_eq!(det.primitives.len(), 1);
    let q = &det.primitives[0];
    let world_corner = f.to_world(DVec2::new(6.5, 4.0));
    let world_arm = f.to_world(DVec2::new(2.5, 4.5));
    assert!(
        !contains(&q.outline, q.frame.to_local(world_corner)),
        "corner covered"
    );
    assert!(contains(&q.outline, q.frame.to_local(world_arm)));
    assert!((q.area - 45.0).abs() < 2.0, "area {}", q.area);
    // The convex hull, by contrast, covers the corner.
    let p = Params {
        hull: HullKind::Convex,
        viewpoint: Some([5.0, -6.0, 1.8]),
        ..Params::gpp2()
    };
    let det = detect(&cloud, &p).unwrap();
    let q = &det.primitives[0];
    assert!(contains(&q.outline, q.frame.to_local(world_corner)));
}

#[test]
fn planes_survive_heavy_outliers() {
    let mut rng = Rng::new(5);
    let mut pts = Vec::new();
    rect(
        &mut pts,
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        20.0,
        20.0,
        0.1,
        0.02,
        &mut rng,
    );
    let n = DVec3::new(1.0, 1.0, 0.0).normalize();
    let u = DVec3::Z.cross(n);
    rect(
        &mut pts,
        DVec3::new(10.0, 10.0, 0.0) - u * 5.0,
        u,
        DVec3::Z,
        10.0,
        4.0,
        0.1,
        0.02,
        &mut rng,
    );
    rect(
        &mut pts,
        DVec3::new(0.0, 20.0, 0.0),
        DVec3::X,
        DVec3::Z,
        20.0,
        5.0,
        0.1,
        0.02,
        &mut rng,
    );
    let planar = pts.len();
    // As many outliers as plane points, uniform in the scene's box.
    for _ in 0..planar {
        pts.push(DVec3::new(
            rng.range(0.0, 20.0),
            rng.range(0.0, 20.0),
            rng.range(0.0, 5.0),
        ));
    }
    let cloud = cloud(&pts);
    let p = Params {
        viewpoint: Some([10.0, 5.0, 1.8]),
        ..Params::gpp2()
    };
    let det = detect(&cloud, &p).unwrap();
    check_invariants(&cloud, &det, &p);
    let truth = [DVec3::Z, n, DVec3::Y];
    for t in truth {
        let best = det
            .primitives
            .iter()
            .filter(|q| q.area > 10.0)
            .map(|q| q.plane.normal.dot(t).abs())
            .fold(0.0, f64::max);
        assert!(best > libm::cos(2f64.to_radians()), "plane {t} not found");
    }
    // Random outliers do not make big polygons of their own.
    let big = det.primitives.iter().filter(|q| q.area > 10.0).count();
    assert_eq!(
        big,
        3,
        "{:?}",
        det.primitives.iter().map(|q| q.area).collect::<Vec<_>>()
    );
}

#[test]
fn degenerate_inputs_give_empty_or_trivial_answers() {
    let p = Params::gpp2();
    let empty = Cloud::from_flat(&[], 3).unwrap();
    assert!(detect(&empty, &p).unwrap().primitives.is_empty());
    for n in 1..=3 {
        let pts: Vec<f32> = (0..n)
            .flat_map(|i| [i as f32, (i * i) as f32, 0.0])
            .collect();
        let c = Cloud::from_flat(&pts, 3).unwrap();
        assert!(detect(&c, &p).unwrap().primitives.is_empty());
    }
    let line: Vec<DVec3> = (0..5000)
        .map(|i| DVec3::new(i as f64 * 0.01, 2.0 * i as f64 * 0.01, 1.0))
        .collect();
    assert!(detect(&cloud(&line), &p).unwrap().primitives.is_empty());
    let same = vec![DVec3::new(1.0, 2.0, 3.0); 5000];
    assert!(detect(&cloud(&same), &p).unwrap().primitives.is_empty());
    // All on one plane: one polygon.
    let mut rng = Rng::new(6);
    let mut pts = Vec::new();
    rect(
        &mut pts,
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        5.0,
        5.0,
        0.05,
        0.0,
        &mut rng,
    );
    let c = cloud(&pts);
    let det = detect(&c, &p).unwrap();
    check_invariants(&c, &det, &p);
    assert_eq!(det.primitives.len(), 1);
    assert_eq!(det.primitives[0].support as usize, pts.len());
}

#[test]
fn bad_values_are_errors_not_panics() {
    let e = Cloud::from_flat(&[0.0, 1.0, f32::NAN], 3).unwrap_err();
    assert!(matches!(e, Error::NonFinite { point: 0 }));
    let e = Cloud::from_flat(&[0.0, 1.0, 2.0, 3.0, f32::INFINITY, 0.0], 3).unwrap_err();
    assert!(matches!(e, Error::NonFinite { point: 1 }));
    assert!(matches!(
        Cloud::from_flat(&[0.0; 7], 3),
        Err(Error::BadLength { .. })
    ));
    assert!(matches!(
        Cloud::from_flat(&[0.0; 6], 2),
        Err(Error::BadStride(2))
    ));
    let mut bad = Params::gpp2();
    bad.other.distance = -1.0;
    let e = detect(&Cloud::default(), &bad).unwrap_err();
    assert!(e.to_string().contains("distance"));
}

#[test]
fn same_input_and_seed_same_output() {
    let mut rng = Rng::new(8);
    let pts = box_room(&mut rng);
    let c = cloud(&pts);
    let p = Params::gpp2();
    let a = detect(&c, &p).unwrap();
    let b = detect(&c, &p).unwrap();
    assert_eq!(a.primitives, b.primitives);
    assert_eq!(a.labels, b.labels);
}

#[test]
fn progress_is_reported_after_each_round_and_can_stop_the_detection() {
    use polyscene::detect::{detect_with_progress, Progress};
    use std::ops::ControlFlow;
    let mut rng = Rng::new(8);
    let pts = box_room(&mut rng);
    let c = cloud(&pts);
    let p = Params::gpp2();
    let plain = detect(&c, &p).unwrap();
    let mut seen: Vec<Progress> = Vec::new();
    let reported = detect_with_progress(&c, &p, &[], &mut |at| {
        seen.push(*at);
        ControlFlow::Continue(())
    })
    .unwrap()
    .expect("not stopped");
    // Watching changes nothing.
    assert_eq!(reported.primitives, plain.primitives);
    assert_eq!(reported.labels, plain.labels);
    assert_eq!(seen.len(), plain.steps.len(), "one report per round");
    for (k, at) in seen.iter().enumerate() {
        assert_eq!(at.round, k + 1);
        assert_eq!(at.points, pts.len());
        assert!(at.points_left <= pts.len());
        if k > 0 {
            assert!(
                at.points_left <= seen[k - 1].points_left,
                "points left only fall"
            );
            assert!(at.primitives >= seen[k - 1].primitives);
        }
    }
    assert!(seen.last().unwrap().primitives >= plain.primitives.len());
    // Stopped after the second round: no result, and no third report.
    let mut calls = 0;
    let stopped = detect_with_progress(&c, &p, &[], &mut |at| {
        calls += 1;
        if at.round == 2 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
    .unwrap();
    assert!(stopped.is_none());
    assert_eq!(calls, 2);
    // Bad options are errors before any round.
    let bad = Params {
        min_area: -1.0,
        ..Params::gpp2()
    };
    let mut called = false;
    assert!(detect_with_progress(&c, &bad, &[], &mut |_| {
        called = true;
        ControlFlow::Continue(())
    })
    .is_err());
    assert!(!called);
}

#[test]
fn far_from_the_origin_gives_the_same_polygons_translated() {
    let mut rng = Rng::new(9);
    let pts = box_room(&mut rng);
    let shift = DVec3::new(500_000.0, 4_500_000.0, 50.0);
    let moved: Vec<DVec3> = pts.iter().map(|&p| p + shift).collect();
    for hull in [HullKind::Convex, HullKind::Concave] {
        let p = Params {
            hull,
            viewpoint: Some([5.0, 4.0, 1.8]),
            ..Params::gpp2()
        };
        let far = Params {
            viewpoint: Some((DVec3::new(5.0, 4.0, 1.8) + shift).to_array()),
            ..p.clone()
        };
        let a = detect(&cloud(&pts), &p).unwrap();
        let b = detect(&cloud(&moved), &far).unwrap();
        assert_eq!(a.primitives.len(), b.primitives.len());
        for (x, y) in a.primitives.iter().zip(&b.primitives) {
            let (vx, vy) = (x.vertices(), y.vertices());
            assert_eq!(vx.len(), vy.len());
            for (u, v) in vx.iter().zip(&vy) {
                assert!((*u + shift - *v).length() < 1e-3, "{hull:?}: {u} vs {v}");
            }
            assert!((x.plane.normal - y.plane.normal).length() < 1e-6);
        }
    }
}

#[test]
fn clouds_beyond_the_scoring_pool_keep_small_planes_and_stay_total() {
    // 1.5M floor points: RANSAC scores on a random subset of 2^18 of them.
    // Once the floor is taken, a 2 m x 1 m wall of 200 points and three
    // stray points are left, few of them (or none) in that subset: the pool
    // is redrawn from the live points, the wall is found, and nothing panics
    // even with `min_inliers` at its smallest.
    let mut rng = Rng::new(21);
    let mut pts = Vec::with_capacity(1_500_300);
    for _ in 0..1_500_000 {
        pts.push(DVec3::new(
            rng.range(0.0, 50.0),
            rng.range(0.0, 30.0),
            rng.range(-0.01, 0.01),
        ));
    }
    for i in 0..20 {
        for j in 0..10 {
            pts.push(DVec3::new(
                80.0,
                10.0 + i as f64 * 0.1,
                1.0 + j as f64 * 0.1,
            ));
        }
    }
    pts.extend([
        DVec3::new(90.0, 0.0, 5.0),
        DVec3::new(95.0, 7.0, 9.0),
        DVec3::new(99.0, 3.0, 2.0),
    ]);
    let cloud = cloud(&pts);
    for min_inliers in [150, 3] {
        let p = Params {
            viewpoint: Some([25.0, 15.0, 2.0]),
            min_inliers,
            min_area: 1.0,
            ..Params::gpp2()
        };
        let det = detect(&cloud, &p).unwrap();
        let floor = det.primitives.iter().find(|q| q.ground).expect("the floor");
        assert!((floor.area - 1500.0).abs() < 30.0, "floor {}", floor.area);
        let wall = det
            .primitives
            .iter()
            .find(|q| q.plane.normal.x.abs() > 0.99)
            .unwrap_or_else(|| panic!("min_inliers {min_inliers}: no wall"));
        assert!(wall.support >= 190, "wall support {}", wall.support);
        assert!((wall.area - 2.0).abs() < 0.6, "wall area {}", wall.area);
    }
}

/// Scored on the LiDAR test bed's ground truth: gpp2 on five simulated
/// street scans (about 120k points each) and on a ten-scan location. The
/// floors sit below what the detector gives today (scans: precision 1.0,
/// recall 0.21, mean one-sided Hausdorff 2.7 mm, completeness 0.49;
/// location A: its road as one 610 m^2 polygon) and above what the
/// count-scored RANSAC gave (recall 0.15, completeness 0.39; on location A
/// a plane tilted across the road and a sidewalk won, its rough support was
/// rejected and the road was lost but for a 140 m^2 piece).
#[test]
fn simulated_street_scans_and_a_location_meet_quality_floors() {
    use polyscene::eval::{evaluate, EvalOptions};
    let (drive, gt) = drive_truth(polyscene::sim::Layout::Street);
    let opts = EvalOptions::default();
    let (mut recall, mut mean, mut completeness) = (0.0, 0.0, 0.0);
    let scans = [10, 30, 50, 70, 90];
    for k in scans {
        let scan = drive.scan(k).unwrap();
        let world = scan.world_points();
        let cloud = Cloud::from_world_f64(&world).unwrap();
        let p = Params {
            viewpoint: Some(scan.pose.w_axis.truncate().to_array()),
            ..Params::gpp2()
        };
        let det = detect(&cloud, &p).unwrap();
        check_invariants(&cloud, &det, &p);
        let polys: Vec<_> = det.primitives.iter().map(|q| q.polygon()).collect();
        let m = evaluate(&polys, &gt, &world, &scan.labels, world.len(), &opts).unwrap();
        assert!(
            m.detection.precision >= 0.95,
            "scan {k}: precision {}",
            m.detection.precision
        );
        // Each surface once: the pieces one plane's clusters and a later
        // round both outlined are merged.
        assert_eq!(m.duplicates.count, 0, "scan {k}: duplicates");
        recall += m.detection.recall / scans.len() as f64;
        mean += m.accuracy.mean.unwrap() / scans.len() as f64;
        completeness += m.completeness.completeness / scans.len() as f64;
    }
    // Measured: recall 0.366, completeness 0.651. Regression guard for the
    // one-shot rules that lift them: no hypotheses through the viewpoint
    // (the facades keep their bands at the sensor's height), occupancy on
    // 2 x 2-cell blocks, no sliver samples, at most `maxHypotheses` a round.
    assert!(recall > 0.33, "recall {recall}");
    assert!(mean < 0.004, "mean one-sided Hausdorff {mean}");
    assert!(completeness > 0.635, "completeness {completeness}");

    let loc = drive.location(0, 10).unwrap();
    let cloud = Cloud::from_world_f64(&loc.points).unwrap();
    let centre = loc.viewpoint();
    let p = Params {
        viewpoint: Some(centre.to_array()),
        ..Params::gpp2()
    };
    let det = detect(&cloud, &p).unwrap();
    let road = det
        .primitives
        .iter()
        .filter(|q| q.ground && q.plane.normal.z > 0.9999 && q.plane.offset.abs() < 0.02)
        .map(|q| q.area)
        .fold(0.0, f64::max);
    assert!(road > 500.0, "largest flat road polygon {road} m^2");
    let m = score_location(&det, &gt, &loc);
    assert!(
        m.detection.precision >= 0.95,
        "location precision {}",
        m.detection.precision
    );
    assert_eq!(m.duplicates.count, 0, "location duplicates");
    // Measured: completeness 0.889. Regression guard: the road's far rings
    // (the ground's clustering tolerance growing with range, its footprint
    // bridging the rings' gaps) and the facades and cars that sliver samples
    // would cut bands out of are what lift it above 0.85.
    assert!(
        m.completeness.completeness > 0.85,
        "location completeness {}",
        m.completeness.completeness
    );
    assert!(
        m.accuracy.mean.unwrap() < 0.006,
        "location mean {:?}",
        m.accuracy.mean
    );
}

/// A parked car's side in two overlapping pieces 2 degrees apart: at RANSAC
/// seed 2, one-shot detection of the street location from scan 60 (mean
/// pose) found one piece tilted by the strip of the car's end face its slab
/// held at the corner, and the merge pass kept it apart (a tenth of its
/// points lay off the other's plane). The strip is taken off and the two
/// merge, at this seed and its neighbours, with the support contract kept.
#[test]
fn a_car_side_tilted_by_its_end_face_merges_at_other_seeds() {
    let (drive, gt) = drive_truth(polyscene::sim::Layout::Street);
    let loc = drive.location(60, 10).unwrap();
    let cloud = Cloud::from_world_f64(&loc.points).unwrap();
    for seed in [1, 2, 3] {
        let p = Params {
            viewpoint: Some(loc.viewpoint().to_array()),
            seed,
            ..Params::gpp2()
        };
        let det = detect(&cloud, &p).unwrap();
        check_invariants(&cloud, &det, &p);
        let m = score_location(&det, &gt, &loc);
        assert_eq!(
            m.duplicates.count, 0,
            "seed {seed}: {:?}",
            m.duplicates.pairs
        );
        assert!(
            m.detection.precision >= 0.95,
            "seed {seed}: precision {}",
            m.detection.precision
        );
    }
}

/// The outline contract on a whole location: every support point within
/// one raster cell plus the simplification tolerance of its outline. The
/// road of a location takes 100-120 vertices; with a vertex cap of 64 the
/// tolerance was raised to meet it and road points lay up to 0.34 m outside
/// (the bound is 0.3 m) on this location and three others.
#[test]
fn a_location_s_support_lies_within_the_outline_resolution() {
    use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};
    let drive = Drive::new(
        Layout::Street,
        1,
        SensorModel::default(),
        DriveOptions::default(),
    )
    .unwrap();
    let loc = drive.location(80, 10).unwrap();
    let centre = loc.viewpoint();
    let det = detect_checked(&loc.points, centre.to_array());
    let road = &det.primitives[0];
    assert!(road.ground && road.area > 500.0, "{}", road.area);
    assert!(road.outline.len() > 64, "{} vertices", road.outline.len());
}

/// gpp2 detection seen from `viewpoint`, its invariants checked.
fn detect_checked(pts: &[DVec3], viewpoint: [f64; 3]) -> polyscene::detect::Detection {
    let c = cloud(pts);
    let p = Params {
        viewpoint: Some(viewpoint),
        ..Params::gpp2()
    };
    let det = detect(&c, &p).unwrap();
    check_invariants(&c, &det, &p);
    det
}

/// 30 m x 30 m of flat ground (z = 0 +- 5 mm) around the origin, every 0.1 m.
fn flat_ground(rng: &mut Rng) -> Vec<DVec3> {
    let mut pts = Vec::new();
    let corner = DVec3::new(-15.0, -15.0, 0.0);
    rect(
        &mut pts,
        corner,
        DVec3::X,
        DVec3::Y,
        30.0,
        30.0,
        0.1,
        0.005,
        rng,
    );
    pts
}

/// Flat ground and a 3 m x 3 m horizontal patch at height `z` above it,
/// 6-9 m from the origin.
fn patch_over_ground(z: f64, rng: &mut Rng) -> Vec<DVec3> {
    let mut pts = flat_ground(rng);
    rect(
        &mut pts,
        DVec3::new(6.0, -1.5, z),
        DVec3::X,
        DVec3::Y,
        3.0,
        3.0,
        0.05,
        0.0,
        rng,
    );
    pts
}

/// How many horizontal primitives lie at height `z`.
fn flat_at(det: &polyscene::detect::Detection, z: f64) -> usize {
    det.primitives
        .iter()
        .filter(|q| {
            q.plane.normal.z.abs() > 0.999 && (q.plane.offset * q.plane.normal.z + z).abs() < 0.02
        })
        .count()
}

/// A sensor cannot see a surface it lies in: a plane through the viewpoint,
/// away from it, is the laser rings at the sensor's own height (over a
/// location they close into a few m^2 of false surface). Such a candidate
/// is dropped; the same patch a little higher, and a floor under a sensor
/// standing on it, are kept.
#[test]
fn planes_through_the_viewpoint_away_from_it_are_not_surfaces() {
    let mut rng = Rng::new(21);
    let p = Params {
        viewpoint: Some([0.0, 0.0, 1.8]),
        ..Params::gpp2()
    };
    // At sensor height: only the ground.
    let c = cloud(&patch_over_ground(1.8, &mut rng));
    let det = detect(&c, &p).unwrap();
    check_invariants(&c, &det, &p);
    assert_eq!(flat_at(&det, 0.0), 1);
    assert_eq!(flat_at(&det, 1.8), 0);
    // Half a metre higher it is seen from below: kept.
    let c = cloud(&patch_over_ground(2.3, &mut rng));
    let det = detect(&c, &p).unwrap();
    assert_eq!((flat_at(&det, 0.0), flat_at(&det, 2.3)), (1, 1));
    // A sensor standing on the floor sees the floor.
    let c = cloud(&flat_ground(&mut rng));
    let on_floor = Params {
        viewpoint: Some([2.0, 3.0, 0.0]),
        ..Params::gpp2()
    };
    assert_eq!(flat_at(&detect(&c, &on_floor).unwrap(), 0.0), 1);
}

/// A cloud gathered from several sensor positions (`detect_from`): a patch
/// whose plane passes through every one of them is laser rings, dropped;
/// one that a sensor saw from below is a surface, kept. Seen from nowhere
/// (no positions) the patch is kept too.
#[test]
fn a_map_drops_planes_seen_edge_on_from_every_sensor_only() {
    use polyscene::detect::detect_from;
    let mut rng = Rng::new(23);
    let c = cloud(&patch_over_ground(1.8, &mut rng));
    let p = Params::gpp2();
    let patches = |det: &polyscene::detect::Detection| flat_at(det, 1.8);
    let level = [DVec3::new(0.0, 0.0, 1.8), DVec3::new(4.0, 0.5, 1.8)];
    let det = detect_from(&c, &p, &level).unwrap();
    check_invariants(&c, &det, &p);
    assert_eq!(patches(&det), 0);
    assert!(det.primitives.iter().any(|q| q.ground), "the ground stays");
    let one_higher = [DVec3::new(0.0, 0.0, 1.8), DVec3::new(4.0, 0.5, 2.6)];
    assert_eq!(patches(&detect_from(&c, &p, &one_higher).unwrap()), 1);
    assert_eq!(patches(&detect_from(&c, &p, &[]).unwrap()), 1);
    // Positions and a single viewpoint together, or a position that is no
    // number, are errors.
    let both = Params {
        viewpoint: Some([0.0, 0.0, 1.8]),
        ..Params::gpp2()
    };
    let e = detect_from(&c, &both, &level).unwrap_err().to_string();
    assert!(e.contains("'viewpoint'"), "{e}");
    let nan = [DVec3::new(0.0, f64::NAN, 1.8)];
    let e = detect_from(&c, &p, &nan).unwrap_err().to_string();
    assert!(
        e.contains("'viewpoints'") && e.contains("position 0"),
        "{e}"
    );
}

/// The beam at the sensor's own elevation draws a horizontal ring across
/// everything around (here vegetation 12 m away, 30,000 points) and a band
/// across every wall. That plane is seen edge-on: as a candidate it would
/// be rejected, and the wall's band would leave play with it. It is no
/// hypothesis at all, so the wall keeps its band and is outlined whole.
#[test]
fn the_ring_at_sensor_height_leaves_the_walls_their_band() {
    let mut rng = Rng::new(5);
    let mut pts = flat_ground(&mut rng);
    let (x, z) = (DVec3::X, DVec3::Z);
    let wall = pts.len()..{
        // 8 m x 4 m, 8 m in front of the sensor.
        rect(
            &mut pts,
            DVec3::new(-4.0, 8.0, 0.0),
            x,
            z,
            8.0,
            4.0,
            0.05,
            0.005,
            &mut rng,
        );
        pts.len()
    };
    for k in 0..30_000 {
        let a = std::f64::consts::TAU * k as f64 / 30_000.0;
        let r = 12.0 + (rng.uniform() - 0.5) * 0.6;
        pts.push(DVec3::new(
            r * a.cos(),
            r * a.sin(),
            1.8 + 0.01 * rng.gaussian(),
        ));
    }
    let det = detect_checked(&pts, [0.0, 0.0, 1.8]);
    // The wall's primitive: the label most of its points carry (those
    // above the ground's slab).
    let wall: Vec<usize> = wall.filter(|&i| pts[i].z > 0.1).collect();
    let mut votes = vec![0usize; det.primitives.len()];
    for &i in &wall {
        if let Some(v) = votes.get_mut(det.labels[i] as usize) {
            *v += 1;
        }
    }
    let id = (0..votes.len()).max_by_key(|&k| votes[k]).unwrap();
    let q = &det.primitives[id];
    assert!(q.plane.normal.y.abs() > 0.999, "{:?}", q.plane);
    assert!(
        votes[id] as f64 > 0.98 * wall.len() as f64,
        "{} of {}",
        votes[id],
        wall.len()
    );
    let band: Vec<usize> = wall
        .into_iter()
        .filter(|&i| (pts[i].z - 1.8).abs() < 0.08)
        .collect();
    let kept = band
        .iter()
        .filter(|&&i| det.labels[i] as usize == id)
        .count();
    assert!(
        kept as f64 > 0.98 * band.len() as f64,
        "band: {kept} of {}",
        band.len()
    );
    // 32 m^2, outlined through the boundary cells' centres.
    assert!(q.area > 29.0 && q.area < 32.1, "wall area {}", q.area);
    // And nothing horizontal at the sensor's height.
    assert!(!det
        .primitives
        .iter()
        .any(|q| q.plane.normal.z.abs() > 0.99
            && (q.plane.offset * q.plane.normal.z + 1.8).abs() < 0.2));
}

/// A far facade as a LiDAR sees it: laser rings 0.49 m apart, dense along
/// each ring. Fewer than half of the 0.2 m cells inside its outline hold a
/// point, but most of its blocks of 2 x 2 cells do: it is a solid surface
/// at the sensor's resolution and is kept.
#[test]
fn a_wall_seen_as_rings_farther_apart_than_a_cell_is_kept() {
    let mut rng = Rng::new(8);
    let mut pts = flat_ground(&mut rng);
    for r in 0..8 {
        for i in 0..120 {
            let z = 0.3 + 0.49 * r as f64 + 0.002 * rng.gaussian();
            pts.push(DVec3::new(
                -3.0 + 0.05 * i as f64,
                12.0 + 0.005 * rng.gaussian(),
                z,
            ));
        }
    }
    let det = detect_checked(&pts, [0.0, 0.0, 1.8]);
    let walls: Vec<_> = det
        .primitives
        .iter()
        .filter(|q| q.plane.normal.y.abs() > 0.999)
        .collect();
    assert_eq!(walls.len(), 1, "{} walls", walls.len());
    // 5.95 m x 3.43 m, to a cell and the simplification tolerance.
    assert!(
        walls[0].area > 16.0 && walls[0].area < 22.0,
        "wall area {}",
        walls[0].area
    );
    let cells = walls[0].footprint.occupied_area() / walls[0].area;
    assert!(cells < 0.5, "cell occupancy {cells}");
}

/// Points on flat ground (z = 0 +- 1 cm) along circles of these radii
/// around the origin, 0.1 m apart along each, each radius off by up to
/// `jitter`: the laser rings of a sensor 1.8 m above the origin.
fn ground_rings(radii: &[f64], jitter: f64, rng: &mut Rng) -> Vec<DVec3> {
    let mut pts = Vec::new();
    for &r in radii {
        let steps = (std::f64::consts::TAU * r / 0.1) as usize;
        for s in 0..steps {
            let a = std::f64::consts::TAU * s as f64 / steps as f64;
            let rr = r + rng.range(-jitter, jitter);
            pts.push(DVec3::new(
                rr * libm::cos(a),
                rr * libm::sin(a),
                rng.range(-0.01, 0.01),
            ));
        }
    }
    pts
}

/// The largest ground polygon's area (m^2) gpp2 with these changes finds
/// in `cloud` seen from 1.8 m above the origin, the detection's invariants
/// checked.
fn largest_ground_area(cloud: &Cloud, change: impl Fn(&mut Params)) -> f64 {
    let mut p = Params {
        viewpoint: Some([0.0, 0.0, 1.8]),
        ..Params::gpp2()
    };
    change(&mut p);
    let det = detect(cloud, &p).unwrap();
    check_invariants(cloud, &det, &p);
    det.primitives
        .iter()
        .filter(|q| q.ground)
        .map(|q| q.area)
        .fold(0.0, f64::max)
}

/// Laser rings on flat ground: 0.15 m apart near the sensor, 0.8 m apart
/// beyond 12 m (as an HDL-64E's lower rings are 15-20 m out). With the
/// ground's clustering tolerance above the far spacing all rings are one
/// surface and one polygon; with the default 0.5 m the far rings are strips
/// of their own, too thin to be polygons, and only the near disc is mapped.
#[test]
fn ground_rings_join_under_the_ground_clustering_tolerance() {
    let mut rng = Rng::new(11);
    let radii: Vec<f64> = (0..60)
        .map(|k| 3.0 + 0.15 * k as f64)
        .chain((0..8).map(|k| 12.8 + 0.8 * k as f64))
        .collect();
    let cloud = cloud(&ground_rings(&radii, 0.03, &mut rng));
    let ground_area = |tol: f64| largest_ground_area(&cloud, |p| p.ground.cluster_tolerance = tol);
    let annulus = std::f64::consts::PI * (18.4f64.powi(2) - 3.0f64.powi(2));
    let near = std::f64::consts::PI * (11.85f64.powi(2) - 3.0f64.powi(2));
    let joined = ground_area(1.0);
    assert!(
        joined > 0.9 * annulus && joined < 1.05 * annulus,
        "one polygon over all rings: {joined} m^2 of {annulus}"
    );
    let split = ground_area(Params::gpp2().ground.cluster_tolerance);
    assert!(
        split > 0.9 * near && split < 1.1 * near,
        "the near disc only: {split} m^2 of {near}"
    );
}

/// A sensor on a vehicle sees the ground from about 3 m out: under and
/// around the vehicle lies a disc where no ring falls. One-shot detection's
/// ground outline leaves that disc out (a hole of `minArea` or more, cut
/// to the outline's edge by a slit), with or without the viewpoint, and
/// nearly all of the polygon lies within 0.2 m of a point. Measured, with
/// the viewpoint and without: 297.8 m^2 (the rings' annulus 289.0 m^2,
/// the outline half a cell beyond them), share 0.9995; with the disc
/// filled (`CascadePolicy::cut_holes` off) 325.0 m^2, share 0.924.
#[test]
fn the_ground_outline_leaves_the_blind_disc_under_the_sensor_out() {
    let mut rng = Rng::new(13);
    let radii: Vec<f64> = (0..48).map(|k| 3.0 + 0.15 * k as f64).collect();
    let pts = ground_rings(&radii, 0.03, &mut rng);
    let cloud = cloud(&pts);
    for viewpoint in [Some([0.0, 0.0, 1.8]), None] {
        let p = Params {
            viewpoint,
            ..Params::gpp2()
        };
        let det = detect(&cloud, &p).unwrap();
        check_invariants(&cloud, &det, &p);
        let ground: Vec<_> = det.primitives.iter().filter(|q| q.ground).collect();
        assert_eq!(ground.len(), 1, "{viewpoint:?}");
        let q = ground[0];
        let annulus = std::f64::consts::PI * (10.05f64.powi(2) - 3.0f64.powi(2));
        assert!(
            q.area > 0.9 * annulus && q.area < 1.05 * annulus,
            "{viewpoint:?}: {} m^2 against the rings' {annulus}",
            q.area
        );
        let ring = q.polygon();
        for c in [
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, -2.0, 0.0),
        ] {
            let local = q.frame.to_local(c);
            assert!(!contains(&q.outline, local), "{viewpoint:?}: {c} covered");
        }
        let on = polyscene::eval::on_data(&[ring], &pts, 0.2);
        assert!(on.share > 0.95, "{viewpoint:?}: share {}", on.share);
    }
}

/// Laser rings on flat ground out to 30 m, 0.15 m apart up to 20 m and
/// then farther apart with the square of the range (0.45 m at 20 m, 1 m at
/// 30 m), as the far rings of a real sensor are. Beyond
/// `groundClusterRange` (20 m) the ground's clustering tolerance grows the
/// same way, so the whole disc is one polygon; without that growth (a range
/// beyond the cloud) the rings past about 22 m are strips of their own, too
/// thin to be polygons, and the ground polygon stops there.
#[test]
fn far_ground_rings_join_beyond_the_ground_clustering_range() {
    let mut rng = Rng::new(12);
    let mut radii = vec![3.0f64];
    while let Some(&r) = radii.last().filter(|&&r| r < 30.0) {
        radii.push(
            r + if r < 20.0 {
                0.15
            } else {
                0.45 * (r / 20.0).powi(2)
            },
        );
    }
    radii.pop();
    let outer = *radii.last().unwrap();
    let cloud = cloud(&ground_rings(&radii, 0.02, &mut rng));
    let ground_area = |range: f64| largest_ground_area(&cloud, |p| p.ground_cluster_range = range);
    let disc = std::f64::consts::PI * (outer * outer - 9.0);
    let joined = ground_area(Params::gpp2().ground_cluster_range);
    assert!(
        joined > 0.9 * disc && joined < 1.05 * disc,
        "one polygon out to {outer:.1} m: {joined} m^2 of {disc}"
    );
    let near = std::f64::consts::PI * (20.0f64.powi(2) - 9.0);
    let split = ground_area(1e6);
    assert!(
        split > 0.9 * near && split < 0.7 * disc,
        "the disc within about 22 m only: {split} m^2 (within 20 m: {near}, all: {disc})"
    );
}

/// A road strip 12 m wide as ten accumulated scans see it far out: laser
/// rings, 0.15 m apart up to 20 m, then gaps growing to 5.8 m at 80 m (four
/// fifths of what the ground's clustering bridges there). The rings are one
/// cluster, and the outline follows them all: the footprint fills the gaps
/// the clustering bridged. Without that the outline's closing radius
/// (`groundAlpha`, 1 m) stops it where the gaps pass 2 m, about 46 m out,
/// and the farther rings lose their label.
#[test]
fn the_ground_outline_follows_far_rings_as_far_as_they_cluster() {
    let mut rng = Rng::new(13);
    let p = Params::gpp2();
    let (range, tol) = (p.ground_cluster_range, p.ground.cluster_tolerance);
    let reach = |r: f64| tol * r * r / (range * range + tol * r);
    let mut radii = vec![3.0f64];
    while let Some(&r) = radii.last().filter(|&&r| r < 80.0) {
        radii.push(r + if r < 20.0 { 0.15 } else { 0.8 * reach(r) });
    }
    radii.pop();
    let outer = *radii.last().unwrap();
    assert!(outer > 75.0, "{outer}");
    let pts: Vec<DVec3> = ground_rings(&radii, 0.02, &mut rng)
        .into_iter()
        .filter(|q| q.y.abs() < 6.0)
        .collect();
    let det = detect_checked(&pts, [0.0, 0.0, 1.8]);
    let road = &det.primitives[0];
    assert!(road.ground);
    // Every ring is in the road's support, the farthest included.
    let kept = det.labels.iter().filter(|&&l| l == 0).count();
    assert!(
        kept as f64 > 0.99 * pts.len() as f64,
        "{kept} of {}",
        pts.len()
    );
    let far: Vec<usize> = (0..pts.len()).filter(|&i| pts[i].x.abs() > 60.0).collect();
    assert!(far.len() > 500 && far.iter().all(|&i| det.labels[i] == 0));
    // One polygon over the strip out to the last ring on both sides, and
    // not beyond it.
    let strip = 12.0 * 2.0 * (outer - 3.0);
    assert!(
        road.area > 0.95 * strip && road.area < 1.05 * strip,
        "{} m^2 of {strip}",
        road.area
    );
    for x in [-0.95 * outer, 0.95 * outer] {
        let q = road.frame.to_local(DVec3::new(x, 0.0, 0.0));
        assert!(contains(&road.outline, q), "({x}, 0)");
    }
    let reach_x = road
        .outline
        .iter()
        .map(|&v| road.frame.to_world(v).x.abs())
        .fold(0.0, f64::max);
    assert!(reach_x < outer + 0.5, "{reach_x} beyond {outer}");
}

/// A world-frame location (ten scans accumulated) given with no viewpoint:
/// its origin is on the road, where no sensor stood, so detection takes the
/// ground from the cloud's local floor and drops the rules that need a
/// viewpoint. Before, the origin was taken for the sensor: the road passed
/// through it edge-on and was rejected as laser rings, and completeness
/// fell to 0.58 (seed 1). Eight locations along the street (scans 10-80):
/// each keeps its ground; without the viewpoint's rules a horizontal patch
/// of laser rings can remain here and there, so precision is judged over
/// all eight. Measured: completeness 0.767-0.830 at each, precision
/// 0.913-0.988 (0.940 on average).
#[test]
fn a_world_frame_location_without_a_viewpoint_keeps_its_ground() {
    let (drive, gt) = drive_truth(polyscene::sim::Layout::Street);
    let p = Params::gpp2();
    assert_eq!(p.viewpoint, None);
    let starts = [10, 20, 30, 40, 50, 60, 70, 80];
    let mut precision = 0.0;
    for start in starts {
        let loc = drive.location(start, 10).unwrap();
        let cloud = Cloud::from_world_f64(&loc.points).unwrap();
        let det = detect(&cloud, &p).unwrap();
        check_invariants(&cloud, &det, &p);
        let ground: f64 = det
            .primitives
            .iter()
            .filter(|q| q.ground)
            .map(|q| q.area)
            .sum();
        assert!(ground > 900.0, "scan {start}: ground {ground} m^2");
        let m = score_location(&det, &gt, &loc);
        assert!(
            m.completeness.completeness > 0.85,
            "scan {start}: {}",
            m.completeness.completeness
        );
        assert_eq!(m.duplicates.count, 0, "scan {start}");
        precision += m.detection.precision / starts.len() as f64;
    }
    assert!(precision > 0.93, "{precision}");
}

/// The same locations with the positions of the scans they were gathered
/// from: the patches of laser rings at the sensors' height (the share of
/// false positives seen from nowhere) are dropped, and what the map holds
/// stays.
#[test]
fn a_location_with_its_sensor_positions_drops_the_rings_and_keeps_the_map() {
    use polyscene::detect::detect_from;
    let (drive, gt) = drive_truth(polyscene::sim::Layout::Street);
    let p = Params::gpp2();
    let starts = [10, 20, 30, 40, 50, 60, 70, 80];
    let (mut precision, mut recall, mut recall_nowhere) = (0.0, 0.0, 0.0);
    for start in starts {
        let loc = drive.location(start, 10).unwrap();
        let cloud = Cloud::from_world_f64(&loc.points).unwrap();
        let sensors: Vec<DVec3> = (start..start + 10)
            .map(|k| drive.scan(k).unwrap().pose.w_axis.truncate())
            .collect();
        let det = detect_from(&cloud, &p, &sensors).unwrap();
        check_invariants(&cloud, &det, &p);
        let m = score_location(&det, &gt, &loc);
        let nowhere = score_location(&detect(&cloud, &p).unwrap(), &gt, &loc);
        println!(
            "scan {start}: precision {:.3} (nowhere {:.3}), recall {:.3} ({:.3}), completeness {:.3} ({:.3})",
            m.detection.precision,
            nowhere.detection.precision,
            m.detection.recall,
            nowhere.detection.recall,
            m.completeness.completeness,
            nowhere.completeness.completeness
        );
        assert!(
            m.completeness.completeness > nowhere.completeness.completeness - 0.01,
            "scan {start}"
        );
        assert_eq!(m.duplicates.count, 0, "scan {start}");
        precision += m.detection.precision / starts.len() as f64;
        recall += m.detection.recall / starts.len() as f64;
        recall_nowhere += nowhere.detection.recall / starts.len() as f64;
    }
    println!("precision {precision:.3}, recall {recall:.3} ({recall_nowhere:.3} from nowhere)");
    assert!(precision > 0.98, "{precision}");
    assert!(recall > recall_nowhere - 0.02, "{recall} {recall_nowhere}");
}

/// Without a viewpoint, `detect` says what it went by: the origin for a
/// scan in its own frame (1.8 m above its ground), no sensor for the same
/// scan moved to map coordinates (read as a map), the viewpoint when given.
#[test]
fn detection_reports_the_sensor_it_went_by() {
    let mut rng = Rng::new(5);
    let pts: Vec<DVec3> = flat_ground(&mut rng)
        .into_iter()
        .map(|q| q - DVec3::new(0.0, 0.0, 1.8))
        .collect();
    let p = Params::gpp2();
    let own = detect(&cloud(&pts), &p).unwrap();
    assert_eq!(own.sensor, Some(DVec3::ZERO));
    let shift = DVec3::new(500_000.0, 4_500_000.0, 100.0);
    let flat: Vec<f64> = pts.iter().flat_map(|&q| (q + shift).to_array()).collect();
    let moved = Cloud::from_flat_f64(&flat, 3).unwrap();
    let map = detect(&moved, &p).unwrap();
    assert_eq!(map.sensor, None);
    let seen = Params {
        viewpoint: Some(shift.to_array()),
        ..Params::gpp2()
    };
    assert_eq!(detect(&moved, &seen).unwrap().sensor, Some(shift));
    // Either way the ground is found.
    assert_eq!(own.primitives.len(), 1);
    assert_eq!(map.primitives.len(), 1);
}

/// A street location seen from its mean pose: horizontal planes at the
/// heights where the laser rings cross the facades and car sides hold a
/// band of each, as lines (a rejected candidate) or fragments (no patch
/// large enough). Such a round takes the points it explains nothing with
/// out of play but spares the bands of the surfaces it crosses, and is
/// not tried again (`CascadePolicy::spare_crossing_surfaces`); without
/// that, sparse facades and car sides lose a band with every such round.
/// Local triples (`CascadePolicy::local_triples`) make such planes rarer,
/// so sparing gains less than it did with triples across the cloud
/// (recall 0.580 against 0.527 at scan 60 then). Judging a candidate's
/// dominant layer (`CascadePolicy::split_rough_layers`) keeps some of the
/// same bands in play, so sparing's own gain is measured with that off in
/// both arms; the cascade as it runs is judged on its own. Four locations
/// along the street (scans 20-80), on average: measured recall 0.532
/// against 0.514, completeness 0.901 against 0.889; as it runs, recall
/// 0.530, precision 0.994.
#[test]
fn a_plane_through_clutter_spares_the_surfaces_it_crosses() {
    use polyscene::detect::CascadePolicy;
    let (drive, gt) = drive_truth(polyscene::sim::Layout::Street);
    let starts = [20, 40, 60, 80];
    let n = starts.len() as f64;
    let (mut with_recall, mut without_recall) = (0.0, 0.0);
    let (mut with_complete, mut without_complete) = (0.0, 0.0);
    let (mut recall, mut precision) = (0.0, 0.0);
    for start in starts {
        let loc = drive.location(start, 10).unwrap();
        let unsplit = CascadePolicy {
            split_rough_layers: false,
            ..CascadePolicy::one_shot()
        };
        let (runs, with) = with_and_without(&loc, unsplit);
        let without = run_with(
            &loc,
            CascadePolicy {
                spare_crossing_surfaces: false,
                ..unsplit
            },
        );
        let score = |det| score_location(det, &gt, &loc);
        let (r, a, b) = (score(&runs), score(&with), score(&without));
        assert_eq!(r.duplicates.count, 0, "scan {start}");
        recall += r.detection.recall / n;
        precision += r.detection.precision / n;
        with_recall += a.detection.recall / n;
        without_recall += b.detection.recall / n;
        with_complete += a.completeness.completeness / n;
        without_complete += b.completeness.completeness / n;
    }
    assert!(recall > 0.52, "recall {recall}");
    assert!(
        with_recall > without_recall + 0.015,
        "recall {with_recall} against {without_recall}"
    );
    assert!(
        with_complete > without_complete + 0.01,
        "completeness {with_complete} against {without_complete}"
    );
    assert!(precision > 0.99, "{precision}");
}

/// A curb is a face 15 cm high between the road and the sidewalk: too
/// narrow for `minWidth`, and the two surfaces' inlier slabs take most of
/// its points, so no round of the cascade finds it. Where the two
/// surfaces' outlines meet a step apart with points in the step, one-shot
/// detection adds it (`CascadePolicy::find_risers`). The simulated
/// crossing's location 80 seen from its mean pose: six curbs of 1 m^2 or
/// more, none found without the rule.
#[test]
fn curbs_between_road_and_sidewalk_are_found() {
    use polyscene::detect::CascadePolicy;
    use polyscene::sim::{Layout, SurfaceKind};
    let (drive, gt) = drive_truth(Layout::Crossing);
    let loc = drive.location(80, 10).unwrap();
    let (with, without) = with_and_without(
        &loc,
        CascadePolicy {
            find_risers: false,
            ..CascadePolicy::one_shot()
        },
    );
    let curbs =
        |m: &polyscene::eval::Metrics| common::found_of_kind(m, drive.scene(), SurfaceKind::Curb);
    let (a, b) = (
        score_location(&with, &gt, &loc),
        score_location(&without, &gt, &loc),
    );
    // Measured: 5 of 6 curbs against none; recall 0.523 against 0.494;
    // precision 1 in both.
    assert_eq!(curbs(&b).0, 0);
    let (found, all) = curbs(&a);
    assert!(all >= 6 && found * 3 >= all * 2, "{found} of {all} curbs");
    assert!(a.detection.recall > b.detection.recall + 0.02);
    assert!(
        a.detection.precision >= b.detection.precision,
        "{}",
        a.detection.precision
    );
    assert!(a.completeness.completeness >= b.completeness.completeness);
    assert_eq!(a.duplicates.count, 0);
}

/// `det`'s polygons scored against the simulated location `loc`.
fn score_location(
    det: &polyscene::detect::Detection,
    gt: &[polyscene::eval::GtSurface],
    loc: &polyscene::sim::Location,
) -> polyscene::eval::Metrics {
    use polyscene::eval::{evaluate, EvalOptions};
    let polys: Vec<_> = det.primitives.iter().map(|q| q.polygon()).collect();
    let (pts, labels) = (&loc.points, &loc.labels);
    evaluate(&polys, gt, pts, labels, pts.len(), &EvalOptions::default()).unwrap()
}

/// One-shot detection of a location seen from its mean pose, as `detect`
/// runs it (invariants checked) and with `policy` instead.
fn with_and_without(
    loc: &polyscene::sim::Location,
    policy: polyscene::detect::CascadePolicy,
) -> (polyscene::detect::Detection, polyscene::detect::Detection) {
    let cloud = Cloud::from_world_f64(&loc.points).unwrap();
    let p = Params {
        viewpoint: Some(loc.viewpoint().to_array()),
        ..Params::gpp2()
    };
    let with = detect(&cloud, &p).unwrap();
    check_invariants(&cloud, &with, &p);
    (with, run_with(loc, policy))
}

/// One-shot detection of a location from its mean pose under `policy`.
fn run_with(
    loc: &polyscene::sim::Location,
    policy: polyscene::detect::CascadePolicy,
) -> polyscene::detect::Detection {
    use polyscene::detect::Detector;
    let cloud = Cloud::from_world_f64(&loc.points).unwrap();
    let p = Params {
        viewpoint: Some(loc.viewpoint().to_array()),
        ..Params::gpp2()
    };
    Detector::new(&p, policy).run(&cloud.points, cloud.origin, loc.viewpoint())
}

/// The simulated drive of a layout (seed 1) and its ground-truth surfaces.
fn drive_truth(
    layout: polyscene::sim::Layout,
) -> (polyscene::sim::Drive, Vec<polyscene::eval::GtSurface>) {
    use polyscene::sim::{Drive, DriveOptions, SensorModel};
    let drive = Drive::new(layout, 1, SensorModel::default(), DriveOptions::default()).unwrap();
    let gt = drive
        .scene()
        .polygons
        .iter()
        .map(|g| polyscene::eval::GtSurface {
            id: g.id,
            polygon: g.polygon.clone(),
        })
        .collect();
    (drive, gt)
}

/// A crossing in a tile seen from nowhere: two roads 12 m wide crossing
/// at z = 0, and a plaza 10 cm higher in each of the four corners. One
/// horizontal plane between them holds both heights within the ground's
/// inlier distance (8 cm) and scores more than either, but it is too rough
/// to be one surface. Both must come out, each at its own height over its
/// own area (the whole candidate used to leave play, roads and plazas
/// with it).
#[test]
fn roads_and_plazas_a_step_above_them_are_separate_surfaces() {
    let (half, road): (f64, f64) = (20.0, 6.0);
    let pts = common::height_field([-half, half], [-half, half], 0.002, 8, |x, y| {
        if x.abs() <= road || y.abs() <= road {
            0.0
        } else {
            0.10
        }
    });
    let det = detect_tile(&pts);
    // Roads: 2 x 40 x 12 - 12 x 12 m^2; plazas: 4 x 14 x 14 m^2.
    for (name, z, want) in [("roads", 0.0, 816.0), ("plazas", 0.10, 784.0)] {
        let at = DVec3::new(0.0, 0.0, z);
        assert_area_on(&det, name, DVec3::Z, at, 0.02, [0.9 * want, 1.1 * want]);
    }
}

/// One-shot detection with the defaults (no viewpoint), invariants checked.
fn detect_tile(pts: &[DVec3]) -> polyscene::detect::Detection {
    let c = cloud(pts);
    let p = Params::gpp2();
    let det = detect(&c, &p).unwrap();
    check_invariants(&c, &det, &p);
    det
}

/// The polygons within 1 degree of `normal` whose planes pass within `tol`
/// of `at` cover between `range[0]` and `range[1]` square metres.
fn assert_area_on(
    det: &polyscene::detect::Detection,
    name: &str,
    normal: DVec3,
    at: DVec3,
    tol: f64,
    range: [f64; 2],
) {
    let area: f64 = det
        .primitives
        .iter()
        .filter(|q| {
            q.plane.normal.dot(normal) > libm::cos(1f64.to_radians())
                && q.plane.signed_distance(at).abs() < tol
        })
        .map(|q| q.area)
        .sum();
    let got: Vec<_> = det
        .primitives
        .iter()
        .map(|q| (q.plane.normal, q.plane.offset, q.area))
        .collect();
    assert!(
        area > range[0] && area < range[1],
        "{name}: {area:.1} m^2, not in {range:?}: {got:?}"
    );
}

#[test]
fn a_sparse_wall_behind_dense_clutter_is_found() {
    let mut rng = Rng::new(11);
    let mut pts = Vec::new();
    // Ground, 40 x 20 m, and a wall 12 x 3 m at y = 15 seen sparsely
    // (0.25 m apart: 16 points a square metre, 637 in all).
    rect(
        &mut pts,
        DVec3::new(-20.0, 0.0, 0.0),
        DVec3::X,
        DVec3::Y,
        40.0,
        20.0,
        0.1,
        0.01,
        &mut rng,
    );
    rect(
        &mut pts,
        DVec3::new(-6.0, 15.0, 0.0),
        DVec3::X,
        DVec3::Z,
        12.0,
        3.0,
        0.25,
        0.01,
        &mut rng,
    );
    // Bins and posts, seen close: cylinders of 0.3 m radius, 1.2 m high,
    // 3000 points each. A plane along one holds more points than the wall
    // and makes a candidate that is too small.
    for _ in 0..25 {
        let c = DVec3::new(rng.range(-18.0, 18.0), rng.range(2.0, 12.0), 0.0);
        for _ in 0..3000 {
            let a = rng.range(0.0, std::f64::consts::TAU);
            let r = 0.3 + 0.01 * rng.gaussian();
            pts.push(c + DVec3::new(r * libm::cos(a), r * libm::sin(a), rng.range(0.0, 1.2)));
        }
    }
    let c = cloud(&pts);
    let p = Params {
        viewpoint: Some([0.0, 0.0, 1.8]),
        ..Params::gpp2()
    };
    let det = detect(&c, &p).unwrap();
    check_invariants(&c, &det, &p);
    let found: f64 = det
        .primitives
        .iter()
        .filter(|q| q.plane.normal.y.abs() > 0.999 && (q.plane.offset.abs() - 15.0).abs() < 0.05)
        .map(|q| q.area)
        .sum();
    let got: Vec<_> = det
        .primitives
        .iter()
        .map(|q| (q.plane.normal, q.area))
        .collect();
    assert!(found > 0.8 * 36.0, "wall: {found:.1} m^2 of 36: {got:?}");
}

/// A tile seen from nowhere: a road at z = 0, a ramp rising at 8 degrees
/// from it, and a plateau at the ramp's top, 1.41 m above the road. Each
/// is its own surface, at its own height and slope, over its own area.
#[test]
fn a_ramp_and_the_plateau_it_climbs_to_are_found_without_a_viewpoint() {
    let slope = 8f64.to_radians();
    let (run, top) = (10.0, 10.0 * libm::tan(slope));
    let pts = common::height_field([-20.0, 30.0], [0.0, 12.0], 0.005, 12, |x, _| {
        if x < 0.0 {
            0.0
        } else if x < run {
            x * libm::tan(slope)
        } else {
            top
        }
    });
    let det = detect_tile(&pts);
    let ramp_normal = DVec3::new(-libm::sin(slope), 0.0, libm::cos(slope));
    // Road 20 x 12, ramp 10 / cos(8 deg) x 12, plateau 20 x 12 m^2.
    for (name, normal, at, want) in [
        ("road", DVec3::Z, DVec3::new(-10.0, 6.0, 0.0), 240.0),
        (
            "ramp",
            ramp_normal,
            DVec3::new(5.0, 6.0, 5.0 * libm::tan(slope)),
            121.2,
        ),
        ("plateau", DVec3::Z, DVec3::new(20.0, 6.0, top), 240.0),
    ] {
        assert_area_on(&det, name, normal, at, 0.03, [0.85 * want, 1.1 * want]);
    }
}

/// A street location seen from nowhere, as a map accumulated over the
/// drive: the facades 40-100 m down the street hold a few laser rings
/// half a metre apart with metre gaps along each, which the first pass's
/// clustering breaks into fragments. The coarse pass
/// (`CascadePolicy::coarse_pass`) finds them on the points that lie too
/// sparsely for it, with a third of `minInliers`, and merges them with the
/// pieces of the same surfaces the first pass found. Eight locations along
/// the street (scans 10-80), on average: measured recall 0.684 against
/// 0.542, completeness 0.939 against 0.804 (higher at every location),
/// precision 0.950 against 0.940.
#[test]
fn a_map_s_sparse_far_surfaces_are_found_at_a_coarser_scale() {
    use polyscene::detect::{CascadePolicy, Detector};
    let (drive, gt) = drive_truth(polyscene::sim::Layout::Street);
    let p = Params::gpp2();
    let starts = [10, 20, 30, 40, 50, 60, 70, 80];
    let n = starts.len() as f64;
    let (mut with, mut without) = ([0.0; 3], [0.0; 3]);
    for start in starts {
        let loc = drive.location(start, 10).unwrap();
        let cloud = Cloud::from_world_f64(&loc.points).unwrap();
        let a = detect(&cloud, &p).unwrap();
        check_invariants(&cloud, &a, &p);
        let far = cloud.origin
            + cloud
                .points
                .iter()
                .map(|q| q.as_dvec3())
                .sum::<glam::DVec3>()
                / cloud.len() as f64
            + glam::DVec3::new(0.0, 0.0, 1e4);
        let policy = CascadePolicy {
            coarse_pass: false,
            ..CascadePolicy::one_shot().without_viewpoint()
        };
        let b = Detector::new(&p, policy).run(&cloud.points, cloud.origin, far);
        let (a, b) = (score_location(&a, &gt, &loc), score_location(&b, &gt, &loc));
        assert_eq!(a.duplicates.count, 0, "scan {start}");
        for (s, m) in [(&mut with, &a), (&mut without, &b)] {
            s[0] += m.detection.recall / n;
            s[1] += m.completeness.completeness / n;
            s[2] += m.detection.precision / n;
        }
        assert!(
            a.completeness.completeness > b.completeness.completeness + 0.05,
            "scan {start}: completeness {} against {}",
            a.completeness.completeness,
            b.completeness.completeness
        );
    }
    assert!(
        with[0] > without[0] + 0.015,
        "recall {with:?} against {without:?}"
    );
    assert!(
        with[1] > without[1] + 0.08,
        "completeness {with:?} against {without:?}"
    );
    assert!(
        with[2] >= without[2],
        "precision {with:?} against {without:?}"
    );
}

/// Laser rings of a sensor 1.8 m above a road, over the half turn to its
/// right, with a sidewalk a 15 cm curb up from 3.5 m to the right: the
/// rings of the lasers at `elevations` (degrees), each beam's range noise
/// (1 cm) along the beam, one beam every 0.2 degrees. Points in the world
/// frame.
fn rings_across_a_curb(elevations: &[f64], rng: &mut Rng) -> Vec<DVec3> {
    let sensor = DVec3::new(0.0, 0.0, 1.8);
    let (right, curb) = (-3.5, 0.15);
    let mut pts = Vec::new();
    for &e in elevations {
        let e = e.to_radians();
        for k in 0..900 {
            let a = (-k as f64 * 0.2).to_radians();
            let dir = DVec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin());
            // The road, unless the beam crosses the curb line first: then
            // the curb's face below its top, or the sidewalk beyond it.
            let mut t = -sensor.z / dir.z;
            if t * dir.y < right {
                let tc = right / dir.y;
                t = if sensor.z + tc * dir.z <= curb {
                    tc
                } else {
                    (curb - sensor.z) / dir.z
                };
            }
            pts.push(sensor + dir * (t + 0.01 * rng.gaussian()));
        }
    }
    pts
}

/// Two laser ring arcs metres apart fit one plane within centimetres.
/// Where rings lie metres apart (a
/// 16-laser sensor's far ground), a candidate can hold nothing but rings
/// (the road's and the sidewalk's beyond a curb) under a plane tilted by a
/// degree or two that fits both to within centimetres: every 0.4 m patch
/// of it with a normal is a single ring. Such a plane is unproven, and is
/// judged by its layers, its noise the rings' spread along its normal.
/// Without that (measured), the first scan of these four far rings ends
/// with 61 m^2 of such a slab, tilted 1.4 degrees; on the bench's 16-laser
/// street drive one such slab merged into the road, tilting it by 0.59
/// degrees, and scan alignment then turned the map after it (mean error
/// 120 mm).
#[test]
fn laser_rings_across_a_curb_give_level_surfaces_only() {
    let elevations = [-8.87, -10.93, -13.0, -15.0];
    let pts = rings_across_a_curb(&elevations, &mut Rng::new(5));
    let local: Vec<f32> = pts
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, (p.z - 1.8) as f32, 0.0])
        .collect();
    let mut scenario = polyscene::Scenario::new(Params::gpp2()).unwrap();
    let pose = glam::DMat4::from_translation(DVec3::new(0.0, 0.0, 1.8));
    scenario.add_scan(&local, 4, &pose).unwrap();
    // (A 2.4 m^2 piece no patch of which has a normal, strips one ring
    // wide, is still kept whole, tilted 3 degrees: docs/LIMITATIONS.md.)
    let mut level = 0.0;
    for q in scenario.primitives().iter().filter(|q| q.area >= 5.0) {
        let z: Vec<f64> = q.outline.iter().map(|&v| q.frame.to_world(v).z).collect();
        let (lo, hi) = z
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &z| (l.min(z), h.max(z)));
        let tilt = q.plane.normal.z.abs().min(1.0).acos().to_degrees();
        assert!(
            tilt < 0.2 && hi - lo < 0.03,
            "a {:.1} m^2 polygon tilted {tilt:.2} degrees spans heights {lo:.3} to {hi:.3}",
            q.area
        );
        level += q.area;
    }
    // Measured: a 17 m^2 piece of the sidewalk, level.
    assert!(level > 8.0, "{level} m^2 found");
}
