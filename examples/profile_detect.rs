use polyscene::{cloud::Cloud, detect::detect, io::read_bin, params::Params};
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let v = read_bin(std::path::Path::new(&path), 4).unwrap();
    let c = Cloud::from_flat(&v, 4).unwrap();
    let p = Params::gpp2();
    let d = detect(&c, &p).unwrap();
    let acc: usize = d.steps.iter().map(|s| s.accepted).sum();
    println!(
        "n={} rounds={} accepted={} work={:.1}M time={:.1}ms",
        c.len(),
        d.steps.len(),
        acc,
        d.work as f64 / 1e6,
        d.time_ms
    );
    for (i, s) in d.steps.iter().enumerate().take(200) {
        if i % 10 == 0 || s.time_ms > 5.0 {
            println!(
                "{i:3} left={:6} inl={:6} cl={:6} acc={} area={:7.1} t={:.2}",
                s.points_left, s.inliers, s.cluster, s.accepted, s.area, s.time_ms
            );
        }
    }
}
