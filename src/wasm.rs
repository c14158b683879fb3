//! The JavaScript binding (wasm-bindgen). It only converts: JS values in
//! (validated at the boundary, errors as JS `Error`s whose message names the
//! problem), one call into the core, plain JS values and typed arrays out.
//!
//! Objects that own wasm memory ([`Scenario`](JsScenario),
//! [`Simulation`](JsSimulation)) hold their core value in an `Option`: their
//! `free()` empties it, so that a later call says the object was freed rather
//! than wasm-bindgen's bare null-pointer message. Results the caller keeps
//! (polygons, reports, meshes, scans) are plain JS objects owning their
//! typed arrays. Nothing here touches `window`: the module works in a page,
//! a Web Worker and Node.

use crate::clock;
use crate::cloud::{check_rigid, Cloud};
use crate::error::Error;
use crate::mesh;
use crate::params::Params;
use crate::primitive::Primitive;
use crate::scenario::Scenario;
use crate::sim::{Drive, DriveOptions, Layout, Scan, SensorModel};
use glam::{DMat4, DVec3};
use js_sys::{
    Array, ArrayBuffer, Float32Array, Float64Array, Function, Object, Reflect, Uint32Array,
};
use serde_json::{Map, Value};
use std::cell::{Cell, RefCell};
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

/// Every fallible export returns this: the error becomes a thrown JS `Error`.
type JsResult<T> = Result<T, JsError>;

/// Largest integer a JS number holds exactly (2^53 - 1).
const MAX_SAFE_INTEGER: f64 = 9_007_199_254_740_991.0;

fn js_err(e: Error) -> JsError {
    JsError::new(&e.to_string())
}

fn invalid(msg: impl Into<String>) -> JsError {
    JsError::new(&msg.into())
}

fn bad_option(key: &str, reason: impl Into<String>) -> Error {
    Error::BadOption {
        key: key.into(),
        reason: reason.into(),
    }
}

// ---------------------------------------------------------------------------
// Module start: the clock and the panic message.

#[wasm_bindgen]
extern "C" {
    #[wasm_bindgen(js_namespace = console, js_name = error)]
    fn console_error(message: &str);
}

thread_local! {
    /// `performance` and its `now` method, looked up once on the global
    /// object (window, worker or Node alike).
    static PERFORMANCE: RefCell<Option<(JsValue, Function)>> = const { RefCell::new(None) };
}

fn now_ms() -> f64 {
    PERFORMANCE.with(|p| {
        p.borrow()
            .as_ref()
            .and_then(|(perf, now)| now.call0(perf).ok())
            .and_then(|v| v.as_f64())
            .unwrap_or_else(js_sys::Date::now)
    })
}

#[wasm_bindgen(start, private)]
fn start() {
    let global: JsValue = js_sys::global().into();
    let perf = Reflect::get(&global, &"performance".into()).unwrap_or(JsValue::UNDEFINED);
    let now = Reflect::get(&perf, &"now".into()).unwrap_or(JsValue::UNDEFINED);
    if let Ok(now) = now.dyn_into::<Function>() {
        PERFORMANCE.with(|p| *p.borrow_mut() = Some((perf, now)));
    }
    clock::install(now_ms);
    // Input is validated at the boundary and the core is meant to be total,
    // so a panic is a bug: say so on the console before the instance traps.
    std::panic::set_hook(Box::new(|info| {
        console_error(&format!(
            "polyscene: internal error, please report it with the input that caused it: {info}"
        ));
    }));
}

// ---------------------------------------------------------------------------
// TypeScript declarations of the plain objects (they flow into the .d.ts).

#[wasm_bindgen(typescript_custom_section)]
const TS_TYPES: &'static str = r#"
/** Names of the parameter presets: the paper's GPP 1 (only large polygons, faster) and GPP 2 (small polygons too). */
export type Preset = "gpp1" | "gpp2";

/** Options of `new Scenario(options)`: the pipeline options. */
export interface ScenarioOptions extends PipelineOptions {}

/** Options of `detect(points, options)`: the pipeline options plus the point layout. */
export interface DetectOptions extends PipelineOptions {
  /** Numbers per point: 3 (x, y, z) or 4 (x, y, z, intensity). Default 3. */
  stride?: 3 | 4;
}

