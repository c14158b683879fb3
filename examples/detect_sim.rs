//! One-shot detection timing on a simulated scan and a simulated location.
//! `cargo run --release --example detect_sim`
use polyscene::cloud::Cloud;
use polyscene::detect::detect;
use polyscene::params::Params;
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};

/// Detect `runs` times from `viewpoint`; print the median time with the
/// polygon and round counts of that run.
fn time(label: &str, cloud: &Cloud, viewpoint: glam::DVec3, runs: usize) {
    let p = Params {
        viewpoint: Some(viewpoint.to_array()),
        ..Params::gpp2()
    };
    let mut t: Vec<_> = (0..runs)
        .map(|_| {
            let d = detect(cloud, &p).unwrap();
            (d.time_ms, d.primitives.len(), d.steps.len())
        })
        .collect();
    t.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (ms, polygons, rounds) = t[runs / 2];
    println!(
        "{label} {} pts: median {ms:.1} ms, {polygons} polygons, {rounds} rounds",
        cloud.len()
    );
}

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
    time("scan ", &cloud, scan.pose.w_axis.truncate(), 7);
    let loc = drive.location(20, 10).unwrap();
    let cloud = Cloud::from_world_f64(&loc.points).unwrap();
    let mean = loc.viewpoint();
    time("location", &cloud, mean, 3);
}
