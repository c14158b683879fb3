//! Native side of the reproduction report (`make repro`, scripts/repro.sh).
//!
//! ```text
//! repro_native export OUT [--seed N] [--starts 0,20,40,60,80] [--data DIR]
//!     simulate the street drive, write the locations A.. (10 scans each,
//!     world frame) as OUT/NAME.bin (f32 x y z intensity) + NAME.labels
//!     (u32 ground-truth ids), the scene's ground truth OUT/gt.json and
//!     OUT/manifest.json (every cloud, the real scans of DIR included)
//! repro_native detect OUT RESULTS [--repeat-sim R] [--repeat-real R] [--variants a,b]
//!     time one-shot detection (variants gpp1, gpp2, gpp2-convex) on every
//!     cloud of the manifest, rounds interleaved; write RESULTS/det_CLOUD_VARIANT.json
//!     (polygons with their ground flag, cascade steps, every time) and
//!     RESULTS/native_times.json
//! repro_native eval OUT JOBS.json RESULT.json
//!     score predictions against the ground truth of the simulated clouds;
//!     a job is {"id", "cloud", "kind": "polygons"|"planes"|"mesh", "path",
//!     "dropGround": bool}; polygons are scored by polyscene::eval::evaluate,
//!     meshes (too many triangles for it) by the same definitions here
//! repro_native pcd IN.bin OUT.pcd [--voxel M] [--bin OUT.bin]
//!     a cloud as a binary PCD (x y z), optionally voxel-downsampled (the
//!     centroid of each occupied voxel), optionally also as a .bin
//! ```
use glam::{DVec2, DVec3};
use polyscene::cloud::Cloud;
use polyscene::detect::detect;
use polyscene::eval::{evaluate, EvalOptions, GtSurface};
use polyscene::geometry::{convex_hull, Frame, Plane, Polygon3};
use polyscene::io::{read_bin, read_labels, write_bin, write_labels};
use polyscene::params::{HullKind, Params};
use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel, LOCATION_SCANS};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

#[derive(Serialize, Deserialize, Clone, Debug)]
#[serde(rename_all = "camelCase")]
struct CloudInfo {
    name: String,
    /// "sim" (with labels and ground truth) or "real".
    kind: String,
    bin: String,
    labels: Option<String>,
    points: usize,
    viewpoint: [f64; 3],
    /// First scan of a simulated location.
    start: Option<usize>,
    scans: usize,
    description: String,
}

#[derive(Serialize, Deserialize)]
struct Manifest {
    seed: u64,
    layout: String,
    clouds: Vec<CloudInfo>,
}

fn arg(args: &[String], key: &str) -> Option<String> {
    args.iter()
        .position(|a| a == key)
        .and_then(|i| args.get(i + 1).cloned())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let r = match args.first().map(String::as_str) {
        Some("export") => export(&args[1..]),
        Some("detect") => detect_cmd(&args[1..]),
        Some("eval") => eval_cmd(&args[1..]),
        Some("pcd") => pcd_cmd(&args[1..]),
        _ => Err("usage: repro_native export|detect|eval|pcd ... (see the file's docs)".into()),
    };
    if let Err(e) = r {
        eprintln!("repro_native: {e}");
        std::process::exit(1);
    }
}

// ---------------------------------------------------------------------------
// export

