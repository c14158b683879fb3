//! Soak benchmark of the scenario (not in CI): a long drive, one table row
//! every 100 scans with the polygon count, the median time of those 100
//! scans (the thread's CPU time, which other processes on a shared machine
//! do not inflate, then the wall clock's, total and for two stages), the
//! process's resident memory and the snapshot's size.
//!
//! ```sh
//! cargo run --release --example soak -- new 10000    # keeps reaching new streets
//! cargo run --release --example soak -- loop 10000   # loops over one street
//! ```
//!
//! `new`: simulated 200-scan drives (street and crossing layouts alternating,
//! a new scene seed each) laid out on a 400 m grid, driven one after the
//! other, so every 200 scans the sensor reaches a street the map has never
//! seen (the pose jumps between them, as after a relocalisation).
//! `loop`: the 200 scans of one street, again and again.
//! Scan times are the scenario's own (`add_scan`), without the simulator. The last line compares the median of the last 100 scans with
//! that of scans 100-199, the last a hash of the final snapshot (equal
//! outputs, equal hashes).

use polyscene::params::Params;
use polyscene::scenario::Scenario;
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};

/// Spacing of the new-area drive's streets (m): farther apart than the
/// scenes are wide, so no street sees another.
const SPACING: f64 = 400.0;

/// CPU time of this thread (ms): on a shared machine the scan times by the
/// wall clock mostly measure the other processes. Wall time where the
/// thread clock is not available.
#[cfg(target_os = "linux")]
fn cpu_ms() -> f64 {
    #[repr(C)]
    struct Timespec {
        sec: i64,
        nsec: i64,
    }
    unsafe extern "C" {
        fn clock_gettime(clock: i32, t: *mut Timespec) -> i32;
    }
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut t = Timespec { sec: 0, nsec: 0 };
    // SAFETY: clock_gettime writes one timespec (two C longs, i64 on the
    // 64-bit Linux targets this runs on) through a valid pointer.
    let ok = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut t) } == 0;
    if ok {
        t.sec as f64 * 1e3 + t.nsec as f64 * 1e-6
    } else {
        f64::NAN
    }
}

#[cfg(not(target_os = "linux"))]
fn cpu_ms() -> f64 {
    use std::sync::OnceLock;
    static START: OnceLock<std::time::Instant> = OnceLock::new();
    START
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
        * 1e3
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[v.len() / 2]
}

/// Resident set size of this process (MiB), from /proc (Linux), or NaN.
fn rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mode = args.next().unwrap_or_else(|| "new".into());
    let scans: usize = args.next().map_or(10_000, |s| s.parse().expect("scans"));
    if mode != "new" && mode != "loop" {
        eprintln!("usage: soak [new|loop] [scans]");
        std::process::exit(2);
    }
    let segment = |k: usize| -> Drive {
        let (layout, seed, origin) = if mode == "loop" {
            (Layout::Street, 1, glam::DVec3::ZERO)
        } else {
            // A snake over a 25-wide grid of street blocks.
            let (row, col) = (k / 25, k % 25);
            let col = if row % 2 == 0 { col } else { 24 - col };
            let layout = if k % 2 == 0 {
                Layout::Street
            } else {
                Layout::Crossing
            };
            let origin = glam::DVec3::new(col as f64 * SPACING, row as f64 * SPACING, 0.0);
            (layout, k as u64 + 1, origin)
        };
        let options = DriveOptions {
            origin,
            ..DriveOptions::default()
        };
        Drive::new(layout, seed, SensorModel::default(), options).expect("drive")
    };
    let mut sc = Scenario::new(Params::gpp2()).expect("params");
    let (mut seg, mut drive) = (0usize, segment(0));
    let mut done_in_seg = 0usize;
    let (mut cpu, mut tot, mut exp, mut mrg) = (vec![], vec![], vec![], vec![]);
    let (mut base, mut last) = (f64::NAN, f64::NAN);
    println!("mode {mode}, {scans} scans");
    println!(
        "| scans | polygons | median CPU ms a scan | wall ms | expansion (wall) | merge (wall) | RSS MiB | snapshot MiB |"
    );
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for k in 0..scans {
        if done_in_seg == drive.len() {
            done_in_seg = 0;
            if mode == "new" {
                seg += 1;
                drive = segment(seg);
            }
        }
        let s = drive.scan(done_in_seg).expect("scan");
        done_in_seg += 1;
        let c0 = cpu_ms();
        let r = sc.add_scan(&s.points, 4, &s.pose).expect("add_scan");
        cpu.push(cpu_ms() - c0);
        tot.push(r.time_ms.total);
        exp.push(r.time_ms.expansion);
        mrg.push(r.time_ms.merge);
        if (k + 1) % 100 == 0 || k + 1 == scans {
            let m = median(&mut cpu);
            if k + 1 == 200 {
                base = m;
            }
            last = m;
            let snap = sc.to_json().len() as f64 / (1024.0 * 1024.0);
            println!(
                "| {} | {} | {:.1} | {:.1} | {:.1} | {:.2} | {:.1} | {:.1} |",
                k + 1,
                r.polygon_count,
                m,
                median(&mut tot),
                median(&mut exp),
                median(&mut mrg),
                rss_mib(),
                snap
            );
            for v in [&mut cpu, &mut tot, &mut exp, &mut mrg] {
                v.clear();
            }
        }
    }
    println!(
        "last 100 scans / scans 100-199 (median CPU time a scan): {:.2}",
        last / base
    );
    // FNV-1a of the final snapshot: equal outputs print equal hashes.
    let hash = sc.to_json().bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    });
    println!("final snapshot hash {hash:016x}");
}
