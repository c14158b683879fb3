//! Per-scan update of the incremental scenario (gpp2, concave, expansion on)
//! on a simulated HDL-64E street drive: the scenario is warmed up with 30
//! scans, then each iteration adds the next scan to a clone of it. One
//! thread. `cargo bench --bench scenario`

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use polyscene::params::Params;
use polyscene::scenario::Scenario;
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("scenario");
    g.sample_size(20);
    for layout in [Layout::Street, Layout::Crossing] {
        let drive = Drive::new(layout, 1, SensorModel::default(), DriveOptions::default()).unwrap();
        let mut warm = Scenario::new(Params::gpp2()).unwrap();
        for k in 0..30 {
            let s = drive.scan(k).unwrap();
            warm.add_scan(&s.points, 4, &s.pose).unwrap();
        }
        let next: Vec<_> = (30..40).map(|k| drive.scan(k).unwrap()).collect();
        let mut i = 0;
        g.bench_function(format!("add_scan/{}", layout.as_str()), |b| {
            b.iter_batched(
                || {
                    i = (i + 1) % next.len();
                    (warm.clone(), i)
                },
                |(mut s, i)| {
                    black_box(
                        s.add_scan(&next[i].points, 4, &next[i].pose)
                            .unwrap()
                            .polygon_count,
                    )
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