fn export(args: &[String]) -> Res<()> {
    let out = PathBuf::from(args.first().ok_or("export OUT")?);
    let seed: u64 = arg(args, "--seed").map_or(Ok(1), |s| s.parse())?;
    let starts: Vec<usize> = arg(args, "--starts")
        .unwrap_or_else(|| "0,20,40,60,80".into())
        .split(',')
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let data = arg(args, "--data").unwrap_or_else(|| "../shared/data".into());
    std::fs::create_dir_all(&out)?;
    let drive = Drive::new(
        Layout::Street,
        seed,
        SensorModel::default(),
        DriveOptions::default(),
    )?;
    let mut clouds = Vec::new();
    for (i, &start) in starts.iter().enumerate() {
        let name = ((b'A' + i as u8) as char).to_string();
        let loc = drive.location(start, LOCATION_SCANS)?;
        let flat: Vec<f32> = loc
            .points
            .iter()
            .zip(&loc.intensities)
            .flat_map(|(p, &s)| [p.x as f32, p.y as f32, p.z as f32, s])
            .collect();
        let bin = out.join(format!("{name}.bin"));
        let labels = out.join(format!("{name}.labels"));
        write_bin(&bin, &flat)?;
        write_labels(&labels, &loc.labels)?;
        let mean = loc.viewpoint();
        clouds.push(CloudInfo {
            name,
            kind: "sim".into(),
            bin: bin.canonicalize()?.display().to_string(),
            labels: Some(labels.canonicalize()?.display().to_string()),
            points: loc.points.len(),
            viewpoint: mean.to_array(),
            start: Some(start),
            scans: LOCATION_SCANS,
            description: format!(
                "simulated street (seed {seed}), scans {start}-{} in the world frame",
                start + LOCATION_SCANS - 1
            ),
        });
        eprintln!(
            "export: location {} (scans {start}..{}): {} points",
            clouds.last().unwrap().name,
            start + LOCATION_SCANS,
            loc.points.len()
        );
    }
    for (file, label, desc) in [
        (
            "ouster_os0_128_single_scan_016.bin",
            "OS0-128",
            "real Ouster OS0-128 street scan (ouster-sdk test data)",
        ),
        (
            "ouster_os1_64_legacy_f12073.bin",
            "OS1-64",
            "real Ouster OS1-64 intersection scan (lidar-utils test data)",
        ),
    ] {
        let p = Path::new(&data).join(file);
        if !p.exists() {
            eprintln!("export: {} missing, real scan skipped", p.display());
            continue;
        }
        let v = read_bin(&p, 4)?;
        clouds.push(CloudInfo {
            name: label.into(),
            kind: "real".into(),
            bin: p.canonicalize()?.display().to_string(),
            labels: None,
            points: v.len() / 4,
            viewpoint: [0.0; 3],
            start: None,
            scans: 1,
            description: desc.into(),
        });
    }
    // The scene's ground truth, world frame.
    let gt: Vec<Value> = drive
        .scene()
        .polygons
        .iter()
        .map(|g| {
            json!({
                "id": g.id,
                "kind": g.kind.as_str(),
                "vertices": g.polygon.vertices().iter().map(|v| v.to_array()).collect::<Vec<_>>(),
            })
        })
        .collect();
    std::fs::write(
        out.join("gt.json"),
        serde_json::to_string(&json!({ "polygons": gt }))?,
    )?;
    let m = Manifest {
        seed,
        layout: "street".into(),
        clouds,
    };
    std::fs::write(out.join("manifest.json"), serde_json::to_string_pretty(&m)?)?;
    Ok(())
}

fn read_manifest(dir: &Path) -> Res<Manifest> {
    Ok(serde_json::from_str(&std::fs::read_to_string(
        dir.join("manifest.json"),
    )?)?)
}

// ---------------------------------------------------------------------------
// detect

