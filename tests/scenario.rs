//! The incremental scenario (Algorithm 2 plus merging) on simulated drives
//! with ground truth.

mod common;

use glam::{DMat4, DVec3};
use polyscene::detect::{CascadePolicy, Detector, NO_PRIMITIVE};
use polyscene::eval::{self, EvalOptions, GtSurface};
use polyscene::geometry::polygon::is_simple;
use polyscene::geometry::Polygon3;
use polyscene::params::{HullKind, Params};
use polyscene::scenario::Scenario;
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel, SurfaceKind};
use polyscene::Error;

const SCANS: usize = 100;

fn drive(layout: Layout, origin: DVec3) -> Drive {
    Drive::new(
        layout,
        1,
        SensorModel::default(),
        DriveOptions {
            origin,
            ..DriveOptions::default()
        },
    )
    .unwrap()
}

fn polygons(s: &Scenario) -> Vec<Polygon3> {
    s.primitives().iter().map(|p| p.polygon()).collect()
}

struct Run {
    scenario: Scenario,
    explained_share_after_5: Vec<f64>,
    duplicate_checks: usize,
}

/// Feed `SCANS` scans; check for duplicates every scan.
fn run(d: &Drive, params: Params) -> Run {
    let mut scenario = Scenario::new(params).unwrap();
    let mut shares = Vec::new();
    let mut checks = 0;
    let opts = EvalOptions::default();
    for k in 0..SCANS {
        let scan = d.scan(k).unwrap();
        let r = scenario.add_scan(&scan.points, 4, &scan.pose).unwrap();
        assert_eq!(r.polygon_count, scenario.primitives().len());
        assert_eq!(r.points, scan.len());
        assert_eq!(r.explained_by_expansion + r.sent_to_detection, r.points);
        assert!(r.explained_by_detection <= r.sent_to_detection);
        let labelled = scenario
            .last_labels()
            .iter()
            .filter(|&&l| l != NO_PRIMITIVE)
            .count();
        assert_eq!(
            labelled,
            r.explained_by_expansion + r.explained_by_detection
        );
        if k >= 5 {
            shares.push(r.explained_by_expansion as f64 / r.points as f64);
        }
        // Every polygon of the map is a region, after every scan: a simple
        // ring of at least one footprint cell. (A piece of a curb under
        // `minArea` only ever grows the riser it continues; an outline
        // traced from one row of cells keeps that row.)
        let cell = scenario.params().other.cell;
        for q in scenario.primitives() {
            assert!(
                is_simple(&q.outline) && q.area >= cell * cell,
                "scan {k}: primitive {} of {} m^2, support {}, born {}",
                q.id,
                q.area,
                q.support,
                q.born_scan
            );
        }
        if scenario.params().expansion {
            let dups = eval::duplicates(&polygons(&scenario), &opts);
            assert_eq!(dups.count, 0, "scan {k}: duplicates {:?}", dups.pairs);
            checks += 1;
        }
    }
    Run {
        scenario,
        explained_share_after_5: shares,
        duplicate_checks: checks,
    }
}

/// Found and eligible surfaces of each kind (vehicles as sides, ends and
/// tops), in the order of `SurfaceKind::ALL`.
fn kinds_found(d: &Drive, m: &eval::Metrics) -> Vec<(String, usize, usize)> {
    use polyscene::sim::SurfaceKind;
    let name = |id: u32| -> String {
        let g = d.scene().polygons.iter().find(|g| g.id == id).unwrap();
        if g.kind != SurfaceKind::Vehicle {
            return g.kind.as_str().to_string();
        }
        let v = g.polygon.vertices();
        let (lo, hi) = v.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let ext = hi - lo;
        if g.polygon.frame.normal.z.abs() > 0.9 {
            "vehicle top".into()
        } else if ext.x.max(ext.y) > 3.0 {
            "vehicle side".into()
        } else {
            "vehicle end".into()
        }
    };
    let mut out: Vec<(String, usize, usize)> = Vec::new();
    for r in m.surfaces.iter().filter(|r| r.eligible) {
        let k = name(r.id);
        match out.iter_mut().find(|e| e.0 == k) {
            Some(e) => {
                e.1 += r.found as usize;
                e.2 += 1;
            }
            None => out.push((k, r.found as usize, 1)),
        }
    }
    out.sort();
    out
}

fn ground_truth(d: &Drive) -> Vec<GtSurface> {
    d.scene()
        .polygons
        .iter()
        .map(|g| GtSurface {
            id: g.id,
            polygon: g.polygon.clone(),
        })
        .collect()
}

