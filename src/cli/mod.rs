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
  polyscene help";

/// Run one command; returns the text for stdout.
pub fn run(argv: &[String]) -> Result<String> {
    let Some((cmd, rest)) = argv.split_first() else {
        return Err(Error::Invalid(format!("no command given\n{USAGE}")));
    };
    let mut args = Args::parse(rest)?;
    match cmd.as_str() {
        "detect" => detect_cmd(&mut args),
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
