//! One-shot detection timing on a simulated scan and a simulated location.
//! `cargo run --release --example detect_sim`
use polyscene::cloud::Cloud;
use polyscene::detect::detect;
use polyscene::params::Params;
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};

fn main() {
    let drive = Drive::new(
        Layout::Street,
        1,
        SensorModel::default(),
        DriveOptions::default(),
    )
    .unwrap();
    let scan = drive.scan(20).unwrap();
    let cloud = Cloud::from_world_f64(&scan.world_points()).unwrap();
    let p = Params {
        viewpoint: scan.pose.w_axis.truncate().to_array(),
        ..Params::gpp2()
    };
    let mut t = vec![];
    for _ in 0..7 {
        let d = detect(&cloud, &p).unwrap();
        t.push((d.time_ms, d.primitives.len(), d.steps.len()));
    }
    t.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!(
        "scan  {} pts: median {:.1} ms, {} polygons, {} rounds",
        cloud.len(),
        t[3].0,
        t[3].1,
        t[3].2
    );
    let loc = drive.location(20, 10).unwrap();
    let cloud = Cloud::from_world_f64(&loc.points).unwrap();
    let mean = loc
        .poses
        .iter()
        .map(|p| p.w_axis.truncate())
        .sum::<glam::DVec3>()
        / loc.poses.len() as f64;
    let p = Params {
        viewpoint: mean.to_array(),
        ..Params::gpp2()
    };
    let mut t = vec![];
    for _ in 0..3 {
        let d = detect(&cloud, &p).unwrap();
        t.push((d.time_ms, d.primitives.len(), d.steps.len()));
    }
    t.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!(
        "location {} pts: median {:.1} ms, {} polygons, {} rounds",
        cloud.len(),
        t[1].0,
        t[1].1,
        t[1].2
    );
}
