//! The simulator in JS: `simulate`, the `Simulation` it returns and the
//! iterator of `for (const scan of simulation)`.

use super::convert::{ground_truth_array, scan_object, set, SimulateOptions};
use super::error::{bad_option, invalid, WasmResult};
use super::js::describe;
use crate::error::Result;
use crate::sim::{Drive, Layout, SensorModel};
use js_sys::{Array, Object, Reflect};
use std::cell::Cell;
use std::rc::Rc;
use wasm_bindgen::prelude::*;

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
    fn step(&self) -> Result<Object> {
        let k = self.cursor.get();
        if k >= self.drive.len() {
            let o = Object::new();
            set(&o, "done", true);
            return Ok(o);
        }
        let scan = self.drive.scan(k)?;
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
    fn get(&self) -> Result<&Rc<SimState>> {
        self.inner.as_ref().ok_or_else(|| invalid(FREED_SIMULATION))
    }
}

/// Start a simulated drive (`SimulateOptions`: `layout` "street" or
/// "crossing", `seed`, `step` in metres, `origin`). Throws on an unknown key
/// or a bad value, naming the key.
#[wasm_bindgen]
pub fn simulate(
    #[wasm_bindgen(unchecked_optional_param_type = "SimulateOptions")] options: Option<JsValue>,
) -> WasmResult<JsSimulation> {
    let options = SimulateOptions::from_js(&options.unwrap_or(JsValue::UNDEFINED))?;
    let drive = Drive::new(
        options.layout,
        options.seed,
        SensorModel::default(),
        options.drive(),
    )?;
    Ok(JsSimulation {
        inner: Some(Rc::new(SimState {
            drive,
            layout: options.layout,
            seed: options.seed,
            cursor: Cell::new(0),
        })),
    })
}

#[wasm_bindgen(js_class = Simulation)]
impl JsSimulation {
    /// Number of scans of the drive.
    #[wasm_bindgen(getter)]
    pub fn length(&self) -> WasmResult<u32> {
        Ok(self.get()?.drive.len() as u32)
    }

    /// Index of the scan `next()` returns.
    #[wasm_bindgen(getter)]
    pub fn cursor(&self) -> WasmResult<u32> {
        Ok(self.get()?.cursor.get() as u32)
    }

    /// The layout name.
    #[wasm_bindgen(getter)]
    pub fn layout(&self) -> WasmResult<String> {
        Ok(self.get()?.layout.as_str().to_string())
    }

    /// The seed.
    #[wasm_bindgen(getter)]
    pub fn seed(&self) -> WasmResult<f64> {
        Ok(self.get()?.seed as f64)
    }

    /// The next scan (`{ done: false, index, points, stride: 4, pose,
    /// labels }`), or `{ done: true }` after the last.
    #[wasm_bindgen(unchecked_return_type = "SimulationStep")]
    pub fn next(&self) -> WasmResult<Object> {
        Ok(self.get()?.step()?)
    }

    /// Scan `index` (0 to `length - 1`), without moving the cursor.
    #[wasm_bindgen(unchecked_return_type = "SimulatedScan")]
    pub fn scan(
        &self,
        #[wasm_bindgen(unchecked_param_type = "number")] index: JsValue,
    ) -> WasmResult<Object> {
        let state = self.get()?;
        let n = state.drive.len();
        // Read as a number here, not converted by the glue (which would run
        // an object's valueOf).
        let Some(index) = index.as_f64() else {
            return Err(bad_option(
                "scan",
                format!("the index must be a number, got {}", describe(&index)),
            )
            .into());
        };
        if !(index.fract() == 0.0 && index >= 0.0 && index < n as f64) {
            return Err(bad_option(
                "scan",
                format!(
                    "index {index} is out of range: this drive has {n} scans (0 to {})",
                    n.saturating_sub(1)
                ),
            )
            .into());
        }
        let k = index as usize;
        let scan = state.drive.scan(k)?;
        Ok(scan_object(k, &scan))
    }

    /// Move the cursor back to the first scan.
    pub fn reset(&self) -> WasmResult<()> {
        self.get()?.cursor.set(0);
        Ok(())
    }

    /// The scene's ground-truth polygons (world coordinates).
    #[wasm_bindgen(js_name = groundTruth, unchecked_return_type = "GroundTruthPolygon[]")]
    pub fn ground_truth(&self) -> WasmResult<Array> {
        Ok(ground_truth_array(&self.get()?.drive.scene().polygons))
    }

    /// An iterator over the remaining scans (it advances this simulation's
    /// cursor), so that `for (const scan of sim)` works.
    #[wasm_bindgen(js_name = "[Symbol.iterator]")]
    pub fn iter(&self) -> WasmResult<ScanIterator> {
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
    pub fn next(&self) -> WasmResult<Object> {
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
