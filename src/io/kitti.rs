//! KITTI odometry sequences on disk, and the conversion of their camera
//! poses to LiDAR poses.
//!
//! A scan is `NNNNNN.bin`, the scan number in six digits: little-endian
//! f32 `x, y, z, reflectance` (stride 4) in the LiDAR frame. Line `k` of a
//! poses file (12 numbers, the row-major 3x4 `[R | t]`) is the pose of scan
//! `k`: scans and poses are matched by number, never by position in a
//! listing, so a missing scan cannot shift the poses of the scans after it.
//!
//! KITTI's poses (`poses/NN.txt`, and SemanticKITTI's
//! `sequences/NN/poses.txt`) are **camera-0 poses**: world-from-camera,
//! the world being camera 0's frame at scan 0. `calib.txt`'s `Tr` maps
//! LiDAR coordinates to camera-0 coordinates, so the world-from-LiDAR pose
//! of scan `k` is `Tr^-1 · P_k · Tr` ([`lidar_poses`]), in the frame of the
//! LiDAR at scan 0 (z up). Reading camera poses as LiDAR poses puts every
//! scan on its side and smears the map.
//!
//! [`Sequence::open`] reads three layouts:
//!
//! - the dataset root, `ROOT/sequences/NN/velodyne/NNNNNN.bin`, with a
//!   sequence id `NN`: poses `ROOT/sequences/NN/poses.txt` or
//!   `ROOT/poses/NN.txt`, calibration `ROOT/sequences/NN/calib.txt`;
//! - a sequence directory `SEQ` holding `velodyne/` (same files);
//! - a flat directory, `DIR/NNNNNN.bin` with `DIR/poses.txt` holding
//!   world-from-LiDAR poses (polyscene's simulated datasets).
//!
//! Poses from the KITTI layouts are camera poses and need the calibration;
//! poses of a flat directory are LiDAR poses unless a calibration is given.
//! Whichever it is, nothing is guessed silently: a KITTI layout without
//! `calib.txt`, or a flat directory with a `calib.txt` beside its poses, is
//! an error that says which option settles it.

use crate::error::{Error, Result};
use glam::{DMat4, DVec4};
use std::path::{Path, PathBuf};

fn io_err(path: &Path, what: impl std::fmt::Display) -> Error {
    Error::Io(format!("{}: {what}", path.display()))
}

/// Parse a KITTI calibration file: the LiDAR-to-camera-0 transform, from
/// the line `Tr:` (odometry; `Tr_velo_to_cam:` and `Tr_velo_cam:` of the
/// object and tracking sets are read too: 12 numbers, row-major 3x4) or
/// from the lines `R:` (9 numbers) and `T:` (3) of the raw data's
/// `calib_velo_to_cam.txt`. Checked to be rigid.
pub fn parse_calib(text: &str) -> Result<DMat4> {
    let mut tr: Option<Vec<f64>> = None;
    let (mut r, mut t): (Option<Vec<f64>>, Option<Vec<f64>>) = (None, None);
    for (lineno, line) in text.lines().enumerate() {
        let Some((key, rest)) = line.split_once(':') else {
            continue;
        };
        let key = key.trim();
        let wanted = matches!(key, "Tr" | "Tr_velo_to_cam" | "Tr_velo_cam" | "R" | "T");
        if !wanted {
            continue;
        }
        let nums: std::result::Result<Vec<f64>, _> =
            rest.split_whitespace().map(str::parse::<f64>).collect();
        let nums = nums.map_err(|e| {
            Error::BadPose(format!(
                "calib line {} ({key}): not a number ({e})",
                lineno + 1
            ))
        })?;
        let expected = match key {
            "R" => 9,
            "T" => 3,
            _ => 12,
        };
        if nums.len() != expected {
            return Err(Error::BadPose(format!(
                "calib line {} ({key}): expected {expected} numbers, found {}",
                lineno + 1,
                nums.len()
            )));
        }
        match key {
            "R" => r = Some(nums),
            "T" => t = Some(nums),
            _ => tr = tr.or(Some(nums)),
        }
    }
    let rows = match (tr, r, t) {
        (Some(tr), _, _) => tr,
        (None, Some(r), Some(t)) => vec![
            r[0], r[1], r[2], t[0], r[3], r[4], r[5], t[1], r[6], r[7], r[8], t[2],
        ],
        _ => {
            return Err(Error::BadPose(
                "no LiDAR-to-camera transform: expected a line `Tr:` with 12 numbers \
                 (KITTI odometry calib.txt), or lines `R:` and `T:`"
                    .into(),
            ))
        }
    };
    let m = from_rows(&rows);
    crate::cloud::check_rigid(&m).map_err(|e| Error::BadPose(format!("calib Tr: {e}")))?;
    Ok(m)
}