fn variant_params(name: &str, viewpoint: [f64; 3]) -> Res<Params> {
    let mut p = match name {
        "gpp1" => Params::gpp1(),
        "gpp2" => Params::gpp2(),
        "gpp2-convex" => Params {
            hull: HullKind::Convex,
            ..Params::gpp2()
        },
        "gpp1-convex" => Params {
            hull: HullKind::Convex,
            ..Params::gpp1()
        },
        o => return Err(format!("unknown variant {o}").into()),
    };
    p.viewpoint = Some(viewpoint);
    Ok(p)
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

fn detect_cmd(args: &[String]) -> Res<()> {
    let dir = PathBuf::from(args.first().ok_or("detect OUT RESULTS")?);
    let results = PathBuf::from(args.get(1).ok_or("detect OUT RESULTS")?);
    let rep_sim: usize = arg(args, "--repeat-sim").map_or(Ok(3), |s| s.parse())?;
    let rep_real: usize = arg(args, "--repeat-real").map_or(Ok(5), |s| s.parse())?;
    let variants: Vec<String> = arg(args, "--variants")
        .unwrap_or_else(|| "gpp1,gpp2,gpp2-convex".into())
        .split(',')
        .map(String::from)
        .collect();
    let only: Option<Vec<String>> =
        arg(args, "--clouds").map(|s| s.split(',').map(String::from).collect());
    std::fs::create_dir_all(&results)?;
    let m = read_manifest(&dir)?;
    let mut summary = Vec::new();
    for c in &m.clouds {
        if only.as_ref().is_some_and(|o| !o.contains(&c.name)) {
            continue;
        }
        let values = read_bin(Path::new(&c.bin), 4)?;
        let cloud = Cloud::from_flat(&values, 4)?;
        let reps = if c.kind == "sim" { rep_sim } else { rep_real };
        let mut times: HashMap<&str, Vec<f64>> = HashMap::new();
        let mut wall: HashMap<&str, Vec<f64>> = HashMap::new();
        let mut last = HashMap::new();
        // Rounds interleaved: one run of every variant per round, so that a
        // noisy moment of the shared machine hits all variants alike.
        for round in 0..reps {
            for v in &variants {
                let p = variant_params(v, c.viewpoint)?;
                let t = Instant::now();
                let d = detect(&cloud, &p)?;
                let w = t.elapsed().as_secs_f64() * 1e3;
                times.entry(v.as_str()).or_default().push(d.time_ms);
                wall.entry(v.as_str()).or_default().push(w);
                eprintln!(
                    "  native {:8} {:12} run {}/{}: {:8.1} ms, {} polygons",
                    c.name,
                    v,
                    round + 1,
                    reps,
                    d.time_ms,
                    d.primitives.len()
                );
                last.insert(v.as_str(), d);
            }
        }
        for v in &variants {
            let d = &last[v.as_str()];
            let polys: Vec<Value> = d
                .primitives
                .iter()
                .map(|p| {
                    json!({
                        "id": p.id,
                        "normal": p.plane.normal.to_array(),
                        "offset": p.plane.offset,
                        "vertices": p.vertices().iter().map(|x| x.to_array()).collect::<Vec<_>>(),
                        "area": p.area,
                        "support": p.support,
                        "ground": p.ground,
                    })
                })
                .collect();
            let t = &times[v.as_str()];
            let doc = json!({
                "cloud": c.name,
                "variant": v,
                "points": cloud.len(),
                "polygons": polys,
                "steps": d.steps,
                "timesMs": t,
                "wallMs": wall[v.as_str()],
                "medianMs": median(t),
                "work": d.work,
            });
            std::fs::write(
                results.join(format!("det_{}_{}.json", c.name, v)),
                serde_json::to_string(&doc)?,
            )?;
            summary.push(json!({
                "cloud": c.name, "variant": v, "points": cloud.len(),
                "polygons": d.primitives.len(), "timesMs": t, "medianMs": median(t),
            }));
        }
    }
    // Merge with an earlier summary (other clouds or variants).
    let path = results.join("native_times.json");
    let mut all: Vec<Value> = std::fs::read_to_string(&path)
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or_default();
    all.retain(|e| {
        !summary
            .iter()
            .any(|s| s["cloud"] == e["cloud"] && s["variant"] == e["variant"])
    });
    all.extend(summary);
    std::fs::write(&path, serde_json::to_string_pretty(&all)?)?;
    Ok(())
}

// ---------------------------------------------------------------------------
// eval

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Job {
    id: String,
    cloud: String,
    kind: String,
    path: String,
    #[serde(default)]
    drop_ground: bool,
}

struct SimCloud {
    points: Vec<DVec3>,
    labels: Vec<u32>,
}

fn load_sim(c: &CloudInfo) -> Res<SimCloud> {
    let v = read_bin(Path::new(&c.bin), 4)?;
    let labels = read_labels(Path::new(c.labels.as_ref().ok_or("no labels")?))?;
    let points = v
        .chunks_exact(4)
        .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
        .collect::<Vec<_>>();
    if points.len() != labels.len() {
        return Err(format!(
            "{}: {} points, {} labels",
            c.name,
            points.len(),
            labels.len()
        )
        .into());
    }
    Ok(SimCloud { points, labels })
}

fn load_gt(dir: &Path) -> Res<(Vec<GtSurface>, HashMap<u32, String>)> {
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("gt.json"))?)?;
    let mut out = Vec::new();
    let mut kinds = HashMap::new();
    for g in doc["polygons"].as_array().ok_or("gt.json: no polygons")? {
        let verts: Vec<DVec3> = g["vertices"]
            .as_array()
            .ok_or("gt vertices")?
            .iter()
            .map(|v| {
                DVec3::new(
                    v[0].as_f64().unwrap(),
                    v[1].as_f64().unwrap(),
                    v[2].as_f64().unwrap(),
                )
            })
            .collect();
        let id = g["id"].as_u64().ok_or("gt id")? as u32;
        kinds.insert(id, g["kind"].as_str().unwrap_or("?").to_string());
        if let Some(polygon) = Polygon3::from_world(&verts) {
            out.push(GtSurface { id, polygon });
        }
    }
    Ok((out, kinds))
}

