//! Conversions at the boundary: JS values in (points, poses, options),
//! Rust values out (plain JS objects owning their typed arrays).
//!
//! The option objects of every call are read one way, by [`read_options`]:
//! a JS object becomes a JSON map (the pipeline options, for
//! `Params::from_options`) and the call's own keys (`stride`, `pose`, the
//! simulator's) are taken out of it in the same pass. The structs below
//! (`*Options` in, `*View` out) are what the calls read and return; `build.rs`
//! generates the `.d.ts` interfaces from them (doc comments included), so
//! their doc comments are the TypeScript documentation.
//!
//! Nothing here calls a JS function that can throw (a JS exception unwinding
//! through wasm would leave a `&mut self` borrowed).

use super::error::{bad_option, invalid, WasmResult};
use crate::cloud::check_rigid;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::params::Params;
use crate::primitive::Primitive;
use crate::sim::{DriveOptions, GtPolygon, Layout, Scan, SurfaceKind};
use glam::{DMat4, DVec3};
use js_sys::{Array, ArrayBuffer, Float32Array, Float64Array, Object, Reflect, Uint32Array, JSON};
use serde_json::{Map, Value};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

/// Largest integer a JS number holds exactly (2^53 - 1).
pub(crate) const MAX_SAFE_INTEGER: f64 = 9_007_199_254_740_991.0;

// ---------------------------------------------------------------------------
// Options in.

/// Numbers per point of a flat buffer: 3 or 4 (`3 | 4` in TypeScript).
pub type Stride = usize;

/// A world-from-sensor pose as the binding reads it (see [`pose_of`]).
pub type Pose = DMat4;

/// Options of `new Scenario(options)`: the pipeline options.
pub struct ScenarioOptions {
    /// The pipeline options (flattened: `PipelineOptions`).
    pub params: Params,
}

/// Options of `detect(points, options)`: the pipeline options plus the point layout.
pub struct DetectOptions {
    /// The pipeline options (flattened: `PipelineOptions`).
    pub params: Params,
    /// Numbers per point: 3 (x, y, z) or 4 (x, y, z, intensity). Default 3.
    pub stride: Stride,
}

/// Options of `scenario.addScan(points, options)`.
pub struct ScanOptions {
    /// Numbers per point: 3 (x, y, z) or 4 (x, y, z, intensity). Default 3.
    pub stride: Stride,
    /// World-from-sensor rigid transform: 16 numbers, column-major (three.js
    /// `Matrix4.elements` order), or an object with such an `elements` array.
    /// Default identity.
    pub pose: Pose,
}

/// Options of `simulate(options)`.
pub struct SimulateOptions {
    /// Scene layout. Default "street".
    pub layout: Layout,
    /// Seed of the scene and of the sensor noise. Default 1. Integer in [0, 2^53).
    pub seed: u64,
    /// Distance driven between scans (m). Default 1.0 (10 m/s at 10 Hz). Range [0.05, 10].
    pub step: f64,
    /// World position of the scene's origin (m), to test far-from-origin coordinates. Default [0, 0, 0].
    pub origin: DVec3,
}

/// The keys a call reads from its options object.
struct Keys {
    /// The object's name in messages ("detect options").
    what: &'static str,
    /// The call's own keys, taken out of the pipeline options: `stride`
    /// (checked as read), `pose` (read as a pose), others (left as JSON).
    own: &'static [&'static str],
    /// `None`: the pipeline options are read too (`Params::from_options`
    /// judges the other keys); `Some(reason)`: any other key is refused at
    /// once with this reason.
    closed: Option<&'static str>,
}

/// An options object as read by [`read_options`].
struct Read {
    /// The JSON values of the keys other than `stride` and `pose`.
    map: Map<String, Value>,
    /// `stride`, default 3.
    stride: Stride,
    /// `pose`, default identity.
    pose: Pose,
}

