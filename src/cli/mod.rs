//! The command-line tool's logic, kept in the library so it is tested like
//! everything else. `run` takes the arguments after the program name and
//! returns what to print on stdout, or an error for stderr.

mod args;

use crate::cloud::Cloud;
use crate::error::{Error, Result};
use crate::params::{HullKind, Params};
use crate::primitive::Primitive;
use args::Args;
use serde::Serialize;
use std::path::Path;

const USAGE: &str = "\
usage:
  polyscene detect CLOUD.bin [--stride 3|4] [--preset gpp1|gpp2] [--hull convex|concave]
                   [--seed N] [--out FILE.json]
      one-shot detection of a world-frame cloud (little-endian f32, stride 4 = KITTI .bin)
  polyscene replay DIR [--preset gpp1|gpp2] [--hull convex|concave] [--seed N]
                   [--no-expansion] [--out FILE.json] [--report FILE.jsonl]
      incremental scenario over DIR/NNNNNN.bin (sensor frame) with DIR/poses.txt (KITTI)
  polyscene simulate street|crossing [--seed N] [--scans K] --out DIR
      write a simulated HDL-64E drive with labels and ground truth
  polyscene eval PRED.json GT_DIR
      score polygons against a simulated dataset's ground truth
  polyscene help";

/// Run one command; returns the text for stdout.
pub fn run(argv: &[String]) -> Result<String> {
    let Some((cmd, rest)) = argv.split_first() else {
        return Err(Error::Invalid(format!("no command given\n{USAGE}")));
    };
    let mut args = Args::parse(rest)?;
    match cmd.as_str() {
        "detect" => detect_cmd(&mut args),
        "replay" => replay_cmd(&mut args),
        "simulate" => simulate_cmd(&mut args),
        "eval" => eval_cmd(&mut args),
        "help" | "--help" | "-h" => Ok(USAGE.to_string()),
        other => Err(Error::Invalid(format!(
            "unknown command '{other}'\n{USAGE}"
        ))),
    }
}

/// Parameters from `--preset`, `--hull` and `--seed`.
fn params_from(args: &mut Args) -> Result<Params> {
    let mut p = Params::preset(args.take("preset").as_deref().unwrap_or("gpp2"))?;
    if let Some(h) = args.take("hull") {
        p.hull = match h.as_str() {
            "convex" => HullKind::Convex,
            "concave" => HullKind::Concave,
            o => {
                return Err(Error::BadOption {
                    key: "hull".into(),
                    reason: format!("expected 'convex' or 'concave', got '{o}'"),
                })
            }
        }
    }
    if let Some(s) = args.take_parsed::<u64>("seed")? {
        p.seed = s;
    }
    p.validate()?;
    Ok(p)
}

/// One polygon of the JSON output.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
pub struct PolygonJson {
    /// Primitive id.
    pub id: u32,
    /// Unit normal.
    pub normal: [f64; 3],
    /// Plane offset (`normal · x + offset = 0`).
    pub offset: f64,
    /// Outline, world coordinates, in order.
    pub vertices: Vec<[f64; 3]>,
    /// Area (m^2).
    pub area: f64,
    /// Support points.
    pub support: u64,
}

impl From<&Primitive> for PolygonJson {
    fn from(p: &Primitive) -> Self {
        PolygonJson {
            id: p.id,
            normal: p.plane.normal.to_array(),
            offset: p.plane.offset,
            vertices: p.vertices().iter().map(|v| v.to_array()).collect(),
            area: p.area,
            support: p.support,
        }
    }
}

/// The JSON document `detect` and `replay` write.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
pub struct PolygonsJson {
    /// The polygons.
    pub polygons: Vec<PolygonJson>,
    /// Time of the computation itself (ms), without file I/O.
    pub time_ms: f64,
}

fn write_or_return(doc: &impl Serialize, out: Option<String>) -> Result<String> {
    let text = serde_json::to_string(doc).map_err(|e| Error::Invalid(e.to_string()))?;
    match out {
        Some(path) => {
            std::fs::write(&path, text + "\n")
                .map_err(|e| Error::Io(format!("cannot write {path}: {e}")))?;
            Ok(String::new())
        }
        None => Ok(text),
    }
}

fn detect_cmd(args: &mut Args) -> Result<String> {
    let path = args.positional(0, "CLOUD.bin")?;
    let stride = args.take_parsed::<usize>("stride")?.unwrap_or(4);
    let params = params_from(args)?;
    let out = args.take("out");
    args.finish()?;
    let values = crate::io::read_bin(Path::new(&path), stride)?;
    let cloud = Cloud::from_flat(&values, stride)?;
    let found = crate::detect::detect(&cloud, &params)?;
    let doc = PolygonsJson {
        polygons: found.primitives.iter().map(PolygonJson::from).collect(),
        time_ms: found.time_ms,
    };
    write_or_return(&doc, out)
}

