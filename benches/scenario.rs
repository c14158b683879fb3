//! Per-scan update of the incremental scenario (gpp2, concave, expansion on)
//! on a simulated HDL-64E drive: the states after scans 0..k are kept for k
//! in 30..40, and each iteration adds scan k to a clone of the state before
//! it (consecutive scans, as in a live drive; the clone is not timed). One
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
        let mut states = Vec::new();
        for k in 0..40 {
            let s = drive.scan(k).unwrap();
            if k >= 30 {
                states.push((warm.clone(), s.clone()));
            }
            warm.add_scan(&s.points, 4, &s.pose).unwrap();
        }
        let mut i = 0;
        g.bench_function(format!("add_scan/{}", layout.as_str()), |b| {
            b.iter_batched(
                || {
                    i = (i + 1) % states.len();
                    (states[i].0.clone(), i)
                },
                |(mut s, i)| {
                    let scan = &states[i].1;
                    black_box(
                        s.add_scan(&scan.points, 4, &scan.pose)
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