/** Options of `scenario.addScan(points, options)`. */
export interface ScanOptions {
  /** Numbers per point: 3 (x, y, z) or 4 (x, y, z, intensity). Default 3. */
  stride?: 3 | 4;
  /**
   * World-from-sensor rigid transform: 16 numbers, column-major (three.js
   * `Matrix4.elements` order), or an object with such an `elements` array.
   * Default identity.
   */
  pose?: Float64Array | Float32Array | number[] | { elements: ArrayLike<number> };
}

/** Options of `simulate(options)`. */
export interface SimulateOptions {
  /** Scene layout. Default "street". */
  layout?: "street" | "crossing";
  /** Seed of the scene and of the sensor noise. Default 1. Integer in [0, 2^53). */
  seed?: number;
  /** Distance driven between scans (m). Default 1.0 (10 m/s at 10 Hz). Range [0.05, 10]. */
  step?: number;
  /** World position of the scene's origin (m), to test far-from-origin coordinates. Default [0, 0, 0]. */
  origin?: [number, number, number];
}

/** A planar polygon of the map (or of one detection). */
export interface Polygon {
  /** Stable id: kept while the polygon grows or absorbs another. */
  id: number;
  /** Unit normal [x, y, z], towards the sensor that first saw it (up for the ground). */
  normal: [number, number, number];
  /** Plane offset d in normal . x + d = 0 (m). */
  offset: number;
  /** Outline x, y, z (world, m), interleaved, counter-clockwise seen from the normal side. */
  vertices: Float64Array;
  /** Outline area (m^2). */
  area: number;
  /** Support points over all scans. */
  support: number;
  /** Support points per m^2 of outline. */
  density: number;
  /** Near-horizontal and below the sensor: road, sidewalk. */
  ground: boolean;
  /** Scan in which it was detected (0 for one-shot detection). */
  bornScan: number;
  /** Last scan in which it gained support (0 for one-shot detection). */
  lastScan: number;
}

/** What one scan did to the scenario. */
export interface ScanReport {
  /** Scan number (0 for the first). */
  scan: number;
  /** Points in the scan. */
  points: number;
  /** Points taken by the expansion of existing polygons. */
  explainedByExpansion: number;
  /** Points given to detection (the rest). */
  sentToDetection: number;
  /** Of those, points taken by the polygons detection added. */
  explainedByDetection: number;
  /** Ids of new polygons. */
  added: number[];
  /** Ids of existing polygons that grew. */
  grown: number[];
  /** Merges made: `removed` was absorbed into `kept`. */
  merged: { kept: number; removed: number }[];
  /** Polygons after the scan. */
  polygonCount: number;
  /** Total outline area after the scan (m^2). */
  totalArea: number;
  /** Wall time per stage (ms). */
  timeMs: { expansion: number; detection: number; merge: number; total: number };
}

/** The polygons triangulated for WebGL. */
export interface Mesh {
  /** Vertex x, y, z relative to `origin` (m). */
  positions: Float32Array;
  /** Three vertex indices per triangle, counter-clockwise seen from the polygon's normal side. */
  indices: Uint32Array;
  /** Per triangle: the id of its polygon. */
  polygonIds: Uint32Array;
  /** World position the positions are relative to (m). */
  origin: [number, number, number];
}

/** One simulated scan. */
export interface SimulatedScan {
  /** Scan number. */
  index: number;
  /** x, y, z, intensity per point (sensor frame, m; intensity in [0, 1]). */
  points: Float32Array;
  /** Always 4. */
  stride: 4;
  /** World-from-sensor pose, column-major 4x4, ready for `addScan`. */
  pose: Float64Array;
  /** Per point: the id of the ground-truth polygon it lies on, or 0xFFFFFFFF (clutter). */
  labels: Uint32Array;
}

/** `simulation.next()`: the next scan, or `{ done: true }` after the last. */
export type SimulationStep = (SimulatedScan & { done: false }) | { done: true };

/** A ground-truth polygon of a simulated scene. */
export interface GroundTruthPolygon {
  /** Dense id; the point label of hits on it. */
  id: number;
  /** What the surface is. */
  kind: "road" | "sidewalk" | "curb" | "facade" | "door" | "wall" | "vehicle" | "ramp";
  /** Unit normal [x, y, z], facing the open side. */
  normal: [number, number, number];
  /** Plane offset d in normal . x + d = 0 (m). */
  offset: number;
  /** Outline x, y, z (world, m), interleaved, counter-clockwise seen from the normal side. */
  vertices: Float64Array;
  /** Area (m^2). */
  area: number;
}

