//! The `Scenario` class: the live map, one scan at a time.

use super::convert::{
    finite_number, mesh_object, points_of, polygons_array, to_js, ScanOptions, ScenarioOptions,
    MAX_SAFE_INTEGER,
};
use super::error::{invalid, Failure, WasmResult};
use super::js::{self, describe};
use crate::cloud::Coordinates;
use crate::mesh;
use crate::scenario::{Scenario, MAX_SNAPSHOT_BYTES};
use js_sys::{Array, JsString, Object, Uint32Array};
use serde_json::Value;
use std::cell::{Ref, RefCell, RefMut};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

const FREED_SCENARIO: &str =
    "this Scenario was freed (free() was called): its wasm memory is released; create a new one";
const BUSY_SCENARIO: &str =
    "this Scenario is busy: a call on it has not returned yet (a callback re-entered it)";

/// The live map: scans arrive one at a time and update a list of planar
/// polygons (the paper's Algorithm 2: expansion of existing polygons,
/// detection on what is left, merging).
///
/// Owns wasm memory: call `free()` when done (or rely on garbage
/// collection). Every result it returns is a plain JS value owned by JS.
/// `JSON.stringify(scenario)` gives its snapshot (through `toJSON()`).
///
/// Every method takes `&self` and reads and checks all its arguments
/// before it borrows the core scenario: the arguments' getters and Proxy
/// traps may call back into this object (even `free()` it), and a failed
/// call leaves the scenario exactly as it was.
#[wasm_bindgen(js_name = Scenario)]
pub struct JsScenario {
    inner: RefCell<Option<Scenario>>,
}

impl JsScenario {
    fn of(scenario: Scenario) -> JsScenario {
        JsScenario {
            inner: RefCell::new(Some(scenario)),
        }
    }

    /// The scenario, or an `Error` when it was freed or is busy.
    pub(super) fn get(&self) -> WasmResult<Ref<'_, Scenario>> {
        let inner = self.inner.try_borrow().map_err(|_| busy())?;
        Ref::filter_map(inner, Option::as_ref).map_err(|_| freed())
    }

    /// The scenario, mutable.
    fn get_mut(&self) -> WasmResult<RefMut<'_, Scenario>> {
        let inner = self.inner.try_borrow_mut().map_err(|_| busy())?;
        RefMut::filter_map(inner, Option::as_mut).map_err(|_| freed())
    }
}

#[cold]
#[inline(never)]
fn freed() -> Failure {
    Failure::new(FREED_SCENARIO)
}

#[cold]
#[inline(never)]
fn busy() -> Failure {
    Failure::new(BUSY_SCENARIO)
}

