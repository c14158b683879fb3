//! Tests of the simulator as a whole: exact hits, determinism, scene
//! contents, orientation of the ground truth, datasets on disk.

use super::*;
use crate::geometry::polygon::{is_simple, signed_area};
use glam::DVec3;

const FAR: DVec3 = DVec3::new(500_000.0, 4_500_000.0, 50.0);

fn drive(layout: Layout, seed: u64, sensor: SensorModel, origin: DVec3) -> Drive {
    let options = DriveOptions {
        origin,
        ..DriveOptions::default()
    };
    Drive::new(layout, seed, sensor, options).unwrap()
}

/// Distance from a world point to a clutter object's surface.
fn clutter_distance(c: &Clutter, p: DVec3) -> f64 {
    match *c {
        Clutter::Pole {
            base,
            radius,
            height,
        }
        | Clutter::Trunk {
            base,
            radius,
            height,
        } => {
            let radial = ((p - base).truncate().length() - radius).abs();
            let above = (p.z - (base.z + height)).max(base.z - p.z).max(0.0);
            radial.max(above)
        }
        Clutter::Crown { centre, radius } => ((p - centre).length() - radius).abs(),
    }
}

#[test]
fn noise_free_hits_lie_on_their_polygons() {
    for layout in Layout::ALL {
        for (origin, k) in [(DVec3::ZERO, 0), (FAR, 100), (FAR, 199)] {
            let d = drive(layout, 7, SensorModel::noise_free(), origin);
            let scene = d.scene();
            let scan = d.scan(k).unwrap();
            assert_eq!(scan.points.len(), 4 * scan.labels.len());
            let sensor = scan.pose.w_axis.truncate();
            let mut clutter = 0;
            for (p, &l) in scan.world_points().iter().zip(&scan.labels) {
                let range = (*p - sensor).length();
                assert!((0.9..=120.0 + 1e-3).contains(&range), "range {range}");
                if l == CLUTTER {
                    clutter += 1;
                    let on = scene.clutter.iter().any(|c| clutter_distance(c, *p) < 1e-4)
                        || scene.minor.iter().any(|m| m.distance(*p) < 1e-4);
                    assert!(on, "{layout} scan {k}: clutter point {p} on nothing");
                    continue;
                }
                let g = scene.polygon(l).expect("label is a polygon id");
                let dist = g.polygon.distance(*p);
                assert!(
                    dist < 1e-4,
                    "{layout} scan {k}: point {p} is {dist} m from its {} polygon {l}",
                    g.kind
                );
            }
            assert!(clutter > 0, "{layout}: no clutter hit");
        }
    }
}

#[test]
fn the_street_is_watertight() {
    // Every ray more than 1.2° below the horizon hits something within range
    // (road, sidewalks, curbs, facades, fences close every escape), so cuts
    // between casting pieces leave no cracks.
    let d = drive(Layout::Street, 2, SensorModel::noise_free(), FAR);
    let s = d.sensor();
    let low = s.elevations_deg.iter().filter(|&&e| e < -1.2).count();
    for k in [0, 33, 150] {
        let scan = d.scan(k).unwrap();
        let n = scan
            .points
            .chunks_exact(4)
            .filter(|p| {
                (p[2] as f64) < -libm::tan(1.2f64.to_radians()) * (p[0] as f64).hypot(p[1] as f64)
            })
            .count();
        assert_eq!(n, low * s.azimuth_steps, "scan {k}");
    }
}