/// Observed and covered area (m^2) per ground-truth kind.
fn by_kind(kinds: &HashMap<u32, String>, per_surface: &[(u32, f64, f64)]) -> Value {
    let mut m: std::collections::BTreeMap<String, (f64, f64)> = Default::default();
    for &(id, obs, cov) in per_surface {
        let e = m
            .entry(kinds.get(&id).cloned().unwrap_or_else(|| "?".into()))
            .or_default();
        e.0 += obs;
        e.1 += cov;
    }
    json!(m
        .into_iter()
        .map(|(k, (o, c))| (k, json!({"observed": o, "covered": c})))
        .collect::<serde_json::Map<_, _>>())
}

/// Polygons from a `{"polygons": [{"vertices", "ground"?}]}` document.
fn read_polygons(path: &Path, drop_ground: bool) -> Res<(Vec<Polygon3>, usize)> {
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    let mut out = Vec::new();
    let mut dropped = 0;
    for p in doc["polygons"].as_array().ok_or("no polygons array")? {
        if drop_ground && p["ground"].as_bool() == Some(true) {
            dropped += 1;
            continue;
        }
        let verts: Vec<DVec3> = p["vertices"]
            .as_array()
            .ok_or("no vertices")?
            .iter()
            .map(|v| {
                DVec3::new(
                    v[0].as_f64().unwrap_or(f64::NAN),
                    v[1].as_f64().unwrap_or(f64::NAN),
                    v[2].as_f64().unwrap_or(f64::NAN),
                )
            })
            .collect();
        if let Some(poly) = Polygon3::from_world(&verts) {
            out.push(poly);
        }
    }
    Ok((out, dropped))
}