/** A snapshot from `scenario.toJSON()`: plain JSON data (parameters included). */
export type ScenarioSnapshot = { params: Required<Omit<PipelineOptions, "preset">>; [key: string]: unknown };
"#;

/// `PipelineOptions`: generated by `build.rs` from `Params` and its doc
/// comments (unit and default per key).
#[wasm_bindgen(typescript_custom_section)]
const TS_PIPELINE_OPTIONS: &'static str =
    include_str!(concat!(env!("OUT_DIR"), "/pipeline_options.d.ts"));

// ---------------------------------------------------------------------------
// JS values in. Nothing here calls a JS function that can throw (a JS
// exception unwinding through wasm would leave a `&mut self` borrowed).

/// The numbers of an array-like: `Float32Array` and `Float64Array` (copied
/// in one go) or an `Array` of numbers. `None` for anything else;
/// `Some(Err(i))` when element `i` of an `Array` is not a number.
fn numbers_of(v: &JsValue) -> Option<Result<Vec<f64>, usize>> {
    if let Some(a) = v.dyn_ref::<Float64Array>() {
        return Some(Ok(a.to_vec()));
    }
    if let Some(a) = v.dyn_ref::<Float32Array>() {
        return Some(Ok(a.to_vec().into_iter().map(f64::from).collect()));
    }
    let a = v.dyn_ref::<Array>()?;
    Some(
        (0..a.length())
            .map(|i| a.get(i).as_f64().ok_or(i as usize))
            .collect(),
    )
}

/// A JS option value as JSON, for serde.
fn json_value(key: &str, v: &JsValue) -> Result<Value, Error> {
    if v.is_null() {
        return Ok(Value::Null);
    }
    if let Some(b) = v.as_bool() {
        return Ok(Value::Bool(b));
    }
    if let Some(x) = v.as_f64() {
        return json_number(key, x);
    }
    if let Some(s) = v.as_string() {
        return Ok(Value::String(s));
    }
    if let Some(nums) = numbers_of(v) {
        let nums = nums.map_err(|i| bad_option(key, format!("element {i} is not a number")))?;
        return nums
            .into_iter()
            .enumerate()
            .map(|(i, x)| {
                json_number(key, x).map_err(|_| {
                    bad_option(key, format!("element {i} must be a finite number, got {x}"))
                })
            })
            .collect::<Result<Vec<Value>, Error>>()
            .map(Value::Array);
    }
    Err(bad_option(
        key,
        format!(
            "expected a number, string, boolean or array, got {}",
            describe(v)
        ),
    ))
}

/// A finite JS number as JSON: an integer when it is one (so that integer
/// options accept `7`), a float otherwise.
fn json_number(key: &str, x: f64) -> Result<Value, Error> {
    if !x.is_finite() {
        return Err(bad_option(key, format!("must be a finite number, got {x}")));
    }
    if x.fract() == 0.0 && x.abs() <= MAX_SAFE_INTEGER {
        return Ok(if x >= 0.0 {
            Value::from(x as u64)
        } else {
            Value::from(x as i64)
        });
    }
    Ok(Value::from(x))
}

/// The own enumerable keys of an options object and their values (keys
/// whose value is `undefined` are left out). `undefined` and `null` are no
/// options.
fn option_entries(what: &str, v: &JsValue) -> Result<Vec<(String, JsValue)>, Error> {
    if v.is_undefined() || v.is_null() {
        return Ok(Vec::new());
    }
    if !v.is_object() || Array::is_array(v) || ArrayBuffer::is_view(v) {
        return Err(Error::Invalid(format!(
            "{what} must be an object of options, got {}",
            describe(v)
        )));
    }
    let obj: &Object = v.unchecked_ref();
    Ok(Object::keys(obj)
        .iter()
        .filter_map(|key| {
            let value = Reflect::get(obj, &key).unwrap_or(JsValue::UNDEFINED);
            (!value.is_undefined()).then(|| (key.as_string().unwrap_or_default(), value))
        })
        .collect())
}

/// An options object as a JSON map.
fn options_map(what: &str, v: &JsValue) -> Result<Map<String, Value>, Error> {
    // Inserted one by one: collecting into the map would sort the entries
    // first, with a sort instance of its own (kilobytes of wasm).
    let mut map = Map::new();
    for (key, value) in option_entries(what, v)? {
        let j = json_value(&key, &value)?;
        map.insert(key, j);
    }
    Ok(map)
}