#[test]
fn noisy_hits_lie_near_their_polygons() {
    let sensor = SensorModel::default();
    let sigma = sensor.range_sigma;
    let d = drive(Layout::Crossing, 3, sensor, FAR);
    let exact = drive(Layout::Crossing, 3, SensorModel::noise_free(), FAR);
    let scan = d.scan(60).unwrap();
    let full = exact.scan(60).unwrap().len();
    // About 5% dropout.
    let kept = scan.len() as f64 / full as f64;
    assert!((0.93..0.97).contains(&kept), "kept {kept}");
    let mut sum_sq = 0.0;
    let mut n = 0.0;
    for (p, &l) in scan.world_points().iter().zip(&scan.labels) {
        if let Some(g) = d.scene().polygon(l) {
            let dist = g.polygon.distance(*p);
            assert!(dist < 6.0 * sigma, "point {dist} m off its polygon");
            sum_sq += dist * dist;
            n += 1.0;
        }
    }
    // The distance to the plane is the range noise times the cosine of the
    // incidence angle, so its RMS is below sigma but not far below.
    let rms = (sum_sq / n).sqrt();
    assert!(rms < sigma && rms > 0.2 * sigma, "rms {rms}");
    for p in scan.points.chunks_exact(4) {
        assert!((0.0..=1.0).contains(&p[3]));
    }
}

#[test]
fn scans_are_deterministic_and_independent() {
    let a = drive(Layout::Street, 11, SensorModel::default(), DVec3::ZERO);
    let b = drive(Layout::Street, 11, SensorModel::default(), DVec3::ZERO);
    // b generates other scans first: scan 5 must not depend on them.
    let _ = b.scan(0).unwrap();
    let _ = b.scan(9).unwrap();
    let (sa, sb) = (a.scan(5).unwrap(), b.scan(5).unwrap());
    let bits = |s: &Scan| s.points.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&sa), bits(&sb));
    assert_eq!(sa.labels, sb.labels);
    assert_eq!(sa.pose, sb.pose);
    // Noise differs between scans.
    assert_ne!(bits(&sa), bits(&a.scan(6).unwrap()));
    // Different seeds give different scenes.
    let c = drive(Layout::Street, 12, SensorModel::default(), DVec3::ZERO);
    assert_ne!(a.scene().ground_truth_json(), c.scene().ground_truth_json());
    let e = drive(Layout::Crossing, 11, SensorModel::default(), DVec3::ZERO);
    let f = drive(Layout::Crossing, 12, SensorModel::default(), DVec3::ZERO);
    assert_ne!(e.scene().ground_truth_json(), f.scene().ground_truth_json());
}

#[test]
fn the_origin_only_moves_poses_and_ground_truth() {
    let a = drive(Layout::Crossing, 2, SensorModel::default(), DVec3::ZERO);
    let b = drive(Layout::Crossing, 2, SensorModel::default(), FAR);
    let (sa, sb) = (a.scan(30).unwrap(), b.scan(30).unwrap());
    assert_eq!(sa.points, sb.points);
    assert_eq!(sa.labels, sb.labels);
    assert!((sb.pose.w_axis.truncate() - sa.pose.w_axis.truncate() - FAR).length() < 1e-6);
    let (ga, gb) = (
        &a.scene().polygons[5].polygon,
        &b.scene().polygons[5].polygon,
    );
    for (va, vb) in ga.vertices().iter().zip(gb.vertices()) {
        assert!((vb - *va - FAR).length() < 1e-6);
    }
}

#[test]
fn point_counts_and_drive_length() {
    for layout in Layout::ALL {
        let d = drive(layout, 1, SensorModel::default(), DVec3::ZERO);
        assert!(d.len() >= 150, "{layout}: {} scans", d.len());
        for k in [0, d.len() / 2, d.len() - 1] {
            let n = d.scan(k).unwrap().len();
            assert!(
                (100_000..=130_000).contains(&n),
                "{layout} scan {k}: {n} points"
            );
        }
        assert!(d.scan(d.len()).is_err());
        // About 1 m between scans, sensor 1.8 m above the road, on the road.
        let p0 = d.pose(0).unwrap().w_axis.truncate();
        let p1 = d.pose(1).unwrap().w_axis.truncate();
        assert!(((p1 - p0).length() - 1.0).abs() < 0.01);
        assert!((p0.z - 1.8).abs() < 1e-12);
        for m in d.poses() {
            assert!(crate::cloud::check_rigid(&m).is_ok());
            assert!(m.w_axis.y.abs() < 3.0, "off the lane: {}", m.w_axis);
        }
    }
    let bad = DriveOptions {
        step: 0.0,
        ..DriveOptions::default()
    };
    assert!(Drive::new(Layout::Street, 1, SensorModel::default(), bad).is_err());
    let sensor = SensorModel {
        azimuth_steps: 0,
        ..SensorModel::default()
    };
    assert!(Drive::new(Layout::Street, 1, sensor, DriveOptions::default()).is_err());
}

