//! Errors at the boundary. Every fallible export returns [`WasmResult`]:
//! its error, a [`Failure`], becomes a thrown JS `Error` whose message says
//! what was wrong and what was expected.
//!
//! `?` converts: [`Failure`] implements `From<E>` for every
//! `E: std::error::Error`, which covers [`crate::Error`] (the core's and the
//! binding's own errors, built with [`invalid`] and [`bad_option`]) and
//! `serde_json::Error`. A value thrown by JS code the binding called (a
//! getter, a Proxy trap, `toJSON`, a detached buffer's `TypeError`) is
//! wrapped by [`Failure::thrown`]: an `Error` naming what was being read,
//! with the thrown value as its `cause`. So every throw of the package is an
//! `Error`, whatever user code throws.

use super::js::summary;
use crate::error::Error;
use js_sys::{Object, Reflect};
use wasm_bindgen::JsValue;

/// What every fallible export returns: the error becomes a thrown JS `Error`.
pub type WasmResult<T> = Result<T, Failure>;

/// A failed call: the message of the JS `Error` it becomes, and the value
/// that JS code threw while the binding read an argument, if that was the
/// failure (the `Error`'s `cause`).
pub struct Failure {
    message: String,
    cause: Option<JsValue>,
}

/// Longest message a failure carries (bytes). A longer one is cut: serde's
/// messages quote the value they refuse, and a hostile snapshot's string of
/// 2^28 characters, quoted, is longer than V8 lets a string be.
const MAX_MESSAGE: usize = 4000;

impl Failure {
    /// A failure with this message (cut after [`MAX_MESSAGE`] bytes) and no
    /// cause.
    pub(crate) fn new(message: impl Into<String>) -> Failure {
        let mut message = message.into();
        if message.len() > MAX_MESSAGE {
            let mut end = MAX_MESSAGE;
            while !message.is_char_boundary(end) {
                end -= 1;
            }
            let all = message.len();
            message.truncate(end);
            message += &format!("... (cut: {all} bytes in all)");
        }
        Failure {
            message,
            cause: None,
        }
    }

    /// JS code threw `value` while the binding was `doing` something
    /// ("reading addScan options.pose"): an `Error` saying so, with the
    /// thrown value as `cause`.
    pub(crate) fn thrown(doing: &str, value: JsValue) -> Failure {
        Failure {
            message: format!("{doing} threw {}", summary(&value)),
            cause: Some(value),
        }
    }

    /// A failure with this message, caused by the thrown `value`.
    pub(crate) fn caused(message: impl Into<String>, value: JsValue) -> Failure {
        Failure {
            cause: Some(value),
            ..Failure::new(message)
        }
    }

    /// The message (for tests and for wrapping).
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl std::fmt::Debug for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl<E: std::error::Error> From<E> for Failure {
    fn from(e: E) -> Failure {
        Failure::new(e.to_string())
    }
}

impl From<Failure> for JsValue {
    // One copy for all exports (inlined, it grew every export's shim).
    #[inline(never)]
    fn from(f: Failure) -> JsValue {
        match f.cause {
            None => js_sys::Error::new(&f.message).into(),
            Some(cause) => {
                // `new Error(message, { cause })`: `cause` an own,
                // non-enumerable property, as JS code makes it.
                let options = Object::new();
                // Setting a property of a fresh plain object cannot fail.
                let _ = Reflect::set(&options, &"cause".into(), &cause);
                js_sys::Error::new_with_options(&f.message, &options).into()
            }
        }
    }
}

/// An error with this message (a bad argument, a freed object, a bad
/// snapshot).
pub(crate) fn invalid(msg: impl Into<String>) -> Error {
    Error::Invalid(msg.into())
}

/// Option `key` refused, and why.
pub(crate) fn bad_option(key: &str, reason: impl Into<String>) -> Error {
    Error::BadOption {
        key: key.into(),
        reason: reason.into(),
    }
}
