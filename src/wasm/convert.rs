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
//! Every read of a caller's value goes through [`super::js`], whose calls
//! cannot let a JS exception through a Rust frame; what JS code throws
//! becomes a [`Failure`] naming what was read, with the thrown value as
//! `cause`.

use super::error::{bad_option, invalid, Failure, WasmResult};
use super::js::{self, describe};
use crate::cloud::check_rigid;
use crate::error::{Error, Result};
use glam::{DMat4, DVec3};
use js_sys::{Array, ArrayBuffer, Float64Array, Object, Reflect};
use serde_json::{Map, Value};
use wasm_bindgen::prelude::*;
// What only the detection binding reads and returns (the `wasm-main` feature).
#[cfg(feature = "wasm-main")]
use crate::{
    cloud::{Cloud, Coordinates, MAX_POINTS},
    mesh::Mesh,
    params::Params,
    primitive::Primitive,
};
#[cfg(feature = "wasm-main")]
use js_sys::{Float32Array, Uint32Array, JSON};

/// Largest integer a JS number holds exactly (2^53 - 1).
pub(crate) const MAX_SAFE_INTEGER: f64 = 9_007_199_254_740_991.0;

// ---------------------------------------------------------------------------
// Options in.

/// Numbers per point of a flat buffer: 3 or 4 (`3 | 4` in TypeScript).
pub type Stride = usize;

/// A world-from-sensor pose as the binding reads it (see [`pose_of`]).
pub type Pose = DMat4;

/// Sensor positions as the binding reads them: x, y, z of each, one flat
/// `Float64Array`, `Float32Array` or `Array` of numbers.
pub type Positions = Vec<DVec3>;

#[cfg(feature = "wasm-main")]
/// Options of `new Scenario(options)`: the pipeline options.
pub struct ScenarioOptions {
    /// The pipeline options (flattened: `PipelineOptions`).
    pub params: Params,
}

#[cfg(feature = "wasm-main")]
/// Options of `detect(points, options)`: the pipeline options plus the point
/// layout and, for an accumulated cloud, its scans' sensor positions.
pub struct DetectOptions {
    /// The pipeline options (flattened: `PipelineOptions`).
    pub params: Params,
    /// Numbers per point: 3 (x, y, z) or 4 (x, y, z, intensity). Default 3,
    /// except that points `polyscene/io` or `polyscene/sim` made with 4 (a
    /// KITTI `.bin`, a simulated scan) are refused without it.
    pub stride: Option<Stride>,
    /// Sensor positions of the scans an accumulated cloud (a map, a tile)
    /// was gathered from (world, m; x, y, z of each, at most 100,000). The
    /// cloud is then seen from no single viewpoint (as a map is without
    /// them), except that a candidate whose plane passes through every one
    /// of them, away from each, is dropped as laser rings. Not with
    /// `viewpoint`. Default none.
    pub viewpoints: Positions,
}

#[cfg(feature = "wasm-main")]
/// Options of `scenario.addScan(points, options)`.
pub struct ScanOptions {
    /// Numbers per point: 3 (x, y, z) or 4 (x, y, z, intensity). Default 3,
    /// except that points `polyscene/io` or `polyscene/sim` made with 4 (a
    /// KITTI `.bin`, a simulated scan) are refused without it.
    pub stride: Option<Stride>,
    /// World-from-sensor rigid transform: 16 numbers, column-major (three.js
    /// `Matrix4.elements` order), or an object with such an `elements` array.
    /// Default identity.
    pub pose: Pose,
}

/// The keys a call reads from its options object.
pub(super) struct Keys {
    /// The object's name in messages ("detect options").
    pub(super) what: &'static str,
    /// The call's own keys, taken out of the pipeline options: `stride`
    /// (checked as read), `pose` (read as a pose), others (left as JSON).
    pub(super) own: &'static [&'static str],
    /// `None`: the pipeline options are read too (`Params::from_options`
    /// judges the other keys); `Some(reason)`: any other key is refused at
    /// once with this reason.
    pub(super) closed: Option<&'static str>,
}

