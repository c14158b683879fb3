//! Point files of any format the command line reads, told by their header.

use crate::cloud::{Cloud, Coordinates};
use crate::error::{Error, Result};
use glam::DVec3;
use std::path::Path;

/// A point file's format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// ASPRS LAS, or LAZ (its compressed form): magic `LASF`. Coordinates
    /// are scaled integers, read as f64.
    Las,
    /// PCL's PCD (ascii, binary, binary_compressed): a first line `# .PCD`
    /// or `VERSION` after `#` comment lines. Fields `x`, `y`, `z` (f32
    /// stays f32; f64 and integers are f64).
    Pcd,
    /// PLY (ascii, binary little- or big-endian): a first line `ply`.
    /// Properties `x`, `y`, `z` of the `vertex` element (float stays f32;
    /// double and integers are f64).
    Ply,
    /// No header: little-endian float32, `stride` values a point (KITTI's
    /// `.bin` is stride 4: x, y, z, reflectance).
    Raw,
}

impl Format {
    /// The format of a file that begins with `head` (its first bytes; 512
    /// are plenty). A file of no known header is [`Format::Raw`]; the
    /// headers of formats not read here (gzip, zip, HDF5, NumPy, E57) and
    /// text (an ASCII XYZ or CSV file, say) are an error saying what the
    /// file looks like, so that no header is ever read as points.
    pub fn sniff(head: &[u8]) -> std::result::Result<Format, String> {
        if head.starts_with(b"LASF") {
            return Ok(Format::Las);
        }
        if head.starts_with(b"ply\n") || head.starts_with(b"ply\r") {
            return Ok(Format::Ply);
        }
        if is_pcd(head) {
            return Ok(Format::Pcd);
        }
        let known: [(&[u8], &str); 6] = [
            (b"\x1f\x8b", "a gzip-compressed file: decompress it first"),
            (b"PK\x03\x04", "a zip archive: unpack it first"),
            (b"\x89HDF", "an HDF5 file, which polyscene does not read"),
            (
                b"\x93NUMPY",
                "a NumPy .npy file, which polyscene does not read",
            ),
            (b"ASTM-E57", "an E57 file, which polyscene does not read"),
            (
                b"\x28\xb5\x2f\xfd",
                "a zstd-compressed file: decompress it first",
            ),
        ];
        for (magic, what) in known {
            if head.starts_with(magic) {
                return Err(what.to_string());
            }
        }
        let text = |b: &u8| matches!(b, b'\t' | b'\n' | b'\r' | 0x20..=0x7e);
        if head.len() >= 4 && head.iter().take(512).all(text) {
            return Err(
                "a text file (ASCII XYZ or CSV?), which polyscene does not read: \
                        write the points as PLY, PCD or LAS, or as raw float32"
                    .to_string(),
            );
        }
        Ok(Format::Raw)
    }

    /// The format's name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Las => "LAS/LAZ",
            Format::Pcd => "PCD",
            Format::Ply => "PLY",
            Format::Raw => "raw float32",
        }
    }
}

/// A PCD header: `# .PCD` first, or `VERSION` as the first line that is
/// not a `#` comment.
fn is_pcd(head: &[u8]) -> bool {
    if head.starts_with(b"# .PCD") {
        return true;
    }
    let mut rest = head;
    while rest.first() == Some(&b'#') {
        match rest.iter().position(|&b| b == b'\n') {
            Some(i) => rest = &rest[i + 1..],
            None => return false,
        }
    }
    rest.starts_with(b"VERSION")
}

/// The points of a file.
#[derive(Clone, Debug, PartialEq)]
pub struct PointFile {
    /// Its format.
    pub format: Format,
    /// Values per point in `coordinates`: 3 for the formats with a header
    /// (`x, y, z`), the given stride for raw files.
    pub stride: usize,
    /// The coordinates, f32 or f64 as the file holds them.
    pub coordinates: Coordinates,
}