/// Planes with per-point labels (a RANSAC loop's output) as polygons: the
/// convex hull of each plane's inliers projected on its plane.
/// `{"planes": [{"normal", "offset"}], "labels": "FILE" (u32 per point of
/// the cloud, plane index or 0xFFFFFFFF), "points": "FILE.bin"?}` (paths
/// relative to the document; without "points", the cloud itself).
fn planes_to_polygons(path: &Path, bin: &str) -> Res<Vec<Polygon3>> {
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    let labels_path = path
        .parent()
        .unwrap_or(Path::new("."))
        .join(doc["labels"].as_str().ok_or("labels")?);
    let labels = read_labels(&labels_path)?;
    // The loop may have run on a downsampled copy of the cloud ("points").
    let v = match doc["points"].as_str() {
        Some(p) => read_bin(&path.parent().unwrap_or(Path::new(".")).join(p), 4)?,
        None => read_bin(Path::new(bin), 4)?,
    };
    if v.len() / 4 != labels.len() {
        return Err(format!(
            "{}: {} labels for {} points",
            path.display(),
            labels.len(),
            v.len() / 4
        )
        .into());
    }
    let planes = doc["planes"].as_array().ok_or("planes")?;
    let mut members: Vec<Vec<DVec3>> = vec![Vec::new(); planes.len()];
    for (p, &l) in v.chunks_exact(4).zip(&labels) {
        if (l as usize) < planes.len() {
            members[l as usize].push(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
        }
    }
    let mut out = Vec::new();
    for (pl, pts) in planes.iter().zip(&members) {
        if pts.len() < 3 {
            continue;
        }
        let n = DVec3::new(
            pl["normal"][0].as_f64().unwrap(),
            pl["normal"][1].as_f64().unwrap(),
            pl["normal"][2].as_f64().unwrap(),
        );
        let len = n.length();
        if len.is_nan() || len <= 0.0 {
            continue;
        }
        let plane = Plane {
            normal: n / len,
            offset: pl["offset"].as_f64().unwrap() / len,
        };
        let c = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
        let frame = Frame::on_plane(&plane, c);
        let flat: Vec<DVec2> = pts.iter().map(|&p| frame.to_local(p)).collect();
        if let Some(ring) = convex_hull(&flat) {
            out.push(Polygon3 { frame, ring });
        }
    }
    Ok(out)
}

fn summary_of(m: &polyscene::eval::Metrics) -> Value {
    json!({
        "accuracy": m.accuracy,
        "completeness": m.completeness,
        "detection": m.detection,
        "duplicates": m.duplicates.count,
        "compactness": m.compactness,
    })
}

fn eval_cmd(args: &[String]) -> Res<()> {
    let dir = PathBuf::from(args.first().ok_or("eval OUT JOBS RESULT")?);
    let jobs: Vec<Job> =
        serde_json::from_str(&std::fs::read_to_string(args.get(1).ok_or("JOBS")?)?)?;
    let result = PathBuf::from(args.get(2).ok_or("RESULT")?);
    let m = read_manifest(&dir)?;
    let (gt, kinds) = load_gt(&dir)?;
    let opts = EvalOptions::default();
    let mut cache: HashMap<String, SimCloud> = HashMap::new();
    let mut out = Vec::new();
    for job in &jobs {
        let Some(c) = m.clouds.iter().find(|c| c.name == job.cloud) else {
            out.push(json!({"id": job.id, "error": format!("unknown cloud {}", job.cloud)}));
            continue;
        };
        if !cache.contains_key(&c.name) {
            cache.insert(c.name.clone(), load_sim(c)?);
        }
        let sc = &cache[&c.name];
        let t = Instant::now();
        let r: Res<Value> = (|| {
            Ok(match job.kind.as_str() {
                "polygons" | "planes" => {
                    let (pred, dropped) = if job.kind == "planes" {
                        (planes_to_polygons(Path::new(&job.path), &c.bin)?, 0)
                    } else {
                        read_polygons(Path::new(&job.path), job.drop_ground)?
                    };
                    let metrics =
                        evaluate(&pred, &gt, &sc.points, &sc.labels, sc.points.len(), &opts)?;
                    let mut s = summary_of(&metrics);
                    s["droppedGround"] = json!(dropped);
                    let per: Vec<(u32, f64, f64)> = metrics
                        .surfaces
                        .iter()
                        .map(|r| (r.id, r.observed_area, r.covered_area))
                        .collect();
                    s["byKind"] = by_kind(&kinds, &per);
                    if !job.drop_ground {
                        s["pointCoverage"] = json!(point_coverage(
                            &pred,
                            &sc.points,
                            &sc.labels,
                            opts.completeness_tolerance
                        ));
                    }
                    s
                }
                "mesh" => {
                    let mesh = read_mesh(Path::new(&job.path))?;
                    mesh_metrics(&mesh, &gt, &kinds, &sc.points, &sc.labels, &opts)
                }
                "polygons-as-mesh" => {
                    // Our polygons triangulated and scored by the mesh code:
                    // a cross-check of the two evaluators.
                    let (pred, _) = read_polygons(Path::new(&job.path), job.drop_ground)?;
                    let mesh = polygons_to_mesh(&pred);
                    mesh_metrics(&mesh, &gt, &kinds, &sc.points, &sc.labels, &opts)
                }
                o => return Err(format!("unknown kind {o}").into()),
            })
        })();
        let secs = t.elapsed().as_secs_f64();
        match r {
            Ok(mut v) => {
                v["id"] = json!(job.id);
                v["cloud"] = json!(job.cloud);
                v["kind"] = json!(job.kind);
                v["evalSeconds"] = json!(secs);
                eprintln!(
                    "  eval {:40} mean {:>8} max {:>8} completeness {:.3} ({:.1} s)",
                    job.id,
                    fmt_opt(v["accuracy"]["mean"].as_f64()),
                    fmt_opt(v["accuracy"]["max"].as_f64()),
                    v["completeness"]["completeness"]
                        .as_f64()
                        .unwrap_or(f64::NAN),
                    secs
                );
                out.push(v);
            }
            Err(e) => {
                eprintln!("  eval {}: error {e}", job.id);
                out.push(json!({"id": job.id, "cloud": job.cloud, "error": e.to_string()}));
            }
        }
    }
    std::fs::write(result, serde_json::to_string_pretty(&out)?)?;
    Ok(())
}

/// Share of the labelled (non-clutter) points within `tol` of a prediction:
/// completeness counted in points rather than in area.
fn point_coverage(pred: &[Polygon3], points: &[DVec3], labels: &[u32], tol: f64) -> Option<f64> {
    let labelled: Vec<DVec3> = points
        .iter()
        .zip(labels)
        .filter(|(_, &l)| l != polyscene::eval::CLUTTER)
        .map(|(p, _)| *p)
        .collect();
    if labelled.is_empty() {
        return None;
    }
    if pred.is_empty() {
        return Some(0.0);
    }
    let as_surfaces: Vec<GtSurface> = pred
        .iter()
        .enumerate()
        .map(|(i, p)| GtSurface {
            id: i as u32,
            polygon: p.clone(),
        })
        .collect();
    let d = nearest_gt(&labelled, &as_surfaces);
    Some(d.iter().filter(|&&x| x <= tol).count() as f64 / labelled.len() as f64)
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |x| format!("{x:.4}"))
}

// ---------------------------------------------------------------------------
// meshes

struct TriMesh {
    verts: Vec<DVec3>,
    tris: Vec<[u32; 3]>,
}