#[wasm_bindgen(js_class = Scenario)]
impl JsScenario {
    /// An empty scenario. `options`: the pipeline options
    /// (`ScenarioOptions`), merged over the preset (default `"gpp2"`).
    /// Throws on an unknown key or a bad value, naming the key.
    #[wasm_bindgen(constructor)]
    pub fn new(
        #[wasm_bindgen(unchecked_optional_param_type = "ScenarioOptions")] options: Option<JsValue>,
    ) -> WasmResult<JsScenario> {
        let options = ScenarioOptions::from_js(&options.unwrap_or(JsValue::UNDEFINED))?;
        Ok(JsScenario::of(Scenario::new(options.params)?))
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
    /// or not rigid, a point beyond 1e9 m after the pose, more than
    /// 2^24 points, an unknown option, a detached buffer; the scenario is
    /// unchanged then.
    #[wasm_bindgen(js_name = addScan, unchecked_return_type = "ScanReport")]
    pub fn add_scan(
        &self,
        #[wasm_bindgen(unchecked_param_type = "Float32Array | Float64Array")] points: JsValue,
        #[wasm_bindgen(unchecked_optional_param_type = "ScanOptions")] options: Option<JsValue>,
    ) -> WasmResult<JsValue> {
        let options = ScanOptions::from_js(&options.unwrap_or(JsValue::UNDEFINED))?;
        let (values, stride) = points_of(&points, options.stride)?;
        let mut scenario = self.get_mut()?;
        let report = match &values {
            Coordinates::F32(v) => scenario.add_scan(v, stride, &options.pose)?,
            Coordinates::F64(v) => scenario.add_scan_f64(v, stride, &options.pose)?,
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
        let text = {
            let scenario = self.get()?;
            let p = scenario.params();
            for (key, v) in [("seed", p.seed), ("maxWork", p.max_work)] {
                if v as f64 > MAX_SAFE_INTEGER {
                    return Err(invalid(format!(
                        "snapshot: option '{key}' is {v}, 2^53 or more, which a JS number \
                         cannot hold exactly; toJSONString() keeps it, for Scenario::from_json \
                         in Rust (fromJSON refuses it)"
                    ))
                    .into());
                }
            }
            scenario.to_json()
        };
        js_sys::JSON::parse(&text)
            .map_err(|_| Failure::new("snapshot: the state could not be serialised"))
    }

    /// The snapshot as a JSON string (exact for every value).
    #[wasm_bindgen(js_name = toJSONString)]
    pub fn to_json_string(&self) -> WasmResult<String> {
        Ok(self.get()?.to_json())
    }

    /// Restore a scenario from `toJSON()` output (an object, e.g. after
    /// `JSON.parse`) or `toJSONString()` output (a string). Throws when it is
    /// not a valid snapshot (see `Scenario::from_json` in the Rust docs for
    /// what is checked) or its JSON text is longer than 2^28 characters.
    /// The text is read by `JSON.parse` (an object is first written by
    /// `JSON.stringify`, as `JSON.stringify(scenario)` would), so a `seed`
    /// or `maxWork` of 2^53 or more, which only Rust can give, is refused.
    /// A little laxer than `Scenario::from_json` in Rust: an integer may be
    /// written as a float (`1.0`), and of two equal keys the last counts.
    #[wasm_bindgen(js_name = fromJSON)]
    pub fn from_json(
        #[wasm_bindgen(unchecked_param_type = "ScenarioSnapshot | string")] snapshot: JsValue,
    ) -> WasmResult<JsScenario> {
        let array =
            js::is_array(&snapshot).map_err(|e| Failure::thrown("reading the snapshot", e))?;
        let json = if snapshot.is_string() {
            snapshot.clone()
        } else if snapshot.is_object() && !array {
            js_sys::JSON::stringify(&snapshot)
                .map_err(|e| Failure::thrown("not a polyscene snapshot: JSON.stringify of it", e))?
                .into()
        } else {
            return Err(invalid(format!(
                "not a polyscene snapshot: expected the object from toJSON() or its JSON string, \
                 got {}",
                describe(&snapshot)
            ))
            .into());
        };
        match json.dyn_ref::<JsString>().filter(|_| json.is_string()) {
            Some(s) if s.length() as usize <= MAX_SNAPSHOT_BYTES => {}
            Some(s) => {
                return Err(invalid(format!(
                    "not a polyscene snapshot: its JSON text has {} characters, more than the \
                     {MAX_SNAPSHOT_BYTES} a snapshot may have",
                    s.length()
                ))
                .into())
            }
            None => {
                return Err(
                    invalid("not a polyscene snapshot: it cannot be turned into JSON").into(),
                )
            }
        }
        // Counted in a copy of the text before `JSON.parse` builds them in
        // JS: every value but the first follows a ',', '[' or ':', every
        // object starts at a '{' (upper bounds: a string may hold them too).
        let (mut values, mut objects) = (1, 0);
        for b in json.as_string().unwrap_or_default().bytes() {
            match b {
                b',' | b'[' | b':' => values += 1,
                b'{' => objects += 1,
                _ => {}
            }
        }
        for (count, most, what) in [
            (
                values,
                MAX_SNAPSHOT_VALUES,
                "values (numbers, strings, arrays, objects)",
            ),
            (objects, MAX_SNAPSHOT_OBJECTS, "objects"),
        ] {
            if count > most {
                return Err(invalid(format!(
                    "not a polyscene snapshot: it holds more than the {most} {what} a snapshot \
                     may have"
                ))
                .into());
            }
        }
        let parsed = js::parse(&json)
            .map_err(|e| Failure::thrown("not a polyscene snapshot: JSON.parse of it", e))?;
        let value = parsed_json(&parsed, 0)
            .map_err(|e| invalid(format!("not a polyscene snapshot: {e}")))?;
        Ok(JsScenario::of(Scenario::from_json_value(value)?))
    }

    /// Release the wasm memory now. Later calls on this object throw an
    /// `Error` saying it was freed; calling `free()` again does nothing.
    #[wasm_bindgen(js_name = free)]
    pub fn release(&self) -> WasmResult<()> {
        *self.inner.try_borrow_mut().map_err(|_| busy())? = None;
        Ok(())
    }
}

/// Deepest nesting [`parsed_json`] follows (a snapshot's is 5).
const MAX_DEPTH: u32 = 32;

/// Most values (numbers, strings, arrays, objects) a snapshot may hold:
/// `JSON.parse` builds them all in JS, and each becomes a JSON value in
/// wasm memory: 24 bytes in its array or object, and an array's own list,
/// an object's map, a string's characters (a 10,000-scan drive's snapshot
/// holds about 6 million).
const MAX_SNAPSHOT_VALUES: usize = 1 << 24;

/// Most objects a snapshot may hold: a JSON object with members takes
/// some 450 bytes of wasm memory (a snapshot holds five a polygon and
/// about 1-2 kB of text per polygon, so this refuses one of more than
/// about 200,000 polygons; a 10,000-scan drive's holds 15,000).
const MAX_SNAPSHOT_OBJECTS: usize = 1 << 20;

/// What `JSON.parse` returned, as a JSON value: plain data, so reading it
/// runs no user code. A number stays the double JS holds (so `toJSONString`
/// output restores exactly, the sign of zeros included), as an integer when
/// it is one below 2^53 (so that integer fields read it).
fn parsed_json(v: &JsValue, depth: u32) -> Result<Value, String> {
    if depth > MAX_DEPTH {
        return Err(format!("nested more than {MAX_DEPTH} deep"));
    }
    if let Some(x) = v.as_f64() {
        return number(x);
    }
    if let Some(b) = v.as_bool() {
        return Ok(Value::Bool(b));
    }
    if let Some(s) = v.as_string() {
        return printable(s).map(Value::String);
    }
    let thrown = |e: JsValue| format!("reading it threw {}", describe(&e));
    if js::is_array(v).map_err(thrown)? {
        let n = js::get(v, "length")
            .map_err(thrown)?
            .as_f64()
            .unwrap_or(0.0) as u32;
        // Most of a snapshot is arrays of numbers: those cross in bulk.
        if let Some(xs) = js::finite_numbers(v, n as usize).map_err(thrown)? {
            let mut out = Vec::with_capacity(xs.len());
            for x in xs {
                out.push(number(x)?);
            }
            return Ok(Value::Array(out));
        }
        let mut out = Vec::with_capacity(n as usize);
        for i in 0..n {
            out.push(parsed_json(
                &js::get_index(v, i).map_err(thrown)?,
                depth + 1,
            )?);
        }
        return Ok(Value::Array(out));
    }
    if v.is_object() {
        let mut out = serde_json::Map::new();
        for key in js::keys(v).map_err(thrown)? {
            let item = js::get_key(v, &key).map_err(thrown)?;
            out.insert(
                printable(key.as_string().unwrap_or_default())?,
                parsed_json(&item, depth + 1)?,
            );
        }
        return Ok(Value::Object(out));
    }
    Ok(Value::Null)
}

/// A snapshot's string (hex digits, option names and values): refused
/// unless printable ASCII. serde's messages quote a string of the wrong
/// type escaped, up to ten bytes a character, which for one of 2^28
/// characters outgrew what wasm memory can hold.
fn printable(s: String) -> Result<String, String> {
    if s.bytes().all(|b| (b' '..=b'~').contains(&b)) {
        Ok(s)
    } else {
        Err("a string holds a character other than printable ASCII".into())
    }
}

/// A JS number as JSON ([`finite_number`]); refused when not finite
/// (`JSON.parse` reads `1e999` as Infinity), as serde refuses it in text.
fn number(x: f64) -> Result<Value, String> {
    if !x.is_finite() {
        return Err(
            "a number is out of range (JSON.parse reads one beyond 1.8e308 as Infinity)".into(),
        );
    }
    Ok(finite_number(x))
}
