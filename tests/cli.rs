//! The command-line tool, through `polyscene::internals::cli::run`: help on every
//! command, every pipeline option on `detect` and `replay`, and errors that
//! name what was wrong. (Native only, like the command line.)
#![cfg(not(target_arch = "wasm32"))]

use polyscene::internals::cli::run;
use polyscene::params::Params;
use std::path::PathBuf;

fn args(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// A temporary directory of this test process, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("polyscene-cli-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A small synthetic cloud (stride 4) written to `dir/cloud.bin`: a flat
/// 12 m x 12 m patch of ground 1.8 m below the origin and a 10 m x 3 m wall,
/// 10 cm point spacing.
fn write_cloud(dir: &TempDir) -> String {
    let mut values: Vec<f32> = Vec::new();
    for i in 0..120 {
        for j in 0..120 {
            let (x, y) = (-6.0 + 0.1 * i as f32, -6.0 + 0.1 * j as f32);
            values.extend([x, y, -1.8, 0.5]);
        }
    }
    for i in 0..100 {
        for k in 0..30 {
            let (y, z) = (-5.0 + 0.1 * i as f32, -1.7 + 0.1 * k as f32);
            values.extend([7.0, y, z, 0.5]);
        }
    }
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let path = dir.0.join("cloud.bin");
    std::fs::write(&path, bytes).unwrap();
    path.to_string_lossy().into_owned()
}

fn polygon_count(json: &str) -> usize {
    let doc: serde_json::Value = serde_json::from_str(json).unwrap();
    doc["polygons"].as_array().unwrap().len()
}

#[test]
fn help_on_every_command_succeeds_and_lists_its_options() {
    let top = run(&args(&["--help"])).unwrap();
    for cmd in ["detect", "replay", "simulate", "eval", "ondata"] {
        assert!(top.contains(cmd), "{top}");
    }
    assert_eq!(run(&args(&["help"])).unwrap(), top);
    for cmd in ["detect", "replay"] {
        let help = run(&args(&[cmd, "--help"])).unwrap();
        // Every pipeline option, by its kebab-case name, with its key.
        for key in Params::keys() {
            let kebab: String = key
                .chars()
                .flat_map(|c| {
                    if c.is_ascii_uppercase() {
                        vec!['-', c.to_ascii_lowercase()]
                    } else {
                        vec![c]
                    }
                })
                .collect();
            assert!(
                help.contains(&format!("--{kebab} ")),
                "{cmd}: --{kebab}\n{help}"
            );
            assert!(help.contains(&format!("`{key}`")), "{cmd}: {key}\n{help}");
        }
        for opt in [
            "--min-area",
            "--preset",
            "--no-expansion",
            "--out",
            "--seed",
        ] {
            assert!(help.contains(opt), "{cmd}: {opt}\n{help}");
        }
    }
    assert!(run(&args(&["detect", "--help"]))
        .unwrap()
        .contains("--stride"));
    assert!(run(&args(&["replay", "--help"]))
        .unwrap()
        .contains("--report"));
    for (cmd, opt) in [
        ("simulate", "--scans"),
        ("eval", "GT_DIR"),
        ("ondata", "--radius"),
    ] {
        let help = run(&args(&[cmd, "--help"])).unwrap();
        assert!(help.contains(opt), "{cmd}: {opt}\n{help}");
    }
    let version = run(&args(&["--version"])).unwrap();
    assert_eq!(version, format!("polyscene {}", env!("CARGO_PKG_VERSION")));
}

#[test]
fn pipeline_options_change_the_result() {
    let dir = TempDir::new("options");
    let cloud = write_cloud(&dir);
    let default = run(&args(&["detect", &cloud, "--stride", "4"])).unwrap();
    assert!(polygon_count(&default) >= 1, "{default}");
    // No polygon is that large.
    let none = run(&args(&[
        "detect",
        &cloud,
        "--stride",
        "4",
        "--min-area",
        "1e9",
    ]))
    .unwrap();
    assert_eq!(polygon_count(&none), 0, "{none}");
    // Lists, booleans, names and integers parse as the JS options do.
    let out = run(&args(&[
        "detect",
        &cloud,
        "--stride",
        "4",
        "--viewpoint",
        "0,0,0.5",
        "--hull",
        "convex",
        "--expansion",
        "false",
        "--max-primitives",
        "1",
        "--preset",
        "gpp1",
    ]))
    .unwrap();
    assert_eq!(polygon_count(&out), 1, "{out}");
    // --out writes the document instead.
    let path = dir.0.join("out.json");
    let path = path.to_string_lossy().into_owned();
    assert_eq!(
        run(&args(&["detect", &cloud, "--stride", "4", "--out", &path])).unwrap(),
        ""
    );
    let written = std::fs::read_to_string(&path).unwrap();
    assert_eq!(polygon_count(&written), polygon_count(&default));
}

#[test]
fn a_misspelt_option_names_the_one_meant() {
    let e = run(&args(&["detect", "x.bin", "--min-aera", "3"])).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("--min-aera"), "{text}");
    assert!(text.contains("--min-area"), "{text}");
}