/// `u32 nverts, u32 ntris, nverts * 3 f32, ntris * 3 u32`, little-endian.
fn read_mesh(path: &Path) -> Res<TriMesh> {
    let b = std::fs::read(path)?;
    if b.len() < 8 {
        return Err("mesh file too short".into());
    }
    let u = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    let nv = u(0) as usize;
    let nt = u(4) as usize;
    if b.len() != 8 + 12 * nv + 12 * nt {
        return Err(format!(
            "mesh file: {} bytes for {nv} vertices, {nt} triangles",
            b.len()
        )
        .into());
    }
    let f = |i: usize| f32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]) as f64;
    let verts = (0..nv)
        .map(|k| DVec3::new(f(8 + 12 * k), f(12 + 12 * k), f(16 + 12 * k)))
        .collect();
    let base = 8 + 12 * nv;
    let tris = (0..nt)
        .map(|k| [u(base + 12 * k), u(base + 12 * k + 4), u(base + 12 * k + 8)])
        .filter(|t| t.iter().all(|&i| (i as usize) < nv))
        .collect();
    Ok(TriMesh { verts, tris })
}

fn polygons_to_mesh(polys: &[Polygon3]) -> TriMesh {
    let mut m = TriMesh {
        verts: Vec::new(),
        tris: Vec::new(),
    };
    for p in polys {
        if let Some(t) = polyscene::mesh::triangulate_ring(&p.ring) {
            let base = m.verts.len() as u32;
            m.verts
                .extend(t.vertices.iter().map(|&q| p.frame.to_world(q)));
            m.tris.extend(
                t.triangles
                    .iter()
                    .map(|tr| [base + tr[0], base + tr[1], base + tr[2]]),
            );
        }
    }
    m
}

/// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + ab * v;
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + ac * w;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w;
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    a + ab * v + ac * w
}

#[derive(Clone, Copy)]
struct Bx {
    min: DVec3,
    max: DVec3,
}

impl Bx {
    fn of(pts: &[DVec3]) -> Bx {
        let mut b = Bx {
            min: DVec3::splat(f64::INFINITY),
            max: DVec3::splat(f64::NEG_INFINITY),
        };
        for &p in pts {
            b.min = b.min.min(p);
            b.max = b.max.max(p);
        }
        b
    }
    fn dist(&self, o: &Bx) -> f64 {
        (self.min - o.max)
            .max(o.min - self.max)
            .max(DVec3::ZERO)
            .length()
    }
    fn point_dist(&self, p: DVec3) -> f64 {
        (self.min - p).max(p - self.max).max(DVec3::ZERO).length()
    }
}

/// Nearest ground-truth distance of every sample, by 4 m tiles with exact
/// culling (the same scheme as polyscene's evaluation index).
fn nearest_gt(samples: &[DVec3], gt: &[GtSurface]) -> Vec<f64> {
    let boxes: Vec<Bx> = gt.iter().map(|g| Bx::of(&g.polygon.vertices())).collect();
    let key = |p: &DVec3| {
        (
            (p.x / 4.0).floor() as i64,
            (p.y / 4.0).floor() as i64,
            (p.z / 4.0).floor() as i64,
        )
    };
    let mut order: Vec<usize> = (0..samples.len()).collect();
    order.sort_by_key(|&i| key(&samples[i]));
    let mut out = vec![f64::NAN; samples.len()];
    let mut start = 0;
    while start < order.len() {
        let k = key(&samples[order[start]]);
        let len = order[start..]
            .iter()
            .take_while(|&&i| key(&samples[i]) == k)
            .count();
        let tile: Vec<DVec3> = order[start..start + len]
            .iter()
            .map(|&i| samples[i])
            .collect();
        let tb = Bx::of(&tile);
        let centre = 0.5 * (tb.min + tb.max);
        let radius = 0.5 * (tb.max - tb.min).length();
        let mut best_upper = f64::INFINITY;
        let mut cands: Vec<(f64, usize)> = Vec::new();
        for (i, b) in boxes.iter().enumerate() {
            let lower = tb.dist(b);
            if lower > best_upper * (1.0 + 1e-9) + 1e-9 {
                continue;
            }
            best_upper = best_upper.min(gt[i].polygon.distance(centre) + radius);
            cands.push((lower, i));
        }
        cands.retain(|c| c.0 <= best_upper * (1.0 + 1e-9) + 1e-9);
        cands.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (j, &i) in order[start..start + len].iter().enumerate() {
            let p = tile[j];
            let mut best = f64::INFINITY;
            for &(lower, g) in &cands {
                if lower > best {
                    break;
                }
                if boxes[g].point_dist(p) > best {
                    continue;
                }
                best = best.min(gt[g].polygon.distance(p));
            }
            out[i] = best;
        }
        start += len;
    }
    out
}

