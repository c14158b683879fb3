//! Fingerprints of every output: one hash per workload over the full state
//! of the primitives (planes, moments, footprints), the labels, the scan
//! reports (without their clocks) and the scenario snapshots. A refactoring
//! that claims "outputs unchanged" must print the same lines before and after.
//! `cargo run --release --example fingerprint`
use polyscene::cloud::Cloud;
use polyscene::detect::detect;
use polyscene::params::{HullKind, Params};
use polyscene::scenario::Scenario;
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};

/// FNV-1a, 64 bits.
fn fnv(h: &mut u64, bytes: &[u8]) {
    for &b in bytes {
        *h ^= b as u64;
        *h = h.wrapping_mul(0x100_0000_01b3);
    }
}

fn one_shot(label: &str, cloud: &Cloud, params: &Params) {
    let d = detect(cloud, params).unwrap();
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    fnv(
        &mut h,
        serde_json::to_string(&d.primitives).unwrap().as_bytes(),
    );
    for l in &d.labels {
        fnv(&mut h, &l.to_le_bytes());
    }
    fnv(&mut h, &d.work.to_le_bytes());
    println!(
        "{label:<28} {:016x} polygons {:3} work {}",
        h,
        d.primitives.len(),
        d.work
    );
}

fn drive(label: &str, layout: Layout, scans: usize, params: Params) {
    let drive = Drive::new(layout, 1, SensorModel::default(), DriveOptions::default()).unwrap();
    let mut sc = Scenario::new(params).unwrap();
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for k in 0..scans.min(drive.len()) {
        let s = drive.scan(k).unwrap();
        let mut r = sc.add_scan(&s.points, 4, &s.pose).unwrap();
        r.time_ms = Default::default();
        fnv(&mut h, serde_json::to_string(&r).unwrap().as_bytes());
        for l in sc.last_labels() {
            fnv(&mut h, &l.to_le_bytes());
        }
    }
    let reports = h;
    fnv(&mut h, sc.to_json().as_bytes());
    println!(
        "{label:<28} {:016x} reports {:016x} polygons {}",
        h,
        reports,
        sc.primitives().len()
    );
}

fn main() {
    let sim = Drive::new(
        Layout::Street,
        1,
        SensorModel::default(),
        DriveOptions::default(),
    )
    .unwrap();
    let scan = sim.scan(20).unwrap();
    let cloud = Cloud::from_world_f64(&scan.world_points()).unwrap();
    let vp = scan.pose.w_axis.truncate().to_array();
    for (name, base) in [("gpp2", Params::gpp2()), ("gpp1", Params::gpp1())] {
        for hull in [HullKind::Concave, HullKind::Convex] {
            let p = Params {
                viewpoint: Some(vp),
                hull,
                ..base.clone()
            };
            one_shot(&format!("street scan {name} {hull:?}"), &cloud, &p);
        }
    }
    for layout in [Layout::Street, Layout::Crossing] {
        let d = Drive::new(layout, 1, SensorModel::default(), DriveOptions::default()).unwrap();
        let loc = d.location(20, 10).unwrap();
        let cloud = Cloud::from_world_f64(&loc.points).unwrap();
        let mean = loc.viewpoint();
        for hull in [HullKind::Concave, HullKind::Convex] {
            let p = Params {
                viewpoint: Some(mean.to_array()),
                hull,
                ..Params::gpp2()
            };
            one_shot(&format!("location {layout:?} {hull:?}"), &cloud, &p);
        }
    }
    for file in [
        "www/data/ouster_os0_128_single_scan_016.bin",
        "www/data/ouster_os1_64_legacy_f12073.bin",
    ] {
        let values = polyscene::io::read_bin(std::path::Path::new(file), 4).unwrap();
        let cloud = Cloud::from_flat(&values, 4).unwrap();
        for seed in 1..=3 {
            let p = Params {
                seed,
                ..Params::gpp2()
            };
            let short = &file[9..21];
            one_shot(&format!("real {short} seed {seed}"), &cloud, &p);
        }
    }
    drive("drive street 100", Layout::Street, 100, Params::gpp2());
    drive(
        "drive street 30 convex",
        Layout::Street,
        30,
        Params {
            hull: HullKind::Convex,
            ..Params::gpp2()
        },
    );
    drive(
        "drive crossing 40 noexp",
        Layout::Crossing,
        40,
        Params {
            expansion: false,
            ..Params::gpp2()
        },
    );
}
