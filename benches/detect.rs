//! One-shot detection (gpp1, gpp2) on a simulated HDL-64E street scan
//! (~120k points), a simulated location (10 scans, ~1.2M points; from its
//! mean pose, and seen from nowhere) and the
//! real Ouster scans bundled in www/data. One thread.
//! `cargo bench --bench detect`

use criterion::{criterion_group, criterion_main, Criterion};
use polyscene::cloud::Cloud;
use polyscene::detect::detect;
use polyscene::params::Params;
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let drive = Drive::new(
        Layout::Street,
        1,
        SensorModel::default(),
        DriveOptions::default(),
    )
    .unwrap();
    let scan = drive.scan(20).unwrap();
    let scan_cloud = Cloud::from_world_f64(&scan.world_points()).unwrap();
    let scan_view = scan.pose.w_axis.truncate().to_array();
    let loc = drive.location(20, 10).unwrap();
    let loc_cloud = Cloud::from_world_f64(&loc.points).unwrap();
    let mean = loc.viewpoint();

    let mut g = c.benchmark_group("detect");
    g.sample_size(10);
    for (name, preset) in [("gpp1", Params::gpp1()), ("gpp2", Params::gpp2())] {
        let p = Params {
            viewpoint: Some(scan_view),
            ..preset.clone()
        };
        g.bench_function(
            format!("{name}/sim-scan-{}k", scan_cloud.len() / 1000),
            |b| b.iter(|| black_box(detect(&scan_cloud, &p).unwrap().primitives.len())),
        );
        let p = Params {
            viewpoint: Some(mean.to_array()),
            ..preset.clone()
        };
        g.bench_function(
            format!("{name}/sim-location-{}k", loc_cloud.len() / 1000),
            |b| b.iter(|| black_box(detect(&loc_cloud, &p).unwrap().primitives.len())),
        );
        // Seen from nowhere, as a map is: the coarse pass runs.
        let p = preset.clone();
        g.bench_function(
            format!(
                "{name}/sim-location-{}k-no-viewpoint",
                loc_cloud.len() / 1000
            ),
            |b| b.iter(|| black_box(detect(&loc_cloud, &p).unwrap().primitives.len())),
        );
        for file in [
            "ouster_os0_128_single_scan_016.bin",
            "ouster_os1_64_legacy_f12073.bin",
        ] {
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("www/data")
                .join(file);
            let Ok(values) = polyscene::io::read_bin(&path, 4) else {
                eprintln!("skipping {file}: not found at {}", path.display());
                continue;
            };
            let cloud = Cloud::from_flat(&values, 4).unwrap();
            g.bench_function(format!("{name}/{}", file.trim_end_matches(".bin")), |b| {
                b.iter(|| black_box(detect(&cloud, &preset).unwrap().primitives.len()))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
