//! `detectWithProgress`: one-shot detection that reports after each round to
//! a JS callback and stops when the callback says so. The callback is called
//! through js-sys's `Function::call1`, a `catch` import: a callback that
//! throws ends the detection, with no unwinding through the wasm (the module
//! stays usable), and the caller gets an `Error` with the thrown value as its
//! `cause`, as for every other value user code throws.

use super::convert::{detect_input, polygons_array};
use super::error::{Failure, WasmResult};
use crate::detect::{detect_with_progress, Progress};
use js_sys::{Array, Function, Object, Reflect};
use std::ops::ControlFlow;
use wasm_bindgen::prelude::*;

/// `detect` that calls `onProgress({ round, pointsLeft,
/// points, polygons })` after each round of the cascade (`pointsLeft` falls
/// towards 0, then, for a cloud seen from nowhere, once more from the
/// sparse points its coarse pass takes up; the rounds' count is not known
/// in advance). `onProgress`
/// returning `false` stops the detection there: it then throws an `Error`
/// saying so. An exception thrown by `onProgress` ends the detection: the
/// `Error` thrown then has it as `cause`. A detection that runs to its end gives what `detect`
/// gives.
#[wasm_bindgen(js_name = detectWithProgress, unchecked_return_type = "Polygon[]")]
pub fn detect_with_progress_js(
    #[wasm_bindgen(unchecked_param_type = "Float32Array | Float64Array")] points: JsValue,
    #[wasm_bindgen(unchecked_param_type = "DetectOptions | undefined")] options: JsValue,
    #[wasm_bindgen(unchecked_param_type = "(progress: DetectProgress) => boolean | void")]
    on_progress: Function,
) -> WasmResult<Array> {
    if !on_progress.is_function() {
        return Err(Failure::new(
            "detectWithProgress: onProgress must be a function",
        ));
    }
    let (cloud, params, viewpoints) = detect_input(&points, &options)?;
    let mut thrown: Option<JsValue> = None;
    let mut last = 0;
    let mut report = |at: &Progress| {
        last = at.round;
        match on_progress.call1(&JsValue::UNDEFINED, &progress_object(at)) {
            Ok(v) if v == JsValue::FALSE => ControlFlow::Break(()),
            Ok(_) => ControlFlow::Continue(()),
            Err(e) => {
                thrown = Some(e);
                ControlFlow::Break(())
            }
        }
    };
    let found = detect_with_progress(&cloud, &params, &viewpoints, &mut report)?;
    if let Some(e) = thrown {
        return Err(Failure::thrown(
            &format!("detectWithProgress: onProgress after round {last}"),
            e,
        ));
    }
    match found {
        Some(found) => Ok(polygons_array(&found.primitives)),
        None => Err(Failure::new(format!(
            "detectWithProgress: stopped by onProgress after round {last}"
        ))),
    }
}

fn progress_object(at: &Progress) -> JsValue {
    let o = Object::new();
    for (key, value) in [
        ("round", at.round),
        ("pointsLeft", at.points_left),
        ("points", at.points),
        ("polygons", at.primitives),
    ] {
        // Setting a data property on a fresh plain object cannot fail.
        let _ = Reflect::set(
            &o,
            &JsValue::from_str(key),
            &JsValue::from_f64(value as f64),
        );
    }
    o.into()
}

#[wasm_bindgen(typescript_custom_section)]
const DETECT_PROGRESS_TS: &str = r#"
/** What `detectWithProgress` reports after each round of the cascade. */
export interface DetectProgress {
    /** Rounds done. */
    round: number;
    /** Points not yet explained or discarded: falls towards 0 (for a cloud seen from nowhere, a second time in its coarse pass, from the sparse points it takes up). */
    pointsLeft: number;
    /** Points of the cloud. */
    points: number;
    /** Polygons accepted so far (before the final merge). */
    polygons: number;
}
"#;
