//! Touching a caller's JS values so that no JS exception crosses a Rust
//! frame.
//!
//! An import that wasm-bindgen does not mark `catch` lets a throw unwind
//! through the wasm frames that called it: their destructors never run, so
//! a borrow of the object stays taken (every later call on it fails with
//! "recursive use of an object"), the shadow stack and the externref table
//! leak, and after some hundred such throws the module traps. Any JS value
//! a caller passes can run code when read (a Proxy's traps, a getter, a
//! detached typed array's `TypeError`), so the binding reads them only
//! through this module, where every call that can run user code is a
//! `catch` import returning the thrown value as `Err`, and the rest cannot
//! throw (`typeof` tests, `ArrayBuffer.isView`, and the typed arrays' own
//! `length` and `Symbol.toStringTag` getters, taken from
//! `%TypedArray%.prototype` once, so that a Proxy or an own property cannot
//! stand in for them).

use js_sys::{Array, ArrayBuffer, Float32Array, Function, JsString, Object, Reflect, Symbol};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

#[wasm_bindgen]
extern "C" {
    #[wasm_bindgen(catch, js_namespace = Object, js_name = keys)]
    fn object_keys(v: &JsValue) -> Result<Array, JsValue>;
    #[wasm_bindgen(catch, js_namespace = Array, js_name = isArray)]
    fn array_is_array(v: &JsValue) -> Result<bool, JsValue>;
    // js-sys's `JSON.parse` takes a `&str`: the text would be copied into
    // wasm memory and back. (These three serve snapshots, which only the
    // detection binding restores.)
    #[cfg(feature = "wasm-main")]
    #[wasm_bindgen(catch, js_namespace = JSON, js_name = parse)]
    fn json_parse(text: &JsValue) -> Result<JsValue, JsValue>;
    #[cfg(feature = "wasm-main")]
    #[wasm_bindgen(catch, js_namespace = Array, js_name = "prototype.every.call")]
    fn array_every(array: &JsValue, test: &JsValue) -> Result<bool, JsValue>;
    #[cfg(feature = "wasm-main")]
    #[wasm_bindgen(thread_local_v2, js_namespace = Number, js_name = isFinite)]
    static NUMBER_IS_FINITE: JsValue;
    // `Float32Array.prototype.set.call(view of dst, src)`: one copy from a
    // typed array into wasm memory (converting the element type), as
    // js-sys's `copy_to`, but `catch` (a detached source throws).
    #[wasm_bindgen(catch, js_namespace = Float32Array, js_name = "prototype.set.call")]
    fn set_f32(dst: &mut [f32], src: &JsValue) -> Result<(), JsValue>;
    #[wasm_bindgen(catch, js_namespace = Float64Array, js_name = "prototype.set.call")]
    fn set_f64(dst: &mut [f64], src: &JsValue) -> Result<(), JsValue>;
}

/// `Err` of a JS call: the value it threw.
pub(crate) type Thrown = JsValue;

/// `%TypedArray%.prototype`'s `Symbol.toStringTag` and `length` getters.
struct TypedGetters {
    tag: Function,
    length: Function,
}

thread_local! {
    static TYPED: Option<TypedGetters> = typed_getters();
}

fn typed_getters() -> Option<TypedGetters> {
    let own = Float32Array::new_with_length(0);
    let base = Object::get_prototype_of(&Object::get_prototype_of(&own));
    let getter = |key: &JsValue| -> Option<Function> {
        let desc = Reflect::get_own_property_descriptor(&base, key).ok()?;
        Reflect::get(&desc, &"get".into())
            .ok()?
            .dyn_into::<Function>()
            .ok()
    };
    Some(TypedGetters {
        tag: getter(&Symbol::to_string_tag().into())?,
        length: getter(&"length".into())?,
    })
}

/// A real typed array's constructor name (`"Float32Array"`, ...) and
/// length; `None` for anything else (a Proxy around one included). The
/// length of a detached one is 0.
pub(crate) fn typed_array(v: &JsValue) -> Option<(String, usize)> {
    if !ArrayBuffer::is_view(v) {
        return None;
    }
    TYPED.with(|t| {
        let t = t.as_ref()?;
        let tag = t.tag.call0(v).ok()?.as_string()?;
        let len = t.length.call0(v).ok()?.as_f64()?;
        Some((tag, len as usize))
    })
}

/// Copy a real typed array of `dst.len()` elements into `dst` (converted
/// to f32). `Err` when it throws (a detached buffer, a BigInt array).
pub(crate) fn copy_f32(dst: &mut [f32], src: &JsValue) -> Result<(), Thrown> {
    set_f32(dst, src)
}

/// Copy a real typed array of `dst.len()` elements into `dst` (converted
/// to f64).
pub(crate) fn copy_f64(dst: &mut [f64], src: &JsValue) -> Result<(), Thrown> {
    set_f64(dst, src)
}

/// `Array.isArray(v)` (true for a Proxy around an Array; throws for a
/// revoked Proxy).
pub(crate) fn is_array(v: &JsValue) -> Result<bool, Thrown> {
    array_is_array(v)
}