/// A short description of a JS value's type, for error messages.
fn describe(v: &JsValue) -> String {
    if v.is_null() {
        return "null".into();
    }
    if v.is_undefined() {
        return "undefined".into();
    }
    if Array::is_array(v) {
        return "an Array".into();
    }
    if v.is_function() {
        return "a function".into();
    }
    if v.is_object() {
        let ctor = Reflect::get(v, &"constructor".into())
            .ok()
            .and_then(|c| Reflect::get(&c, &"name".into()).ok())
            .and_then(|n| n.as_string());
        return match ctor {
            Some(name) if !name.is_empty() => format!("a {name}"),
            _ => "an object".into(),
        };
    }
    if let Some(s) = v.as_string() {
        return format!("the string \"{s}\"");
    }
    match v.as_f64() {
        Some(x) => format!("the number {x}"),
        None => v
            .js_typeof()
            .as_string()
            .unwrap_or_else(|| "a value".into()),
    }
}

/// Take `stride` out of `map` (3 or 4), or `default`.
fn take_stride(map: &mut Map<String, Value>, default: usize) -> Result<usize, Error> {
    match map.remove("stride").map(|v| (v.as_u64(), v)) {
        None => Ok(default),
        Some((Some(s @ (3 | 4)), _)) => Ok(s as usize),
        Some((_, other)) => Err(bad_option(
            "stride",
            format!("must be 3 (x, y, z) or 4 (x, y, z, intensity), got {other}"),
        )),
    }
}

/// Interleaved points: a `Float32Array` (copied once into wasm memory), or
/// a `Float64Array` or `Array` of numbers (converted to f32).
fn points_of(v: &JsValue) -> Result<Vec<f32>, Error> {
    if let Some(a) = v.dyn_ref::<Float32Array>() {
        return Ok(a.to_vec());
    }
    match numbers_of(v) {
        Some(Ok(nums)) => Ok(nums.into_iter().map(|x| x as f32).collect()),
        Some(Err(i)) => Err(Error::Invalid(format!(
            "points: element {i} is not a number"
        ))),
        None => Err(Error::Invalid(format!(
            "points must be a Float32Array of interleaved x, y, z[, intensity] values \
             (or a Float64Array or Array of numbers), got {}",
            describe(v)
        ))),
    }
}

/// A world-from-sensor pose: 16 numbers in column-major order
/// (`Float64Array`, `Float32Array`, `Array`) or an object with such an
/// `elements` array (a three.js `Matrix4`); identity when `undefined` or
/// `null`. Checked to be rigid.
fn pose_of(v: &JsValue) -> Result<DMat4, Error> {
    const EXPECTED: &str =
        "expected 16 numbers (a column-major 4x4 matrix, three.js Matrix4.elements order)";
    if v.is_undefined() || v.is_null() {
        return Ok(DMat4::IDENTITY);
    }
    let mut raw = v.clone();
    if raw.is_object() && !Array::is_array(&raw) && !ArrayBuffer::is_view(&raw) {
        if let Ok(elements) = Reflect::get(&raw, &"elements".into()) {
            if !elements.is_undefined() {
                raw = elements;
            }
        }
    }
    let nums = match numbers_of(&raw) {
        Some(Ok(nums)) => nums,
        Some(Err(i)) => return Err(Error::BadPose(format!("element {i} is not a number"))),
        None => return Err(Error::BadPose(format!("{EXPECTED}, got {}", describe(v)))),
    };
    let Ok(cols) = <[f64; 16]>::try_from(nums.as_slice()) else {
        return Err(Error::BadPose(format!(
            "{EXPECTED}, got {} numbers",
            nums.len()
        )));
    };
    let m = DMat4::from_cols_array(&cols);
    check_rigid(&m)?;
    Ok(m)
}

// ---------------------------------------------------------------------------
// JS values out.

fn set(obj: &Object, key: &str, value: impl Into<JsValue>) {
    // Setting a property on a fresh plain object cannot fail.
    let _ = Reflect::set(obj, &key.into(), &value.into());
}

fn vec3(v: DVec3) -> Array {
    Array::of3(&v.x.into(), &v.y.into(), &v.z.into())
}

fn flat_vertices(verts: &[DVec3]) -> Float64Array {
    let flat: Vec<f64> = verts.iter().flat_map(|v| v.to_array()).collect();
    Float64Array::from(&flat[..])
}

