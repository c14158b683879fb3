//! PLY files through `ply-rs-bw`: ascii and binary (little- and
//! big-endian), the `x`, `y`, `z` properties of the `vertex` element; other
//! elements (faces, edges) are read past.

use crate::cloud::Coordinates;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{Property, PropertyAccess, PropertyType, ScalarType};

/// One element of the file: the coordinates, when it is a vertex.
#[derive(Default)]
struct Vertex {
    xyz: [Option<f64>; 3],
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex::default()
    }

    fn set_property(&mut self, name: &str, property: Property) {
        let slot = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return,
        };
        self.xyz[slot] = match property {
            Property::Char(v) => Some(v as f64),
            Property::UChar(v) => Some(v as f64),
            Property::Short(v) => Some(v as f64),
            Property::UShort(v) => Some(v as f64),
            Property::Int(v) => Some(v as f64),
            Property::UInt(v) => Some(v as f64),
            Property::Float(v) => Some(v as f64),
            Property::Double(v) => Some(v),
            _ => None,
        };
    }
}

/// The points of a PLY file held in `bytes`: f32 when `x`, `y` and `z`
/// are all `float`, else f64.
pub(super) fn read(bytes: &[u8]) -> Result<Coordinates, String> {
    let parser = Parser::<Vertex>::new();
    let mut cursor = std::io::Cursor::new(bytes);
    let ply = parser
        .read_ply(&mut cursor)
        .map_err(|e| format!("not a readable PLY file: {e}"))?;
    let Some(def) = ply.header.elements.get("vertex") else {
        return Err("PLY without a 'vertex' element".into());
    };
    let mut f32s = true;
    for name in ["x", "y", "z"] {
        match def.properties.get(name).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(t)) => f32s &= *t == ScalarType::Float,
            Some(PropertyType::List(..)) => {
                return Err(format!(
                    "PLY vertex property '{name}' is a list, not a number"
                ))
            }
            None => {
                let names: Vec<&str> = def.properties.keys().map(String::as_str).collect();
                return Err(format!(
                    "PLY vertex properties are {}: no '{name}' (x, y, z are needed)",
                    names.join(" ")
                ));
            }
        }
    }
    let vertices = ply.payload.get("vertex").map_or(&[][..], Vec::as_slice);
    let mut values = Vec::with_capacity(vertices.len() * 3);
    for (k, v) in vertices.iter().enumerate() {
        let [Some(x), Some(y), Some(z)] = v.xyz else {
            return Err(format!("PLY vertex {k}: no x, y, z values"));
        };
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err(format!("PLY vertex {k} has a NaN or infinite coordinate"));
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
