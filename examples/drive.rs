use polyscene::params::Params;
use polyscene::scenario::Scenario;
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};
fn main() {
    let layout: Layout = std::env::args()
        .nth(1)
        .unwrap_or("street".into())
        .parse()
        .unwrap();
    let scans: usize = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(60);
    let expansion = std::env::args()
        .nth(3)
        .map(|s| s != "noexp")
        .unwrap_or(true);
    let drive = Drive::new(layout, 1, SensorModel::default(), DriveOptions::default()).unwrap();
    let mut sc = Scenario::new(Params {
        expansion,
        ..Params::gpp2()
    })
    .unwrap();
    let mut times = vec![];
    for k in 0..scans.min(drive.len()) {
        let t = std::time::Instant::now();
        let s = drive.scan(k).unwrap();
        let tsim = t.elapsed().as_secs_f64() * 1e3;
        let r = sc.add_scan(&s.points, 4, &s.pose).unwrap();
        times.push(r.time_ms.total);
        if k % 10 == 0 || k + 1 == scans {
            println!("scan {k:3} pts {:6} expl {:6} det {:6} +{} grown {} merged {} polys {:3} area {:8.1} t exp {:5.1} det {:5.1} mrg {:4.1} tot {:5.1} sim {:5.1}",
                r.points, r.explained_by_expansion, r.sent_to_detection, r.added.len(), r.grown.len(), r.merged.len(), r.polygon_count, r.total_area,
                r.time_ms.expansion, r.time_ms.detection, r.time_ms.merge, r.time_ms.total, tsim);
        }
    }
    times.sort_by(f64::total_cmp);
    println!("median total {:.1} ms", times[times.len() / 2]);
}