fn polygon_object(p: &Primitive) -> Object {
    let o = Object::new();
    set(&o, "id", p.id);
    set(&o, "normal", vec3(p.plane.normal));
    set(&o, "offset", p.plane.offset);
    set(&o, "vertices", flat_vertices(&p.vertices()));
    set(&o, "area", p.area);
    set(&o, "support", p.support as f64);
    set(&o, "density", p.density());
    set(&o, "ground", p.ground);
    set(&o, "bornScan", p.born_scan as f64);
    set(&o, "lastScan", p.last_scan as f64);
    o
}

fn polygons_array(prims: &[Primitive]) -> Array {
    prims.iter().map(polygon_object).collect()
}

/// A serialisable value as a plain JS object, through JSON text (the serde
/// code is shared with snapshots, which keeps the wasm small).
fn to_js<T: serde::Serialize>(value: &T) -> JsResult<JsValue> {
    let text = serde_json::to_string(value).map_err(|e| invalid(e.to_string()))?;
    js_sys::JSON::parse(&text).map_err(|_| invalid("internal error: unparsable JSON"))
}

fn scan_object(index: usize, scan: &Scan) -> Object {
    let o = Object::new();
    set(&o, "index", index as f64);
    set(&o, "points", Float32Array::from(&scan.points[..]));
    set(&o, "stride", 4);
    set(
        &o,
        "pose",
        Float64Array::from(&scan.pose.to_cols_array()[..]),
    );
    set(&o, "labels", Uint32Array::from(&scan.labels[..]));
    o
}

// ---------------------------------------------------------------------------
// Free functions.

/// One-shot detection of planar polygons in a world-frame cloud (the paper's
/// Algorithm 1).
///
/// `points`: interleaved x, y, z[, intensity] (`options.stride`, default 3)
/// in metres, a `Float32Array` (copied once). `options`: the pipeline
/// options (`DetectOptions`); `viewpoint` is the sensor position (default
/// the origin: a scan in its own sensor frame).
///
/// Returns the polygons (plain objects owned by JS), `bornScan`/`lastScan`
/// 0. Throws an `Error` naming the problem on a length not divisible by the
/// stride, a NaN or infinite coordinate, or a bad option.
#[wasm_bindgen(unchecked_return_type = "Polygon[]")]
pub fn detect(
    #[wasm_bindgen(unchecked_param_type = "Float32Array")] points: JsValue,
    #[wasm_bindgen(unchecked_param_type = "DetectOptions")] options: Option<JsValue>,
) -> JsResult<Array> {
    let options = options.unwrap_or(JsValue::UNDEFINED);
    let mut map = options_map("detect options", &options).map_err(js_err)?;
    let stride = take_stride(&mut map, 3).map_err(js_err)?;
    let params = Params::from_options(&map).map_err(js_err)?;
    let values = points_of(&points).map_err(js_err)?;
    let cloud = Cloud::from_flat(&values, stride).map_err(js_err)?;
    let found = crate::detect::detect(&cloud, &params).map_err(js_err)?;
    Ok(polygons_array(&found.primitives))
}

/// Every option of a preset with its value (`"gpp1"` or `"gpp2"`, default
/// `"gpp2"`): the defaults `new Scenario(options)` starts from, e.g. to
/// populate a GUI.
#[wasm_bindgen(js_name = defaultOptions, unchecked_return_type = "Required<Omit<PipelineOptions, \"preset\">>")]
pub fn default_options(
    #[wasm_bindgen(unchecked_param_type = "Preset | undefined")] preset: Option<String>,
) -> JsResult<JsValue> {
    let params = Params::preset(preset.as_deref().unwrap_or("gpp2")).map_err(js_err)?;
    to_js(&params)
}

/// The crate version (semver string).
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

