//! The command-line tool's logic, kept in the library so it is tested like
//! everything else. [`run`] takes the arguments after the program name and
//! returns what to print on stdout (the polygons, a report, or the help
//! text), or an error for stderr.
//!
//! The arguments are parsed by `clap`. The pipeline options of `detect` and
//! `replay` are not listed here: [`command`] adds one `--kebab-case` option
//! per [`Params::keys`] key (`minArea` is `--min-area`), so a new parameter
//! is on the command line by itself, and their values go through
//! [`Params::from_options`], the parser (and error messages) of the JS
//! options.

use crate::error::{Error, Result};
use crate::params::Params;
use crate::primitive::Primitive;
use clap::error::ErrorKind;
use clap::{Arg, ArgAction, ArgMatches, Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use serde::Serialize;
use serde_json::{Map, Value};
use std::path::Path;

/// Heading of the pipeline options in `--help`.
const PIPELINE_HEADING: &str = "Pipeline options (the keys of the JS options)";

#[derive(Parser)]
#[command(
    name = "polyscene",
    version,
    about = "Planar polygon maps from LiDAR scans: detection, incremental replay, \
             simulation and evaluation",
    arg_required_else_help = true
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// One-shot detection of a world-frame cloud (LAS/LAZ, PCD, PLY, or raw
    /// float32 with --stride)
    Detect(DetectArgs),
    /// Incremental scenario over a KITTI sequence (velodyne/NNNNNN.bin,
    /// camera poses and calib.txt) or DIR/NNNNNN.bin with DIR/poses.txt
    /// (LiDAR poses, as `simulate` writes)
    Replay(ReplayArgs),
    /// Write a simulated HDL-64E drive with labels and ground truth
    Simulate(SimulateArgs),
    /// Score polygons against a simulated dataset's ground truth
    Eval(EvalArgs),
    /// Share of the polygons' area with a point of the cloud within --radius
    /// (no ground truth needed; one JSON line)
    Ondata(OnDataArgs),
}

#[derive(Args)]
struct DetectArgs {
    /// The cloud, world frame: LAS/LAZ, PCD or PLY (told by the header;
    /// coordinates kept in f64 where the file has them), or headerless
    /// little-endian float32 with --stride
    #[arg(value_name = "CLOUD")]
    cloud: String,
    /// Values per point of a headerless float32 file: 4 (x, y, z,
    /// intensity: KITTI .bin) or 3 (x, y, z). No default: a wrong guess
    /// reads plausible nonsense
    #[arg(long, value_name = "3|4")]
    stride: Option<usize>,
    /// Poses (12 numbers a line, world-from-LiDAR) of the scans the cloud
    /// was accumulated from: a candidate seen edge-on from every one of
    /// their positions is dropped as laser rings; the rest as for a map
    /// seen from nowhere (conflicts with --viewpoint)
    #[arg(long, value_name = "poses.txt", conflicts_with = "viewpoint")]
    poses: Option<String>,
    /// The same from the positions themselves (world, m): x,y,z of each
    /// scan's sensor (JS `viewpoints`; conflicts with --viewpoint and
    /// --poses)
    #[arg(
        long,
        value_name = "X,Y,Z,...",
        value_delimiter = ',',
        allow_hyphen_values = true,
        conflicts_with_all = ["viewpoint", "poses"]
    )]
    viewpoints: Vec<f64>,
    /// KITTI calibration: --poses are KITTI camera-0 poses, converted to
    /// LiDAR poses with its Tr (Tr^-1 . P . Tr)
    #[arg(long, value_name = "calib.txt", requires = "poses")]
    calib: Option<String>,
    #[command(flatten)]
    pipeline: PipelineArgs,
    /// Write the polygons (JSON) to FILE instead of stdout
    #[arg(long, value_name = "FILE.json")]
    out: Option<String>,
}