#[test]
fn both_layouts_have_every_element() {
    for seed in [1, 2, 3] {
        for layout in Layout::ALL {
            let scene = Scene::new(layout, seed, DVec3::ZERO).unwrap();
            let counts = scene.kind_counts();
            for (kind, n) in &counts {
                let needed = *kind != SurfaceKind::Ramp || layout == Layout::Crossing;
                assert!(!needed || *n > 0, "{layout} seed {seed}: no {kind}");
            }
            let of = |k: SurfaceKind| scene.polygons.iter().filter(move |p| p.kind == k);
            // Doors are 0.3 m behind a parallel facade that has a notch.
            for door in of(SurfaceKind::Door) {
                let dp = door.polygon.plane();
                let c = door.polygon.vertices().iter().sum::<DVec3>() / 4.0;
                let behind = of(SurfaceKind::Facade).any(|f| {
                    let fp = f.polygon.plane();
                    fp.normal.dot(dp.normal) > 1.0 - 1e-9
                        && (fp.signed_distance(c) + 0.3).abs() < 1e-6
                        && f.polygon.ring.len() >= 8
                });
                assert!(behind, "{layout}: door {} has no notched facade", door.id);
            }
            // Stepped rooflines: non-convex facades without a door notch too.
            let stepped = of(SurfaceKind::Facade)
                .filter(|f| f.polygon.frame.normal.z.abs() < 1e-9)
                .filter(|f| {
                    let top = f
                        .polygon
                        .vertices()
                        .iter()
                        .map(|v| v.z)
                        .fold(f64::MIN, f64::max);
                    f.polygon
                        .vertices()
                        .iter()
                        .filter(|v| (v.z - top).abs() < 1e-9)
                        .count()
                        == 2
                        && f.polygon.vertices().iter().filter(|v| v.z > 3.0).count() == 4
                })
                .count();
            assert!(stepped > 0, "{layout}: no stepped roofline");
            // Cars: 4 sides and a top each, box from 0.3 m up.
            let cars = of(SurfaceKind::Vehicle).count();
            assert!(
                cars >= 50 && cars % 5 == 0,
                "{layout}: {cars} vehicle polygons"
            );
            for v in of(SurfaceKind::Vehicle) {
                let zmin = v
                    .polygon
                    .vertices()
                    .iter()
                    .map(|p| p.z)
                    .fold(f64::MAX, f64::min);
                assert!((zmin - 0.3).abs() < 1e-9 || v.polygon.frame.normal.z > 0.999);
            }
            let poles = scene
                .clutter
                .iter()
                .filter(|c| matches!(c, Clutter::Pole { .. }));
            let crowns = scene
                .clutter
                .iter()
                .filter(|c| matches!(c, Clutter::Crown { .. }));
            assert!(poles.count() > 2 && crowns.count() > 2);
            if layout == Layout::Crossing {
                let odd = of(SurfaceKind::Wall).any(|w| {
                    let n = w.polygon.frame.normal;
                    n.z.abs() < 1e-9 && n.x.abs().min(n.y.abs()) > 0.3
                });
                assert!(odd, "no wall at an odd angle");
                let ramp = of(SurfaceKind::Ramp).next().unwrap();
                let tilt = libm::acos(ramp.polygon.frame.normal.z).to_degrees();
                assert!((6.0..=10.0).contains(&tilt), "ramp tilt {tilt}");
                // L-shaped corner buildings: a road-facing facade along each road.
                let facing = |axis: DVec3| {
                    of(SurfaceKind::Facade)
                        .filter(|f| f.polygon.frame.normal.dot(axis).abs() > 0.999)
                        .count()
                };
                assert!(facing(DVec3::X) > 4 && facing(DVec3::Y) > 4);
            }
        }
    }
}