#[test]
fn a_bad_value_names_the_key() {
    let dir = TempDir::new("values");
    let cloud = write_cloud(&dir);
    for (opt, value, key) in [
        ("--min-area", "abc", "minArea"),
        ("--min-area", "-1", "minArea"),
        ("--min-inliers", "1.5", "minInliers"),
        ("--hull", "round", "hull"),
        ("--viewpoint", "1,x,3", "viewpoint"),
        ("--viewpoint", "1,2", "viewpoint"),
        ("--expansion", "maybe", "expansion"),
        ("--preset", "gpp3", "preset"),
    ] {
        let e = run(&args(&["detect", &cloud, "--stride", "4", opt, value])).unwrap_err();
        let text = e.to_string();
        assert!(text.contains(&format!("'{key}'")), "{opt} {value}: {text}");
    }
    // Given twice, or with its --no- form: a usage error.
    assert!(run(&args(&[
        "detect", &cloud, "--stride", "4", "--seed", "1", "--seed", "2"
    ]))
    .is_err());
    assert!(run(&args(&[
        "replay",
        "d",
        "--expansion",
        "true",
        "--no-expansion"
    ]))
    .is_err());
}

#[test]
fn bad_files_and_commands_are_errors() {
    let e = run(&args(&["detect", "/nonexistent/cloud.bin"])).unwrap_err();
    assert!(e.to_string().contains("/nonexistent/cloud.bin"), "{e}");
    assert!(run(&args(&[])).is_err());
    assert!(run(&args(&["frobnicate"])).is_err());
    assert!(run(&args(&["detect"])).is_err());
    assert!(run(&args(&["simulate", "street"])).is_err());
    let e = run(&args(&["simulate", "avenue", "--out", "/nonexistent/x"])).unwrap_err();
    assert!(e.to_string().contains("'layout'"), "{e}");
}

#[test]
fn the_command_line_is_consistent() {
    // Clap's own checks: no two options with one name, conflicts that
    // name existing options.
    polyscene::internals::cli::command().debug_assert();
}

