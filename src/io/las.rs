//! LAS and LAZ files through the `las` crate (with `laz`): the scaled
//! integer coordinates become f64 (`x * scale + offset`), read in chunks so
//! that a header promising more points than the file holds costs nothing.

use crate::cloud::Coordinates;

/// Points read a chunk at a time.
const CHUNK: u64 = 1 << 20;

/// The points of a LAS/LAZ file held in `bytes`, as f64 `x, y, z`.
pub(super) fn read(bytes: Vec<u8>) -> Result<Coordinates, String> {
    let size = bytes.len();
    let mut reader = las::Reader::new(std::io::Cursor::new(bytes))
        .map_err(|e| format!("not a readable LAS/LAZ file: {e}"))?;
    let header = reader.header();
    let promised = header.number_of_points();
    let kind = if header.point_format().is_compressed {
        "LAZ"
    } else {
        "LAS"
    };
    // No more than the file could hold uncompressed, whatever it promises.
    let mut values = Vec::with_capacity((promised.min(size as u64) as usize).saturating_mul(3));
    loop {
        let chunk = reader.read_points(CHUNK).map_err(|e| {
            format!(
                "{kind} point {} of {promised}: {e} (a truncated or damaged file?)",
                values.len() / 3
            )
        })?;
        if chunk.is_empty() {
            break;
        }
        for ((x, y), z) in chunk.x().zip(chunk.y()).zip(chunk.z()) {
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                return Err(format!(
                    "{kind} point {} has a NaN or infinite coordinate (scale or offset?)",
                    values.len() / 3
                ));
            }
            values.extend([x, y, z]);
        }
    }
    if (values.len() / 3) as u64 != promised {
        return Err(format!(
            "the {kind} header promises {promised} points, the file holds {}",
            values.len() / 3
        ));
    }
    Ok(Coordinates::F64(values))
}