#[test]
fn ground_truth_is_simple_ccw_and_faces_the_sensor() {
    for layout in Layout::ALL {
        let d = drive(layout, 5, SensorModel::noise_free(), FAR);
        let scene = d.scene();
        for (i, g) in scene.polygons.iter().enumerate() {
            assert_eq!(g.id as usize, i);
            assert!(
                is_simple(&g.polygon.ring),
                "{layout}: polygon {i} not simple"
            );
            assert!(signed_area(&g.polygon.ring) > 0.0);
            // The Newell normal of the world outline agrees with the frame.
            let again = crate::geometry::Polygon3::from_world(&g.polygon.vertices()).unwrap();
            assert!(again.frame.normal.dot(g.polygon.frame.normal) > 1.0 - 1e-9);
            if g.kind.is_ground() {
                assert!(
                    g.polygon.frame.normal.z > 0.98,
                    "{layout}: {} {i} not up",
                    g.kind
                );
            } else {
                assert!(g.polygon.frame.normal.z.abs() < 1e-9 || g.kind == SurfaceKind::Vehicle);
            }
        }
        // From the first pose, the street's curbs and doors face the sensor.
        let first = d.pose(0).unwrap().w_axis.truncate();
        if layout == Layout::Street {
            for g in &scene.polygons {
                if matches!(g.kind, SurfaceKind::Curb | SurfaceKind::Door) || g.kind.is_ground() {
                    assert!(
                        g.polygon.plane().signed_distance(first) > 0.0,
                        "{} {}",
                        g.kind,
                        g.id
                    );
                }
            }
        }
        // Every hit, from every pose, is on the normal side of its polygon.
        for k in [0, 40, 90, 100, 110, 160] {
            let scan = d.scan(k).unwrap();
            let sensor = scan.pose.w_axis.truncate();
            for &l in &scan.labels {
                if let Some(g) = scene.polygon(l) {
                    let s = g.polygon.plane().signed_distance(sensor);
                    assert!(
                        s > 0.0,
                        "{layout} scan {k}: {} {l} seen from behind",
                        g.kind
                    );
                }
            }
        }
    }
}

#[test]
fn locations_accumulate_scans_in_the_world_frame() {
    let d = drive(Layout::Street, 4, SensorModel::default(), FAR);
    let loc = d.location(20, LOCATION_SCANS).unwrap();
    assert_eq!(loc.poses.len(), 10);
    assert_eq!(loc.points.len(), loc.labels.len());
    assert_eq!(loc.points.len(), loc.intensities.len());
    assert!(loc.points.len() > 1_000_000, "{}", loc.points.len());
    let s = d.scan(25).unwrap();
    let offset: usize = (20..25).map(|k| d.scan(k).unwrap().len()).sum();
    assert_eq!(loc.points[offset], s.world_points()[0]);
    assert_eq!(loc.labels[offset..offset + s.len()], s.labels[..]);
    assert!(d.location(195, 10).is_err());
    assert!(d.location(0, 0).is_err());
    assert!(d.location(usize::MAX, 2).is_err());
}

#[test]
fn layout_names() {
    assert_eq!("street".parse::<Layout>().unwrap(), Layout::Street);
    assert_eq!(" Crossing ".parse::<Layout>().unwrap(), Layout::Crossing);
    for l in Layout::ALL {
        assert_eq!(l.as_str().parse::<Layout>().unwrap(), l);
    }
    let e = "highway".parse::<Layout>().unwrap_err();
    assert!(matches!(e, crate::Error::BadOption { ref key, .. } if key == "layout"));
    assert!(e.to_string().contains("highway"));
    for k in SurfaceKind::ALL {
        assert_eq!(k.as_str().parse::<SurfaceKind>().unwrap(), k);
        let json = serde_json::to_string(&k).unwrap();
        assert_eq!(json, format!("\"{}\"", k.as_str()));
    }
    assert!("tree".parse::<SurfaceKind>().is_err());
}

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    std::env::temp_dir().join(format!(
        "polyscene-sim-{tag}-{}-{nanos}",
        std::process::id()
    ))
}

