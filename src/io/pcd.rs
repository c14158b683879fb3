//! PCD files (PCL) through `pcd-rs`: ascii, binary and binary_compressed,
//! fields `x`, `y`, `z` of any numeric type. Points whose coordinates are
//! NaN are PCL's "no return" (organized clouds, `is_dense` false) and are
//! left out; an infinite coordinate is an error.

use crate::cloud::Coordinates;
use pcd_rs::{DynReader, Field, ValueKind};

/// The first value of a field as f64.
fn value(f: &Field) -> Option<f64> {
    Some(match f {
        Field::I8(v) => *v.first()? as f64,
        Field::I16(v) => *v.first()? as f64,
        Field::I32(v) => *v.first()? as f64,
        Field::I64(v) => *v.first()? as f64,
        Field::U8(v) => *v.first()? as f64,
        Field::U16(v) => *v.first()? as f64,
        Field::U32(v) => *v.first()? as f64,
        Field::U64(v) => *v.first()? as f64,
        Field::F32(v) => *v.first()? as f64,
        Field::F64(v) => *v.first()?,
    })
}

/// The points of a PCD file held in `bytes`: f32 when `x`, `y` and `z`
/// are all F32 fields, else f64.
pub(super) fn read(bytes: &[u8]) -> Result<Coordinates, String> {
    let reader =
        DynReader::from_bytes(bytes).map_err(|e| format!("not a readable PCD file: {e}"))?;
    let meta = reader.meta().clone();
    let field = |name: &str| -> Result<usize, String> {
        let names: Vec<&str> = meta.field_defs.iter().map(|f| f.name.as_str()).collect();
        let i = names.iter().position(|&n| n == name).ok_or_else(|| {
            format!(
                "PCD fields are {}: no '{name}' (x, y, z are needed)",
                names.join(" ")
            )
        })?;
        if meta.field_defs[i].count != 1 {
            return Err(format!(
                "PCD field '{name}' has COUNT {}, expected 1",
                meta.field_defs[i].count
            ));
        }
        Ok(i)
    };
    let (ix, iy, iz) = (field("x")?, field("y")?, field("z")?);
    let f32s = [ix, iy, iz]
        .iter()
        .all(|&i| meta.field_defs[i].kind == ValueKind::F32);
    let promised = meta.num_points;
    let mut values: Vec<f64> = Vec::with_capacity((promised.min(bytes.len() as u64) as usize) * 3);
    for (k, record) in reader.enumerate() {
        let record = record.map_err(|e| {
            format!("PCD point {k} of {promised}: {e} (a truncated or damaged file?)")
        })?;
        let get = |i: usize| record.0.get(i).and_then(value);
        let (Some(x), Some(y), Some(z)) = (get(ix), get(iy), get(iz)) else {
            return Err(format!("PCD point {k}: no x, y, z values"));
        };
        if x.is_nan() || y.is_nan() || z.is_nan() {
            continue;
        }
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err(format!("PCD point {k} has an infinite coordinate"));
        }
        values.extend([x, y, z]);
    }
    Ok(if f32s {
        // Exact: every value came from an f32.
        Coordinates::F32(values.into_iter().map(|v| v as f32).collect())
    } else {
        Coordinates::F64(values)
    })
}