/// World points and labels of the first `SCANS` scans.
fn observations(d: &Drive) -> (Vec<DVec3>, Vec<u32>) {
    let (mut pts, mut labels) = (Vec::new(), Vec::new());
    for k in 0..SCANS {
        let s = d.scan(k).unwrap();
        pts.extend(s.world_points());
        labels.extend_from_slice(&s.labels);
    }
    (pts, labels)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn drive_through(layout: Layout) {
    let d = drive(layout, DVec3::ZERO);
    let with = run(&d, Params::gpp2());
    let without = run(
        &d,
        Params {
            expansion: false,
            ..Params::gpp2()
        },
    );
    assert_eq!(with.duplicate_checks, SCANS);
    // Fig. 14a: without expansion every scan re-detects and appends.
    let (nw, nwo) = (
        with.scenario.primitives().len(),
        without.scenario.primitives().len(),
    );
    assert!(
        nw * 5 < nwo,
        "{layout:?}: {nw} polygons with expansion, {nwo} without"
    );
    // After the first scans most points are explained by expansion.
    let share = median(with.explained_share_after_5.clone());
    let least = with
        .explained_share_after_5
        .iter()
        .copied()
        .fold(1.0, f64::min);
    // About a tenth of each scan is clutter (trees, poles) that no
    // primitive can explain; measured median ~0.89 on both layouts.
    assert!(
        share > 0.85,
        "{layout:?}: median share explained by expansion {share}"
    );
    assert!(
        least > 0.75,
        "{layout:?}: worst share explained by expansion {least}"
    );
    // As accurate and complete as one-shot detection on the accumulated cloud.
    let gt = ground_truth(&d);
    let (pts, labels) = observations(&d);
    let opts = EvalOptions::default();
    let inc = eval::evaluate(
        &polygons(&with.scenario),
        &gt,
        &pts,
        &labels,
        pts.len(),
        &opts,
    )
    .unwrap();
    // Curbs (15 cm faces between the road and the sidewalks) become risers
    // from each scan's points and the pool's, and grow by merging the
    // pieces that continue them, as rectangles (measured: 7 of the
    // crossing's 8 curbs of 1 m^2 or more, 6 without the pool's; 3 of 4
    // then when their outlines were traced from 0.2 m cells; the street's
    // two run the whole 449 m of the scene, and the pieces found cover
    // less than half of what the drive saw of them).
    if layout == Layout::Crossing {
        let (found, all) = common::found_of_kind(&inc, d.scene(), SurfaceKind::Curb);
        assert!(found >= 4, "{found} of {all} curbs");
    }
    let mean_pose = polyscene::io::mean_position(&d.poses()[..SCANS]).unwrap();
    let cloud = common::cloud(&pts);
    // One-shot baselines on the accumulated cloud. The paper's Algorithm 1
    // (the largest cluster of each round's plane, nothing merged), as it
    // is (ten rejections in a row end it: on 12M points that is right after
    // the large, well-supported surfaces) and run to completion (no
    // rejection stop: it ends when no plane has `minInliers` support or at
    // its round limit), which also goes after the smaller surfaces the
    // scenario maps. And polyscene's own one-shot detection (every cluster
    // of a round's plane judged, pieces merged), the strongest baseline.
    let one_shot = |max_rejections: usize, paper: bool| {
        let params = Params {
            viewpoint: Some(mean_pose.to_array()),
            max_rejections,
            ..Params::gpp2()
        };
        let one = if paper {
            // The scenario's cascade with the paper's plain sampler, and
            // without the rules about the bands of crossing surfaces and
            // domes.
            let paper = CascadePolicy {
                reject_slivers: false,
                spare_crossing_surfaces: false,
                judge_without_crossing_bands: false,
                reject_domes: false,
                ..CascadePolicy::scenario_leftovers()
            };
            Detector::new(&params, paper).run(&cloud.points, cloud.origin, mean_pose)
        } else {
            polyscene::detect::detect(&cloud, &params).unwrap()
        };
        let polys: Vec<Polygon3> = one.primitives.iter().map(|p| p.polygon()).collect();
        let e = eval::evaluate(&polys, &gt, &pts, &labels, pts.len(), &opts).unwrap();
        (e, polys.len())
    };
    let (shot, shot_n) = one_shot(Params::gpp2().max_rejections, true);
    let (full, full_n) = one_shot(1_000_000, true);
    let (ours, ours_n) = one_shot(Params::gpp2().max_rejections, false);
    let line = |name: &str, e: &eval::Metrics, n: usize| {
        format!(
            "{name} P {:.3} R {:.3} H {:.4} C {:.3} n {n} d {}",
            e.detection.precision,
            e.detection.recall,
            e.accuracy.mean.unwrap(),
            e.completeness.completeness,
            e.duplicates.count
        )
    };
    eprintln!(
        "{layout:?}: {} | {} | {} | {} | explained median {share:.3} min {least:.3}",
        line("incremental", &inc, nw),
        line("paper one-shot", &shot, shot_n),
        line("paper one-shot to completion", &full, full_n),
        line("polyscene one-shot", &ours, ours_n),
    );
    // At least as good as the paper's complete one-shot on every measure.
    assert!(
        inc.detection.precision >= full.detection.precision,
        "precision vs complete one-shot"
    );
    assert!(
        inc.detection.recall >= full.detection.recall,
        "recall vs complete one-shot"
    );
    assert!(
        inc.accuracy.mean.unwrap() <= full.accuracy.mean.unwrap(),
        "mean Hausdorff vs complete one-shot"
    );
    assert!(
        inc.completeness.completeness >= full.completeness.completeness,
        "completeness vs complete one-shot"
    );
    assert!(
        inc.duplicates.count <= full.duplicates.count,
        "duplicates vs complete one-shot"
    );
    // The stopped one-shot keeps only the large surfaces (measured: recall
    // 0.155 / 0.103 street / crossing, precision 0.960 / 0.980, mean error
    // 4.0 / 3.0 mm); the scenario finds about 5x more of the scene, vehicle
    // faces among them, so its mean error is behind that selection's (its
    // precision, 1.000 / 0.996, is not compared either). It
    // must beat it on what it is for:
    assert!(inc.detection.recall > 2.0 * shot.detection.recall, "recall");
    assert!(
        inc.completeness.completeness > shot.completeness.completeness,
        "completeness"
    );
    assert!(inc.duplicates.count <= shot.duplicates.count, "duplicates");
    // polyscene's one-shot on the whole drive (measured: street
    // P 1.000 R 0.527 C 0.869, one duplicate pair; crossing P 0.995 R 0.472
    // C 0.856, none): the scenario finds more of the scene (1.52x and
    // 1.49x the surfaces), without duplicates, and stays as precise (P
    // 1.000 and 0.996). The one-shot's area-weighted mean error is the
    // lower one (street 4.7 vs 5.0 mm, crossing 3.8 vs 4.5 mm): it fits
    // each surface to the whole
    // drive at once, and leaves out most of the vehicle faces. So the mean
    // is not compared here; BENCHMARKS.md gives both. The scenario must
    // cover at least nine tenths of what the one-shot covers (it covers
    // more: its pool gathers the far road rings the one-shot clusters by a
    // tolerance growing with range).
    assert!(
        inc.detection.precision > 0.985
            && inc.detection.precision > ours.detection.precision - 0.005,
        "precision vs polyscene one-shot"
    );
    assert!(
        inc.detection.recall > 1.1 * ours.detection.recall,
        "recall vs polyscene one-shot"
    );
    assert!(
        inc.completeness.completeness > 0.9 * ours.completeness.completeness,
        "completeness vs polyscene one-shot"
    );
    assert!(
        inc.duplicates.count <= ours.duplicates.count,
        "duplicates vs polyscene one-shot"
    );
    // What a driving map needs, kind by kind: found / eligible surfaces.
    // Measured (found / eligible): street road 1/1, sidewalks 2/2, vehicle
    // sides 40/66, ends 63/75; crossing road 1/1, ramp 1/1, sidewalks and
    // plaza 0.15 m above the road 4/4, vehicle sides 38/93, ends 48/78.
    // Curbs (street 0/2, crossing 7/8) are not asserted: a riser needs
    // both surfaces found beside it (docs/LIMITATIONS.md).
    let kinds = kinds_found(&d, &inc);
    eprintln!("{layout:?} kinds: {kinds:?}");
    let found_share = |k: &str| {
        let (found, all) = kinds
            .iter()
            .filter(|e| e.0 == k)
            .fold((0, 0), |(f, a), e| (f + e.1, a + e.2));
        assert!(all > 0, "{layout:?}: no eligible {k}");
        found as f64 / all as f64
    };
    for k in ["road", "sidewalk"] {
        assert_eq!(
            found_share(k),
            1.0,
            "{layout:?}: every {k} found: {kinds:?}"
        );
    }
    if layout == Layout::Crossing {
        assert_eq!(found_share("ramp"), 1.0, "the ramp: {kinds:?}");
    }
    assert!(
        found_share("vehicle side") > 0.35,
        "{layout:?} vehicle sides: {kinds:?}"
    );
    assert!(
        found_share("vehicle end") > 0.5,
        "{layout:?} vehicle ends: {kinds:?}"
    );
    // Absolute floors below the measured values (BENCHMARKS.md): street /
    // crossing P 0.995 / 0.991, R 0.763 / 0.622, C 0.943 / 0.915, mean
    // 5.2 / 4.3 mm.
    assert!(inc.detection.precision > 0.985, "precision");
    assert!(inc.detection.recall > 0.5, "recall");
    assert!(inc.completeness.completeness > 0.85, "completeness");
    assert!(inc.accuracy.mean.unwrap() < 0.015, "mean Hausdorff");
}

#[test]
fn street_drive_with_expansion_beats_appending_and_one_shot() {
    drive_through(Layout::Street);
}

#[test]
fn crossing_drive_with_expansion_beats_appending_and_one_shot() {
    drive_through(Layout::Crossing);
}

/// A sensor with a quarter of the HDL-64E's lasers (every fourth: 16
/// lasers 1.3-2 degrees apart from +2 to -25 degrees; a VLP-16 has 2
/// degrees from +15 to -15): its laser rings on the ground lie metres
/// apart, so most 0.4 m patches of the near ground hold one.
fn sparse_drive() -> Drive {
    let elevations_deg = polyscene::sim::hdl64_elevations_deg()
        .into_iter()
        .step_by(4)
        .collect();
    let sensor = SensorModel {
        elevations_deg,
        ..SensorModel::default()
    };
    Drive::new(Layout::Crossing, 1, sensor, DriveOptions::default()).unwrap()
}

#[test]
fn a_sparse_sensor_keeps_its_ground_and_its_precision() {
    // A patch holding one laser ring lies on that laser's cone, whatever
    // the surface: near the sensor the cones of the lower lasers lean 15-25
    // degrees from level. Counted, such patches vote the road out in the
    // normal-consistency test, and their spread of micrometres, taken for
    // the surface's noise, keeps a slab tilted across two surfaces whole.
    // Measured on this drive, with single rings counted: 7.8 m^2 of ground
    // after the first scan, precision 0.978 after 30 scans (mean error
    // 4.2 mm); left out: 34.5 m^2, precision 1.000 (3.8 mm). (The same
    // drive thinned from the HDL-64E's scans and replayed from files,
    // another draw of the noise, ended turned by scan alignment towards
    // such a slab: mean error 46.8 -> 4.8 mm; BENCHMARKS.md.)
    let d = sparse_drive();
    let mut s = Scenario::new(Params::gpp2()).unwrap();
    let scans = 30;
    for k in 0..scans {
        let scan = d.scan(k).unwrap();
        s.add_scan(&scan.points, 4, &scan.pose).unwrap();
        if k == 0 {
            let ground: f64 = s
                .primitives()
                .iter()
                .filter(|p| p.ground)
                .map(|p| p.area)
                .sum();
            assert!(ground > 20.0, "first scan: {ground} m^2 of ground");
        }
    }
    let gt = ground_truth(&d);
    let (mut pts, mut labels) = (Vec::new(), Vec::new());
    for k in 0..scans {
        let scan = d.scan(k).unwrap();
        pts.extend(scan.world_points());
        labels.extend_from_slice(&scan.labels);
    }
    let m = eval::evaluate(
        &polygons(&s),
        &gt,
        &pts,
        &labels,
        pts.len(),
        &EvalOptions::default(),
    )
    .unwrap();
    assert!(m.detection.precision > 0.99, "{:?}", m.detection);
    let mean = m.accuracy.mean.unwrap();
    assert!(mean < 0.006, "mean error {mean} m");
}

#[test]
fn snapshot_and_restore_mid_drive_continues_identically() {
    let d = drive(Layout::Crossing, DVec3::ZERO);
    for hull in [HullKind::Concave, HullKind::Convex] {
        let params = Params {
            hull,
            ..Params::gpp2()
        };
        let mut a = Scenario::new(params.clone()).unwrap();
        let mut b = Scenario::new(params).unwrap();
        for k in 0..12 {
            let s = d.scan(k).unwrap();
            a.add_scan(&s.points, 4, &s.pose).unwrap();
            if k < 6 {
                b.add_scan(&s.points, 4, &s.pose).unwrap();
            }
            if k == 5 {
                let text = b.to_json();
                b = Scenario::from_json(&text).unwrap();
                // Through a parsed value (as the binding restores, but
                // parsed by serde here): the same state.
                let value = serde_json::from_str(&text).unwrap();
                assert_eq!(Scenario::from_json_value(value).unwrap(), b);
            }
            if k >= 6 {
                b.add_scan(&s.points, 4, &s.pose).unwrap();
            }
        }
        assert_eq!(a.primitives(), b.primitives(), "{hull:?}");
        assert_eq!(a.to_json(), b.to_json());
    }
    assert!(Scenario::from_json("{\"not\": 1}").is_err());
}

#[test]
fn far_from_the_origin_gives_the_same_scenario_translated() {
    let shift = DVec3::new(500_000.0, 4_500_000.0, 50.0);
    let (near, far) = (
        drive(Layout::Street, DVec3::ZERO),
        drive(Layout::Street, shift),
    );
    let mut a = Scenario::new(Params::gpp2()).unwrap();
    let mut b = Scenario::new(Params::gpp2()).unwrap();
    for k in 0..15 {
        let (s, t) = (near.scan(k).unwrap(), far.scan(k).unwrap());
        assert_eq!(
            s.points, t.points,
            "scans in the sensor frame are identical"
        );
        a.add_scan(&s.points, 4, &s.pose).unwrap();
        b.add_scan(&t.points, 4, &t.pose).unwrap();
    }
    assert_eq!(a.primitives().len(), b.primitives().len());
    for (p, q) in a.primitives().iter().zip(b.primitives()) {
        assert_eq!(p.id, q.id);
        let (u, v) = (p.vertices(), q.vertices());
        assert_eq!(u.len(), v.len());
        for (x, y) in u.iter().zip(&v) {
            assert!((*x + shift - *y).length() < 1e-3, "{x} vs {y}");
        }
    }
}

#[test]
fn empty_scans_and_bad_poses() {
    let mut s = Scenario::new(Params::gpp2()).unwrap();
    let r = s.add_scan(&[], 4, &DMat4::IDENTITY).unwrap();
    assert_eq!((r.points, r.polygon_count, r.scan), (0, 0, 0));
    let d = drive(Layout::Street, DVec3::ZERO);
    let scan = d.scan(0).unwrap();
    s.add_scan(&scan.points, 4, &scan.pose).unwrap();
    let before = s.primitives().to_vec();
    let r = s.add_scan(&[], 4, &scan.pose).unwrap();
    assert_eq!(r.scan, 2);
    assert_eq!(s.primitives(), &before[..], "an empty scan changes nothing");
    let scaled = scan.pose * DMat4::from_scale(DVec3::splat(1.1));
    let e = s.add_scan(&scan.points, 4, &scaled).unwrap_err();
    assert!(matches!(e, Error::BadPose(_)), "{e}");
    assert!(e.to_string().contains("orthonormal"));
    let mut nan = scan.pose;
    nan.w_axis.x = f64::NAN;
    assert!(matches!(
        s.add_scan(&scan.points, 4, &nan),
        Err(Error::BadPose(_))
    ));
    assert!(matches!(
        s.add_scan(&scan.points[..5], 4, &scan.pose),
        Err(Error::BadLength { .. })
    ));
    assert_eq!(s.scans(), 3, "failed scans are not counted");
    assert_eq!(s.primitives(), &before[..], "failed scans change nothing");
}

#[test]
fn a_scenario_refuses_a_viewpoint_its_poses_would_override() {
    let params = Params {
        viewpoint: Some([1.0, 2.0, 1.8]),
        ..Params::gpp2()
    };
    let e = Scenario::new(params).unwrap_err();
    assert!(
        matches!(&e, Error::BadOption { key, .. } if key == "viewpoint"),
        "{e}"
    );
    assert!(e.to_string().contains("pose"), "{e}");
}

#[test]
fn memory_is_bounded_by_the_mapped_area_not_the_scans() {
    // The same place seen 60 times: support keeps counting (3x between scan
    // 20 and 60) but polygons, vertices and footprint bytes barely move.
    // (Each scan's detection draws a new random sample of the ~14k leftover
    // clutter points and now and then accepts one more small plane there:
    // growth bounded by the clutter of the mapped area.)
    let d = drive(Layout::Street, DVec3::ZERO);
    let scan = d.scan(10).unwrap();
    let mut s = Scenario::new(Params::gpp2()).unwrap();
    let size = |s: &Scenario| -> (usize, usize, usize) {
        let p = s.primitives();
        (
            p.len(),
            p.iter().map(|q| q.outline.len()).sum(),
            p.iter().map(|q| q.footprint.heap_bytes()).sum(),
        )
    };
    let mut sizes = Vec::new();
    let mut support = Vec::new();
    let mut pool = Vec::new();
    for _ in 0..60 {
        let r = s.add_scan(&scan.points, 4, &scan.pose).unwrap();
        pool.push(r.pool_points);
        sizes.push(size(&s));
        support.push(s.primitives().iter().map(|q| q.support).sum::<u64>());
    }
    let (early, late) = (sizes[19], sizes[59]);
    assert!(late.0 <= early.0 + 3, "polygons {early:?} -> {late:?}");
    assert!(
        late.1 * 10 <= early.1 * 11,
        "vertices {early:?} -> {late:?}"
    );
    assert!(
        late.2 * 10 <= early.2 * 11,
        "footprint bytes {early:?} -> {late:?}"
    );
    assert!(
        support[59] > 2 * support[19],
        "support should keep counting"
    );
    // The pool of unexplained points holds one point a voxel of what no
    // primitive explains: the same place seen again does not grow it.
    assert!(pool[19] > 0 && pool[19] <= s.params().pool_max_points);
    assert!(
        pool[59] * 10 <= pool[19] * 11,
        "pool {} -> {}",
        pool[19],
        pool[59]
    );
    // Outlines stay within the vertex budget.
    assert!(s
        .primitives()
        .iter()
        .all(|q| q.outline.len() <= s.params().max_vertices));
}

/// A drive whose poses drift, as real odometry does: each scan adds up to
/// 3 cm and 0.15 degrees (about each axis, turning about the world origin,
/// so the sensor, up to 59 m from it, moves up to 15 cm more a scan), bounded at 12 cm
/// and 0.6 degrees. A surface seen again through a pose off must grow or
/// merge, not duplicate. Measured: 141 polygons against 135 without drift,
/// no duplicate pair (137 and none with `alignScans` off: the pool and the
/// merge of layers within the inlier distance catch what alignment does
/// not).
#[test]
fn a_drive_with_drifting_poses_grows_what_it_saw_before() {
    use polyscene::internals::Rng;
    let d = drive(Layout::Street, DVec3::ZERO);
    let scans = 60;
    let (mut clean, mut noisy) = (
        Scenario::new(Params::gpp2()).unwrap(),
        Scenario::new(Params::gpp2()).unwrap(),
    );
    let mut rng = Rng::new(5);
    let (mut t, mut a) = (DVec3::ZERO, DVec3::ZERO);
    let step = |x: f64, r: &mut Rng| (r.uniform() * 2.0 - 1.0) * x;
    for k in 0..scans {
        let s = d.scan(k).unwrap();
        clean.add_scan(&s.points, 4, &s.pose).unwrap();
        t = (t + DVec3::new(
            step(0.03, &mut rng),
            step(0.03, &mut rng),
            step(0.03, &mut rng),
        ))
        .clamp(DVec3::splat(-0.12), DVec3::splat(0.12));
        let r = 0.15f64.to_radians();
        a = (a + DVec3::new(step(r, &mut rng), step(r, &mut rng), step(r, &mut rng)))
            .clamp(DVec3::splat(-4.0 * r), DVec3::splat(4.0 * r));
        let error =
            DMat4::from_translation(t) * DMat4::from_euler(glam::EulerRot::ZYX, a.z, a.y, a.x);
        noisy.add_scan(&s.points, 4, &(error * s.pose)).unwrap();
    }
    let dup = eval::duplicates(&polygons(&noisy), &EvalOptions::default());
    let (n, m) = (clean.primitives().len(), noisy.primitives().len());
    eprintln!(
        "{m} polygons with drifting poses, {n} without; duplicates {:?}",
        dup.pairs
    );
    assert!(dup.count <= 1, "duplicate pairs {:?}", dup.pairs);
    assert!(
        m * 10 <= n * 14,
        "{m} polygons with drifting poses, {n} without"
    );
}

/// Finite float32 points can leave every float range once a pose rotates
/// them (3.4e38 m along two axes), and a rigid pose can move a scan to
/// 1e308 m: both are errors that name the point or the pose, the scenario
/// is left exactly as it was, and the next good scan goes in. (Before,
/// the first panicked in the voxel hash and the second put infinities in
/// the map.)
#[test]
fn coordinates_beyond_any_map_are_errors_and_change_nothing() {
    let d = drive(Layout::Street, DVec3::ZERO);
    let mut s = Scenario::new(Params::gpp2()).unwrap();
    let first = d.scan(0).unwrap();
    s.add_scan(&first.points, 4, &first.pose).unwrap();
    let before = s.to_json();
    let rot = DMat4::from_rotation_z(30f64.to_radians());
    let e = s.add_scan(&[3.4e38, 3.4e38, 3.4e38], 3, &rot).unwrap_err();
    assert!(matches!(e, Error::OutOfRange { point: 0, .. }), "{e}");
    assert!(e.to_string().contains("point 0"), "{e}");
    let far = DMat4::from_translation(DVec3::new(1e308, 0.0, 0.0));
    let e = s.add_scan(&first.points, 4, &far).unwrap_err();
    assert!(matches!(e, Error::BadPose(_)), "{e}");
    assert_eq!(s.to_json(), before);
    let next = d.scan(1).unwrap();
    let r = s.add_scan(&next.points, 4, &next.pose).unwrap();
    assert!(r.explained_by_expansion > r.points / 2);
    let cloud = polyscene::Cloud::from_flat(&[0.0, 0.0, 0.0, 1e30, 0.0, 0.0], 3);
    assert!(matches!(cloud, Err(Error::OutOfRange { point: 1, .. })));
}

/// A scenario after `scans` scans of a crossing drive, and its snapshot as
/// a JSON value.
fn snapshot_after(scans: usize, hull: HullKind) -> (Scenario, serde_json::Value) {
    let d = drive(Layout::Crossing, DVec3::ZERO);
    let mut s = Scenario::new(Params {
        hull,
        ..Params::gpp2()
    })
    .unwrap();
    for k in 0..scans {
        let scan = d.scan(k).unwrap();
        s.add_scan(&scan.points, 4, &scan.pose).unwrap();
    }
    let v = serde_json::from_str(&s.to_json()).unwrap();
    (s, v)
}

#[test]
fn snapshots_of_drives_pass_the_snapshot_checks() {
    // Far from the origin too: the bounds must hold for every state the
    // pipeline reaches, or a saved map could not be restored.
    for (layout, origin) in [
        (Layout::Street, DVec3::ZERO),
        (Layout::Crossing, DVec3::new(6.4e6, -3.1e5, 120.0)),
    ] {
        let d = drive(layout, origin);
        for hull in [HullKind::Concave, HullKind::Convex] {
            let mut s = Scenario::new(Params {
                hull,
                ..Params::gpp2()
            })
            .unwrap();
            for k in 0..30 {
                let scan = d.scan(k).unwrap();
                s.add_scan(&scan.points, 4, &scan.pose).unwrap();
                if k % 10 == 9 {
                    let back = Scenario::from_json(&s.to_json())
                        .unwrap_or_else(|e| panic!("{layout:?} {hull:?} scan {k}: {e}"));
                    assert_eq!(back.primitives(), s.primitives());
                }
            }
        }
    }
}

#[test]
fn corrupt_snapshots_are_refused_with_a_message() {
    use serde_json::json;
    let (mut s, good) = snapshot_after(6, HullKind::Concave);
    assert!(good["primitives"].as_array().unwrap().len() >= 3);
    type Edit = fn(&mut serde_json::Value);
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "a vertex at -1e200 m",
            |v| v["primitives"][0]["outline"][0][0] = json!(-1e200),
            "outline vertex 0",
        ),
        (
            "a vertex beyond the bound",
            |v| v["primitives"][1]["outline"][2][1] = json!(3e9),
            "outline vertex 2",
        ),
        (
            "a wrong area",
            |v| v["primitives"][0]["area"] = json!(1e6),
            "area",
        ),
        (
            "a negative area",
            |v| v["primitives"][0]["area"] = json!(-1.0),
            "area",
        ),
        (
            "two vertices",
            |v| {
                let o = v["primitives"][0]["outline"].as_array_mut().unwrap();
                o.truncate(2);
            },
            "2 vertices",
        ),
        (
            "a normal of length 2",
            |v| v["primitives"][0]["plane"]["normal"] = json!([0.0, 0.0, 2.0]),
            "unit normal",
        ),
        (
            "a far plane",
            |v| v["primitives"][0]["plane"]["offset"] = json!(1e300),
            "offset",
        ),
        (
            "a far frame",
            |v| v["primitives"][0]["frame"]["origin"] = json!([1e12, 0.0, 0.0]),
            "frame",
        ),
        (
            "a skewed frame",
            |v| v["primitives"][0]["frame"]["u"] = json!([0.6, 0.8, 0.0]),
            "orthonormal",
        ),
        (
            "negative moments",
            |v| v["primitives"][0]["moments"]["count"] = json!(-5.0),
            "moments",
        ),
        (
            "huge moments",
            |v| v["primitives"][0]["moments"]["sum_sq"][0] = json!(1e308 * 10.0),
            "not a polyscene snapshot",
        ),
        (
            "a far footprint",
            |v| v["primitives"][0]["footprint"]["x0"] = json!(1i64 << 40),
            "footprint",
        ),
        (
            "a pose correction with a scale",
            |v| v["correction"][0] = json!(2.0),
            "pose correction",
        ),
        (
            "a pose correction to 1e300 m",
            |v| v["correction"][12] = json!(1e300),
            "pose correction",
        ),
        (
            "unsorted ids",
            |v| v["primitives"].as_array_mut().unwrap().swap(0, 1),
            "sorted",
        ),
        (
            "an id at nextId",
            |v| v["nextId"] = json!(v["primitives"][0]["id"]),
            "nextId",
        ),
        (
            "a future scan",
            |v| v["primitives"][0]["last_scan"] = json!(6),
            "lastScan",
        ),
        (
            "born after last",
            |v| {
                let last = v["primitives"][0]["last_scan"].as_u64().unwrap();
                v["primitives"][0]["born_scan"] = json!(last + 1);
            },
            "bornScan",
        ),
    ];
    for (name, edit, want) in cases {
        let mut bad = good.clone();
        edit(&mut bad);
        let e = Scenario::from_json(&bad.to_string())
            .map(|_| ())
            .unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("not a polyscene snapshot"), "{name}: {msg}");
        assert!(msg.contains(want), "{name}: expected '{want}' in: {msg}");
        // A parsed value is refused alike (but for the text's position).
        let e = Scenario::from_json_value(bad).map(|_| ()).unwrap_err();
        assert!(msg.starts_with(&e.to_string()), "{name}: {e} against {msg}");
    }
    // A scenario never has a viewpoint (its scans' poses place the
    // sensor): a snapshot with one is refused as `Scenario::new` refuses it.
    let mut seen_from = good.clone();
    seen_from["params"]["viewpoint"] = json!([0.0, 0.0, 1.8]);
    let e = Scenario::from_json(&seen_from.to_string())
        .map(|_| ())
        .unwrap_err();
    assert!(e.to_string().contains("'viewpoint'"), "{e}");
    // The good snapshot still loads and continues like the original.
    let mut back = Scenario::from_json(&good.to_string()).unwrap();
    let scan = drive(Layout::Crossing, DVec3::ZERO).scan(6).unwrap();
    let a = s.add_scan(&scan.points, 4, &scan.pose).unwrap();
    let b = back.add_scan(&scan.points, 4, &scan.pose).unwrap();
    assert_eq!(
        (a.added, a.grown, a.polygon_count),
        (b.added, b.grown, b.polygon_count)
    );
}