#[test]
fn datasets_round_trip_and_bad_files_are_named() {
    let dir = temp_dir("dataset");
    let sensor = SensorModel::default();
    write_dataset(&dir, Layout::Crossing, 9, 3, &sensor).unwrap();
    let data = read_dataset(&dir).unwrap();
    let d = Drive::new(Layout::Crossing, 9, sensor.clone(), DriveOptions::default()).unwrap();
    assert_eq!(data.scans.len(), 3);
    assert_eq!(data.poses.len(), 3);
    for (k, s) in data.scans.iter().enumerate() {
        let scan = d.scan(k).unwrap();
        assert_eq!(s.name, format!("{k:06}.bin"));
        assert_eq!(s.points, scan.points);
        assert_eq!(s.labels.as_ref(), Some(&scan.labels));
        assert!(data.poses[k].abs_diff_eq(scan.pose, 1e-9));
    }
    let gt = data.ground_truth.as_ref().unwrap();
    assert_eq!(gt.layout, "crossing");
    assert_eq!(gt.seed, 9);
    assert_eq!(gt.polygons.len(), d.scene().polygons.len());
    for (a, b) in gt.polygons.iter().zip(&d.scene().polygons) {
        assert_eq!((a.id, a.kind), (b.id, b.kind));
        let (va, vb) = (a.polygon.vertices(), b.polygon.vertices());
        assert_eq!(va.len(), vb.len());
        for (p, q) in va.iter().zip(&vb) {
            assert!((*p - *q).length() < 1e-9);
        }
    }
    // Too many scans is refused.
    assert!(write_dataset(&dir, Layout::Street, 1, 10_000, &sensor).is_err());

    // Bad inputs: the error names the file.
    let label = dir.join("000001.label");
    std::fs::write(&label, [0u8; 8]).unwrap();
    let e = read_dataset(&dir).unwrap_err().to_string();
    assert!(e.contains("000001.label"), "{e}");
    std::fs::remove_file(&label).unwrap();
    let data = read_dataset(&dir).unwrap();
    assert!(data.scans[1].labels.is_none() && data.scans[2].labels.is_some());

    let gt_path = dir.join("ground_truth.json");
    let text = std::fs::read_to_string(&gt_path).unwrap();
    std::fs::write(&gt_path, text.replacen("\"road\"", "\"river\"", 1)).unwrap();
    let e = read_dataset(&dir).unwrap_err().to_string();
    assert!(e.contains("ground_truth.json"), "{e}");
    std::fs::write(&gt_path, "{}").unwrap();
    assert!(read_dataset(&dir).is_err());
    std::fs::remove_file(&gt_path).unwrap();
    assert!(read_dataset(&dir).unwrap().ground_truth.is_none());

    let poses = dir.join("poses.txt");
    let text = std::fs::read_to_string(&poses).unwrap();
    let first = text.lines().next().unwrap().to_string();
    std::fs::write(&poses, format!("{first}\n")).unwrap();
    let e = read_dataset(&dir).unwrap_err().to_string();
    assert!(e.contains("poses.txt"), "{e}");
    std::fs::remove_file(&poses).unwrap();
    let e = read_dataset(&dir).unwrap_err().to_string();
    assert!(e.contains("poses.txt"), "{e}");

    let bin = dir.join("000000.bin");
    std::fs::write(&bin, [0u8; 5]).unwrap();
    let e = read_dataset(&dir).unwrap_err().to_string();
    assert!(e.contains("000000.bin"), "{e}");

    std::fs::remove_dir_all(&dir).unwrap();
    assert!(read_dataset(&dir).is_err());
}