/// `--poses` gives detection the positions of the poses (as
/// `--viewpoints` does): a horizontal patch in the plane of every one of
/// them is dropped as laser rings, one that a position lies above is kept;
/// a bad poses file is an error naming it, and a list of positions that is
/// not x, y, z triples or that comes with `--viewpoint` is refused.
#[test]
fn poses_give_the_sensor_positions_of_an_accumulated_cloud() {
    let dir = TempDir::new("poses");
    // A 12 m floor 1.8 m below the poses, and a 2 m x 2 m patch at their
    // height, 2-4 m from them.
    let mut values: Vec<f32> = Vec::new();
    for i in 0..120 {
        for j in 0..120 {
            values.extend([-6.0 + 0.1 * i as f32, -6.0 + 0.1 * j as f32, -1.8, 0.5]);
        }
    }
    for i in 0..40 {
        for j in 0..40 {
            values.extend([2.0 + 0.05 * i as f32, 1.0 + 0.05 * j as f32, 0.0, 0.5]);
        }
    }
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let cloud = dir.0.join("cloud.bin");
    std::fs::write(&cloud, bytes).unwrap();
    let cloud = cloud.to_string_lossy().into_owned();
    let poses = dir.0.join("poses.txt");
    std::fs::write(
        &poses,
        "1 0 0 -1 0 1 0 0 0 0 1 0.1\n1 0 0 1 0 1 0 0 0 0 1 -0.1\n",
    )
    .unwrap();
    let poses = poses.to_string_lossy().into_owned();
    let detect = |more: &[&str]| {
        let mut a = vec!["detect", &cloud, "--stride", "4"];
        a.extend_from_slice(more);
        run(&args(&a))
    };
    let strip = |s: &str| {
        let mut v: serde_json::Value = serde_json::from_str(s).unwrap();
        v["timeMs"] = serde_json::Value::Null;
        v
    };
    let patches = |s: &str| {
        let v: serde_json::Value = serde_json::from_str(s).unwrap();
        v["polygons"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|p| {
                let (nz, d) = (
                    p["normal"][2].as_f64().unwrap(),
                    p["offset"].as_f64().unwrap(),
                );
                nz.abs() > 0.999 && d.abs() < 0.05
            })
            .count()
    };
    let by_poses = detect(&["--poses", &poses]).unwrap();
    let by_positions = detect(&["--viewpoints", "-1,0,0.1,1,0,-0.1"]).unwrap();
    assert_eq!(strip(&by_poses), strip(&by_positions));
    assert_eq!(patches(&by_poses), 0);
    assert!(polygon_count(&by_poses) >= 1, "the floor stays");
    let one_above = detect(&["--viewpoints", "-1,0,0.1,1,0,1.5"]).unwrap();
    assert_eq!(patches(&one_above), 1);
    let bad = dir.0.join("bad.txt");
    std::fs::write(&bad, "1 0 0\n").unwrap();
    let e = detect(&["--poses", &bad.to_string_lossy()]).unwrap_err();
    assert!(e.to_string().contains("bad.txt"), "{e}");
    let e = detect(&["--viewpoints", "1,2"]).unwrap_err();
    assert!(e.to_string().contains("'viewpoints'"), "{e}");
    assert!(detect(&["--poses", &poses, "--viewpoint", "0,0,0"]).is_err());
    assert!(detect(&["--viewpoints", "0,0,0", "--viewpoint", "0,0,0"]).is_err());
    assert!(detect(&["--viewpoints", "0,0,0", "--poses", &poses]).is_err());
}

/// `ondata`: the polygons detected on a cloud lie on it; a polygon far from
/// every point is named by its id with share 0; a bad radius is refused.
#[test]
fn ondata_measures_the_polygons_against_their_cloud() {
    let dir = TempDir::new("ondata");
    let cloud = write_cloud(&dir);
    let pred = dir.0.join("pred.json");
    let pred = pred.to_string_lossy().into_owned();
    run(&args(&["detect", &cloud, "--stride", "4", "--out", &pred])).unwrap();
    let out = run(&args(&["ondata", &pred, &cloud, "--stride", "4"])).unwrap();
    assert!(!out.contains('\n'), "one line: {out}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(doc["share"].as_f64().unwrap() >= 0.95, "{out}");
    assert_eq!(doc["radius"].as_f64(), Some(0.2));
    assert_eq!(doc["points"].as_u64(), Some(120 * 120 + 100 * 30));
    assert!(doc["polygons"].as_array().unwrap().len() >= 2, "{out}");
    // A 2 x 2 m square 50 m away from every point: share 0, under its id.
    let off = dir.0.join("off.json");
    std::fs::write(
        &off,
        r#"{"polygons":[{"id":7,"vertices":[[50,0,0],[52,0,0],[52,2,0],[50,2,0]]}]}"#,
    )
    .unwrap();
    let off = off.to_string_lossy().into_owned();
    let doc: serde_json::Value =
        serde_json::from_str(&run(&args(&["ondata", &off, &cloud, "--stride", "4"])).unwrap())
            .unwrap();
    assert_eq!(doc["share"].as_f64(), Some(0.0));
    assert_eq!(doc["polygons"][0]["id"].as_u64(), Some(7));
    assert_eq!(doc["polygons"][0]["share"].as_f64(), Some(0.0));
    let e = run(&args(&[
        "ondata",
        &off,
        &cloud,
        "--stride",
        "4",
        "--radius=-1",
    ]))
    .unwrap_err();
    assert!(e.to_string().contains("--radius"), "{e}");
}

// ---------------------------------------------------------------------------
// File formats, map coordinates and KITTI sequences.

/// Where the map-coordinate copies of a cloud lie (UTM-like; whole metres).
const UTM: [f64; 3] = [500_000.0, 4_500_000.0, 50.0];

/// Scan 0 of the simulated street drive in its sensor frame, every
/// coordinate rounded to 1/1024 m: exact in f32 near the origin, and exact
/// in f64 (and in a LAS file with scale 1/1024) at [`UTM`], so every format
/// holds the very same points.
fn street_scan() -> Vec<[f32; 3]> {
    use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};
    let drive = Drive::new(
        Layout::Street,
        1,
        SensorModel::default(),
        DriveOptions::default(),
    )
    .unwrap();
    let scan = drive.scan(0).unwrap();
    scan.points
        .chunks_exact(4)
        .map(|p| [0, 1, 2].map(|i| (p[i] * 1024.0).round() / 1024.0))
        .collect()
}