#[derive(Args)]
struct ReplayArgs {
    /// The scans: a KITTI sequence (SEQ/velodyne/NNNNNN.bin, poses
    /// SEQ/poses.txt or ROOT/poses/NN.txt, SEQ/calib.txt), a KITTI dataset
    /// root with --sequence, or a flat DIR/NNNNNN.bin with DIR/poses.txt of
    /// world-from-LiDAR poses. Scans are stride-4 float32 (x, y, z,
    /// intensity) in the LiDAR frame; scan k goes with pose line k
    #[arg(value_name = "DIR")]
    dir: String,
    /// The sequence (e.g. 00) when DIR is a KITTI dataset root
    #[arg(long, value_name = "ID")]
    sequence: Option<String>,
    /// The poses file, instead of the layout's
    #[arg(long, value_name = "FILE")]
    poses: Option<String>,
    /// KITTI calibration (found as SEQ/calib.txt in KITTI's layout): the
    /// poses are camera-0 poses, converted to LiDAR poses with its Tr
    #[arg(long, value_name = "calib.txt", conflicts_with = "lidar_poses")]
    calib: Option<String>,
    /// The poses are world-from-LiDAR already (no calibration, no
    /// conversion), also in KITTI's layout
    #[arg(long)]
    lidar_poses: bool,
    /// Replay the scans that are there when scan numbers are missing (each
    /// with the pose of its number) instead of refusing the sequence
    #[arg(long)]
    skip_missing: bool,
    /// Leave out empty (0-byte) scans instead of refusing the sequence
    #[arg(long)]
    skip_empty: bool,
    #[command(flatten)]
    pipeline: PipelineArgs,
    /// Write the polygons (JSON) to FILE instead of stdout
    #[arg(long, value_name = "FILE.json")]
    out: Option<String>,
    /// Write each scan's report (one JSON line per scan) to FILE
    #[arg(long, value_name = "FILE.jsonl")]
    report: Option<String>,
}

/// Options of `detect` and `replay` besides the per-key pipeline options.
#[derive(Args)]
struct PipelineArgs {
    /// The parameter set the pipeline options override [default: gpp2]
    #[arg(long, value_name = "gpp1|gpp2", help_heading = PIPELINE_HEADING)]
    preset: Option<String>,
    /// Same as --expansion false: the paper's mode without expansion
    #[arg(long, conflicts_with = "expansion", help_heading = PIPELINE_HEADING)]
    no_expansion: bool,
}

#[derive(Args)]
struct SimulateArgs {
    /// The scene layout: street or crossing
    #[arg(value_name = "LAYOUT")]
    layout: String,
    /// Seed of the scene
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Number of scans to write
    #[arg(long, default_value_t = 100)]
    scans: usize,
    /// Directory to write the dataset to (created if missing)
    #[arg(long, value_name = "DIR", required = true)]
    out: String,
}

#[derive(Args)]
struct EvalArgs {
    /// Polygons to score: a JSON document as `detect` and `replay` write
    #[arg(value_name = "PRED.json")]
    pred: String,
    /// A simulated dataset with ground_truth.json and .label files
    #[arg(value_name = "GT_DIR")]
    gt_dir: String,
}

#[derive(Args)]
struct OnDataArgs {
    /// Polygons to measure: a JSON document as `detect` and `replay` write
    #[arg(value_name = "PRED.json")]
    pred: String,
    /// The cloud they were made from, in the same frame: LAS/LAZ, PCD, PLY,
    /// or headerless little-endian float32 with --stride
    #[arg(value_name = "CLOUD")]
    cloud: String,
    /// Values per point of a headerless float32 file: 4 (x, y, z,
    /// intensity: KITTI .bin) or 3 (x, y, z); no default
    #[arg(long, value_name = "3|4")]
    stride: Option<usize>,
    /// Distance (m) from a polygon's sample to the nearest point that still
    /// counts as on the data
    #[arg(long, value_name = "M", default_value_t = 0.2)]
    radius: f64,
}

/// One `--kebab-case` option per pipeline parameter, on `cmd`.
fn with_pipeline_options(mut cmd: clap::Command) -> clap::Command {
    let defaults = serde_json::to_value(Params::gpp2()).unwrap_or_default();
    for key in Params::keys() {
        let default = defaults.get(&key).cloned().unwrap_or(Value::Null);
        let value_name = match &default {
            Value::Bool(_) => "true|false",
            Value::Number(n) if n.is_f64() => "X",
            Value::Number(_) => "N",
            Value::Array(_) => "X,Y,...",
            _ => "NAME",
        };
        let shown = match &default {
            Value::String(s) => s.clone(),
            Value::Array(a) => a.iter().map(Value::to_string).collect::<Vec<_>>().join(","),
            v => v.to_string(),
        };
        cmd = cmd.arg(
            Arg::new(key.clone())
                .long(crate::params::split_camel(&key, '-'))
                .value_name(value_name)
                .action(ArgAction::Set)
                .allow_hyphen_values(true)
                .help_heading(PIPELINE_HEADING)
                .help(format!("Option `{key}` [gpp2: {shown}]")),
        );
    }
    cmd
}