// ---------------------------------------------------------------------------
// Scenario.

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
    fn get(&self) -> JsResult<&Scenario> {
        self.inner.as_ref().ok_or_else(|| invalid(FREED_SCENARIO))
    }

    fn get_mut(&mut self) -> JsResult<&mut Scenario> {
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
    ) -> JsResult<JsScenario> {
        let options = options.unwrap_or(JsValue::UNDEFINED);
        let map = options_map("Scenario options", &options).map_err(js_err)?;
        let params = Params::from_options(&map).map_err(js_err)?;
        let inner = Scenario::new(params).map_err(js_err)?;
        Ok(JsScenario { inner: Some(inner) })
    }

    /// Add a scan and update the map.
    ///
    /// `points`: interleaved x, y, z[, intensity] in the sensor frame
    /// (metres), a `Float32Array` (copied once). `options.stride`: 3 or 4
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
    ) -> JsResult<JsValue> {
        let scenario = self.get_mut()?;
        let options = options.unwrap_or(JsValue::UNDEFINED);
        let mut pose = DMat4::IDENTITY;
        let mut stride = 3;
        for (key, value) in option_entries("addScan options", &options).map_err(js_err)? {
            match key.as_str() {
                "pose" => pose = pose_of(&value).map_err(js_err)?,
                "stride" => {
                    let mut m = Map::new();
                    m.insert(key.clone(), json_value(&key, &value).map_err(js_err)?);
                    stride = take_stride(&mut m, 3).map_err(js_err)?;
                }
                _ => {
                    return Err(js_err(bad_option(
                        &key,
                        "unknown option; addScan takes stride and pose",
                    )))
                }
            }
        }
        let values = points_of(&points).map_err(js_err)?;
        let report = scenario.add_scan(&values, stride, &pose).map_err(js_err)?;
        to_js(&report)
    }

    /// The polygons, sorted by id: plain objects owned by JS (see `Polygon`).
    #[wasm_bindgen(unchecked_return_type = "Polygon[]")]
    pub fn polygons(&self) -> JsResult<Array> {
        Ok(polygons_array(self.get()?.primitives()))
    }

    /// Per point of the last scan: the id of the polygon that explained it,
    /// or `0xFFFFFFFF` when none did (empty before the first scan).
    #[wasm_bindgen(js_name = lastLabels)]
    pub fn last_labels(&self) -> JsResult<Uint32Array> {
        Ok(Uint32Array::from(self.get()?.last_labels()))
    }

    /// The polygons triangulated for WebGL (constrained Delaunay inside
    /// each outline): positions relative to `origin`, triangles
    /// counter-clockwise seen from the normal side, one polygon id per
    /// triangle. Outlines that cannot be triangulated are left out.
    #[wasm_bindgen(unchecked_return_type = "Mesh")]
    pub fn mesh(&self) -> JsResult<Object> {
        let m = mesh::triangulate(self.get()?.primitives());
        let o = Object::new();
        set(&o, "positions", Float32Array::from(&m.positions[..]));
        set(&o, "indices", Uint32Array::from(&m.indices[..]));
        set(&o, "polygonIds", Uint32Array::from(&m.polygon_ids[..]));
        set(&o, "origin", vec3(m.origin));
        Ok(o)
    }

    /// Scans added so far.
    #[wasm_bindgen(getter)]
    pub fn scans(&self) -> JsResult<f64> {
        Ok(self.get()?.scans() as f64)
    }

    /// Number of polygons.
    #[wasm_bindgen(getter, js_name = polygonCount)]
    pub fn polygon_count(&self) -> JsResult<u32> {
        Ok(self.get()?.primitives().len() as u32)
    }

    /// The parameters in effect, every key (`PipelineOptions` without
    /// `preset`).
    #[wasm_bindgen(unchecked_return_type = "Required<Omit<PipelineOptions, \"preset\">>")]
    pub fn options(&self) -> JsResult<JsValue> {
        to_js(self.get()?.params())
    }

    /// The whole state as a plain JSON-safe object (parameters included):
    /// `Scenario.fromJSON(JSON.parse(JSON.stringify(snapshot)))` continues
    /// exactly as if never stopped. Called by `JSON.stringify(scenario)`.
    #[wasm_bindgen(js_name = toJSON, unchecked_return_type = "ScenarioSnapshot")]
    pub fn to_json(&self) -> JsResult<JsValue> {
        let scenario = self.get()?;
        let p = scenario.params();
        for (key, v) in [("seed", p.seed), ("maxWork", p.max_work)] {
            if v as f64 > MAX_SAFE_INTEGER {
                return Err(invalid(format!(
                    "snapshot: option '{key}' is {v}, above 2^53, which a JS number cannot hold \
                     exactly; use toJSONString()"
                )));
            }
        }
        js_sys::JSON::parse(&scenario.to_json())
            .map_err(|_| invalid("snapshot: the state could not be serialised"))
    }

    /// The snapshot as a JSON string (exact for every value).
    #[wasm_bindgen(js_name = toJSONString)]
    pub fn to_json_string(&self) -> JsResult<String> {
        Ok(self.get()?.to_json())
    }

    /// Restore a scenario from `toJSON()` output (an object, e.g. after
    /// `JSON.parse`) or `toJSONString()` output (a string). Throws when it is
    /// not a valid snapshot.
    #[wasm_bindgen(js_name = fromJSON)]
    pub fn from_json(
        #[wasm_bindgen(unchecked_param_type = "ScenarioSnapshot | string")] snapshot: JsValue,
    ) -> JsResult<JsScenario> {
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
            )));
        };
        let inner = Scenario::from_json(&text).map_err(js_err)?;
        Ok(JsScenario { inner: Some(inner) })
    }

    /// Release the wasm memory now. Later calls on this object throw an
    /// `Error` saying it was freed; calling `free()` again does nothing.
    #[wasm_bindgen(js_name = free)]
    pub fn release(&mut self) {
        self.inner = None;
    }
}

