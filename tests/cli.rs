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

/// `--poses` makes the mean position of the poses the viewpoint: the same
/// polygons as `--viewpoint` at that mean; a bad poses file is an error
/// naming it, and both options together are refused.
#[test]
fn poses_give_the_viewpoint_of_an_accumulated_cloud() {
    let dir = TempDir::new("poses");
    let cloud = write_cloud(&dir);
    let poses = dir.0.join("poses.txt");
    std::fs::write(
        &poses,
        "1 0 0 -1 0 1 0 0 0 0 1 0.1\n1 0 0 1 0 1 0 0 0 0 1 -0.1\n",
    )
    .unwrap();
    let poses = poses.to_string_lossy().into_owned();
    let by_poses = run(&args(&[
        "detect", &cloud, "--stride", "4", "--poses", &poses,
    ]))
    .unwrap();
    let by_viewpoint = run(&args(&[
        "detect",
        &cloud,
        "--stride",
        "4",
        "--viewpoint",
        "0,0,0",
    ]))
    .unwrap();
    let strip = |s: &str| {
        let mut v: serde_json::Value = serde_json::from_str(s).unwrap();
        v["timeMs"] = serde_json::Value::Null;
        v
    };
    assert_eq!(strip(&by_poses), strip(&by_viewpoint));
    assert!(polygon_count(&by_poses) >= 2);
    let moved = run(&args(&[
        "detect",
        &cloud,
        "--stride",
        "4",
        "--viewpoint",
        "30,0,-1.8",
    ]))
    .unwrap();
    assert_ne!(
        strip(&moved),
        strip(&by_poses),
        "the viewpoint matters here"
    );
    let bad = dir.0.join("bad.txt");
    std::fs::write(&bad, "1 0 0\n").unwrap();
    let e = run(&args(&[
        "detect",
        &cloud,
        "--stride",
        "4",
        "--poses",
        &bad.to_string_lossy(),
    ]))
    .unwrap_err();
    assert!(e.to_string().contains("bad.txt"), "{e}");
    assert!(run(&args(&[
        "detect",
        &cloud,
        "--stride",
        "4",
        "--poses",
        &poses,
        "--viewpoint",
        "0,0,0"
    ]))
    .is_err());
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
