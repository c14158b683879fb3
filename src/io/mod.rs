//! Reading and writing the on-disk formats: KITTI-style `.bin` scans
//! (little-endian f32, stride 3 or 4), per-point `.label` files (little-endian
//! u32), KITTI odometry `poses.txt` (12 numbers per line: the row-major top
//! three rows of a 4x4 world-from-sensor transform) and KITTI sequences with
//! their calibration ([`kitti`]).
//!
//! Natively, [`read_points`] reads a point file of any format the command
//! line takes: LAS/LAZ (`las`), PCD (`pcd-rs`), PLY (`ply-rs-bw`), told by
//! its header ([`Format::sniff`]), or headerless little-endian float32 with
//! a stride the caller gives. These readers are not in the wasm build.

use crate::error::{Error, Result};
use glam::{DMat4, DVec3, DVec4};
use std::path::Path;

pub mod kitti;
#[cfg(not(target_arch = "wasm32"))]
mod las;
#[cfg(not(target_arch = "wasm32"))]
mod pcd;
#[cfg(not(target_arch = "wasm32"))]
mod ply;
#[cfg(not(target_arch = "wasm32"))]
mod points;

#[cfg(not(target_arch = "wasm32"))]
pub use points::{read_points, Format, PointFile};

/// Decode little-endian f32s; `stride` numbers per point. Errors on a length
/// that is not a whole number of points and on NaN or infinite coordinates.
pub fn decode_f32(bytes: &[u8], stride: usize) -> Result<Vec<f32>> {
    if stride != 3 && stride != 4 {
        return Err(Error::BadStride(stride));
    }
    if bytes.len() % (4 * stride) != 0 {
        return Err(Error::Io(format!(
            "file size {} bytes is not a multiple of {} (stride {stride} x 4-byte floats)",
            bytes.len(),
            4 * stride
        )));
    }
    let out: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    crate::cloud::check_finite(&out, stride)?;
    Ok(out)
}

/// Read a `.bin` scan (see [`decode_f32`]).
pub fn read_bin(path: &Path, stride: usize) -> Result<Vec<f32>> {
    let bytes = std::fs::read(path)
        .map_err(|e| Error::Io(format!("cannot read {}: {e}", path.display())))?;
    decode_f32(&bytes, stride).map_err(|e| Error::Io(format!("{}: {e}", path.display())))
}

/// Write f32s little-endian.
pub fn write_bin(path: &Path, values: &[f32]) -> Result<()> {
    let mut bytes = Vec::with_capacity(values.len() * 4);
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes)
        .map_err(|e| Error::Io(format!("cannot write {}: {e}", path.display())))
}

/// Read a `.label` file of little-endian u32.
pub fn read_labels(path: &Path) -> Result<Vec<u32>> {
    let bytes = std::fs::read(path)
        .map_err(|e| Error::Io(format!("cannot read {}: {e}", path.display())))?;
    if bytes.len() % 4 != 0 {
        return Err(Error::Io(format!(
            "{}: size {} is not a multiple of 4",
            path.display(),
            bytes.len()
        )));
    }
    Ok(bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// Write little-endian u32 labels.
pub fn write_labels(path: &Path, labels: &[u32]) -> Result<()> {
    let mut bytes = Vec::with_capacity(labels.len() * 4);
    for v in labels {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes)
        .map_err(|e| Error::Io(format!("cannot write {}: {e}", path.display())))
}

/// The mean position of `poses` (world-from-sensor). `None` for no poses.
/// For a cloud accumulated from them, give detection every position
/// ([`crate::detect::detect_from`]) rather than their mean as the viewpoint.
pub fn mean_position(poses: &[DMat4]) -> Option<DVec3> {
    if poses.is_empty() {
        return None;
    }
    let sum: DVec3 = poses.iter().map(|m| m.w_axis.truncate()).sum();
    Some(sum / poses.len() as f64)
}

/// Parse KITTI odometry poses: one pose per non-empty line, 12 numbers, the
/// row-major 3x4 `[R | t]` world-from-sensor. Checked to be rigid.
pub fn parse_poses(text: &str) -> Result<Vec<DMat4>> {
    let mut out = Vec::new();
    for (lineno, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let nums: std::result::Result<Vec<f64>, _> =
            line.split_whitespace().map(str::parse::<f64>).collect();
        let nums = nums.map_err(|e| {
            Error::BadPose(format!("poses line {}: not a number ({e})", lineno + 1))
        })?;
        if nums.len() != 12 {
            return Err(Error::BadPose(format!(
                "poses line {}: expected 12 numbers, found {}",
                lineno + 1,
                nums.len()
            )));
        }
        let m = DMat4::from_cols(
            DVec4::new(nums[0], nums[4], nums[8], 0.0),
            DVec4::new(nums[1], nums[5], nums[9], 0.0),
            DVec4::new(nums[2], nums[6], nums[10], 0.0),
            DVec4::new(nums[3], nums[7], nums[11], 1.0),
        );
        crate::cloud::check_rigid(&m)
            .map_err(|e| Error::BadPose(format!("poses line {}: {e}", lineno + 1)))?;
        out.push(m);
    }
    Ok(out)
}

/// One KITTI pose line (12 numbers, row-major 3x4).
pub fn format_pose(m: &DMat4) -> String {
    let r = |i: usize| m.row(i);
    let (a, b, c) = (r(0), r(1), r(2));
    format!(
        "{:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e}",
        a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, c.x, c.y, c.z, c.w
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn poses_round_trip_and_reject_non_rigid() {
        let m = DMat4::from_rotation_translation(
            glam::DQuat::from_rotation_z(0.3),
            DVec3::new(500_000.123, 4_500_000.5, 50.0),
        );
        let text = format!("{}\n\n{}\n", format_pose(&m), format_pose(&DMat4::IDENTITY));
        let back = parse_poses(&text).unwrap();
        assert_eq!(back.len(), 2);
        assert!(back[0].abs_diff_eq(m, 1e-9));
        let bad = "2 0 0 0 0 1 0 0 0 0 1 0";
        assert!(matches!(parse_poses(bad), Err(Error::BadPose(_))));
        assert!(parse_poses("1 0 0").is_err());
    }

    #[test]
    fn decode_checks_size_and_values() {
        let mut bytes = Vec::new();
        for v in [1.0f32, 2.0, 3.0, 0.5] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        assert_eq!(decode_f32(&bytes, 4).unwrap(), vec![1.0, 2.0, 3.0, 0.5]);
        assert!(decode_f32(&bytes[..12], 4).is_err());
        bytes[0..4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(matches!(
            decode_f32(&bytes, 4),
            Err(Error::NonFinite { point: 0 })
        ));
    }
}