// ---------------------------------------------------------------------------
// Simulation.

const FREED_SIMULATION: &str =
    "this Simulation was freed (free() was called): its wasm memory is released; call simulate() again";

/// A drive and the position of the next scan, shared with the iterators.
struct SimState {
    drive: Drive,
    layout: Layout,
    seed: u64,
    cursor: Cell<usize>,
}

impl SimState {
    fn step(&self) -> JsResult<Object> {
        let k = self.cursor.get();
        if k >= self.drive.len() {
            let o = Object::new();
            set(&o, "done", true);
            return Ok(o);
        }
        let scan = self.drive.scan(k).map_err(js_err)?;
        self.cursor.set(k + 1);
        let o = scan_object(k, &scan);
        set(&o, "done", false);
        Ok(o)
    }
}

/// The built-in simulator: a Velodyne HDL-64E driven through a procedural
/// street at about 10 m/s, 10 scans per second, every point labelled with
/// the ground-truth polygon it lies on. Deterministic: the same options give
/// bit-identical scans natively and in wasm.
///
/// Owns wasm memory (the scene): call `free()` when done. Scans are
/// simulated on demand and returned as JS-owned typed arrays. Iterable:
/// `for (const scan of sim)` runs through the remaining scans.
#[wasm_bindgen(js_name = Simulation)]
pub struct JsSimulation {
    inner: Option<Rc<SimState>>,
}

impl JsSimulation {
    fn get(&self) -> JsResult<&Rc<SimState>> {
        self.inner.as_ref().ok_or_else(|| invalid(FREED_SIMULATION))
    }
}

/// Start a simulated drive (`SimulateOptions`: `layout` "street" or
/// "crossing", `seed`, `step` in metres, `origin`). Throws on an unknown key
/// or a bad value, naming the key.
#[wasm_bindgen]
pub fn simulate(
    #[wasm_bindgen(unchecked_param_type = "SimulateOptions")] options: Option<JsValue>,
) -> JsResult<JsSimulation> {
    let options = options.unwrap_or(JsValue::UNDEFINED);
    let mut map = options_map("simulate options", &options).map_err(js_err)?;
    let layout: Layout = match map.remove("layout") {
        None => Layout::Street,
        Some(Value::String(s)) => s.parse().map_err(js_err)?,
        Some(other) => {
            return Err(js_err(bad_option(
                "layout",
                format!("expected 'street' or 'crossing', got {other}"),
            )))
        }
    };
    let seed = match map.remove("seed") {
        None => 1,
        Some(v) => v.as_u64().ok_or_else(|| {
            js_err(bad_option(
                "seed",
                format!("expected a non-negative integer, got {v}"),
            ))
        })?,
    };
    let mut drive_options = DriveOptions::default();
    if let Some(v) = map.remove("step") {
        drive_options.step = v
            .as_f64()
            .ok_or_else(|| js_err(bad_option("step", format!("expected a number, got {v}"))))?;
    }
    if let Some(v) = map.remove("origin") {
        let o: Option<[f64; 3]> = serde_json::from_str(&v.to_string()).ok();
        drive_options.origin = DVec3::from_array(o.ok_or_else(|| {
            js_err(bad_option(
                "origin",
                format!("expected an array of 3 numbers, got {v}"),
            ))
        })?);
    }
    if let Some(key) = map.keys().next() {
        return Err(js_err(bad_option(
            key,
            "unknown option; simulate takes layout, seed, step and origin",
        )));
    }
    let drive = Drive::new(layout, seed, SensorModel::default(), drive_options).map_err(js_err)?;
    Ok(JsSimulation {
        inner: Some(Rc::new(SimState {
            drive,
            layout,
            seed,
            cursor: Cell::new(0),
        })),
    })
}

