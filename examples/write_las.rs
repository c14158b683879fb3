//! Write a raw float32 scan (stride 4, as KITTI's `.bin`) as LAS or LAZ
//! with the `las` crate: scale 1/1024 m, the points moved by a shift that is
//! also the header's offset, so points on a 1/1024 m grid are stored exactly.
//!
//! ```text
//! cargo run --release --example write_las -- IN.bin OUT.las|OUT.laz [X,Y,Z]
//! ```
//!
//! A `.laz` output is compressed (LAZ). The JS readers' tests
//! (tests/js/io.test.mjs) make their LAZ fixtures with it: no JS library
//! writes LAZ.

use polyscene::io::read_bin;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 || args.len() > 3 {
        eprintln!("usage: write_las IN.bin OUT.las|OUT.laz [X,Y,Z]");
        std::process::exit(2);
    }
    let shift: Vec<f64> = args
        .get(2)
        .map(|s| {
            s.split(',')
                .map(|v| v.parse().expect("shift: three numbers X,Y,Z"))
                .collect()
        })
        .unwrap_or_else(|| vec![0.0; 3]);
    assert_eq!(shift.len(), 3, "shift: three numbers X,Y,Z");
    let values = read_bin(Path::new(&args[0]), 4).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1);
    });
    let mut builder = las::Builder::from((1, 2));
    builder.point_format = las::point::Format::new(0).unwrap();
    builder.point_format.is_compressed = args[1].ends_with(".laz");
    let t = |offset: f64| las::Transform {
        scale: 1.0 / 1024.0,
        offset,
    };
    builder.transforms = las::Vector {
        x: t(shift[0]),
        y: t(shift[1]),
        z: t(shift[2]),
    };
    let mut writer = las::Writer::from_path(&args[1], builder.into_header().unwrap())
        .unwrap_or_else(|e| {
            eprintln!("{}: {e}", args[1]);
            std::process::exit(1);
        });
    for p in values.chunks_exact(4) {
        writer
            .write_point(las::Point {
                x: p[0] as f64 + shift[0],
                y: p[1] as f64 + shift[1],
                z: p[2] as f64 + shift[2],
                ..Default::default()
            })
            .unwrap();
    }
    writer.close().unwrap();
}