/// Accuracy and completeness of a triangle mesh with the definitions of
/// polyscene::eval (module docs): triangles sampled on a 0.1 m equivalent
/// density (at least one sample each, weight = area / samples), max over
/// samples and vertices; completeness over the same observed cells.
fn mesh_metrics(
    mesh: &TriMesh,
    gt: &[GtSurface],
    kinds: &HashMap<u32, String>,
    points: &[DVec3],
    labels: &[u32],
    opts: &EvalOptions,
) -> Value {
    let s = opts.sample_spacing;
    let mut samples = Vec::new();
    let mut weights = Vec::new();
    let mut total_area = 0.0;
    let mut used = vec![false; mesh.verts.len()];
    // R2 low-discrepancy sequence: deterministic and well spread.
    let (a1, a2) = (0.754_877_666_246_692_8, 0.569_840_290_998_053_3);
    for t in &mesh.tris {
        let (a, b, c) = (
            mesh.verts[t[0] as usize],
            mesh.verts[t[1] as usize],
            mesh.verts[t[2] as usize],
        );
        let area = 0.5 * (b - a).cross(c - a).length();
        if !area.is_finite() || area <= 0.0 {
            continue;
        }
        for &i in t {
            used[i as usize] = true;
        }
        total_area += area;
        let n = ((area / (s * s)).round() as usize).clamp(1, 2_000_000);
        for k in 0..n {
            let (mut u, mut v) = if n == 1 {
                (1.0 / 3.0, 1.0 / 3.0)
            } else {
                ((0.5 + a1 * k as f64).fract(), (0.5 + a2 * k as f64).fract())
            };
            if u + v > 1.0 {
                u = 1.0 - u;
                v = 1.0 - v;
            }
            samples.push(a + (b - a) * u + (c - a) * v);
            weights.push(area / n as f64);
        }
    }
    let d = nearest_gt(&samples, gt);
    let vert_pts: Vec<DVec3> = mesh
        .verts
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(v, _)| *v)
        .collect();
    let dv = nearest_gt(&vert_pts, gt);
    let wsum: f64 = weights.iter().sum();
    let mean = d.iter().zip(&weights).map(|(x, w)| x * w).sum::<f64>() / wsum;
    let mut pairs: Vec<(f64, f64)> = d.iter().copied().zip(weights.iter().copied()).collect();
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut cum = 0.0;
    let mut med = f64::NAN;
    for (x, w) in &pairs {
        cum += w;
        if cum >= 0.5 * wsum {
            med = *x;
            break;
        }
    }
    let max = d.iter().chain(&dv).copied().fold(0.0f64, f64::max);

    // Completeness: observed cells as in polyscene::eval, covered when within
    // the tolerance of a triangle (uniform grid of triangle boxes).
    let tol = opts.completeness_tolerance;
    let cellg = 0.5;
    let gkey = |p: DVec3| {
        (
            (p.x / cellg).floor() as i64,
            (p.y / cellg).floor() as i64,
            (p.z / cellg).floor() as i64,
        )
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
    for (ti, t) in mesh.tris.iter().enumerate() {
        let pts = [
            mesh.verts[t[0] as usize],
            mesh.verts[t[1] as usize],
            mesh.verts[t[2] as usize],
        ];
        let b = Bx::of(&pts);
        let (lo, hi) = (
            gkey(b.min - DVec3::splat(tol)),
            gkey(b.max + DVec3::splat(tol)),
        );
        let cells = ((hi.0 - lo.0 + 1) * (hi.1 - lo.1 + 1) * (hi.2 - lo.2 + 1)) as usize;
        if cells > 4096 {
            // Huge triangles (Poisson's extrapolated skirts): index them
            // coarsely by their own box; the exact test still decides.
            continue;
        }
        for x in lo.0..=hi.0 {
            for y in lo.1..=hi.1 {
                for z in lo.2..=hi.2 {
                    grid.entry((x, y, z)).or_default().push(ti as u32);
                }
            }
        }
    }
    let huge: Vec<u32> = mesh
        .tris
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            let pts = [
                mesh.verts[t[0] as usize],
                mesh.verts[t[1] as usize],
                mesh.verts[t[2] as usize],
            ];
            let b = Bx::of(&pts);
            let (lo, hi) = (
                gkey(b.min - DVec3::splat(tol)),
                gkey(b.max + DVec3::splat(tol)),
            );
            ((hi.0 - lo.0 + 1) * (hi.1 - lo.1 + 1) * (hi.2 - lo.2 + 1)) as usize > 4096
        })
        .map(|(i, _)| i as u32)
        .collect();
    let cell = opts.cell_size;
    let mut slots: HashMap<u32, usize> = HashMap::new();
    for (i, g) in gt.iter().enumerate() {
        slots.insert(g.id, i);
    }
    let mut bins: Vec<HashMap<(i64, i64), (DVec2, usize)>> = vec![HashMap::new(); gt.len()];
    for (&p, &l) in points.iter().zip(labels) {
        let Some(&slot) = slots.get(&l) else { continue };
        let q = gt[slot].polygon.frame.to_local(p);
        let k = ((q.x / cell).floor() as i64, (q.y / cell).floor() as i64);
        let e = bins[slot].entry(k).or_insert((DVec2::ZERO, 0));
        e.0 += q;
        e.1 += 1;
    }
    let (mut observed, mut covered) = (0usize, 0usize);
    let mut per = Vec::new();
    for (slot, b) in bins.iter().enumerate() {
        let (o0, c0) = (observed, covered);
        for (sum, n) in b.values() {
            let c = gt[slot].polygon.frame.to_world(*sum / *n as f64);
            observed += 1;
            let near = |ti: u32| {
                let t = mesh.tris[ti as usize];
                let q = closest_on_triangle(
                    c,
                    mesh.verts[t[0] as usize],
                    mesh.verts[t[1] as usize],
                    mesh.verts[t[2] as usize],
                );
                (q - c).length() <= tol
            };
            let hit = grid
                .get(&gkey(c))
                .is_some_and(|v| v.iter().any(|&ti| near(ti)))
                || huge.iter().any(|&ti| near(ti));
            covered += usize::from(hit);
        }
        per.push((
            gt[slot].id,
            (observed - o0) as f64 * cell * cell,
            (covered - c0) as f64 * cell * cell,
        ));
    }
    let ca = cell * cell;
    json!({
        "accuracy": {
            "area_samples": samples.len(),
            "boundary_samples": vert_pts.len(),
            "sampled_area": total_area,
            "mean": mean,
            "median": med,
            "max": max,
        },
        "completeness": {
            "observed_area": observed as f64 * ca,
            "covered_area": covered as f64 * ca,
            "completeness": if observed > 0 { covered as f64 / observed as f64 } else { 0.0 },
        },
        "detection": null,
        "byKind": by_kind(kinds, &per),
        "mesh": { "vertices": mesh.verts.len(), "triangles": mesh.tris.len(), "area": total_area },
        "compactness": {
            "bytes": 12 * mesh.verts.len() + 12 * mesh.tris.len(),
            "input_points": points.len(),
            "input_bytes": 12 * points.len(),
        },
    })
}

