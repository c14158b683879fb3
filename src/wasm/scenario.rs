//! The `Scenario` class: the live map, one scan at a time.

use super::convert::{
    describe, mesh_object, points_of, polygons_array, to_js, ScanOptions, ScenarioOptions,
    MAX_SAFE_INTEGER,
};
use super::error::{invalid, WasmResult};
use crate::cloud::Coordinates;
use crate::error::Result;
use crate::mesh;
use crate::scenario::Scenario;
use js_sys::{Array, Object, Uint32Array};
use wasm_bindgen::prelude::*;

const FREED_SCENARIO: &str =
    "this Scenario was freed (free() was called): its wasm memory is released; create a new one";

/// The live map: scans arrive one at a time and update a list of planar
/// polygons (the paper's Algorithm 2: expansion of existing polygons,
/// detection on what is left, merging).
///
/// Owns wasm memory: call `free()` when done (or rely on garbage
/// collection). Every result it returns is a plain JS value owned by JS.
/// `JSON.stringify(scenario)` gives its snapshot (through `toJSON()`).
#[wasm_bindgen(js_name = Scenario)]
pub struct JsScenario {
    inner: Option<Scenario>,
}

impl JsScenario {
    fn get(&self) -> Result<&Scenario> {
        self.inner.as_ref().ok_or_else(|| invalid(FREED_SCENARIO))
    }

    fn get_mut(&mut self) -> Result<&mut Scenario> {
        self.inner.as_mut().ok_or_else(|| invalid(FREED_SCENARIO))
    }
}

#[wasm_bindgen(js_class = Scenario)]
impl JsScenario {
    /// An empty scenario. `options`: the pipeline options
    /// (`ScenarioOptions`), merged over the preset (default `"gpp2"`).
    /// Throws on an unknown key or a bad value, naming the key.
    #[wasm_bindgen(constructor)]
    pub fn new(
        #[wasm_bindgen(unchecked_param_type = "ScenarioOptions")] options: Option<JsValue>,
    ) -> WasmResult<JsScenario> {
        let options = ScenarioOptions::from_js(&options.unwrap_or(JsValue::UNDEFINED))?;
        let inner = Scenario::new(options.params)?;
        Ok(JsScenario { inner: Some(inner) })
    }

    /// Add a scan and update the map.
    ///
    /// `points`: interleaved x, y, z[, intensity] in the sensor frame
    /// (metres), a `Float32Array` (copied once; within 1e5 m of the sensor)
    /// or a `Float64Array` (kept in f64: map coordinates, e.g. with the
    /// identity pose). `options.stride`: 3 or 4
    /// (default 3). `options.pose`: world-from-sensor rigid transform, 16
    /// numbers column-major (three.js `Matrix4.elements` order, or a
    /// `Matrix4`), identity when omitted.
    ///
    /// Returns what the scan did. Throws on a length not divisible by the
    /// stride, a NaN or infinite coordinate, a pose that is not 16 numbers
    /// or not rigid, an unknown option; the scenario is unchanged then.
    #[wasm_bindgen(js_name = addScan, unchecked_return_type = "ScanReport")]
    pub fn add_scan(
        &mut self,
        #[wasm_bindgen(unchecked_param_type = "Float32Array")] points: JsValue,
        #[wasm_bindgen(unchecked_param_type = "ScanOptions")] options: Option<JsValue>,
    ) -> WasmResult<JsValue> {
        let scenario = self.get_mut()?;
        let options = ScanOptions::from_js(&options.unwrap_or(JsValue::UNDEFINED))?;
        let values = points_of(&points)?;
        let report = match &values {
            Coordinates::F32(v) => scenario.add_scan(v, options.stride, &options.pose)?,
            Coordinates::F64(v) => scenario.add_scan_f64(v, options.stride, &options.pose)?,
        };
        to_js(&report)
    }

    /// The polygons, sorted by id: plain objects owned by JS (see `Polygon`).
    #[wasm_bindgen(unchecked_return_type = "Polygon[]")]
    pub fn polygons(&self) -> WasmResult<Array> {
        Ok(polygons_array(self.get()?.primitives()))
    }