/// The whole command line: the derived commands plus the pipeline options.
pub fn command() -> clap::Command {
    Cli::command()
        .mut_subcommand("detect", with_pipeline_options)
        .mut_subcommand("replay", with_pipeline_options)
}

/// Run one command; returns the text for stdout. `--help` and `--version`
/// return their text; a usage error is an [`Error::Invalid`] with clap's
/// message (suggestions included).
pub fn run(argv: &[String]) -> Result<String> {
    let args = std::iter::once("polyscene".to_string()).chain(argv.iter().cloned());
    let matches = match command().try_get_matches_from(args) {
        Ok(m) => m,
        Err(e) => {
            let text = e.render().to_string();
            return match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    Ok(text.trim_end().to_string())
                }
                _ => Err(Error::Invalid(
                    text.trim_end()
                        .strip_prefix("error: ")
                        .unwrap_or(text.trim_end())
                        .to_string(),
                )),
            };
        }
    };
    let cli = Cli::from_arg_matches(&matches).map_err(|e| Error::Invalid(e.to_string()))?;
    let sub = matches.subcommand().map(|(_, m)| m);
    match cli.command {
        Cmd::Detect(a) => {
            let params = params_from(&a.pipeline, sub)?;
            detect_cmd(a, params)
        }
        Cmd::Replay(a) => {
            let params = params_from(&a.pipeline, sub)?;
            replay_cmd(a, params)
        }
        Cmd::Simulate(a) => simulate_cmd(a),
        Cmd::Eval(a) => eval_cmd(a),
        Cmd::Ondata(a) => ondata_cmd(a),
    }
}

/// A command-line value as JSON, as the JS options would give it: `true`
/// and `false` are booleans, numbers are numbers (integers when they are
/// one, so that integer options accept `150`), `a,b,c` is an array of
/// numbers, anything else a string. [`Params::from_options`] then checks
/// types and ranges.
fn option_value(key: &str, text: &str) -> Result<Value> {
    fn number(key: &str, text: &str) -> Option<Result<Value>> {
        let x: f64 = text.trim().parse().ok()?;
        Some(if !x.is_finite() {
            Err(Error::BadOption {
                key: key.into(),
                reason: format!("must be a finite number, got {text}"),
            })
        } else if x.fract() == 0.0 && x.abs() <= 9_007_199_254_740_991.0 {
            Ok(if x >= 0.0 {
                Value::from(x as u64)
            } else {
                Value::from(x as i64)
            })
        } else {
            Ok(Value::from(x))
        })
    }
    match text {
        "true" => return Ok(Value::Bool(true)),
        "false" => return Ok(Value::Bool(false)),
        _ => {}
    }
    if let Some(v) = number(key, text) {
        return v;
    }
    if text.contains(',') {
        return text
            .split(',')
            .enumerate()
            .map(|(i, t)| {
                number(key, t).unwrap_or_else(|| {
                    Err(Error::BadOption {
                        key: key.into(),
                        reason: format!("element {i} of '{text}' is not a number"),
                    })
                })
            })
            .collect::<Result<Vec<Value>>>()
            .map(Value::Array);
    }
    Ok(Value::String(text.to_string()))
}

/// The parameters: the pipeline options given, as an options object for
/// [`Params::from_options`].
fn params_from(pipeline: &PipelineArgs, sub: Option<&ArgMatches>) -> Result<Params> {
    let mut options = Map::new();
    if let Some(p) = &pipeline.preset {
        options.insert("preset".into(), Value::String(p.clone()));
    }
    if pipeline.no_expansion {
        options.insert("expansion".into(), Value::Bool(false));
    }
    if let Some(m) = sub {
        for key in Params::keys() {
            if let Ok(Some(text)) = m.try_get_one::<String>(&key) {
                options.insert(key.clone(), option_value(&key, text)?);
            }
        }
    }
    Params::from_options(&options)
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
    /// Support points (over all scans).
    pub support: u64,
    /// Support points per m^2 of outline.
    pub density: f64,
    /// Ground (road, sidewalk, plaza): by the local floor in one-shot
    /// detection, `groundDepth` under the sensor in the scenario.
    pub ground: bool,
    /// Scan in which it was detected (0 for one-shot detection).
    pub born_scan: u64,
    /// Last scan in which it gained support (0 for one-shot detection).
    pub last_scan: u64,
}