// ---------------------------------------------------------------------------
// pcd

fn pcd_cmd(args: &[String]) -> Res<()> {
    let input = args.first().ok_or("pcd IN.bin OUT.pcd")?;
    let output = args.get(1).ok_or("pcd IN.bin OUT.pcd")?;
    let voxel: Option<f64> = arg(args, "--voxel").map(|s| s.parse()).transpose()?;
    let v = read_bin(Path::new(input), 4)?;
    let mut pts: Vec<[f32; 3]> = v.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect();
    if let Some(s) = voxel {
        // Centroid per voxel, voxels in first-seen order.
        let mut acc: HashMap<(i64, i64, i64), (DVec3, usize, usize)> = HashMap::new();
        for (i, p) in pts.iter().enumerate() {
            let k = (
                (p[0] as f64 / s).floor() as i64,
                (p[1] as f64 / s).floor() as i64,
                (p[2] as f64 / s).floor() as i64,
            );
            let e = acc.entry(k).or_insert((DVec3::ZERO, 0, i));
            e.0 += DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            e.1 += 1;
        }
        let mut cells: Vec<_> = acc.into_values().collect();
        cells.sort_by_key(|c| c.2);
        pts = cells
            .iter()
            .map(|(s, n, _)| {
                let c = *s / *n as f64;
                [c.x as f32, c.y as f32, c.z as f32]
            })
            .collect();
    }
    let n = pts.len();
    let mut bytes = format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n"
    )
    .into_bytes();
    for p in &pts {
        for x in p {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
    }
    std::fs::write(output, bytes)?;
    if let Some(bin) = arg(args, "--bin") {
        let flat: Vec<f32> = pts.iter().flat_map(|p| [p[0], p[1], p[2], 0.0]).collect();
        write_bin(Path::new(&bin), &flat)?;
    }
    eprintln!("pcd: {n} points -> {output}");
    Ok(())
}