/// The one reader of option objects. `undefined` and `null` are no options;
/// anything but a plain object is refused. Keys are read in the object's
/// order (own enumerable keys; a key whose value is `undefined` is not
/// given), and the first bad one is reported: a key the call does not take,
/// a value JSON cannot hold, a bad `stride` or `pose`.
fn read_options(v: &JsValue, keys: &Keys) -> Result<Read> {
    let mut read = Read {
        map: Map::new(),
        stride: 3,
        pose: DMat4::IDENTITY,
    };
    if v.is_undefined() || v.is_null() {
        return Ok(read);
    }
    if !v.is_object() || Array::is_array(v) || ArrayBuffer::is_view(v) {
        return Err(invalid(format!(
            "{} must be an object of options, got {}",
            keys.what,
            describe(v)
        )));
    }
    let obj: &Object = v.unchecked_ref();
    for key in Object::keys(obj).iter() {
        let value = Reflect::get(obj, &key).unwrap_or(JsValue::UNDEFINED);
        if value.is_undefined() {
            continue;
        }
        let key = key.as_string().unwrap_or_default();
        let own = keys.own.contains(&key.as_str());
        if let (false, Some(reason)) = (own, keys.closed) {
            return Err(bad_option(&key, reason));
        }
        if own && key == "pose" {
            read.pose = pose_of(&value)?;
            continue;
        }
        let json = json_value(&key, &value)?;
        if own && key == "stride" {
            read.stride = match json.as_u64() {
                Some(s @ (3 | 4)) => s as usize,
                _ => {
                    return Err(bad_option(
                        "stride",
                        format!("must be 3 (x, y, z) or 4 (x, y, z, intensity), got {json}"),
                    ))
                }
            };
            continue;
        }
        // Inserted one by one: collecting into the map would sort the
        // entries first, with a sort instance of its own (kilobytes of wasm).
        read.map.insert(key, json);
    }
    Ok(read)
}

impl ScenarioOptions {
    /// Read `new Scenario(options)`'s options.
    pub(crate) fn from_js(v: &JsValue) -> Result<Self> {
        let read = read_options(
            v,
            &Keys {
                what: "Scenario options",
                own: &[],
                closed: None,
            },
        )?;
        Ok(ScenarioOptions {
            params: Params::from_options(&read.map)?,
        })
    }
}

impl DetectOptions {
    /// Read `detect(points, options)`'s options.
    pub(crate) fn from_js(v: &JsValue) -> Result<Self> {
        let read = read_options(
            v,
            &Keys {
                what: "detect options",
                own: &["stride"],
                closed: None,
            },
        )?;
        Ok(DetectOptions {
            params: Params::from_options(&read.map)?,
            stride: read.stride,
        })
    }
}

impl ScanOptions {
    /// Read `scenario.addScan(points, options)`'s options.
    pub(crate) fn from_js(v: &JsValue) -> Result<Self> {
        let read = read_options(
            v,
            &Keys {
                what: "addScan options",
                own: &["stride", "pose"],
                closed: Some("unknown option; addScan takes stride and pose"),
            },
        )?;
        Ok(ScanOptions {
            stride: read.stride,
            pose: read.pose,
        })
    }
}

impl SimulateOptions {
    /// Read `simulate(options)`'s options.
    pub(crate) fn from_js(v: &JsValue) -> Result<Self> {
        let mut map = read_options(
            v,
            &Keys {
                what: "simulate options",
                own: &["layout", "seed", "step", "origin"],
                closed: Some("unknown option; simulate takes layout, seed, step and origin"),
            },
        )?
        .map;
        let layout = match map.remove("layout") {
            None => Layout::Street,
            Some(Value::String(s)) => s.parse()?,
            Some(other) => {
                return Err(bad_option(
                    "layout",
                    format!("expected 'street' or 'crossing', got {other}"),
                ))
            }
        };
        let seed = match map.remove("seed") {
            None => 1,
            Some(v) => v.as_u64().ok_or_else(|| {
                bad_option("seed", format!("expected a non-negative integer, got {v}"))
            })?,
        };
        let defaults = DriveOptions::default();
        let step = match map.remove("step") {
            None => defaults.step,
            Some(v) => v
                .as_f64()
                .ok_or_else(|| bad_option("step", format!("expected a number, got {v}")))?,
        };
        let origin = match map.remove("origin") {
            None => defaults.origin,
            Some(v) => {
                let o: Option<[f64; 3]> = serde_json::from_str(&v.to_string()).ok();
                DVec3::from_array(o.ok_or_else(|| {
                    bad_option("origin", format!("expected an array of 3 numbers, got {v}"))
                })?)
            }
        };
        Ok(SimulateOptions {
            layout,
            seed,
            step,
            origin,
        })
    }

    /// The drive's options.
    pub(crate) fn drive(&self) -> DriveOptions {
        DriveOptions {
            step: self.step,
            origin: self.origin,
        }
    }
}

// ---------------------------------------------------------------------------
// Values in.

