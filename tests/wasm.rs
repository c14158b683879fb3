//! The binding layer (`src/wasm/`) under Node: `wasm-pack test --node --
//! --test wasm`. Options parsing, errors as JS `Error`s naming the problem,
//! a small detection, the scenario's conversions. (The package as a whole is
//! tested by `node --test tests/js/`.) With `--features wasm-sim` (as
//! `scripts/test-js.sh` runs it) the simulator's binding is tested too.
#![cfg(all(target_arch = "wasm32", feature = "wasm-main"))]

use js_sys::{Array, Float32Array, Float64Array, Reflect, Uint32Array, JSON};
use polyscene::params::Params;
#[cfg(feature = "wasm-sim")]
use polyscene::wasm::simulate;
use polyscene::wasm::{default_options, detect, Failure, JsScenario};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use wasm_bindgen_test::wasm_bindgen_test;

fn json(text: &str) -> JsValue {
    JSON::parse(text).expect("test JSON")
}

fn get(v: &JsValue, key: &str) -> JsValue {
    Reflect::get(v, &key.into()).expect("property")
}

/// The message of the `Error` a `Failure` becomes in JS.
fn message<T>(r: Result<T, Failure>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => {
            let v = JsValue::from(e);
            let err: &js_sys::Error = v.dyn_ref().expect("a JS Error");
            err.message().into()
        }
    }
}

/// A 10 m x 10 m floor sampled every 10 cm at height 0 (stride 3).
fn floor() -> Float32Array {
    let mut pts = Vec::new();
    for i in 0..100 {
        for j in 0..100 {
            pts.extend_from_slice(&[i as f32 * 0.1, j as f32 * 0.1, 0.0]);
        }
    }
    Float32Array::from(&pts[..])
}

#[wasm_bindgen_test]
fn options_merge_over_the_preset() {
    let s = JsScenario::new(Some(json(
        r#"{"preset": "gpp1", "hull": "convex", "minArea": 3, "seed": 12}"#,
    )))
    .unwrap();
    let o = s.options().unwrap();
    assert_eq!(get(&o, "hull").as_string().unwrap(), "convex");
    assert_eq!(get(&o, "minArea").as_f64(), Some(3.0));
    assert_eq!(get(&o, "seed").as_f64(), Some(12.0));
    assert_eq!(
        get(&o, "minInliers").as_f64(),
        Some(Params::gpp1().min_inliers as f64)
    );
    // No options at all: gpp2.
    let d = JsScenario::new(None).unwrap().options().unwrap();
    let want = default_options(None).unwrap();
    assert_eq!(
        JSON::stringify(&d).unwrap().as_string(),
        JSON::stringify(&want).unwrap().as_string()
    );
    // Every Params key is in the defaults, each with a value.
    let mut keys: Vec<String> = js_sys::Object::keys(want.unchecked_ref::<js_sys::Object>())
        .iter()
        .filter_map(|k| k.as_string())
        .collect();
    keys.sort();
    assert_eq!(keys, Params::keys());
}