    /// Per point of the last scan: the id of the polygon that explained it,
    /// or `0xFFFFFFFF` when none did (empty before the first scan).
    #[wasm_bindgen(js_name = lastLabels)]
    pub fn last_labels(&self) -> WasmResult<Uint32Array> {
        Ok(Uint32Array::from(self.get()?.last_labels()))
    }

    /// The polygons triangulated for WebGL (constrained Delaunay inside
    /// each outline): positions relative to `origin`, triangles
    /// counter-clockwise seen from the normal side, one polygon id per
    /// triangle. Outlines that cannot be triangulated are left out.
    #[wasm_bindgen(unchecked_return_type = "Mesh")]
    pub fn mesh(&self) -> WasmResult<Object> {
        Ok(mesh_object(&mesh::triangulate(self.get()?.primitives())))
    }

    /// Scans added so far.
    #[wasm_bindgen(getter)]
    pub fn scans(&self) -> WasmResult<f64> {
        Ok(self.get()?.scans() as f64)
    }

    /// Number of polygons.
    #[wasm_bindgen(getter, js_name = polygonCount)]
    pub fn polygon_count(&self) -> WasmResult<u32> {
        Ok(self.get()?.primitives().len() as u32)
    }

    /// The parameters in effect, every key (`PipelineOptions` without
    /// `preset`).
    #[wasm_bindgen(unchecked_return_type = "Required<Omit<PipelineOptions, \"preset\">>")]
    pub fn options(&self) -> WasmResult<JsValue> {
        to_js(self.get()?.params())
    }

    /// The whole state as a plain JSON-safe object (parameters included):
    /// `Scenario.fromJSON(JSON.parse(JSON.stringify(snapshot)))` continues
    /// exactly as if never stopped. Called by `JSON.stringify(scenario)`.
    #[wasm_bindgen(js_name = toJSON, unchecked_return_type = "ScenarioSnapshot")]
    pub fn to_json(&self) -> WasmResult<JsValue> {
        let scenario = self.get()?;
        let p = scenario.params();
        for (key, v) in [("seed", p.seed), ("maxWork", p.max_work)] {
            if v as f64 > MAX_SAFE_INTEGER {
                return Err(invalid(format!(
                    "snapshot: option '{key}' is {v}, above 2^53, which a JS number cannot hold \
                     exactly; use toJSONString()"
                ))
                .into());
            }
        }
        js_sys::JSON::parse(&scenario.to_json())
            .map_err(|_| JsError::new("snapshot: the state could not be serialised"))
    }

    /// The snapshot as a JSON string (exact for every value).
    #[wasm_bindgen(js_name = toJSONString)]
    pub fn to_json_string(&self) -> WasmResult<String> {
        Ok(self.get()?.to_json())
    }

    /// Restore a scenario from `toJSON()` output (an object, e.g. after
    /// `JSON.parse`) or `toJSONString()` output (a string). Throws when it is
    /// not a valid snapshot.
    #[wasm_bindgen(js_name = fromJSON)]
    pub fn from_json(
        #[wasm_bindgen(unchecked_param_type = "ScenarioSnapshot | string")] snapshot: JsValue,
    ) -> WasmResult<JsScenario> {
        let text = if let Some(s) = snapshot.as_string() {
            s
        } else if snapshot.is_object() && !Array::is_array(&snapshot) {
            js_sys::JSON::stringify(&snapshot)
                .ok()
                .and_then(|s| s.as_string())
                .ok_or_else(|| invalid("not a polyscene snapshot: it cannot be turned into JSON"))?
        } else {
            return Err(invalid(format!(
                "not a polyscene snapshot: expected the object from toJSON() or its JSON string, \
                 got {}",
                describe(&snapshot)
            ))
            .into());
        };
        let inner = Scenario::from_json(&text)?;
        Ok(JsScenario { inner: Some(inner) })
    }

    /// Release the wasm memory now. Later calls on this object throw an
    /// `Error` saying it was freed; calling `free()` again does nothing.
    #[wasm_bindgen(js_name = free)]
    pub fn release(&mut self) {
        self.inner = None;
    }
}