impl From<&Primitive> for PolygonJson {
    /// The fields of the JS API's polygon objects (`PolygonView` in the
    /// binding), with the outline as an array of points.
    fn from(p: &Primitive) -> Self {
        PolygonJson {
            id: p.id,
            normal: p.plane.normal.to_array(),
            offset: p.plane.offset,
            vertices: p.vertices().iter().map(|v| v.to_array()).collect(),
            area: p.area,
            support: p.support,
            density: p.density(),
            ground: p.ground,
            born_scan: p.born_scan,
            last_scan: p.last_scan,
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

/// The points of a cloud file ([`crate::io::read_points`]); `--stride` is
/// for headerless files only.
fn read_cloud(path: &str, stride: Option<usize>) -> Result<crate::io::PointFile> {
    let file = crate::io::read_points(Path::new(path), stride)?;
    if let (Some(s), false) = (stride, file.format == crate::io::Format::Raw) {
        return Err(Error::Invalid(format!(
            "{path}: a {} file, which says what its points hold: --stride {s} is for \
             headerless float32 files only",
            file.format.name()
        )));
    }
    Ok(file)
}

/// `error` about the points of `path`, with the file named.
fn in_file(path: &str, error: Error) -> Error {
    match error {
        Error::Io(m) if m.contains(path) => Error::Io(m),
        other => Error::Io(format!("{path}: {other}")),
    }
}

/// Poses of a file, as world-from-LiDAR: KITTI camera poses converted with
/// the `calib` file's Tr when one is given.
fn read_lidar_poses(path: &str, calib: Option<&str>) -> Result<Vec<glam::DMat4>> {
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::Io(format!("cannot read {path}: {e}")))?;
    let poses = crate::io::parse_poses(&text).map_err(|e| match e {
        Error::BadPose(m) => Error::BadPose(format!("{path}: {m}")),
        other => other,
    })?;
    let Some(calib) = calib else {
        return Ok(poses);
    };
    let text = std::fs::read_to_string(calib)
        .map_err(|e| Error::Io(format!("cannot read {calib}: {e}")))?;
    let tr = crate::io::kitti::parse_calib(&text).map_err(|e| in_file(calib, e))?;
    Ok(crate::io::kitti::lidar_poses(&poses, &tr))
}

fn detect_cmd(args: DetectArgs, params: Params) -> Result<String> {
    crate::detect::check_flat_positions(args.viewpoints.len())?;
    let mut viewpoints: Vec<glam::DVec3> = args
        .viewpoints
        .chunks_exact(3)
        .map(|c| glam::DVec3::new(c[0], c[1], c[2]))
        .collect();
    if let Some(path) = &args.poses {
        let poses = read_lidar_poses(path, args.calib.as_deref())?;
        if poses.is_empty() {
            return Err(Error::BadPose(format!("{path}: no poses")));
        }
        viewpoints = poses.iter().map(|m| m.w_axis.truncate()).collect();
    }
    let file = read_cloud(&args.cloud, args.stride)?;
    let cloud = file.cloud().map_err(|e| in_file(&args.cloud, e))?;
    let found = crate::detect::detect_from(&cloud, &params, &viewpoints)?;
    if params.viewpoint.is_none() && viewpoints.is_empty() {
        eprintln!("polyscene detect: {}", sensor_note(found.sensor));
    }
    let doc = PolygonsJson {
        polygons: found.primitives.iter().map(PolygonJson::from).collect(),
        time_ms: found.time_ms,
    };
    write_or_return(&doc, args.out)
}

/// What `detect` took for the sensor when no `--viewpoint` or `--poses`
/// said (on stderr: the two readings give different polygons).
fn sensor_note(sensor: Option<glam::DVec3>) -> &'static str {
    match sensor {
        Some(_) => "no --viewpoint: the origin is taken for the sensor (a scan in its own frame)",
        None => {
            "no --viewpoint: no sensor could have stood at the origin, so the cloud is read as \
             a map seen from nowhere (ground from its local floor, a coarse pass for sparse \
             surfaces); for a scan in map coordinates give --viewpoint X,Y,Z, for a map --poses FILE"
        }
    }
}

fn replay_cmd(args: ReplayArgs, params: Params) -> Result<String> {
    use crate::cloud::Coordinates;
    let options = crate::io::kitti::SequenceOptions {
        sequence: args.sequence,
        poses: args.poses.map(Into::into),
        calib: args.calib.map(Into::into),
        lidar_poses: args.lidar_poses,
        skip_missing: args.skip_missing,
        skip_empty: args.skip_empty,
    };
    let seq = crate::io::kitti::Sequence::open(Path::new(&args.dir), &options)?;
    let mut scenario = crate::scenario::Scenario::new(params)?;
    let mut lines = String::new();
    let mut total_ms = 0.0;
    for (scan, pose) in seq.scans.iter().zip(&seq.poses) {
        // KITTI's .bin is stride 4; a file with a header is read as its
        // format, never as raw values.
        let file = crate::io::read_points(&scan.path, Some(4))?;
        let name = scan.path.display().to_string();
        let report = match &file.coordinates {
            Coordinates::F32(v) => scenario.add_scan(v, file.stride, pose),
            Coordinates::F64(v) => scenario.add_scan_f64(v, file.stride, pose),
        }
        .map_err(|e| in_file(&name, e))?;
        total_ms += report.time_ms.total;
        lines.push_str(&serde_json::to_string(&report).map_err(|e| Error::Invalid(e.to_string()))?);
        lines.push('\n');
    }
    if let Some(path) = args.report {
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
    write_or_return(&doc, args.out)
}

fn simulate_cmd(args: SimulateArgs) -> Result<String> {
    let layout: crate::sim::Layout = args.layout.parse()?;
    crate::sim::write_dataset(
        Path::new(&args.out),
        layout,
        args.seed,
        args.scans,
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
    #[serde(default)]
    id: Option<u32>,
    vertices: Vec<[f64; 3]>,
}

/// The polygons of a `detect`/`replay` document with their ids (the
/// position in the file when a polygon has none); polygons without area
/// (fewer than three vertices, collinear) are left out.
fn read_pred(pred_path: &str) -> Result<Vec<(u32, crate::geometry::Polygon3)>> {
    let text = std::fs::read_to_string(pred_path)
        .map_err(|e| Error::Io(format!("cannot read {pred_path}: {e}")))?;
    let doc: PredDoc = serde_json::from_str(&text)
        .map_err(|e| Error::Io(format!("{pred_path}: not a polygons document: {e}")))?;
    Ok(doc
        .polygons
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            let v: Vec<glam::DVec3> = p
                .vertices
                .iter()
                .map(|&a| glam::DVec3::from_array(a))
                .collect();
            let id = p.id.unwrap_or(i as u32);
            crate::geometry::Polygon3::from_world(&v).map(|poly| (id, poly))
        })
        .collect())
}

fn eval_cmd(args: EvalArgs) -> Result<String> {
    let (pred_path, gt_dir) = (args.pred, args.gt_dir);
    let pred: Vec<crate::geometry::Polygon3> =
        read_pred(&pred_path)?.into_iter().map(|p| p.1).collect();
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

/// One polygon of the `ondata` output.
#[derive(Serialize)]
struct OnDataPolygonJson {
    id: u32,
    area: f64,
    samples: usize,
    share: f64,
}

/// The JSON line `ondata` prints.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct OnDataJson {
    radius: f64,
    points: usize,
    area: f64,
    near_area: f64,
    share: f64,
    /// In the order of the file.
    polygons: Vec<OnDataPolygonJson>,
}

fn ondata_cmd(args: OnDataArgs) -> Result<String> {
    if args.radius.is_nan() || args.radius < 0.0 {
        return Err(Error::Invalid(format!(
            "--radius {}: expected a distance of 0 m or more",
            args.radius
        )));
    }
    let pred = read_pred(&args.pred)?;
    let points = read_cloud(&args.cloud, args.stride)?.world_points();
    let polygons: Vec<crate::geometry::Polygon3> = pred.iter().map(|p| p.1.clone()).collect();
    let r = crate::eval::on_data(&polygons, &points, args.radius);
    let doc = OnDataJson {
        radius: r.radius,
        points: r.points,
        area: r.area,
        near_area: r.near_area,
        share: r.share,
        polygons: pred
            .iter()
            .zip(&r.polygons)
            .map(|((id, _), p)| OnDataPolygonJson {
                id: *id,
                area: p.area,
                samples: p.samples,
                share: p.share,
            })
            .collect(),
    };
    write_or_return(&doc, None)
}