/// A 4x4 transform from the 12 numbers of a row-major 3x4 `[R | t]`.
fn from_rows(n: &[f64]) -> DMat4 {
    DMat4::from_cols(
        DVec4::new(n[0], n[4], n[8], 0.0),
        DVec4::new(n[1], n[5], n[9], 0.0),
        DVec4::new(n[2], n[6], n[10], 0.0),
        DVec4::new(n[3], n[7], n[11], 1.0),
    )
}

/// World-from-LiDAR poses from KITTI's world-from-camera-0 poses and the
/// calibration's `tr` (LiDAR to camera 0): `Tr^-1 · P · Tr` each.
pub fn lidar_poses(camera_poses: &[DMat4], tr: &DMat4) -> Vec<DMat4> {
    let inv = tr.inverse();
    camera_poses.iter().map(|p| inv * *p * *tr).collect()
}

/// One scan file of a sequence.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanFile {
    /// The scan number (the file name's digits; the line of its pose).
    pub number: usize,
    /// The file.
    pub path: PathBuf,
    /// Its size in bytes.
    pub bytes: u64,
}

/// The scan files `NNNNNN.bin` of `dir`, by number. Errors name the file:
/// a `.bin` whose name is not a number, two files of one number, an empty
/// (0-byte) file unless `allow_empty` (then it is listed, with `bytes` 0),
/// and a gap in the numbering (scan 0 up) unless `skip_missing`. No `.bin`
/// at all is an error too.
pub fn scan_files(dir: &Path, skip_missing: bool, allow_empty: bool) -> Result<Vec<ScanFile>> {
    let entries =
        std::fs::read_dir(dir).map_err(|e| io_err(dir, format!("cannot list directory: {e}")))?;
    let mut scans: Vec<ScanFile> = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| io_err(dir, format!("cannot list directory: {e}")))?;
        let path = entry.path();
        if !(path.extension().is_some_and(|x| x == "bin") && path.is_file()) {
            continue;
        }
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let number =
            (!stem.is_empty() && stem.len() <= 9 && stem.bytes().all(|b| b.is_ascii_digit()))
                .then(|| stem.parse::<usize>().ok())
                .flatten()
                .ok_or_else(|| {
                    io_err(
                        &path,
                        "not a scan file name: scans are NNNNNN.bin, the scan number, which \
                     is also the line of its pose",
                    )
                })?;
        let size = entry
            .metadata()
            .map_err(|e| io_err(&path, format!("cannot read: {e}")))?
            .len();
        scans.push(ScanFile {
            number,
            path,
            bytes: size,
        });
    }
    if scans.is_empty() {
        return Err(io_err(dir, "no .bin scans found"));
    }
    scans.sort_by(|a, b| a.number.cmp(&b.number).then(a.path.cmp(&b.path)));
    for w in scans.windows(2) {
        if w[0].number == w[1].number {
            return Err(io_err(
                &w[1].path,
                format!(
                    "scan number {} again (also {})",
                    w[0].number,
                    w[0].path.display()
                ),
            ));
        }
    }
    if !skip_missing {
        for (k, scan) in scans.iter().enumerate() {
            if scan.number != k {
                return Err(io_err(
                    dir,
                    format!(
                        "scan {k:06}.bin is missing (the next is {}): scans are matched \
                         with poses by number; to replay the scans that are there, each \
                         with the pose of its number, pass --skip-missing",
                        scan.path.display()
                    ),
                ));
            }
        }
    }
    if !allow_empty {
        if let Some(scan) = scans.iter().find(|s| s.bytes == 0) {
            return Err(io_err(
                &scan.path,
                "empty file (0 bytes), not a scan: pass --skip-empty to leave empty scans out",
            ));
        }
    }
    Ok(scans)
}