/// An options object as read by [`read_options`].
pub(super) struct Read {
    /// The JSON values of the keys other than `stride` and `pose`.
    pub(super) map: Map<String, Value>,
    /// `stride`, if given.
    stride: Option<Stride>,
    /// `pose`, default identity.
    pose: Pose,
    /// `viewpoints`, default none.
    viewpoints: Positions,
}

/// Longest key or string value of an options object (UTF-16 units): the
/// longest valid one has a few dozen.
const MAX_OPTION_CHARS: u32 = 256;

/// Most numbers in an array option value (a pose has 16).
const MAX_OPTION_NUMBERS: usize = 64;

/// Most sensor positions in `viewpoints`.
const MAX_VIEWPOINTS: usize = 100_000;

/// The one reader of option objects. `undefined` and `null` are no options;
/// anything but a plain object is refused. Keys are read in the object's
/// order (own enumerable keys; a key whose value is `undefined` is not
/// given), and the first bad one is reported: a key the call does not take,
/// a value JSON cannot hold, a bad `stride` or `pose`. Whatever the object's
/// getters or Proxy traps throw becomes an `Error` naming the key, with the
/// thrown value as `cause`.
pub(super) fn read_options(v: &JsValue, keys: &Keys) -> WasmResult<Read> {
    let mut read = Read {
        map: Map::new(),
        stride: None,
        pose: DMat4::IDENTITY,
        viewpoints: Vec::new(),
    };
    if v.is_undefined() || v.is_null() {
        return Ok(read);
    }
    let what = keys.what;
    let array = js::is_array(v).map_err(|e| Failure::thrown(&format!("reading {what}"), e))?;
    if !v.is_object() || array || ArrayBuffer::is_view(v) {
        return Err(invalid(format!(
            "{what} must be an object of options, got {}",
            describe(v)
        ))
        .into());
    }
    let names =
        js::keys(v).map_err(|e| Failure::thrown(&format!("listing the keys of {what}"), e))?;
    for name in names {
        let Some(key) = js::short_string(&name, MAX_OPTION_CHARS) else {
            return Err(invalid(format!(
                "{what}: a key longer than {MAX_OPTION_CHARS} characters is no option"
            ))
            .into());
        };
        let value = js::get_key(v, &name)
            .map_err(|e| Failure::thrown(&format!("reading {what}.{key}"), e))?;
        if value.is_undefined() {
            continue;
        }
        let own = keys.own.contains(&key.as_str());
        if let (false, Some(reason)) = (own, keys.closed) {
            return Err(bad_option(&key, reason).into());
        }
        if own && key == "pose" {
            read.pose = pose_of(&value)?;
            continue;
        }
        if own && key == "viewpoints" {
            read.viewpoints = positions_of(&value)?;
            continue;
        }
        let json = json_value(&key, &value)?;
        if own && key == "stride" {
            read.stride = match json.as_u64() {
                Some(s @ (3 | 4)) => Some(s as usize),
                _ => {
                    return Err(bad_option(
                        "stride",
                        format!("must be 3 (x, y, z) or 4 (x, y, z, intensity), got {json}"),
                    )
                    .into())
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

#[cfg(feature = "wasm-main")]
impl ScenarioOptions {
    /// Read `new Scenario(options)`'s options.
    pub(crate) fn from_js(v: &JsValue) -> WasmResult<Self> {
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

#[cfg(feature = "wasm-main")]
impl DetectOptions {
    /// Read `detect(points, options)`'s options.
    pub(crate) fn from_js(v: &JsValue) -> WasmResult<Self> {
        let read = read_options(
            v,
            &Keys {
                what: "detect options",
                own: &["stride", "viewpoints"],
                closed: None,
            },
        )?;
        Ok(DetectOptions {
            params: Params::from_options(&read.map)?,
            stride: read.stride,
            viewpoints: read.viewpoints,
        })
    }
}

#[cfg(feature = "wasm-main")]
impl ScanOptions {
    /// Read `scenario.addScan(points, options)`'s options.
    pub(crate) fn from_js(v: &JsValue) -> WasmResult<Self> {
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

// ---------------------------------------------------------------------------
// Values in.

/// An element type the binding reads numbers into.
trait Number: Copy + Default {
    fn of_f64(x: f64) -> Self;
    /// Copy a real `Float32Array` or `Float64Array` of `dst.len()`
    /// elements into `dst`.
    fn copy(dst: &mut [Self], src: &JsValue) -> std::result::Result<(), js::Thrown>;
}

impl Number for f32 {
    fn of_f64(x: f64) -> f32 {
        x as f32
    }
    fn copy(dst: &mut [f32], src: &JsValue) -> std::result::Result<(), js::Thrown> {
        js::copy_f32(dst, src)
    }
}

impl Number for f64 {
    fn of_f64(x: f64) -> f64 {
        x
    }
    fn copy(dst: &mut [f64], src: &JsValue) -> std::result::Result<(), js::Thrown> {
        js::copy_f64(dst, src)
    }
}

/// Why reading an array-like failed before its elements were judged.
enum NumbersError {
    /// Not a `Float32Array`, `Float64Array` or `Array`.
    NotArray,
    /// Element `i` of an `Array` is this value, not a number.
    NotNumber(usize, JsValue),
    /// Anything else (too long, a throw, no memory): the final error.
    Failed(Failure),
}

impl From<Failure> for NumbersError {
    fn from(f: Failure) -> Self {
        NumbersError::Failed(f)
    }
}

/// An empty vector with room for `len` numbers, or an `Error` when wasm
/// memory cannot grow that far.
fn room<T>(len: usize, what: &str) -> WasmResult<Vec<T>> {
    let mut out = Vec::new();
    out.try_reserve_exact(len).map_err(|_| {
        Failure::new(format!(
            "{what}: {len} numbers do not fit in the memory left to this wasm instance"
        ))
    })?;
    Ok(out)
}

/// The numbers of a `Float32Array` or `Float64Array` (copied in one go) or
/// of an `Array` of numbers, at most `max` of them (checked before anything
/// is allocated). `what` names the value in messages ("points", "option
/// 'pose'"). A Proxy, a look-alike object or another typed array is
/// [`NumbersError::NotArray`].
fn numbers_of<T: Number>(
    v: &JsValue,
    what: &str,
    max: usize,
    check_len: &dyn Fn(usize) -> Result<()>,
) -> std::result::Result<Vec<T>, NumbersError> {
    let Some((tag, len)) = js::typed_array(v) else {
        // The slow path, shared by both element types.
        return Ok(array_numbers(v, what, max, check_len)?
            .into_iter()
            .map(T::of_f64)
            .collect());
    };
    if tag != "Float32Array" && tag != "Float64Array" {
        return Err(NumbersError::NotArray);
    }
    let len = checked_len(len as f64, what, max, check_len)?;
    let mut out = room::<T>(len, what)?;
    out.resize(len, T::default());
    T::copy(&mut out, v).map_err(|e| {
        // Only a detached buffer makes an empty view's copy throw.
        if len == 0 {
            Failure::caused(
                format!(
                    "{what}: the {tag}'s buffer is detached (it was transferred, e.g. by \
                     postMessage) and can no longer be read"
                ),
                e,
            )
        } else {
            Failure::thrown(&format!("reading {what} (a {tag})"), e)
        }
    })?;
    Ok(out)
}

/// A length within `max` and accepted by `check_len`.
fn checked_len(
    len: f64,
    what: &str,
    max: usize,
    check_len: &dyn Fn(usize) -> Result<()>,
) -> WasmResult<usize> {
    if !(len >= 0.0 && len.fract() == 0.0) {
        return Err(Failure::new(format!(
            "{what}: its length is not a whole number"
        )));
    }
    if len > max as f64 {
        return Err(Failure::new(format!(
            "{what}: {len} numbers is more than the {max} it may hold"
        )));
    }
    check_len(len as usize)?;
    Ok(len as usize)
}

/// The numbers of an `Array` (or a Proxy around one), element by element.
fn array_numbers(
    v: &JsValue,
    what: &str,
    max: usize,
    check_len: &dyn Fn(usize) -> Result<()>,
) -> std::result::Result<Vec<f64>, NumbersError> {
    let array = js::is_array(v).map_err(|e| Failure::thrown(&format!("reading {what}"), e))?;
    if !array {
        return Err(NumbersError::NotArray);
    }
    let len = js::get(v, "length")
        .map_err(|e| Failure::thrown(&format!("reading {what}.length"), e))?
        .as_f64()
        .unwrap_or(f64::NAN);
    let len = checked_len(len, what, max, check_len)?;
    let mut out = room::<f64>(len, what)?;
    for i in 0..len {
        let x = js::get_index(v, i as u32)
            .map_err(|e| Failure::thrown(&format!("reading {what}[{i}]"), e))?;
        match x.as_f64() {
            Some(x) => out.push(x),
            None => return Err(NumbersError::NotNumber(i, x)),
        }
    }
    Ok(out)
}

/// A JS option value as JSON, for serde.
fn json_value(key: &str, v: &JsValue) -> WasmResult<Value> {
    if v.is_null() {
        return Ok(Value::Null);
    }
    if let Some(b) = v.as_bool() {
        return Ok(Value::Bool(b));
    }
    if let Some(x) = v.as_f64() {
        return Ok(json_number(key, x)?);
    }
    if v.is_string() {
        return match js::short_string(v, MAX_OPTION_CHARS) {
            Some(s) => Ok(Value::String(s)),
            None => Err(bad_option(
                key,
                format!("a string of more than {MAX_OPTION_CHARS} characters is no valid value"),
            )
            .into()),
        };
    }
    let nums = match numbers_of::<f64>(v, &format!("option '{key}'"), MAX_OPTION_NUMBERS, &|_| {
        Ok(())
    }) {
        Ok(nums) => nums,
        Err(NumbersError::Failed(f)) => return Err(f),
        Err(NumbersError::NotNumber(i, x)) => {
            return Err(bad_option(
                key,
                format!("element {i} is not a number (got {})", describe(&x)),
            )
            .into())
        }
        Err(NumbersError::NotArray) => {
            return Err(bad_option(
                key,
                format!(
                    "expected a number, string, boolean or array, got {}",
                    describe(v)
                ),
            )
            .into())
        }
    };
    let mut out = Vec::with_capacity(nums.len());
    for (i, x) in nums.into_iter().enumerate() {
        if !x.is_finite() {
            return Err(
                bad_option(key, format!("element {i} must be a finite number, got {x}")).into(),
            );
        }
        out.push(json_number(key, x)?);
    }
    Ok(Value::Array(out))
}

/// A finite JS number as an option's JSON (-0 is 0: a `seed` of -0 is 0).
fn json_number(key: &str, x: f64) -> Result<Value> {
    if !x.is_finite() {
        return Err(bad_option(key, format!("must be a finite number, got {x}")));
    }
    Ok(finite_number(if x == 0.0 { 0.0 } else { x }))
}

/// A finite JS number as JSON: an integer when it is one below 2^53 (so
/// that integer fields read `7`), else the double (-0 included).
pub(super) fn finite_number(x: f64) -> Value {
    let int = x.fract() == 0.0 && x.abs() <= MAX_SAFE_INTEGER && x.to_bits() != (-0.0f64).to_bits();
    match int {
        true if x >= 0.0 => Value::from(x as u64),
        true => Value::from(x as i64),
        false => Value::from(x),
    }
}

#[cfg(feature = "wasm-main")]
/// Interleaved points, `stride` numbers each: a `Float32Array` (copied once
/// into wasm memory) stays f32; a `Float64Array` or `Array` of numbers stays
/// f64, re-centred in f64 by the core before anything becomes f32 (map
/// coordinates). More than [`MAX_POINTS`] points are refused before anything
/// is allocated. `stride` when given, else [`default_stride`]; the values
/// come with the stride they were read at.
pub(crate) fn points_of(v: &JsValue, stride: Option<Stride>) -> WasmResult<(Coordinates, Stride)> {
    let stride = match stride {
        Some(s) => s,
        None => default_stride(v)?,
    };
    // A length that is no multiple of the stride is refused before the copy.
    let whole = |len: usize| {
        if len % stride == 0 {
            Ok(())
        } else {
            Err(Error::BadLength { len, stride })
        }
    };
    let max = MAX_POINTS.saturating_mul(stride);
    let read = match js::typed_array(v) {
        Some((tag, _)) if tag == "Float32Array" => {
            numbers_of::<f32>(v, "points", max, &whole).map(Coordinates::F32)
        }
        _ => numbers_of::<f64>(v, "points", max, &whole).map(Coordinates::F64),
    };
    match read {
        Ok(values) => Ok((values, stride)),
        Err(NumbersError::Failed(f)) => Err(f),
        Err(NumbersError::NotNumber(i, x)) => Err(invalid(format!(
            "points: element {i} is not a number (got {}); points are one flat list \
             of interleaved x, y, z[, intensity] values",
            describe(&x)
        ))
        .into()),
        Err(NumbersError::NotArray) => Err(invalid(format!(
            "points must be a Float32Array of interleaved x, y, z[, intensity] values \
             (or a Float64Array or Array of numbers), got {}",
            describe(v)
        ))
        .into()),
    }
}

#[cfg(feature = "wasm-main")]
/// The stride of points given without one: 3, unless they are a typed array
/// that `polyscene/io` or `polyscene/sim` marked with another (its own
/// `stride` property, not enumerable), which is refused: x, y, z, intensity
/// read as x, y, z make other, wrong points, and often no error (when the
/// length is a multiple of 3).
fn default_stride(v: &JsValue) -> WasmResult<Stride> {
    if js::typed_array(v).is_some() {
        let mark = js::get(v, "stride").map_err(|e| Failure::thrown("reading points.stride", e))?;
        if let Some(s) = mark.as_f64().filter(|&s| s != 3.0) {
            return Err(bad_option(
                "stride",
                format!(
                    "not given, and these points were made with {s} values a point \
                     (polyscene/io and polyscene/sim mark theirs): pass {{ stride: {s} }}"
                ),
            )
            .into());
        }
    }
    Ok(3)
}

#[cfg(feature = "wasm-main")]
/// The cloud and the parameters of a one-shot detection call (`detect`,
/// `detectFlat`, `detectWithProgress`): the options first (they give the
/// stride), then the points, read as [`points_of`] reads them.
pub(crate) fn detect_input(
    points: &JsValue,
    options: &JsValue,
) -> WasmResult<(Cloud, Params, Positions)> {
    let options = DetectOptions::from_js(options)?;
    let (values, stride) = points_of(points, options.stride)?;
    let cloud = values.cloud(stride)?;
    Ok((cloud, options.params, options.viewpoints))
}

/// `viewpoints`: x, y, z of each position in one flat list of numbers.
fn positions_of(v: &JsValue) -> WasmResult<Positions> {
    const WHAT: &str = "option 'viewpoints'";
    let whole = crate::detect::check_flat_positions;
    let nums = match numbers_of::<f64>(v, WHAT, 3 * MAX_VIEWPOINTS, &whole) {
        Ok(nums) => nums,
        Err(NumbersError::Failed(f)) => return Err(f),
        Err(NumbersError::NotNumber(i, x)) => {
            return Err(bad_option(
                "viewpoints",
                format!("element {i} is not a number (got {})", describe(&x)),
            )
            .into())
        }
        Err(NumbersError::NotArray) => {
            return Err(bad_option(
                "viewpoints",
                format!(
                    "expected a Float64Array, Float32Array or Array of numbers \
                     (x, y, z of each position), got {}",
                    describe(v)
                ),
            )
            .into())
        }
    };
    Ok(nums
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect())
}

/// A world-from-sensor pose: 16 numbers in column-major order
/// (`Float64Array`, `Float32Array`, `Array`) or an object with such an
/// `elements` array (a three.js `Matrix4`); identity when `undefined` or
/// `null`. Checked to be rigid.
fn pose_of(v: &JsValue) -> WasmResult<DMat4> {
    const EXPECTED: &str =
        "expected 16 numbers (a column-major 4x4 matrix, three.js Matrix4.elements order)";
    if v.is_undefined() || v.is_null() {
        return Ok(DMat4::IDENTITY);
    }
    let mut raw = v.clone();
    let array = js::is_array(v).map_err(|e| Failure::thrown("reading option 'pose'", e))?;
    if raw.is_object() && !array && !ArrayBuffer::is_view(&raw) {
        let elements = js::get(&raw, "elements")
            .map_err(|e| Failure::thrown("reading option 'pose'.elements", e))?;
        if !elements.is_undefined() {
            raw = elements;
        }
    }
    let nums = match numbers_of::<f64>(&raw, "option 'pose'", MAX_OPTION_NUMBERS, &|_| Ok(())) {
        Ok(nums) => nums,
        Err(NumbersError::Failed(f)) => return Err(f),
        Err(NumbersError::NotNumber(i, _)) => {
            return Err(Error::BadPose(format!("element {i} is not a number")).into())
        }
        Err(NumbersError::NotArray) => {
            return Err(Error::BadPose(format!("{EXPECTED}, got {}", describe(v))).into())
        }
    };
    let Ok(cols) = <[f64; 16]>::try_from(nums.as_slice()) else {
        return Err(Error::BadPose(format!("{EXPECTED}, got {} numbers", nums.len())).into());
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

#[cfg(feature = "wasm-main")]
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
    /// Ground (road, sidewalk, plaza): by the local floor in one-shot detection, by `groundDepth` under the sensor in the scenario.
    pub ground: bool,
    /// Scan in which it was detected (0 for one-shot detection).
    pub born_scan: u64,
    /// Last scan in which it gained support (0 for one-shot detection).
    pub last_scan: u64,
}

#[cfg(feature = "wasm-main")]
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

#[cfg(feature = "wasm-main")]
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

#[cfg(feature = "wasm-main")]
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

/// Set a property of a fresh plain object.
pub(crate) fn set(obj: &Object, key: &str, value: impl Into<JsValue>) {
    // Setting a property on a fresh plain object cannot fail.
    let _ = Reflect::set(obj, &key.into(), &value.into());
}

pub(super) fn vec3(v: DVec3) -> Array {
    Array::of3(&v.x.into(), &v.y.into(), &v.z.into())
}

pub(super) fn flat_vertices(verts: &[DVec3]) -> Float64Array {
    let flat: Vec<f64> = verts.iter().flat_map(|v| v.to_array()).collect();
    Float64Array::from(&flat[..])
}

#[cfg(feature = "wasm-main")]
/// The primitives as `Polygon` objects.
pub(crate) fn polygons_array(prims: &[Primitive]) -> Array {
    prims
        .iter()
        .map(|p| PolygonView::of(p).into_object())
        .collect()
}

#[cfg(feature = "wasm-main")]
/// The mesh as a `Mesh` object.
pub(crate) fn mesh_object(m: &Mesh) -> Object {
    MeshView::of(m).into_object()
}

#[cfg(feature = "wasm-main")]
/// A serialisable value as a plain JS object, through JSON text (the serde
/// code is shared with snapshots, which keeps the wasm small).
pub(crate) fn to_js<T: serde::Serialize>(value: &T) -> WasmResult<JsValue> {
    let text = serde_json::to_string(value)?;
    JSON::parse(&text).map_err(|_| Failure::new("internal error: unparsable JSON"))
}