#[test]
fn a_snapshot_at_the_coordinate_bound_is_accepted_and_scans_go_on() {
    // An outline reaching 1e9 m (the coordinate bound) is a legal state:
    // the next scan must finish (it once took a minute for -1e200).
    let (_, mut v) = snapshot_after(3, HullKind::Convex);
    let p = &mut v["primitives"][0];
    let outline: Vec<[f64; 2]> = serde_json::from_value(p["outline"].clone()).unwrap();
    let origin: [f64; 3] = serde_json::from_value(p["frame"]["origin"].clone()).unwrap();
    let u: [f64; 3] = serde_json::from_value(p["frame"]["u"].clone()).unwrap();
    // Move vertex 0 along u until its world position reaches 0.9e9 m on u's main axis.
    let axis = (0..3)
        .max_by(|&a, &b| u[a].abs().total_cmp(&u[b].abs()))
        .unwrap();
    let mut ring = outline.clone();
    ring[0][0] += (0.9e9 - origin[axis].abs()) / u[axis].abs();
    let area = 0.5
        * (0..ring.len())
            .map(|i| {
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>();
    if area <= 0.0 {
        return; // moving the vertex folded the ring: nothing to test here
    }
    p["outline"] = serde_json::json!(ring);
    p["area"] = serde_json::json!(area);
    let mut s = Scenario::from_json(&v.to_string()).unwrap();
    let scan = drive(Layout::Crossing, DVec3::ZERO).scan(3).unwrap();
    s.add_scan(&scan.points, 4, &scan.pose).unwrap();
}

#[test]
fn too_many_points_are_refused_before_anything_is_read() {
    use polyscene::cloud::MAX_POINTS;
    // Zeroed pages are not touched by the count check.
    let values = vec![0f32; (MAX_POINTS + 1) * 3];
    let e = polyscene::Cloud::from_flat(&values, 3).unwrap_err();
    assert!(
        matches!(e, Error::TooManyPoints { points, limit } if points == MAX_POINTS + 1 && limit == MAX_POINTS),
        "{e}"
    );
    let mut s = Scenario::new(Params::gpp2()).unwrap();
    let e = s.add_scan(&values, 3, &DMat4::IDENTITY).unwrap_err();
    assert!(e.to_string().contains("more than the 16777216"), "{e}");
    assert_eq!(s.scans(), 0);
}

#[test]
fn an_expansion_gate_below_three_centimetres_is_taken_as_given() {
    // expandAcross below the gate's 3 cm floor once made the gate's clamp panic.
    let d = drive(Layout::Street, DVec3::ZERO);
    let mut params = Params::gpp2();
    params.other.expand_across = 1e-3;
    params.ground.expand_across = 1e-3;
    let mut s = Scenario::new(params).unwrap();
    for k in 0..3 {
        let scan = d.scan(k).unwrap();
        s.add_scan(&scan.points, 4, &scan.pose).unwrap();
    }
    assert!(!s.primitives().is_empty());
}

/// A street-like box seen from a sensor 1.8 m above its floor, in the
/// sensor frame: a 40 x 12 m floor, walls along both sides and, with
/// `end`, a wall across its end (the only surface that fixes the position
/// along the street). Points 0.15 m apart with 5 mm noise.
fn street_box(end: bool, seed: u64) -> Vec<f32> {
    use glam::DVec3 as V;
    use polyscene::internals::Rng;
    let mut rng = Rng::new(seed);
    let mut pts = Vec::new();
    let (step, sigma) = (0.15, 0.005);
    common::rect(
        &mut pts,
        V::new(-20.0, -6.0, -1.8),
        V::X,
        V::Y,
        40.0,
        12.0,
        step,
        sigma,
        &mut rng,
    );
    for y in [-6.0, 6.0] {
        common::rect(
            &mut pts,
            V::new(-20.0, y, -1.8),
            V::X,
            V::Z,
            40.0,
            5.8,
            step,
            sigma,
            &mut rng,
        );
    }
    if end {
        common::rect(
            &mut pts,
            V::new(20.0, -6.0, -1.8),
            V::Y,
            V::Z,
            12.0,
            5.8,
            step,
            sigma,
            &mut rng,
        );
    }
    common::flat(&pts)
}

/// The pose error of a drifting odometry: a shift and a turn about the
/// sensor (at `pose`'s origin).
fn pose_error(shift: DVec3, turn_deg: DVec3) -> DMat4 {
    let r = turn_deg * std::f64::consts::PI / 180.0;
    DMat4::from_translation(shift) * DMat4::from_euler(glam::EulerRot::ZYX, r.z, r.y, r.x)
}

/// The world displacement of point `p` (sensor frame, identity true pose)
/// once placed through `pose` and moved by the scenario's correction.
fn placed_off(s: &Scenario, pose: &DMat4, p: DVec3) -> DVec3 {
    (s.correction() * *pose).transform_point3(p) - p
}

/// The street box (`end`: with its end wall) mapped from the true pose,
/// then seen again (fresh noise) through a pose 5 cm and 0.1-0.15 degrees
/// off: the scenario, the second scan's report and the pose error.
fn seen_again_through_an_error(end: bool) -> (Scenario, polyscene::ScanReport, DMat4) {
    let error = pose_error(DVec3::new(0.05, -0.04, 0.03), DVec3::new(0.1, -0.1, 0.15));
    let mut s = Scenario::new(Params::gpp2()).unwrap();
    s.add_scan(&street_box(end, 1), 3, &DMat4::IDENTITY)
        .unwrap();
    let r = s.add_scan(&street_box(end, 2), 3, &error).unwrap();
    (s, r, error)
}

#[test]
fn alignment_undoes_a_pose_error_where_the_scene_pins_it_down() {
    // With the end wall every direction is
    // pinned: the corrected placement is within 5 mm everywhere in the
    // box. Without alignment the 5 cm error alone would exceed the 3-8 cm
    // expansion gate at the far end.
    let (s, r, error) = seen_again_through_an_error(true);
    let a = &r.alignment;
    assert!(a.applied && a.constrained == 6, "{a:?}");
    for p in [
        DVec3::new(19.0, 5.0, 3.0),
        DVec3::new(-19.0, -5.0, -1.8),
        DVec3::new(0.0, 6.0, 0.0),
    ] {
        let off = placed_off(&s, &error, p);
        assert!(off.length() < 0.005, "{p} placed {off} off");
    }
    assert_eq!(
        a.correction,
        s.correction().to_cols_array(),
        "the report gives the correction"
    );
    // The scan grew what scan 0 found instead of adding a second layer.
    assert!(
        r.explained_by_expansion as f64 > 0.95 * r.points as f64,
        "{r:?}"
    );
}

#[test]
fn alignment_leaves_alone_the_directions_nothing_pins_down() {
    // Without the end wall nothing tells where along the street the scan
    // is: the fit corrects the other five directions and keeps the given
    // position along x (it does not slide), and says so.
    let (s, r, error) = seen_again_through_an_error(false);
    assert!(
        r.alignment.applied && r.alignment.constrained == 5,
        "{:?}",
        r.alignment
    );
    for p in [DVec3::new(19.0, 5.0, 3.0), DVec3::new(-19.0, -5.0, -1.8)] {
        let off = placed_off(&s, &error, p);
        assert!(
            off.y.abs() < 0.005 && off.z.abs() < 0.005,
            "{p} placed {off} off"
        );
        assert!(
            (off.x - 0.05).abs() < 0.005,
            "{p} placed {off} off: it slid along x"
        );
    }
}

#[test]
fn exact_poses_are_left_exactly_as_given() {
    // The same place seen again through the same pose (fresh noise): the
    // fit's step is below the deadband, nothing moves, and the map is the
    // one alignment off gives.
    let run = |align: bool| {
        let mut p = Params::gpp2();
        p.align_scans = align;
        let mut s = Scenario::new(p).unwrap();
        let mut reports = Vec::new();
        for seed in 1..4 {
            reports.push(
                s.add_scan(&street_box(true, seed), 3, &DMat4::IDENTITY)
                    .unwrap(),
            );
        }
        (s, reports)
    };
    let ((on, reports), (off, _)) = (run(true), run(false));
    assert!(reports[1..]
        .iter()
        .all(|r| r.alignment.pairs > 1000 && !r.alignment.applied));
    assert_eq!(on.correction(), DMat4::IDENTITY);
    assert_eq!(on.primitives(), off.primitives());
}

#[test]
fn one_polygon_fitted_off_does_not_turn_exact_poses() {
    // The street box seen twice through the true pose; in the first scan
    // a 6 x 4 m roof 1.3 m above the floor lies tilted (as one scan's fit
    // of a car's roof was, 2.5 degrees off, on the independent bench), in
    // the second it is level. That roof alone pulls the second scan
    // towards its tilt; the floor and the walls hold it where it is. No
    // correction is applied, and the map is the one alignment off gives.
    let scan = |seed: u64, tilt_deg: f64| {
        use polyscene::internals::Rng;
        let mut pts: Vec<f32> = street_box(true, seed);
        let t = tilt_deg.to_radians();
        let mut roof = Vec::new();
        common::rect(
            &mut roof,
            DVec3::new(-3.0, -2.0, -0.5),
            DVec3::X,
            DVec3::new(0.0, t.cos(), t.sin()),
            6.0,
            4.0,
            0.03,
            0.005,
            &mut Rng::new(seed + 100),
        );
        pts.extend(common::flat(&roof));
        pts
    };
    let run = |align: bool, pose: DMat4| {
        let mut p = Params::gpp2();
        p.align_scans = align;
        let mut s = Scenario::new(p).unwrap();
        s.add_scan(&scan(1, 1.0), 3, &DMat4::IDENTITY).unwrap();
        let r = s.add_scan(&scan(2, 0.0), 3, &pose).unwrap();
        (s, r)
    };
    let ((on, r), (off, _)) = (run(true, DMat4::IDENTITY), run(false, DMat4::IDENTITY));
    assert!(
        r.alignment.pairs > 1000 && !r.alignment.applied,
        "{:?}",
        r.alignment
    );
    assert_eq!(on.correction(), DMat4::IDENTITY);
    assert_eq!(on.primitives(), off.primitives());
    // Seen through a pose 5 cm and 0.1-0.15 degrees off, every polygon
    // agrees on the step, the roof too: the error is undone as without
    // the roof (within 5 mm; the roof's tilt weighs little on it).
    let error = pose_error(DVec3::new(0.05, -0.04, 0.03), DVec3::new(0.1, -0.1, 0.15));
    let (s, r) = run(true, error);
    assert!(r.alignment.applied, "{:?}", r.alignment);
    for p in [DVec3::new(19.0, 5.0, 3.0), DVec3::new(-19.0, -5.0, -1.8)] {
        let off = placed_off(&s, &error, p);
        assert!(off.length() < 0.005, "{p} placed {off} off");
    }
}

/// The drift test on the project's simulator: poses that drift as
/// in the fidelity bench's `--pose-noise 0.03,0.15` (each scan adds up to
/// 3 cm and 0.15 degrees about each axis, turning about the sensor,
/// bounded at 12 cm and 0.6 degrees). Measured (street, 60 scans): share
/// explained by expansion 0.939, as with exact poses (0.787 without
/// alignment), 140 polygons against 135, no duplicate pair.
#[test]
fn a_drifting_drive_is_explained_as_well_as_an_exact_one() {
    use polyscene::internals::Rng;
    let d = drive(Layout::Street, DVec3::ZERO);
    let scans = 60;
    let run = |noise: bool, align: bool| {
        let mut p = Params::gpp2();
        p.align_scans = align;
        let mut s = Scenario::new(p).unwrap();
        let mut rng = Rng::new(11);
        let (mut t, mut a) = (DVec3::ZERO, DVec3::ZERO);
        let step = |x: f64, r: &mut Rng| (r.uniform() * 2.0 - 1.0) * x;
        let mut explained = 0.0;
        for k in 0..scans {
            let scan = d.scan(k).unwrap();
            t = (t + DVec3::new(
                step(0.03, &mut rng),
                step(0.03, &mut rng),
                step(0.03, &mut rng),
            ))
            .clamp(DVec3::splat(-0.12), DVec3::splat(0.12));
            a = (a + DVec3::new(
                step(0.15, &mut rng),
                step(0.15, &mut rng),
                step(0.15, &mut rng),
            ))
            .clamp(DVec3::splat(-0.6), DVec3::splat(0.6));
            let pose = if noise {
                // Turned about the sensor, shifted in the world.
                let e = pose_error(DVec3::ZERO, a);
                let (_, r, p) = scan.pose.to_scale_rotation_translation();
                DMat4::from_rotation_translation(glam::DQuat::from_mat4(&e) * r, p + t)
            } else {
                scan.pose
            };
            let r = s.add_scan(&scan.points, 4, &pose).unwrap();
            if k > 0 {
                explained += r.explained_by_expansion as f64 / r.points as f64;
            }
        }
        (s, explained / (scans - 1) as f64)
    };
    let (exact, e0) = run(false, true);
    let (drifting, e1) = run(true, true);
    let (_, e_off) = run(true, false);
    let dup = eval::duplicates(&polygons(&drifting), &EvalOptions::default());
    let (n, m) = (exact.primitives().len(), drifting.primitives().len());
    eprintln!(
        "explained {e1:.3} drifting, {e0:.3} exact, {e_off:.3} drifting without alignment; \
         {m} polygons against {n}; duplicates {:?}",
        dup.pairs
    );
    assert!(e1 >= e0 - 0.05, "explained {e1:.3} against {e0:.3}");
    assert!(
        e_off < e0 - 0.05,
        "the drift should matter without alignment: {e_off:.3}"
    );
    assert_eq!(dup.count, 0, "duplicate pairs {:?}", dup.pairs);
    assert!(m * 10 <= n * 12, "{m} polygons drifting, {n} exact");
}

/// A car's end, a wall 1.8 m wide and 1.2 m high 6 m ahead of the sensor
/// (points 5 cm apart, noise `sigma` m), and with `beside` what lies just past
/// its edge: `Some(true)` a tree crown (8,000 points filling a 2 m box
/// that the end's plane cuts through the middle of), `Some(false)` the
/// end's own plane going on 2 m.
fn car_end(beside: Option<bool>, sigma: f64, seed: u64) -> Vec<f32> {
    use glam::DVec3 as V;
    use polyscene::internals::Rng;
    let mut rng = Rng::new(seed);
    let mut pts = Vec::new();
    let step = 0.05;
    let corner = V::new(6.0, -0.9, -1.3);
    common::rect(
        &mut pts,
        corner,
        V::Y,
        V::Z,
        1.8,
        1.2,
        step,
        sigma,
        &mut rng,
    );
    match beside {
        Some(true) => {
            for _ in 0..8000 {
                pts.push(V::new(
                    rng.range(5.0, 7.0),
                    rng.range(0.95, 2.95),
                    rng.range(-1.3, 0.7),
                ));
            }
        }
        Some(false) => {
            let corner = V::new(6.0, 0.95, -1.3);
            common::rect(
                &mut pts,
                corner,
                V::Y,
                V::Z,
                2.0,
                1.2,
                step,
                sigma,
                &mut rng,
            );
        }
        None => {}
    }
    common::flat(&pts)
}

#[test]
fn expansion_takes_more_of_a_surface_not_a_slice_of_a_volume() {
    // How far the end's polygon reaches along y after a second scan.
    let reach = |beside: bool, sigma: f64| {
        let mut s = Scenario::new(Params::gpp2()).unwrap();
        s.add_scan(&car_end(None, sigma, 1), 3, &DMat4::IDENTITY)
            .unwrap();
        s.add_scan(&car_end(Some(beside), sigma, 2), 3, &DMat4::IDENTITY)
            .unwrap();
        let ends: Vec<f64> = s
            .primitives()
            .iter()
            .filter(|p| p.plane.normal.x.abs() > 0.99 && (p.plane.offset.abs() - 6.0).abs() < 0.05)
            .flat_map(|p| p.vertices().into_iter().map(|v| v.y))
            .collect();
        assert!(!ends.is_empty(), "the end is mapped");
        ends.into_iter().fold(f64::NEG_INFINITY, f64::max)
    };
    // 5 mm noise, as the simulators', and 2 cm, as a real sensor's at
    // range (the gate then widens with the end's own spread).
    for sigma in [0.005, 0.02] {
        let tree = reach(true, sigma);
        assert!(
            tree < 1.2,
            "{sigma}: the end grew into the crown's slice, to y = {tree}"
        );
        let wall = reach(false, sigma);
        assert!(
            wall > 2.7,
            "{sigma}: the end did not grow along its own plane: y = {wall}"
        );
    }
}

/// A 4.5 x 1.2 m surface (a car's side, or the same patch laid flat on
/// the ground) seen from a sensor standing still at the origin, a little
/// of it in each scan: `per_scan` new random points, 1 cm of noise. The
/// scans after which a primitive lies on it (its normal within 10 degrees
/// of the surface's, the surface's centre within 0.1 m of its plane).
fn sparse_surface_found_after(upright: bool, scans: usize, per_scan: usize) -> Vec<usize> {
    use polyscene::internals::Rng;
    let mut rng = Rng::new(5);
    let (origin, u, v) = if upright {
        (DVec3::new(10.0, 20.0, -1.5), DVec3::X, DVec3::Z)
    } else {
        (DVec3::new(10.0, 6.0, -1.8), DVec3::X, DVec3::Y)
    };
    let normal = u.cross(v);
    let mut s = Scenario::new(Params::default()).unwrap();
    let mut found = Vec::new();
    for k in 0..scans {
        let pts: Vec<DVec3> = (0..per_scan)
            .map(|_| {
                origin
                    + u * rng.range(0.0, 4.5)
                    + v * rng.range(0.0, 1.2)
                    + normal * 0.01 * rng.gaussian()
            })
            .collect();
        s.add_scan(&common::flat(&pts), 3, &DMat4::IDENTITY)
            .unwrap();
        let on = s.primitives().iter().any(|q| {
            q.plane.normal.dot(normal).abs() > 10f64.to_radians().cos()
                && q.plane.signed_distance(origin + u * 2.25 + v * 0.6).abs() < 0.1
        });
        if on {
            found.push(k);
        }
    }
    found
}

/// The pool thins what it keeps to one point a 0.1 m voxel, so a surface
/// of `minArea` holds at most 150 points there: a far car side seen a few
/// rings at a time may never gather `minInliers` (150) in the pool, and the
/// scenario's detection on it asks for what a `minArea` polygon holds on
/// that grid at `minOccupancy` (75) instead. Near the ground it still asks
/// for `minInliers`: far ground is laser rings seen at a grazing angle,
/// whose planes tilt (`CascadePolicy::pool_support`).
#[test]
fn a_car_side_seen_a_little_in_each_scan_is_found_once_the_pool_holds_it() {
    // 10 points a scan: 80-120 in the pool by scans 8-11.
    let side = sparse_surface_found_after(true, 12, 10);
    assert!(
        side.first().is_some_and(|&k| k <= 11),
        "upright: found after scans {side:?}"
    );
    let flat = sparse_surface_found_after(false, 20, 10);
    assert!(
        flat.first().is_some_and(|&k| k >= 13),
        "on the ground: found after scans {flat:?}"
    );
}

/// A scenario's first scan meets an empty map: expansion explained none of
/// it, so its detection runs on a whole scan, and a candidate that may hold
/// two surfaces is judged on its dominant layer, as in one-shot detection
/// (`CascadePolicy::on_empty_map`). The scan: two roads 12 m wide crossing
/// 1.8 m below the sensor, and a plaza a curb (15 cm) higher in each
/// corner. A plane between the two heights holds both within the ground's
/// inlier distance and scores more than either, but is too rough to be
/// one surface; the whole candidate used to leave play, roads and plazas
/// with it (measured: 5 of these 12 RANSAC seeds). On the independent
/// bench's drifting drives a first scan kept such a plane tilted across a
/// curb, and the map a duplicate pair. At every seed both come out, each
/// at its own height over its own area.
#[test]
fn a_first_scan_keeps_roads_and_plazas_a_step_above_them() {
    let (half, road): (f64, f64) = (20.0, 6.0);
    let pts = common::height_field([-half, half], [-half, half], 0.002, 8, |x, y| {
        if x.abs() <= road || y.abs() <= road {
            -1.8
        } else {
            -1.65
        }
    });
    let scan = common::flat(&pts);
    for seed in 1..=12 {
        let mut s = Scenario::new(Params {
            seed,
            ..Params::gpp2()
        })
        .unwrap();
        s.add_scan(&scan, 3, &DMat4::IDENTITY).unwrap();
        // Roads: 2 x 40 x 12 - 12 x 12 m^2; plazas: 4 x 14 x 14 m^2.
        for (name, z, want) in [("roads", -1.8, 816.0), ("plazas", -1.65, 784.0)] {
            let at = DVec3::new(0.0, 0.0, z);
            let area: f64 = s
                .primitives()
                .iter()
                .filter(|q| {
                    q.plane.normal.dot(DVec3::Z).abs() > 1f64.to_radians().cos()
                        && q.plane.signed_distance(at).abs() < 0.02
                })
                .map(|q| q.area)
                .sum();
            let got: Vec<_> = s
                .primitives()
                .iter()
                .map(|q| (q.plane.normal, q.plane.offset, q.area))
                .collect();
            assert!(
                (0.9 * want..1.1 * want).contains(&area),
                "seed {seed}, {name}: {area:.1} m^2 of {want}: {got:?}"
            );
        }
    }
}
