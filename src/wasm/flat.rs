//! Columnar polygons for JS: `scenario.polygonsFlat()` and `detectFlat`.
//! The core builds the columns ([`crate::flat::flatten`]); this file only
//! copies each into a typed array.

use super::convert::{detect_input, set};
use super::error::WasmResult;
use super::scenario::JsScenario;
use crate::flat::{flatten, FlatPolygons};
use crate::primitive::Primitive;
use js_sys::{Float64Array, Object, Uint32Array, Uint8Array};
use wasm_bindgen::prelude::*;

/// Polygons as columns, one row per polygon, ready for deck.gl binary attributes (`startIndices` = `ringOffsets`, `getPolygon` = `positions` with size 3) or GeoArrow-style columns. Rings are open (the first vertex is not repeated).
pub struct FlatPolygonsView {
    /// Vertex x, y, z (world, m), polygon after polygon, each ring counter-clockwise seen from the normal side.
    pub positions: Float64Array,
    /// n + 1 vertex offsets: polygon i is vertices ringOffsets[i] .. ringOffsets[i + 1] (multiply by 3 for positions); starts with 0.
    pub ring_offsets: Uint32Array,
    /// Per polygon: its stable id (as `Polygon.id`).
    pub ids: Uint32Array,
    /// Per polygon: unit normal x, y, z.
    pub normals: Float64Array,
    /// Per polygon: outline area (m^2).
    pub areas: Float64Array,
    /// Per polygon: 0 ground (road, sidewalk), 1 wall (not ground, normal within 20 degrees of horizontal), 2 other.
    pub kinds: Uint8Array,
}

impl FlatPolygonsView {
    fn of(f: &FlatPolygons) -> Self {
        FlatPolygonsView {
            positions: Float64Array::from(&f.positions[..]),
            ring_offsets: Uint32Array::from(&f.ring_offsets[..]),
            ids: Uint32Array::from(&f.ids[..]),
            normals: Float64Array::from(&f.normals[..]),
            areas: Float64Array::from(&f.areas[..]),
            kinds: Uint8Array::from(&f.kinds[..]),
        }
    }

    fn into_object(self) -> Object {
        let FlatPolygonsView {
            positions,
            ring_offsets,
            ids,
            normals,
            areas,
            kinds,
        } = self;
        let o = Object::new();
        set(&o, "positions", positions);
        set(&o, "ringOffsets", ring_offsets);
        set(&o, "ids", ids);
        set(&o, "normals", normals);
        set(&o, "areas", areas);
        set(&o, "kinds", kinds);
        o
    }
}

fn flat_object(prims: &[Primitive]) -> Object {
    FlatPolygonsView::of(&flatten(prims)).into_object()
}

#[wasm_bindgen(js_class = Scenario)]
impl JsScenario {
    /// The polygons as columns of typed arrays (see `FlatPolygons`), sorted
    /// by id: the same polygons as `polygons()`, without an object per
    /// polygon.
    #[wasm_bindgen(js_name = polygonsFlat, unchecked_return_type = "FlatPolygons")]
    pub fn polygons_flat(&self) -> WasmResult<Object> {
        Ok(flat_object(self.get()?.primitives()))
    }
}

/// One-shot detection, as `detect`, with the polygons as columns of typed
/// arrays (see `FlatPolygons`). Same arguments and errors as `detect`.
#[wasm_bindgen(js_name = detectFlat, unchecked_return_type = "FlatPolygons")]
pub fn detect_flat(
    #[wasm_bindgen(unchecked_param_type = "Float32Array | Float64Array")] points: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "DetectOptions")] options: Option<JsValue>,
) -> WasmResult<Object> {
    let (cloud, params, viewpoints) =
        detect_input(&points, &options.unwrap_or(JsValue::UNDEFINED))?;
    let found = crate::detect::detect_from(&cloud, &params, &viewpoints)?;
    Ok(flat_object(&found.primitives))
}