/// `JSON.parse(text)` of a JS string, left in JS.
#[cfg(feature = "wasm-main")]
pub(crate) fn parse(text: &JsValue) -> Result<JsValue, Thrown> {
    json_parse(text)
}

/// The elements of the Array `v` of length `len`, when every one is a
/// finite number (`Number.isFinite`, which converts nothing), in two calls
/// whatever the length; `None` when one is not.
#[cfg(feature = "wasm-main")]
pub(crate) fn finite_numbers(v: &JsValue, len: usize) -> Result<Option<Vec<f64>>, Thrown> {
    if !NUMBER_IS_FINITE.with(|test| array_every(v, test))? {
        return Ok(None);
    }
    let mut out = vec![0.0; len];
    copy_f64(&mut out, v)?;
    Ok(Some(out))
}

/// `Object.keys(v)`: own enumerable string keys (a Proxy's `ownKeys` and
/// `getOwnPropertyDescriptor` traps run).
pub(crate) fn keys(v: &JsValue) -> Result<Vec<JsValue>, Thrown> {
    // The result is a fresh Array of strings: iterating it runs no user code.
    Ok(object_keys(v)?.iter().collect())
}

/// `v[key]` (getters and Proxy traps run).
pub(crate) fn get(v: &JsValue, key: &str) -> Result<JsValue, Thrown> {
    Reflect::get(v, &JsValue::from_str(key))
}

/// `v[key]` for a key as JS gave it (from [`keys`]).
pub(crate) fn get_key(v: &JsValue, key: &JsValue) -> Result<JsValue, Thrown> {
    Reflect::get(v, key)
}

/// `v[i]`.
pub(crate) fn get_index(v: &JsValue, i: u32) -> Result<JsValue, Thrown> {
    Reflect::get_u32(v, i)
}

/// Longest string the binding copies out of JS for a message.
const SHOWN_CHARS: u32 = 120;

/// A JS string, when it has at most `max` UTF-16 units (checked before any
/// copy into wasm memory); `None` for a non-string or a longer one.
pub(crate) fn short_string(v: &JsValue, max: u32) -> Option<String> {
    let s = v.dyn_ref::<JsString>().filter(|_| v.is_string())?;
    if s.length() > max {
        return None;
    }
    v.as_string()
}

/// A string for a message, cut after a few dozen characters.
fn cut(v: &JsValue) -> String {
    let Some(s) = v.dyn_ref::<JsString>().filter(|_| v.is_string()) else {
        return String::new();
    };
    let n = s.length();
    let head = s.slice(0, SHOWN_CHARS).as_string().unwrap_or_default();
    if n > SHOWN_CHARS {
        format!("{head}... ({n} characters)")
    } else {
        head
    }
}

/// A short description of a JS value's type, for error messages. Reads the
/// `constructor.name` of objects, catching what that throws.
pub(crate) fn describe(v: &JsValue) -> String {
    if v.is_null() {
        return "null".into();
    }
    if v.is_undefined() {
        return "undefined".into();
    }
    if v.is_string() {
        return format!("the string \"{}\"", cut(v));
    }
    if let Some(x) = v.as_f64() {
        return format!("the number {x}");
    }
    if let Some(b) = v.as_bool() {
        return format!("the boolean {b}");
    }
    if v.is_function() {
        return "a function".into();
    }
    if v.is_object() {
        if let Ok(true) = is_array(v) {
            return "an Array".into();
        }
        let ctor = get(v, "constructor")
            .ok()
            .and_then(|c| get(&c, "name").ok())
            .and_then(|n| short_string(&n, SHOWN_CHARS));
        return match ctor {
            // A Proxy around an Array or a typed array, or an object
            // given its prototype: not the real thing.
            Some(name) if name.ends_with("Array") && !ArrayBuffer::is_view(v) => {
                format!("an object that is no real {name} (a Proxy?)")
            }
            Some(name) if !name.is_empty() => format!("{} {name}", article(&name)),
            _ => "an object".into(),
        };
    }
    // A symbol or a bigint.
    match v.js_typeof().as_string() {
        Some(t) => format!("a {t}"),
        None => "a value".into(),
    }
}

/// "a" or "an" before `word`.
fn article(word: &str) -> &'static str {
    match word.chars().next() {
        Some('A' | 'E' | 'I' | 'O' | 'U' | 'a' | 'e' | 'i' | 'o' | 'u') => "an",
        _ => "a",
    }
}

/// What a thrown value was, for the message of the `Error` that wraps it:
/// `TypeError: message` for an error object, else [`describe`].
pub(crate) fn summary(v: &JsValue) -> String {
    if v.is_object() {
        let field = |key| get(v, key).ok().filter(|s| s.is_string());
        if let Some(message) = field("message") {
            let name = field("name")
                .and_then(|n| short_string(&n, SHOWN_CHARS))
                .unwrap_or_else(|| "Error".into());
            return format!("{name}: {}", cut(&message));
        }
    }
    describe(v)
}