fn path_of(dir: &TempDir, name: &str) -> String {
    dir.0.join(name).to_string_lossy().into_owned()
}

/// `points` as raw little-endian float32, stride 4 (x, y, z, intensity 0.5).
fn write_raw(path: &str, points: &[[f32; 3]], shift: [f64; 3]) {
    let mut bytes = Vec::with_capacity(points.len() * 16);
    for p in points {
        for i in 0..3 {
            bytes.extend_from_slice(&((p[i] as f64 + shift[i]) as f32).to_le_bytes());
        }
        bytes.extend_from_slice(&0.5f32.to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

/// `points` moved by `shift` as LAS (or LAZ) with the `las` crate: scale
/// 1/1024 m, offset `shift`, so the stored integers are exact.
fn write_las(path: &str, points: &[[f32; 3]], shift: [f64; 3], compressed: bool) {
    let mut builder = las::Builder::from((1, 2));
    builder.point_format = las::point::Format::new(0).unwrap();
    builder.point_format.is_compressed = compressed;
    let t = |offset: f64| las::Transform {
        scale: 1.0 / 1024.0,
        offset,
    };
    builder.transforms = las::Vector {
        x: t(shift[0]),
        y: t(shift[1]),
        z: t(shift[2]),
    };
    let mut writer = las::Writer::from_path(path, builder.into_header().unwrap()).unwrap();
    for p in points {
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

/// A PCD file: ascii float32 with an intensity field and one NaN point
/// (PCL's "no return"), or binary float64 moved by `shift`.
fn write_pcd(path: &str, points: &[[f32; 3]], binary_f64_shift: Option<[f64; 3]>) {
    let mut out = Vec::new();
    match binary_f64_shift {
        None => {
            let n = points.len() + 1;
            out.extend(
                format!(
                    "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n\
                     FIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n\
                     WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA ascii\n"
                )
                .bytes(),
            );
            for (i, p) in points.iter().enumerate() {
                out.extend(format!("{} {} {} 0.5\n", p[0], p[1], p[2]).bytes());
                if i == 10 {
                    out.extend(b"nan nan nan 0\n");
                }
            }
        }
        Some(shift) => {
            let n = points.len();
            out.extend(
                format!(
                    "VERSION .7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\n\
                     WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n"
                )
                .bytes(),
            );
            for p in points {
                for i in 0..3 {
                    out.extend((p[i] as f64 + shift[i]).to_le_bytes());
                }
            }
        }
    }
    std::fs::write(path, out).unwrap();
}

/// A PLY file: ascii float32 (its size padded by a comment to a multiple of
/// 16 bytes, the size of a raw stride-4 file), or binary little-endian
/// float64 moved by `shift`; both with an empty face element.
fn write_ply(path: &str, points: &[[f32; 3]], binary_f64_shift: Option<[f64; 3]>) {
    let n = points.len();
    let (kind, ty) = match binary_f64_shift {
        None => ("ascii", "float"),
        Some(_) => ("binary_little_endian", "double"),
    };
    let mut body = Vec::new();
    match binary_f64_shift {
        None => {
            for p in points {
                body.extend(format!("{} {} {}\n", p[0], p[1], p[2]).bytes());
            }
        }
        Some(shift) => {
            for p in points {
                for i in 0..3 {
                    body.extend((p[i] as f64 + shift[i]).to_le_bytes());
                }
            }
        }
    }
    let header = |pad: usize| {
        format!(
            "ply\nformat {kind} 1.0\ncomment {}\nelement vertex {n}\nproperty {ty} x\n\
             property {ty} y\nproperty {ty} z\nelement face 0\n\
             property list uchar int vertex_indices\nend_header\n",
            "x".repeat(pad)
        )
    };
    let pad = (16 - (header(1).len() + body.len()) % 16) % 16 + 1;
    let mut out = header(pad).into_bytes();
    out.extend(body);
    assert_eq!(out.len() % 16, 0);
    std::fs::write(path, out).unwrap();
}

/// The polygons of a `detect`/`replay` document: vertices moved back by
/// `shift`, normals, areas.
fn polygons(json: &str, shift: [f64; 3]) -> Vec<(Vec<[f64; 3]>, [f64; 3], f64)> {
    let doc: serde_json::Value = serde_json::from_str(json).unwrap();
    doc["polygons"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let v = |a: &serde_json::Value| {
                let a = a.as_array().unwrap();
                [0, 1, 2].map(|i| a[i].as_f64().unwrap())
            };
            let vertices = p["vertices"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| {
                    let x = v(x);
                    [0, 1, 2].map(|i| x[i] - shift[i])
                })
                .collect();
            (vertices, v(&p["normal"]), p["area"].as_f64().unwrap())
        })
        .collect()
}

/// The same polygons, to 1 mm.
fn assert_same_polygons(what: &str, got: &str, shift: [f64; 3], want: &str) {
    let (a, b) = (polygons(got, shift), polygons(want, [0.0; 3]));
    assert_eq!(a.len(), b.len(), "{what}: polygon count");
    for (k, (p, q)) in a.iter().zip(&b).enumerate() {
        assert_eq!(p.0.len(), q.0.len(), "{what}: polygon {k} vertex count");
        for (u, v) in p.0.iter().zip(&q.0) {
            let d = (0..3).map(|i| (u[i] - v[i]).abs()).fold(0.0, f64::max);
            assert!(d <= 1e-3, "{what}: polygon {k} vertex {u:?} vs {v:?}");
        }
        let dn = (0..3).map(|i| (p.1[i] - q.1[i]).abs()).fold(0.0, f64::max);
        assert!(dn < 1e-6, "{what}: polygon {k} normal");
        assert!((p.2 - q.2).abs() < 1e-3, "{what}: polygon {k} area");
    }
}

/// LAS and LAZ in map coordinates, PCD (ascii float32, binary float64 in
/// map coordinates) and PLY (ascii float32, binary float64 in map
/// coordinates) give the polygons of the same points as raw float32 in the
/// local frame, to 1 mm once moved back; a PLY whose size is a multiple of
/// 16 bytes is read as PLY. The same scan as raw float32 at map
/// coordinates is refused with the fix in the message.
#[test]
fn every_format_gives_the_polygons_of_the_raw_local_cloud() {
    let dir = TempDir::new("formats");
    let points = street_scan();
    let raw = path_of(&dir, "local.bin");
    write_raw(&raw, &points, [0.0; 3]);
    let detect = |file: &str, extra: &[&str]| {
        let mut a = args(&["detect", file]);
        a.extend(args(extra));
        run(&a).unwrap_or_else(|e| panic!("{file}: {e}"))
    };
    let local_vp = ["--viewpoint", "0,0,0"];
    let utm_vp = ["--viewpoint", "500000,4500000,50"];
    let want = detect(&raw, &["--stride", "4", local_vp[0], local_vp[1]]);
    let count = polygon_count(&want);
    assert!(count >= 10, "{want}");

    for name in [
        "utm.las",
        "utm.laz",
        "ascii.pcd",
        "utm-binary.pcd",
        "ascii.ply",
        "utm-binary.ply",
    ] {
        let path = path_of(&dir, name);
        let shift = if name.starts_with("utm") {
            UTM
        } else {
            [0.0; 3]
        };
        match name {
            "utm.las" => write_las(&path, &points, UTM, false),
            "utm.laz" => write_las(&path, &points, UTM, true),
            "ascii.pcd" => write_pcd(&path, &points, None),
            "utm-binary.pcd" => write_pcd(&path, &points, Some(UTM)),
            "ascii.ply" => write_ply(&path, &points, None),
            _ => write_ply(&path, &points, Some(UTM)),
        }
        let vp = if shift[0] == 0.0 { local_vp } else { utm_vp };
        let got = detect(&path, &vp);
        assert_same_polygons(name, &got, shift, &want);
        // A file with a header says what its points hold: no --stride.
        let e = run(&args(&["detect", &path, "--stride", "4"])).unwrap_err();
        assert!(e.to_string().contains("--stride"), "{e}");
    }
    // The ascii PLY's size is a multiple of 16, yet it is no raw file.
    let ply = path_of(&dir, "ascii.ply");
    assert_eq!(std::fs::metadata(&ply).unwrap().len() % 16, 0);

    // Raw float32 at map coordinates: refused, naming the file and the fix.
    let far = path_of(&dir, "utm.bin");
    write_raw(&far, &points, UTM);
    let e = run(&args(&["detect", &far, "--stride", "4"]))
        .unwrap_err()
        .to_string();
    for word in ["utm.bin", "float32", "float64", "500 mm"] {
        assert!(e.contains(word), "{word}: {e}");
    }
}

/// Every bad file is an error naming the file and its problem, never an
/// empty result.
#[test]
fn bad_files_are_named_with_their_problem() {
    let dir = TempDir::new("badfiles");
    let points = &street_scan()[..2000];
    let check = |name: &str, bytes: &[u8], stride: Option<&str>, problem: &str| {
        let path = path_of(&dir, name);
        std::fs::write(&path, bytes).unwrap();
        let mut a = args(&["detect", &path]);
        if let Some(s) = stride {
            a.extend(args(&["--stride", s]));
        }
        let e = run(&a).unwrap_err().to_string();
        assert!(e.contains(name), "{name}: {e}");
        assert!(e.contains(problem), "{name}: '{problem}' in {e}");
        e
    };
    check("empty.bin", b"", Some("4"), "empty file (0 bytes)");
    check("odd.bin", &[0u8; 20], Some("4"), "not a multiple of 16");
    check("nostride.bin", &[0u8; 32], None, "--stride 4");
    check("stride5.bin", &[0u8; 40], Some("5"), "stride");
    let mut nan = vec![0u8; 32];
    nan[20..24].copy_from_slice(&f32::NAN.to_le_bytes());
    check("nan.bin", &nan, Some("4"), "point 1");
    check(
        "points.xyz",
        b"1.0 2.0 3.0\n4.0 5.0 6.0\n",
        Some("3"),
        "text file",
    );
    check(
        "cloud.bin.gz",
        b"\x1f\x8b\x08\x00\x00\x00\x00\x00",
        Some("4"),
        "gzip",
    );

    // A LAS file cut short: its header promises more points.
    let las = path_of(&dir, "full.las");
    write_las(&las, points, UTM, false);
    let bytes = std::fs::read(&las).unwrap();
    check("cut.las", &bytes[..bytes.len() - 100], None, "truncated");
    check("header.las", &bytes[..50], None, "LAS");

    // PLY and PCD without z, or cut short.
    let ply = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nend_header\n1 2\n3 4\n";
    check("noz.ply", ply, None, "no 'z'");
    let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
    check("short.ply", ply, None, "PLY");
    let pcd = b"VERSION .7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2\n";
    check("noz.pcd", pcd, None, "no 'z'");
    let pcd = b"VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary\n\x00\x00\x00\x00";
    check("short.pcd", pcd, None, "PCD");
}

/// `detect` takes one cloud and `--help`; a second file name is refused.
#[test]
fn detect_takes_one_file_and_help() {
    let help = run(&args(&["detect", "--help"])).unwrap();
    assert!(help.contains("--stride") && help.contains("LAS"), "{help}");
    let e = run(&args(&["detect", "a.bin", "b.bin", "--stride", "4"])).unwrap_err();
    assert!(e.to_string().contains("b.bin"), "{e}");
}

/// KITTI's Tr of odometry sequence 00 (LiDAR to camera 0), as calib.txt.
const CALIB_00: &str = "P0: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00
Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 -7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01
";

/// A simulated drive written by `simulate` (LiDAR poses, flat layout) and
/// the same scans in KITTI's layout with camera poses and calib.txt give
/// the same map, from the sequence directory and from the dataset root;
/// without the calibration the sequence is refused, and read as LiDAR
/// poses it gives a different (wrong) map.
#[test]
fn kitti_sequences_replay_in_their_layout_with_calib() {
    let dir = TempDir::new("kitti");
    let flat = path_of(&dir, "flat");
    run(&args(&[
        "simulate", "street", "--seed", "2", "--scans", "6", "--out", &flat,
    ]))
    .unwrap();
    let want = run(&args(&["replay", &flat])).unwrap();
    assert!(polygon_count(&want) >= 10, "{want}");

    // KITTI's layout: ROOT/sequences/00/{velodyne,calib.txt}, ROOT/poses/00.txt.
    let root = dir.0.join("dataset");
    let seq = root.join("sequences").join("00");
    std::fs::create_dir_all(seq.join("velodyne")).unwrap();
    std::fs::create_dir_all(root.join("poses")).unwrap();
    for k in 0..6 {
        let name = format!("{k:06}.bin");
        std::fs::copy(
            std::path::Path::new(&flat).join(&name),
            seq.join("velodyne").join(&name),
        )
        .unwrap();
    }
    std::fs::write(seq.join("calib.txt"), CALIB_00).unwrap();
    let tr = polyscene::io::kitti::parse_calib(CALIB_00).unwrap();
    let lidar = polyscene::io::parse_poses(
        &std::fs::read_to_string(std::path::Path::new(&flat).join("poses.txt")).unwrap(),
    )
    .unwrap();
    let camera: String = lidar
        .iter()
        .map(|l| polyscene::io::format_pose(&(tr * *l * tr.inverse())) + "\n")
        .collect();
    std::fs::write(root.join("poses").join("00.txt"), &camera).unwrap();
    let (root_s, seq_s) = (
        root.to_string_lossy().into_owned(),
        seq.to_string_lossy().into_owned(),
    );
    let from_seq = run(&args(&["replay", &seq_s])).unwrap();
    assert_same_polygons("sequence dir", &from_seq, [0.0; 3], &want);
    let from_root = run(&args(&["replay", &root_s, "--sequence", "00"])).unwrap();
    assert_same_polygons("dataset root", &from_root, [0.0; 3], &want);
    let e = run(&args(&["replay", &root_s])).unwrap_err().to_string();
    assert!(e.contains("--sequence") && e.contains("00"), "{e}");
    // Camera poses read as LiDAR poses: another map (what the flag is for).
    let wrong = run(&args(&["replay", &seq_s, "--lidar-poses"])).unwrap();
    assert_ne!(polygons(&wrong, [0.0; 3]), polygons(&want, [0.0; 3]));

    // Without calib.txt: refused, naming the ways out; --calib elsewhere works.
    let calib = dir.0.join("calib-00.txt");
    std::fs::rename(seq.join("calib.txt"), &calib).unwrap();
    let e = run(&args(&["replay", &seq_s])).unwrap_err().to_string();
    assert!(
        e.contains("camera") && e.contains("--calib") && e.contains("--lidar-poses"),
        "{e}"
    );
    let calib_s = calib.to_string_lossy().into_owned();
    let with_calib = run(&args(&["replay", &seq_s, "--calib", &calib_s])).unwrap();
    assert_same_polygons("--calib", &with_calib, [0.0; 3], &want);
    // A calib.txt beside a flat layout's poses: which frame is asked for.
    std::fs::copy(&calib, std::path::Path::new(&flat).join("calib.txt")).unwrap();
    let e = run(&args(&["replay", &flat])).unwrap_err().to_string();
    assert!(e.contains("--calib") && e.contains("--lidar-poses"), "{e}");
    let same = run(&args(&["replay", &flat, "--lidar-poses"])).unwrap();
    assert_same_polygons("--lidar-poses", &same, [0.0; 3], &want);
}

/// What `replay` cannot align is refused: a missing scan number (it would
/// shift the poses of every later scan), an empty scan, a file that is not
/// a scan number; `--skip-missing` and `--skip-empty` say to go on, each
/// scan with the pose of its number.
#[test]
fn replay_refuses_what_it_cannot_align() {
    let dir = TempDir::new("align");
    let flat = dir.0.join("drive");
    let flat_s = flat.to_string_lossy().into_owned();
    run(&args(&[
        "simulate", "street", "--seed", "3", "--scans", "4", "--out", &flat_s,
    ]))
    .unwrap();
    // Scan 1 gone: refused; with --skip-missing, scans 0, 2, 3 with poses
    // 0, 2, 3, the same map as a drive written without scan 1's points.
    let one = flat.join("000001.bin");
    let saved = std::fs::read(&one).unwrap();
    std::fs::remove_file(&one).unwrap();
    let e = run(&args(&["replay", &flat_s])).unwrap_err().to_string();
    assert!(
        e.contains("000001.bin is missing") && e.contains("--skip-missing"),
        "{e}"
    );
    let skipped = run(&args(&["replay", &flat_s, "--skip-missing"])).unwrap();
    // An empty scan 1: refused; with --skip-empty, the same map.
    std::fs::write(&one, b"").unwrap();
    let e = run(&args(&["replay", &flat_s])).unwrap_err().to_string();
    assert!(
        e.contains("000001.bin") && e.contains("empty") && e.contains("--skip-empty"),
        "{e}"
    );
    let empty_skipped = run(&args(&["replay", &flat_s, "--skip-empty"])).unwrap();
    assert_same_polygons("skip empty", &empty_skipped, [0.0; 3], &skipped);
    // The poses really are matched by number: scan 1 back, the map differs.
    std::fs::write(&one, saved).unwrap();
    let all = run(&args(&["replay", &flat_s])).unwrap();
    assert_ne!(polygons(&all, [0.0; 3]), polygons(&skipped, [0.0; 3]));
    // A scan file whose name is not a number.
    std::fs::write(flat.join("extra.bin"), [0u8; 16]).unwrap();
    let e = run(&args(&["replay", &flat_s])).unwrap_err().to_string();
    assert!(e.contains("extra.bin") && e.contains("NNNNNN.bin"), "{e}");
    std::fs::remove_file(flat.join("extra.bin")).unwrap();
    // One pose too few.
    let poses = flat.join("poses.txt");
    let text = std::fs::read_to_string(&poses).unwrap();
    let three: String = text.lines().take(3).map(|l| format!("{l}\n")).collect();
    std::fs::write(&poses, three).unwrap();
    let e = run(&args(&["replay", &flat_s])).unwrap_err().to_string();
    assert!(e.contains("poses.txt") && e.contains("3 poses"), "{e}");
}

/// `detect` and `replay` write each polygon with the fields of the JS
/// API's polygon objects: the floor is ground and the wall is not, the
/// density is the support over the area, and a drive's polygons carry the
/// scans that found them and last grew them.
#[test]
fn polygons_carry_ground_density_and_scans() {
    let dir = TempDir::new("fields");
    let cloud = write_cloud(&dir);
    let out = run(&args(&["detect", &cloud, "--stride", "4"])).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let all = doc["polygons"].as_array().unwrap();
    let up = |p: &serde_json::Value| p["normal"][2].as_f64().unwrap().abs() > 0.99;
    // The keys of the JS polygon objects (`POLYGON_KEYS` in
    // tests/js/api.test.mjs), whatever their order.
    let keys: Vec<&str> = all[0]
        .as_object()
        .unwrap()
        .keys()
        .map(|k| k.as_str())
        .collect();
    let js = [
        "id", "normal", "offset", "vertices", "area", "support", "density", "ground", "bornScan",
        "lastScan",
    ];
    let mut sorted = js.to_vec();
    sorted.sort_unstable();
    assert_eq!(keys, sorted, "serde_json's map sorts its keys");
    let floor = all.iter().find(|p| up(p)).expect("the floor");
    let wall = all.iter().find(|p| !up(p)).expect("the wall");
    assert_eq!(floor["ground"].as_bool(), Some(true), "{out}");
    assert_eq!(wall["ground"].as_bool(), Some(false), "{out}");
    for p in all {
        let (support, area) = (p["support"].as_f64().unwrap(), p["area"].as_f64().unwrap());
        assert!((p["density"].as_f64().unwrap() - support / area).abs() < 1e-9);
        assert_eq!(
            (p["bornScan"].as_u64(), p["lastScan"].as_u64()),
            (Some(0), Some(0))
        );
    }

    let flat = path_of(&dir, "drive");
    run(&args(&[
        "simulate", "street", "--seed", "2", "--scans", "6", "--out", &flat,
    ]))
    .unwrap();
    let out = run(&args(&["replay", &flat])).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let all = doc["polygons"].as_array().unwrap();
    let area = |p: &serde_json::Value| p["area"].as_f64().unwrap();
    let road = all
        .iter()
        .filter(|p| up(p))
        .max_by(|a, b| area(a).total_cmp(&area(b)))
        .unwrap();
    assert_eq!(road["ground"].as_bool(), Some(true), "{road}");
    assert!(all.iter().any(|p| !up(p)));
    assert!(all.iter().filter(|p| !up(p)).all(|p| p["ground"] == false));
    let scans: Vec<(u64, u64)> = all
        .iter()
        .map(|p| {
            (
                p["bornScan"].as_u64().unwrap(),
                p["lastScan"].as_u64().unwrap(),
            )
        })
        .collect();
    assert!(scans.iter().all(|&(b, l)| b <= l && l <= 5), "{scans:?}");
    assert!(
        scans.iter().any(|&(_, l)| l == 5),
        "the last scan grew one: {scans:?}"
    );
    assert!(
        scans.iter().any(|&(b, _)| b > 0),
        "a later scan found one: {scans:?}"
    );
}