impl PointFile {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.coordinates.len() / self.stride
    }

    /// No points?
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The world-frame cloud (see [`Coordinates::cloud`]).
    pub fn cloud(&self) -> Result<Cloud> {
        self.coordinates.cloud(self.stride)
    }

    /// Every point's `x, y, z` in f64.
    pub fn world_points(&self) -> Vec<DVec3> {
        (0..self.len())
            .filter_map(|i| self.coordinates.point(self.stride, i))
            .collect()
    }
}

/// Read the points of `path`: LAS/LAZ, PCD or PLY by their header, or raw
/// little-endian float32 when no header is recognised, with `raw_stride`
/// values a point (3 or 4; `None` makes a raw file an error that asks for
/// it). Errors name the file and the problem: unreadable, empty (0 bytes),
/// a header of another format, a size that is not a whole number of
/// points, NaN or infinite values, a format without `x, y, z`.
pub fn read_points(path: &Path, raw_stride: Option<usize>) -> Result<PointFile> {
    let named = |what: String| Error::Io(format!("{}: {what}", path.display()));
    let bytes = std::fs::read(path)
        .map_err(|e| Error::Io(format!("cannot read {}: {e}", path.display())))?;
    if bytes.is_empty() {
        return Err(named("empty file (0 bytes): no points".into()));
    }
    let format = Format::sniff(&bytes[..bytes.len().min(512)]).map_err(named)?;
    let (stride, coordinates) = match format {
        Format::Las => (3, super::las::read(bytes).map_err(named)?),
        Format::Pcd => (3, super::pcd::read(&bytes).map_err(named)?),
        Format::Ply => (3, super::ply::read(&bytes).map_err(named)?),
        Format::Raw => {
            let Some(stride) = raw_stride else {
                return Err(named(format!(
                    "no LAS/LAZ, PCD or PLY header, so raw little-endian float32 \
                     ({} bytes); say how many values a point has: --stride 4 (x, y, z, \
                     intensity, as KITTI .bin) or --stride 3",
                    bytes.len()
                )));
            };
            let values = super::decode_f32(&bytes, stride).map_err(|e| named(e.to_string()))?;
            (stride, Coordinates::F32(values))
        }
    };
    if format != Format::Raw {
        // The readers give finite x, y, z triples.
        debug_assert_eq!(coordinates.len() % 3, 0);
    }
    Ok(PointFile {
        format,
        stride,
        coordinates,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_are_told_apart_and_never_raw() {
        assert_eq!(Format::sniff(b"LASF\x00\x00"), Ok(Format::Las));
        assert_eq!(Format::sniff(b"ply\nformat ascii 1.0\n"), Ok(Format::Ply));
        assert_eq!(Format::sniff(b"ply\r\nformat"), Ok(Format::Ply));
        assert_eq!(
            Format::sniff(b"# .PCD v0.7 - Point Cloud Data\nVERSION 0.7\n"),
            Ok(Format::Pcd)
        );
        assert_eq!(
            Format::sniff(b"VERSION .7\nFIELDS x y z\n"),
            Ok(Format::Pcd)
        );
        assert_eq!(
            Format::sniff(b"# made by hand\n# twice\nVERSION 0.7\n"),
            Ok(Format::Pcd)
        );
        assert!(Format::sniff(b"\x1f\x8b\x08\x00")
            .unwrap_err()
            .contains("gzip"));
        let text = Format::sniff(b"1.0 2.0 3.0\n4.0 5.0 6.0\n").unwrap_err();
        assert!(text.contains("text"), "{text}");
        // Floats are raw (the bytes of 1.5, -2.25, 0.0, 7.0).
        let raw: Vec<u8> = [1.5f32, -2.25, 0.0, 7.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(Format::sniff(&raw), Ok(Format::Raw));
        // "plyx" is not a PLY header.
        assert_eq!(Format::sniff(b"plyx\x00\x00\x00\x00"), Ok(Format::Raw));
    }
}