/// How [`Sequence::open`] finds and reads a sequence; `Default` reads a
/// sequence directory or a flat directory with everything in its place.
#[derive(Clone, Debug, Default)]
pub struct SequenceOptions {
    /// The sequence id (`"00"`) when the path is a dataset root.
    pub sequence: Option<String>,
    /// The poses file, instead of the layout's.
    pub poses: Option<PathBuf>,
    /// The calibration file, instead of the layout's `calib.txt`: the poses
    /// are camera-0 poses and are converted with its `Tr`.
    pub calib: Option<PathBuf>,
    /// The poses are world-from-LiDAR already: no calibration, no
    /// conversion (conflicts with `calib`).
    pub lidar_poses: bool,
    /// Replay the scans that are there when numbers are missing.
    pub skip_missing: bool,
    /// Leave out empty (0-byte) scans instead of refusing them.
    pub skip_empty: bool,
}

/// A sequence's scans with their world-from-LiDAR poses; the points are
/// read one scan at a time by the caller (a KITTI sequence holds gigabytes).
#[derive(Clone, Debug)]
pub struct Sequence {
    /// The scans, by number (without the empty ones left out).
    pub scans: Vec<ScanFile>,
    /// The empty (0-byte) scans left out (`skip_empty`).
    pub skipped_empty: Vec<ScanFile>,
    /// World-from-LiDAR pose of each scan (same order).
    pub poses: Vec<DMat4>,
    /// The poses file read.
    pub poses_path: PathBuf,
    /// The calibration the poses were converted with (`None`: they were
    /// LiDAR poses).
    pub calib: Option<PathBuf>,
}

impl Sequence {
    /// Find and read a sequence at `path` (see the module doc for the
    /// layouts): its scan files and their LiDAR poses.
    pub fn open(path: &Path, options: &SequenceOptions) -> Result<Sequence> {
        if options.lidar_poses && options.calib.is_some() {
            return Err(Error::Invalid(
                "--calib converts camera poses; --lidar-poses says there is nothing to \
                 convert: give one of them"
                    .into(),
            ));
        }
        // The sequence directory, and whether it is in KITTI's layout.
        let root_seqs = path.join("sequences");
        let (seq_dir, kitti) = if root_seqs.is_dir() {
            let Some(id) = &options.sequence else {
                return Err(io_err(
                    path,
                    format!(
                        "a KITTI dataset root: pick a sequence with --sequence ID (found {})",
                        list_dirs(&root_seqs)
                    ),
                ));
            };
            let dir = root_seqs.join(id);
            if !dir.is_dir() {
                return Err(io_err(
                    &dir,
                    format!("no such sequence (found {})", list_dirs(&root_seqs)),
                ));
            }
            (dir, true)
        } else {
            if let Some(id) = &options.sequence {
                return Err(io_err(
                    path,
                    format!("--sequence {id} needs a KITTI dataset root (a sequences/ directory)"),
                ));
            }
            (path.to_path_buf(), path.join("velodyne").is_dir())
        };
        let scan_dir = if kitti {
            seq_dir.join("velodyne")
        } else {
            seq_dir.clone()
        };
        let scans = scan_files(&scan_dir, options.skip_missing, options.skip_empty)?;

        let poses_path = match &options.poses {
            Some(p) => p.clone(),
            None if !kitti => seq_dir.join("poses.txt"),
            None => {
                let id = seq_dir
                    .file_name()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                let beside = seq_dir.join("poses.txt");
                let root = seq_dir
                    .parent()
                    .and_then(Path::parent)
                    .map(|r| r.join("poses").join(format!("{id}.txt")));
                match root {
                    _ if beside.is_file() => beside,
                    Some(r) if r.is_file() => r,
                    r => {
                        return Err(io_err(
                            &seq_dir,
                            format!(
                                "no poses: looked for {}{}; give the file with --poses",
                                beside.display(),
                                r.map(|r| format!(" and {}", r.display()))
                                    .unwrap_or_default()
                            ),
                        ))
                    }
                }
            }
        };
        let text = std::fs::read_to_string(&poses_path)
            .map_err(|e| io_err(&poses_path, format!("cannot read: {e}")))?;
        let poses = super::parse_poses(&text).map_err(|e| io_err(&poses_path, e))?;

        // Which frame the poses are in.
        let calib = if options.lidar_poses {
            None
        } else if let Some(c) = &options.calib {
            Some(c.clone())
        } else if kitti {
            let c = seq_dir.join("calib.txt");
            if !c.is_file() {
                return Err(io_err(
                    &poses_path,
                    format!(
                        "KITTI poses are camera-0 poses, and {} (whose Tr maps LiDAR to \
                         camera) is missing: pass --calib FILE, or --lidar-poses if these \
                         poses are world-from-LiDAR already",
                        c.display()
                    ),
                ));
            }
            Some(c)
        } else {
            let c = seq_dir.join("calib.txt");
            if c.is_file() {
                return Err(io_err(
                    &c,
                    format!(
                        "a KITTI calibration beside {}: if those are KITTI camera poses, \
                         pass --calib {} to convert them to LiDAR poses; if they are \
                         world-from-LiDAR already, pass --lidar-poses",
                        poses_path.display(),
                        c.display()
                    ),
                ));
            }
            None
        };
        let poses = match &calib {
            Some(c) => {
                let text = std::fs::read_to_string(c)
                    .map_err(|e| io_err(c, format!("cannot read: {e}")))?;
                let tr = parse_calib(&text).map_err(|e| io_err(c, e))?;
                lidar_poses(&poses, &tr)
            }
            None => poses,
        };

        // Poses by scan number.
        let last = scans.last().map_or(0, |s| s.number);
        let (scans, skipped_empty): (Vec<ScanFile>, Vec<ScanFile>) =
            scans.into_iter().partition(|s| s.bytes > 0);
        let expected = if options.skip_missing {
            last < poses.len()
        } else {
            // Every number from 0 is there (empty ones perhaps left out):
            // one pose per scan file, as KITTI has.
            last + 1 == poses.len()
        };
        if !expected {
            return Err(io_err(
                &poses_path,
                format!(
                    "{} poses for scans numbered 0 to {last}{}",
                    poses.len(),
                    if options.skip_missing {
                        ""
                    } else {
                        " (one pose per scan, line k for scan k)"
                    }
                ),
            ));
        }
        let poses = scans.iter().map(|s| poses[s.number]).collect();
        Ok(Sequence {
            scans,
            skipped_empty,
            poses,
            poses_path,
            calib,
        })
    }
}

