//! Simulated datasets on disk, in the KITTI odometry layout plus labels and
//! ground truth:
//!
//! - `NNNNNN.bin`: scan `N` (6 digits), little-endian f32 `x, y, z,
//!   intensity` in the sensor frame;
//! - `NNNNNN.label`: one little-endian u32 label per point (polygon id or
//!   [`CLUTTER`](super::CLUTTER));
//! - `poses.txt`: one KITTI pose line per scan (world-from-sensor);
//! - `ground_truth.json`: `{"layout", "seed", "polygons": [{"id", "kind",
//!   "normal", "offset", "vertices"}]}`, world coordinates, vertices in
//!   outline order (counter-clockwise seen from the normal side),
//!   `normal · x + offset = 0`.

use super::drive::{Drive, DriveOptions};
use super::sensor::SensorModel;
use super::truth::{parse_ground_truth, GroundTruth, Layout};
use crate::error::{Error, Result};
use crate::io;
use glam::DMat4;
use std::path::{Path, PathBuf};

/// One scan of a dataset on disk.
#[derive(Clone, Debug, PartialEq)]
pub struct DatasetScan {
    /// File name of the scan (e.g. `000042.bin`).
    pub name: String,
    /// Points `x, y, z, intensity` (stride 4) in the sensor frame.
    pub points: Vec<f32>,
    /// Per-point labels, if a matching `.label` file exists.
    pub labels: Option<Vec<u32>>,
}

/// A dataset read back from disk by [`read_dataset`].
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    /// Scans sorted by file name.
    pub scans: Vec<DatasetScan>,
    /// World-from-sensor pose of each scan (same order).
    pub poses: Vec<DMat4>,
    /// The ground truth, if `ground_truth.json` exists.
    pub ground_truth: Option<GroundTruth>,
}

fn io_err(path: &Path, what: impl std::fmt::Display) -> Error {
    Error::Io(format!("{}: {what}", path.display()))
}

/// Simulate the first `scans` scans of the drive of `layout` and `seed` with
/// `sensor` (default drive options) and write them to `dir` (created if
/// missing): `NNNNNN.bin`, `NNNNNN.label`, `poses.txt`, `ground_truth.json`.
pub fn write_dataset(
    dir: &Path,
    layout: Layout,
    seed: u64,
    scans: usize,
    sensor: &SensorModel,
) -> Result<()> {
    let drive = Drive::new(layout, seed, sensor.clone(), DriveOptions::default())?;
    write_drive(dir, &drive, scans)
}

/// Write the first `scans` scans of `drive` to `dir` (see [`write_dataset`]).
pub(crate) fn write_drive(dir: &Path, drive: &Drive, scans: usize) -> Result<()> {
    if scans == 0 || scans > drive.len() {
        return Err(Error::BadOption {
            key: "scans".into(),
            reason: format!("expected 1 to {} scans, got {scans}", drive.len()),
        });
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| io_err(dir, format!("cannot create directory: {e}")))?;
    let mut poses = String::new();
    for k in 0..scans {
        let scan = drive.scan(k)?;
        io::write_bin(&dir.join(format!("{k:06}.bin")), &scan.points)?;
        io::write_labels(&dir.join(format!("{k:06}.label")), &scan.labels)?;
        poses.push_str(&io::format_pose(&scan.pose));
        poses.push('\n');
    }
    let path = dir.join("poses.txt");
    std::fs::write(&path, poses).map_err(|e| io_err(&path, format!("cannot write: {e}")))?;
    let path = dir.join("ground_truth.json");
    std::fs::write(&path, drive.scene().ground_truth_json())
        .map_err(|e| io_err(&path, format!("cannot write: {e}")))?;
    Ok(())
}

/// Read a dataset written by [`write_dataset`] (or any KITTI-style folder of
/// stride-4 `.bin` scans with a `poses.txt` of world-from-LiDAR poses):
/// scans by number, which must run 0, 1, 2, ... (a gap would shift the
/// poses; see [`io::kitti::scan_files`]),
/// their labels where a `.label` file exists, the poses (one per scan), and
/// the ground truth if `ground_truth.json` exists. Errors name the file.
pub fn read_dataset(dir: &Path) -> Result<Dataset> {
    // Numbered 0, 1, 2, ... without a gap or an empty file: line k of
    // poses.txt goes with scan k.
    let bins: Vec<(String, PathBuf)> = io::kitti::scan_files(dir, false, false)?
        .into_iter()
        .map(|s| {
            let name = s
                .path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            (name, s.path)
        })
        .collect();
    let mut scans = Vec::with_capacity(bins.len());
    for (name, path) in bins {
        let points = io::read_bin(&path, 4)?;
        let label_path = path.with_extension("label");
        let labels = if label_path.is_file() {
            let labels = io::read_labels(&label_path)?;
            if labels.len() * 4 != points.len() {
                return Err(io_err(
                    &label_path,
                    format!(
                        "{} labels for the {} points of {name}",
                        labels.len(),
                        points.len() / 4
                    ),
                ));
            }
            Some(labels)
        } else {
            None
        };
        scans.push(DatasetScan {
            name,
            points,
            labels,
        });
    }
    let path = dir.join("poses.txt");
    let text =
        std::fs::read_to_string(&path).map_err(|e| io_err(&path, format!("cannot read: {e}")))?;
    let poses = io::parse_poses(&text).map_err(|e| io_err(&path, e))?;
    if poses.len() != scans.len() {
        return Err(io_err(
            &path,
            format!("{} poses for {} scans", poses.len(), scans.len()),
        ));
    }
    let path = dir.join("ground_truth.json");
    let ground_truth = if path.is_file() {
        let text = std::fs::read_to_string(&path)
            .map_err(|e| io_err(&path, format!("cannot read: {e}")))?;
        Some(parse_ground_truth(&text).map_err(|e| io_err(&path, e))?)
    } else {
        None
    };
    Ok(Dataset {
        scans,
        poses,
        ground_truth,
    })
}