/// The numbers of an array-like: `Float32Array` and `Float64Array` (copied
/// in one go) or an `Array` of numbers. `None` for anything else;
/// `Some(Err(i))` when element `i` of an `Array` is not a number.
fn numbers_of(v: &JsValue) -> Option<std::result::Result<Vec<f64>, usize>> {
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
fn json_value(key: &str, v: &JsValue) -> Result<Value> {
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
        let nums = match nums {
            Ok(nums) => nums,
            Err(i) => return Err(bad_option(key, format!("element {i} is not a number"))),
        };
        let mut out = Vec::with_capacity(nums.len());
        for (i, x) in nums.into_iter().enumerate() {
            if !x.is_finite() {
                return Err(bad_option(
                    key,
                    format!("element {i} must be a finite number, got {x}"),
                ));
            }
            out.push(json_number(key, x)?);
        }
        return Ok(Value::Array(out));
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
fn json_number(key: &str, x: f64) -> Result<Value> {
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

/// A short description of a JS value's type, for error messages.
pub(crate) fn describe(v: &JsValue) -> String {
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

/// Interleaved points: a `Float32Array` (copied once into wasm memory)
/// stays f32; a `Float64Array` or `Array` of numbers stays f64, re-centred
/// in f64 by the core before anything becomes f32 (map coordinates).
pub(crate) fn points_of(v: &JsValue) -> Result<crate::cloud::Coordinates> {
    use crate::cloud::Coordinates;
    if let Some(a) = v.dyn_ref::<Float32Array>() {
        return Ok(Coordinates::F32(a.to_vec()));
    }
    match numbers_of(v) {
        Some(Ok(nums)) => Ok(Coordinates::F64(nums)),
        Some(Err(i)) => Err(invalid(format!("points: element {i} is not a number"))),
        None => Err(invalid(format!(
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
fn pose_of(v: &JsValue) -> Result<DMat4> {
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
// Values out.

/// The number `N` (a TypeScript literal type).
pub struct Exactly<const N: u32>;

impl<const N: u32> From<Exactly<N>> for JsValue {
    fn from(_: Exactly<N>) -> JsValue {
        JsValue::from(N)
    }
}

/// A planar polygon of the map (or of one detection).
pub struct PolygonView {
    /// Stable id: kept while the polygon grows or absorbs another.
    pub id: u32,
    /// Unit normal [x, y, z], towards the sensor that first saw it (up for the ground).
    pub normal: DVec3,
    /// Plane offset d in normal . x + d = 0 (m).
    pub offset: f64,
    /// Outline x, y, z (world, m), interleaved, counter-clockwise seen from the normal side.
    pub vertices: Float64Array,
    /// Outline area (m^2).
    pub area: f64,
    /// Support points over all scans.
    pub support: u64,
    /// Support points per m^2 of outline.
    pub density: f64,
    /// Near-horizontal and below the sensor: road, sidewalk.
    pub ground: bool,
    /// Scan in which it was detected (0 for one-shot detection).
    pub born_scan: u64,
    /// Last scan in which it gained support (0 for one-shot detection).
    pub last_scan: u64,
}

impl PolygonView {
    fn of(p: &Primitive) -> Self {
        PolygonView {
            id: p.id,
            normal: p.plane.normal,
            offset: p.plane.offset,
            vertices: flat_vertices(&p.vertices()),
            area: p.area,
            support: p.support,
            density: p.density(),
            ground: p.ground,
            born_scan: p.born_scan,
            last_scan: p.last_scan,
        }
    }

    fn into_object(self) -> Object {
        // Destructured, so that a new field cannot be forgotten here; the
        // keys are the fields' names in camelCase, as in the `.d.ts`.
        let PolygonView {
            id,
            normal,
            offset,
            vertices,
            area,
            support,
            density,
            ground,
            born_scan,
            last_scan,
        } = self;
        let o = Object::new();
        set(&o, "id", id);
        set(&o, "normal", vec3(normal));
        set(&o, "offset", offset);
        set(&o, "vertices", vertices);
        set(&o, "area", area);
        set(&o, "support", support as f64);
        set(&o, "density", density);
        set(&o, "ground", ground);
        set(&o, "bornScan", born_scan as f64);
        set(&o, "lastScan", last_scan as f64);
        o
    }
}

/// The polygons triangulated for WebGL.
pub struct MeshView {
    /// Vertex x, y, z relative to `origin` (m).
    pub positions: Float32Array,
    /// Three vertex indices per triangle, counter-clockwise seen from the polygon's normal side.
    pub indices: Uint32Array,
    /// Per triangle: the id of its polygon.
    pub polygon_ids: Uint32Array,
    /// World position the positions are relative to (m).
    pub origin: DVec3,
}

impl MeshView {
    fn of(m: &Mesh) -> Self {
        MeshView {
            positions: Float32Array::from(&m.positions[..]),
            indices: Uint32Array::from(&m.indices[..]),
            polygon_ids: Uint32Array::from(&m.polygon_ids[..]),
            origin: m.origin,
        }
    }

    fn into_object(self) -> Object {
        let MeshView {
            positions,
            indices,
            polygon_ids,
            origin,
        } = self;
        let o = Object::new();
        set(&o, "positions", positions);
        set(&o, "indices", indices);
        set(&o, "polygonIds", polygon_ids);
        set(&o, "origin", vec3(origin));
        o
    }
}

/// One simulated scan.
pub struct ScanView {
    /// Scan number.
    pub index: usize,
    /// x, y, z, intensity per point (sensor frame, m; intensity in [0, 1]).
    pub points: Float32Array,
    /// Always 4.
    pub stride: Exactly<4>,
    /// World-from-sensor pose, column-major 4x4, ready for `addScan`.
    pub pose: Float64Array,
    /// Per point: the id of the ground-truth polygon it lies on, or 0xFFFFFFFF (clutter).
    pub labels: Uint32Array,
}

impl ScanView {
    fn of(index: usize, scan: &Scan) -> Self {
        ScanView {
            index,
            points: Float32Array::from(&scan.points[..]),
            stride: Exactly,
            pose: Float64Array::from(&scan.pose.to_cols_array()[..]),
            labels: Uint32Array::from(&scan.labels[..]),
        }
    }

    fn into_object(self) -> Object {
        let ScanView {
            index,
            points,
            stride,
            pose,
            labels,
        } = self;
        let o = Object::new();
        set(&o, "index", index as f64);
        set(&o, "points", points);
        set(&o, "stride", stride);
        set(&o, "pose", pose);
        set(&o, "labels", labels);
        o
    }
}

/// A ground-truth polygon of a simulated scene.
pub struct GroundTruthView {
    /// Dense id; the point label of hits on it.
    pub id: u32,
    /// What the surface is.
    pub kind: SurfaceKind,
    /// Unit normal [x, y, z], facing the open side.
    pub normal: DVec3,
    /// Plane offset d in normal . x + d = 0 (m).
    pub offset: f64,
    /// Outline x, y, z (world, m), interleaved, counter-clockwise seen from the normal side.
    pub vertices: Float64Array,
    /// Area (m^2).
    pub area: f64,
}

impl GroundTruthView {
    fn of(g: &GtPolygon) -> Self {
        let plane = g.polygon.plane();
        GroundTruthView {
            id: g.id,
            kind: g.kind,
            normal: plane.normal,
            offset: plane.offset,
            vertices: flat_vertices(&g.polygon.vertices()),
            area: g.polygon.area(),
        }
    }

    fn into_object(self) -> Object {
        let GroundTruthView {
            id,
            kind,
            normal,
            offset,
            vertices,
            area,
        } = self;
        let o = Object::new();
        set(&o, "id", id);
        set(&o, "kind", kind.as_str());
        set(&o, "normal", vec3(normal));
        set(&o, "offset", offset);
        set(&o, "vertices", vertices);
        set(&o, "area", area);
        o
    }
}

/// Set a property of a fresh plain object.
pub(crate) fn set(obj: &Object, key: &str, value: impl Into<JsValue>) {
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

/// The primitives as `Polygon` objects.
pub(crate) fn polygons_array(prims: &[Primitive]) -> Array {
    prims
        .iter()
        .map(|p| PolygonView::of(p).into_object())
        .collect()
}

/// The mesh as a `Mesh` object.
pub(crate) fn mesh_object(m: &Mesh) -> Object {
    MeshView::of(m).into_object()
}

/// Scan `index` as a `SimulatedScan` object.
pub(crate) fn scan_object(index: usize, scan: &Scan) -> Object {
    ScanView::of(index, scan).into_object()
}

/// The ground-truth polygons as `GroundTruthPolygon` objects.
pub(crate) fn ground_truth_array(polygons: &[GtPolygon]) -> Array {
    polygons
        .iter()
        .map(|g| GroundTruthView::of(g).into_object())
        .collect()
}

/// A serialisable value as a plain JS object, through JSON text (the serde
/// code is shared with snapshots, which keeps the wasm small).
pub(crate) fn to_js<T: serde::Serialize>(value: &T) -> WasmResult<JsValue> {
    let text = serde_json::to_string(value)?;
    JSON::parse(&text).map_err(|_| JsError::new("internal error: unparsable JSON"))
}
