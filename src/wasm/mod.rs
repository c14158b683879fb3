//! The JavaScript binding (wasm-bindgen). It only converts: JS values in
//! (validated at the boundary, errors as JS `Error`s whose message names the
//! problem), one call into the core, plain JS values and typed arrays out.
//!
//! - [`convert`]: JS values in (points, poses, options, read one way) and
//!   plain JS objects out; its structs define the `.d.ts` interfaces, which
//!   `build.rs` generates from them;
//! - [`js`]: every touch of a caller's JS value, made so that no JS
//!   exception can cross a Rust frame (a getter, a Proxy trap, a detached
//!   buffer);
//! - [`flat`]: polygons as columns (`polygonsFlat`, `detectFlat`);
//! - [`progress`]: `detectWithProgress`, a callback between detection rounds;
//! - [`error`]: the boundary's error type, so that `?` converts; a value
//!   thrown by the caller's code becomes an `Error` with it as `cause`;
//! - [`scenario`]: the `Scenario` class;
//! - [`sim`]: `simulate`, `Simulation` and its iterator;
//! - here: the module start, `detect`, `defaultOptions`, `version`.
//!
//! Two wasm builds of this crate share the module: the Cargo feature
//! `wasm-main` (default) gives `polyscene_bg.wasm` (detection, `Scenario`,
//! options, columns, progress, `version`), `wasm-sim` gives
//! `polyscene_sim_bg.wasm` (`polyscene/sim`: `simulate`, `Simulation`,
//! `version`; `scripts/build-wasm.sh` builds it with
//! `--no-default-features --features wasm-sim`). Each carries only its own
//! code: the package's detection wasm is 32 kB gzipped smaller without the
//! simulator, and the simulator's has no detection code. Both features
//! together (the binding tests, `tests/wasm.rs`) give one wasm with both.
//!
//! Objects that own wasm memory ([`Scenario`](JsScenario),
//! [`Simulation`](JsSimulation)) hold their core value in an `Option`: their
//! `free()` empties it, so that a later call says the object was freed rather
//! than wasm-bindgen's bare null-pointer message. Results the caller keeps
//! (polygons, reports, meshes, scans) are plain JS objects owning their
//! typed arrays. Nothing here touches `window`: the module works in a page,
//! a Web Worker and Node.

mod convert;
mod error;
#[cfg(feature = "wasm-main")]
mod flat;
mod js;
#[cfg(feature = "wasm-main")]
mod progress;
#[cfg(feature = "wasm-main")]
mod scenario;
#[cfg(feature = "wasm-sim")]
mod sim;

pub use error::{Failure, WasmResult};
#[cfg(feature = "wasm-main")]
pub use scenario::JsScenario;
#[cfg(feature = "wasm-sim")]
pub use sim::{simulate, JsSimulation, ScanIterator};

use crate::clock;
#[cfg(feature = "wasm-main")]
use crate::params::Params;
#[cfg(feature = "wasm-main")]
use convert::{detect_input, polygons_array, to_js};
#[cfg(feature = "wasm-main")]
use js_sys::Array;
use js_sys::{Function, Reflect};
use std::cell::RefCell;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

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
// TypeScript declarations (they flow into the .d.ts).

/// The types that are no struct's mirror: names and unions (the
/// simulator's are in [`sim`]).
#[cfg(feature = "wasm-main")]
#[wasm_bindgen(typescript_custom_section)]
const TS_TYPES: &'static str = r#"
/** Names of the parameter presets: the paper's GPP 1 (only large polygons, faster) and GPP 2 (small polygons too). */
export type Preset = "gpp1" | "gpp2";

/** A snapshot from `scenario.toJSON()`: plain JSON data (parameters included). */
export type ScenarioSnapshot = { params: Required<Omit<PipelineOptions, "preset">>; [key: string]: unknown };
"#;

/// The interfaces of the options of single calls and of the results:
/// generated by `build.rs` from their Rust structs (`convert`'s `*Options`
/// and `*View`, the core's `ScanReport`) and their doc comments.
#[cfg(feature = "wasm-main")]
#[wasm_bindgen(typescript_custom_section)]
const TS_INTERFACES: &'static str = include_str!(concat!(env!("OUT_DIR"), "/interfaces.d.ts"));

/// `PipelineOptions`: generated by `build.rs` from `Params` and its doc
/// comments (unit and default per key).
#[cfg(feature = "wasm-main")]
#[wasm_bindgen(typescript_custom_section)]
const TS_PIPELINE_OPTIONS: &'static str =
    include_str!(concat!(env!("OUT_DIR"), "/pipeline_options.d.ts"));

// ---------------------------------------------------------------------------
// Free functions.

/// One-shot detection of planar polygons in a world-frame cloud (the paper's
/// Algorithm 1).
///
/// `points`: interleaved x, y, z[, intensity] (`options.stride`, default 3)
/// in metres, a `Float32Array` (copied once; coordinates within 1e5 m of
/// the origin) or a `Float64Array` (kept in f64 and re-centred: map
/// coordinates). `options` (`DetectOptions`): the pipeline options, and
/// `stride`; `viewpoint` is the sensor position of one scan (default: the
/// origin when a sensor could have stood there, a scan in its own frame;
/// else none, a map), `viewpoints` the sensor positions of the scans an
/// accumulated cloud was gathered from.
///
/// Returns the polygons (plain objects owned by JS), `bornScan`/`lastScan`
/// 0. Throws an `Error` naming the problem on a length not divisible by the
/// stride, a NaN or infinite coordinate, more than 2^24 points, a detached
/// buffer, or a bad option.
#[cfg(feature = "wasm-main")]
#[wasm_bindgen(unchecked_return_type = "Polygon[]")]
pub fn detect(
    #[wasm_bindgen(unchecked_param_type = "Float32Array | Float64Array")] points: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "DetectOptions")] options: Option<JsValue>,
) -> WasmResult<Array> {
    let (cloud, params, viewpoints) =
        detect_input(&points, &options.unwrap_or(JsValue::UNDEFINED))?;
    let found = crate::detect::detect_from(&cloud, &params, &viewpoints)?;
    Ok(polygons_array(&found.primitives))
}

/// Every option of a preset with its value (`"gpp1"` or `"gpp2"`, default
/// `"gpp2"`): the defaults `new Scenario(options)` starts from, e.g. to
/// populate a GUI.
#[cfg(feature = "wasm-main")]
#[wasm_bindgen(js_name = defaultOptions, unchecked_return_type = "Required<Omit<PipelineOptions, \"preset\">>")]
pub fn default_options(
    #[wasm_bindgen(unchecked_optional_param_type = "Preset")] preset: Option<JsValue>,
) -> WasmResult<JsValue> {
    let name = if let Some(preset) = preset {
        // A preset name is short: a long string is refused before it is copied.
        js::short_string(&preset, 16).ok_or_else(|| {
            error::bad_option(
                "preset",
                format!("expected 'gpp1' or 'gpp2', got {}", js::describe(&preset)),
            )
        })?
    } else {
        "gpp2".to_string()
    };
    to_js(&Params::preset(&name)?)
}

/// The crate version (semver string).
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}