#[wasm_bindgen(js_class = Simulation)]
impl JsSimulation {
    /// Number of scans of the drive.
    #[wasm_bindgen(getter)]
    pub fn length(&self) -> JsResult<u32> {
        Ok(self.get()?.drive.len() as u32)
    }

    /// Index of the scan `next()` returns.
    #[wasm_bindgen(getter)]
    pub fn cursor(&self) -> JsResult<u32> {
        Ok(self.get()?.cursor.get() as u32)
    }

    /// The layout name.
    #[wasm_bindgen(getter)]
    pub fn layout(&self) -> JsResult<String> {
        Ok(self.get()?.layout.as_str().to_string())
    }

    /// The seed.
    #[wasm_bindgen(getter)]
    pub fn seed(&self) -> JsResult<f64> {
        Ok(self.get()?.seed as f64)
    }

    /// The next scan (`{ done: false, index, points, stride: 4, pose,
    /// labels }`), or `{ done: true }` after the last.
    #[wasm_bindgen(unchecked_return_type = "SimulationStep")]
    pub fn next(&self) -> JsResult<Object> {
        self.get()?.step()
    }

    /// Scan `index` (0 to `length - 1`), without moving the cursor.
    #[wasm_bindgen(unchecked_return_type = "SimulatedScan")]
    pub fn scan(&self, index: f64) -> JsResult<Object> {
        let state = self.get()?;
        let n = state.drive.len();
        if !(index.fract() == 0.0 && index >= 0.0 && index < n as f64) {
            return Err(js_err(bad_option(
                "scan",
                format!(
                    "index {index} is out of range: this drive has {n} scans (0 to {})",
                    n - 1
                ),
            )));
        }
        let k = index as usize;
        let scan = state.drive.scan(k).map_err(js_err)?;
        Ok(scan_object(k, &scan))
    }

    /// Move the cursor back to the first scan.
    pub fn reset(&self) -> JsResult<()> {
        self.get()?.cursor.set(0);
        Ok(())
    }

    /// The scene's ground-truth polygons (world coordinates).
    #[wasm_bindgen(js_name = groundTruth, unchecked_return_type = "GroundTruthPolygon[]")]
    pub fn ground_truth(&self) -> JsResult<Array> {
        let state = self.get()?;
        Ok(state
            .drive
            .scene()
            .polygons
            .iter()
            .map(|g| {
                let o = Object::new();
                let plane = g.polygon.plane();
                set(&o, "id", g.id);
                set(&o, "kind", g.kind.as_str());
                set(&o, "normal", vec3(plane.normal));
                set(&o, "offset", plane.offset);
                set(&o, "vertices", flat_vertices(&g.polygon.vertices()));
                set(&o, "area", g.polygon.area());
                o
            })
            .collect())
    }

    /// An iterator over the remaining scans (it advances this simulation's
    /// cursor), so that `for (const scan of sim)` works.
    #[wasm_bindgen(js_name = "[Symbol.iterator]")]
    pub fn iter(&self) -> JsResult<ScanIterator> {
        Ok(ScanIterator {
            state: Rc::clone(self.get()?),
        })
    }

    /// Release the wasm memory now (the scene). Later calls on this object
    /// throw an `Error` saying it was freed.
    #[wasm_bindgen(js_name = free)]
    pub fn release(&mut self) {
        self.inner = None;
    }
}

/// The iterator of `for (const scan of simulation)` (JS iterator protocol).
#[wasm_bindgen]
pub struct ScanIterator {
    state: Rc<SimState>,
}

#[wasm_bindgen]
impl ScanIterator {
    /// Iterators are iterable: an iterator over the same remaining scans.
    #[wasm_bindgen(js_name = "[Symbol.iterator]")]
    pub fn iter(&self) -> ScanIterator {
        ScanIterator {
            state: Rc::clone(&self.state),
        }
    }

    /// `{ value: scan, done: false }`, then `{ value: undefined, done: true }`.
    #[wasm_bindgen(unchecked_return_type = "IteratorResult<SimulatedScan>")]
    pub fn next(&self) -> JsResult<Object> {
        let step = self.state.step()?;
        let done = Reflect::get(&step, &"done".into())
            .ok()
            .and_then(|d| d.as_bool())
            .unwrap_or(true);
        let o = Object::new();
        if done {
            set(&o, "value", JsValue::UNDEFINED);
        } else {
            let _ = Reflect::delete_property(&step, &"done".into());
            set(&o, "value", step);
        }
        set(&o, "done", done);
        Ok(o)
    }
}