/// The subdirectory names of `dir`, sorted, for a message.
fn list_dirs(dir: &Path) -> String {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|it| {
            it.filter_map(|e| e.ok())
                .filter(|e| e.path().is_dir())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DQuat, DVec3};

    /// KITTI odometry's Tr of sequence 00 (LiDAR to camera 0).
    const TR_00: &str = "Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 \
        -1.198459927713e-02 -7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 \
        -5.403984729748e-02 9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 \
        -2.921968648686e-01";

    #[test]
    fn calib_reads_tr_and_r_t() {
        let text = format!("P0: 7.18 0 607 0 0 7.18 185 0 0 0 1 0\n{TR_00}\n");
        let tr = parse_calib(&text).unwrap();
        // LiDAR x (forward) is camera z.
        let x = tr.transform_vector3(DVec3::X);
        assert!((x - DVec3::Z).length() < 1e-2, "{x}");
        let raw = "R: 1 0 0 0 0 -1 0 1 0\nT: 0.1 0.2 0.3\n";
        let m = parse_calib(raw).unwrap();
        assert_eq!(m.w_axis.truncate(), DVec3::new(0.1, 0.2, 0.3));
        assert!(parse_calib("P0: 1 2 3\n").is_err());
        assert!(parse_calib("Tr: 1 0 0\n").is_err());
        assert!(parse_calib("Tr: 2 0 0 0 0 1 0 0 0 0 1 0\n").is_err());
    }

    /// A LiDAR moving along its own x (forward) with a yaw: the camera
    /// poses KITTI would store (`Tr · L · Tr^-1`) convert back exactly.
    #[test]
    fn camera_poses_convert_to_lidar_poses() {
        let tr = parse_calib(TR_00).unwrap();
        let lidar: Vec<DMat4> = (0..5)
            .map(|k| {
                DMat4::from_rotation_translation(
                    DQuat::from_rotation_z(0.1 * k as f64),
                    DVec3::new(2.0 * k as f64, 0.3 * k as f64, 0.01 * k as f64),
                )
            })
            .collect();
        let camera: Vec<DMat4> = lidar.iter().map(|l| tr * *l * tr.inverse()).collect();
        // The camera moves along its z (forward) and turns about its y.
        assert!(camera[1].w_axis.z > 1.9 && camera[1].w_axis.y.abs() < 0.1);
        for (got, want) in lidar_poses(&camera, &tr).iter().zip(&lidar) {
            assert!(got.abs_diff_eq(*want, 1e-9), "{got} {want}");
        }
    }
}