#[wasm_bindgen_test]
fn option_errors_are_js_errors_naming_the_key() {
    for (opts, words) in [
        (
            r#"{"minAreaa": 1}"#,
            "option 'minAreaa': unknown option (did you mean 'minArea'?)",
        ),
        (r#"{"minArea": "big"}"#, "option 'minArea'"),
        (r#"{"minArea": -1}"#, "option 'minArea'"),
        (r#"{"preset": "gpp3"}"#, "option 'preset'"),
        (r#"{"hull": "round"}"#, "option 'hull'"),
        (r#"{"seed": 1.5}"#, "option 'seed'"),
        (r#"{"viewpoint": [1, 2]}"#, "option 'viewpoint'"),
    ] {
        let m = message(JsScenario::new(Some(json(opts))));
        assert!(m.contains(words), "{opts}: {m}");
    }
    let m = message(JsScenario::new(Some("gpp1".into())));
    assert!(m.contains("must be an object"), "{m}");
    // A NaN cannot come through JSON: build it by hand.
    let o = js_sys::Object::new();
    Reflect::set(&o, &"alpha".into(), &f64::NAN.into()).unwrap();
    let m = message(JsScenario::new(Some(o.into())));
    assert!(m.contains("option 'alpha': must be a finite number"), "{m}");
}

#[wasm_bindgen_test]
fn a_small_detection() {
    let found = detect(floor().into(), Some(json(r#"{"viewpoint": [5, 5, 1.8]}"#))).unwrap();
    assert_eq!(found.length(), 1);
    let p = found.get(0);
    let area = get(&p, "area").as_f64().unwrap();
    assert!((area - 99.0).abs() < 3.0, "{area}");
    assert_eq!(get(&p, "ground").as_bool(), Some(true));
    let normal: Array = get(&p, "normal").dyn_into().unwrap();
    assert!(normal.get(2).as_f64().unwrap() > 0.999);
    let v: Float64Array = get(&p, "vertices").dyn_into().unwrap();
    assert_eq!(v.length() % 3, 0);
    assert_eq!(get(&p, "bornScan").as_f64(), Some(0.0));
    // Bad input: stride, length, NaN, type.
    let m = message(detect(floor().into(), Some(json(r#"{"stride": 5}"#))));
    assert!(m.contains("option 'stride'"), "{m}");
    let m = message(detect(Float32Array::new_with_length(4).into(), None));
    assert!(
        m.contains("length 4 is not a multiple of the stride 3"),
        "{m}"
    );
    let nan = Float32Array::from(&[0.0, f32::NAN, 0.0][..]);
    let m = message(detect(nan.into(), None));
    assert!(m.contains("point 0 has a NaN"), "{m}");
    let m = message(detect("x".into(), None));
    assert!(m.contains("points must be a Float32Array"), "{m}");
}

#[wasm_bindgen_test]
fn a_scenario_takes_scans_with_poses_and_refuses_bad_ones() {
    let s = JsScenario::new(None).unwrap();
    // The floor seen from 1.8 m above its centre: the pose moves the sensor
    // frame to the world.
    let pose = json("[1,0,0,0, 0,1,0,0, 0,0,1,0, 5,5,1.8,1]");
    let opts = js_sys::Object::new();
    Reflect::set(&opts, &"pose".into(), &pose).unwrap();
    let report = s.add_scan(floor().into(), Some(opts.into())).unwrap();
    assert_eq!(get(&report, "polygonCount").as_f64(), Some(1.0));
    assert_eq!(get(&report, "points").as_f64(), Some(10_000.0));
    let polys = s.polygons().unwrap();
    let v: Float64Array = get(&polys.get(0), "vertices").dyn_into().unwrap();
    // World frame: x in [5, 15] m.
    assert!(v.to_vec().chunks(3).all(|p| p[0] > 4.5 && p[0] < 15.5));
    let labels: Uint32Array = s.last_labels().unwrap();
    assert_eq!(labels.length(), 10_000);
    let mesh = s.mesh().unwrap();
    let ids: Uint32Array = get(&mesh, "polygonIds").dyn_into().unwrap();
    let idx: Uint32Array = get(&mesh, "indices").dyn_into().unwrap();
    assert_eq!(idx.length(), 3 * ids.length());
    assert!(ids.length() > 0);
    for (pose, words) in [
        ("[1,2,3]", "16 numbers"),
        ("[2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]", "not orthonormal"),
        ("[1,0,0,5, 0,1,0,0, 0,0,1,0, 0,0,0,1]", "bottom row"),
    ] {
        let opts = js_sys::Object::new();
        Reflect::set(&opts, &"pose".into(), &json(pose)).unwrap();
        let m = message(s.add_scan(floor().into(), Some(opts.into())));
        assert!(
            m.contains("invalid pose") && m.contains(words),
            "{pose}: {m}"
        );
    }
    assert_eq!(s.scans().unwrap(), 1.0, "refused scans change nothing");
    // Snapshots: to JSON and back.
    let snap = s.to_json().unwrap();
    let again = JsScenario::from_json(snap).unwrap();
    assert_eq!(again.polygon_count().unwrap(), 1);
    let m = message(JsScenario::from_json("{}".into()));
    assert!(m.contains("not a polyscene snapshot"), "{m}");
    // After free(): a clear message.
    s.release().unwrap();
    let m = message(s.polygons());
    assert!(m.contains("Scenario was freed"), "{m}");
}

/// The simulator's binding (its own wasm in the package; here with
/// `--features wasm-sim`, as scripts/test-js.sh runs it).
#[cfg(feature = "wasm-sim")]
#[wasm_bindgen_test]
fn the_simulator_runs() {
    let sim = simulate(Some(json(
        r#"{"layout": "crossing", "seed": 3, "step": 5}"#,
    )))
    .unwrap();
    let n = sim.length().unwrap();
    assert!(n > 10);
    let scan = sim.next().unwrap();
    assert_eq!(get(&scan, "done").as_bool(), Some(false));
    let pts: Float32Array = get(&scan, "points").dyn_into().unwrap();
    let labels: Uint32Array = get(&scan, "labels").dyn_into().unwrap();
    assert_eq!(pts.length(), 4 * labels.length());
    assert_eq!(sim.cursor().unwrap(), 1);
    let m = message(simulate(Some(json(r#"{"layout": "forest"}"#))));
    assert!(m.contains("option 'layout'"), "{m}");
    let m = message(sim.scan(JsValue::from(n as f64)));
    assert!(m.contains("out of range"), "{m}");
}

/// The wasm build's own code paths against their portable references, bit
/// for bit: the simd128 kernels of the RANSAC search (native builds run AVX
/// or SSE2 against the same references) and `floor_i64` (`f64.floor` here).
#[wasm_bindgen_test]
fn wasm_paths_match_their_references() {
    use polyscene::internals::floor_i64;
    use polyscene::internals::kernels::{
        inliers, inliers_scalar, msac_scalar, msac_sum, PlaneF32, Points,
    };
    // A pseudo-random slab of points around z = 0.5, with NaNs and -0.
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = |scale: f32| {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as f32 * scale
    };
    let n = 1000;
    let mut xs: Vec<f32> = (0..n).map(|_| next(20.0)).collect();
    let ys: Vec<f32> = (0..n).map(|_| next(20.0)).collect();
    let mut zs: Vec<f32> = (0..n).map(|_| 0.5 + next(0.2)).collect();
    for i in (3..n).step_by(17) {
        xs[i] = f32::NAN;
    }
    for i in (5..n).step_by(23) {
        zs[i] = -0.0;
    }
    let plane = PlaneF32 {
        nx: 0.01,
        ny: -0.02,
        nz: 0.999_75,
        d: -0.5,
    };
    let mut listed = 0;
    for len in (0..70).chain([999, 1000]) {
        for start in [0, 3] {
            let end = (start + len).min(n);
            let pts = Points::new(&xs, &ys, &zs).slice(start..end);
            let (got, want) = (msac_sum(pts, plane, 10.0), msac_scalar(pts, plane, 10.0));
            assert_eq!(
                got.to_bits(),
                want.to_bits(),
                "msac len {len} start {start}"
            );
            let (mut got, mut want) = (Vec::new(), Vec::new());
            inliers(pts, plane, 0.1, 7, &mut got);
            inliers_scalar(pts, plane, 0.1, 7, &mut want);
            assert_eq!(got, want, "inliers len {len} start {start}");
            listed += got.len();
        }
    }
    assert!(listed > 100, "{listed}");
    // floor_i64 (f64.floor here) against libm's floor, as the native unit
    // test checks the native formula: quarter steps around zero and far
    // out, either side of each integer, the i64 limits and beyond, NaN.
    let mut probes: Vec<f64> = (-40..=40).map(|k| k as f64 * 0.25).collect();
    for base in [1e6, 4503599627370495.0, 9.2e18] {
        probes.extend([
            base - 0.5,
            base,
            base + 0.5,
            -base - 0.5,
            -base,
            -base + 0.5,
        ]);
    }
    probes.extend([
        1e19,
        -1e19,
        f64::INFINITY,
        f64::NEG_INFINITY,
        -0.0,
        1e-300,
        -1e-300,
    ]);
    for x in probes {
        assert_eq!(floor_i64(x), libm::floor(x) as i64, "{x}");
    }
    assert_eq!(floor_i64(f64::NAN), 0);
}