fn replay_cmd(args: &mut Args) -> Result<String> {
    let dir = args.positional(0, "DIR")?;
    let mut params = params_from(args)?;
    if args.flag("no-expansion") {
        params.expansion = false;
    }
    let out = args.take("out");
    let report_path = args.take("report");
    args.finish()?;
    let data = crate::sim::read_dataset(Path::new(&dir))?;
    let mut scenario = crate::scenario::Scenario::new(params)?;
    let mut lines = String::new();
    let mut total_ms = 0.0;
    for (scan, pose) in data.scans.iter().zip(&data.poses) {
        let report = scenario.add_scan(&scan.points, 4, pose)?;
        total_ms += report.time_ms.total;
        lines.push_str(&serde_json::to_string(&report).map_err(|e| Error::Invalid(e.to_string()))?);
        lines.push('\n');
    }
    if let Some(path) = report_path {
        std::fs::write(&path, lines).map_err(|e| Error::Io(format!("cannot write {path}: {e}")))?;
    }
    let doc = PolygonsJson {
        polygons: scenario
            .primitives()
            .iter()
            .map(PolygonJson::from)
            .collect(),
        time_ms: total_ms,
    };
    write_or_return(&doc, out)
}

fn simulate_cmd(args: &mut Args) -> Result<String> {
    let layout: crate::sim::Layout = args.positional(0, "LAYOUT")?.parse()?;
    let seed = args.take_parsed::<u64>("seed")?.unwrap_or(1);
    let scans = args.take_parsed::<usize>("scans")?.unwrap_or(100);
    let out = args
        .take("out")
        .ok_or_else(|| Error::Invalid("simulate needs --out DIR".into()))?;
    args.finish()?;
    crate::sim::write_dataset(
        Path::new(&out),
        layout,
        seed,
        scans,
        &crate::sim::SensorModel::default(),
    )?;
    Ok(String::new())
}

#[derive(serde::Deserialize)]
struct PredDoc {
    polygons: Vec<PredPolygon>,
}

#[derive(serde::Deserialize)]
struct PredPolygon {
    vertices: Vec<[f64; 3]>,
}

fn eval_cmd(args: &mut Args) -> Result<String> {
    let pred_path = args.positional(0, "PRED.json")?;
    let gt_dir = args.positional(1, "GT_DIR")?;
    args.finish()?;
    let text = std::fs::read_to_string(&pred_path)
        .map_err(|e| Error::Io(format!("cannot read {pred_path}: {e}")))?;
    let doc: PredDoc = serde_json::from_str(&text)
        .map_err(|e| Error::Io(format!("{pred_path}: not a polygons document: {e}")))?;
    let pred: Vec<crate::geometry::Polygon3> = doc
        .polygons
        .iter()
        .filter_map(|p| {
            let v: Vec<glam::DVec3> = p
                .vertices
                .iter()
                .map(|&a| glam::DVec3::from_array(a))
                .collect();
            crate::geometry::Polygon3::from_world(&v)
        })
        .collect();
    let data = crate::sim::read_dataset(Path::new(&gt_dir))?;
    let gt = data
        .ground_truth
        .as_ref()
        .ok_or_else(|| Error::Io(format!("{gt_dir}: no ground_truth.json")))?;
    let surfaces: Vec<crate::eval::GtSurface> = gt
        .polygons
        .iter()
        .map(|g| crate::eval::GtSurface {
            id: g.id,
            polygon: g.polygon.clone(),
        })
        .collect();
    let (mut points, mut labels) = (Vec::new(), Vec::new());
    for (scan, pose) in data.scans.iter().zip(&data.poses) {
        let Some(l) = &scan.labels else {
            continue;
        };
        for (p, &lab) in scan.points.chunks_exact(4).zip(l) {
            points.push(pose.transform_point3(glam::DVec3::new(
                p[0] as f64,
                p[1] as f64,
                p[2] as f64,
            )));
            labels.push(lab);
        }
    }
    let n = data.scans.iter().map(|s| s.points.len() / 4).sum();
    let metrics = crate::eval::evaluate(
        &pred,
        &surfaces,
        &points,
        &labels,
        n,
        &crate::eval::EvalOptions::default(),
    )?;
    Ok(metrics.to_string())
}
