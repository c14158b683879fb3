//! Errors at the boundary. Every fallible export returns [`WasmResult`]:
//! its error, a [`JsError`], becomes a thrown JS `Error` whose message is the
//! Rust error's `Display`.
//!
//! `?` converts: [`JsError`] implements `From<E>` for every
//! `E: std::error::Error`, which covers [`crate::Error`] (the core's and the
//! binding's own errors, built with [`invalid`] and [`bad_option`]) and
//! `serde_json::Error`. So the binding's helpers return
//! [`crate::error::Result`] and the exports `?` them.

pub use wasm_bindgen::JsError;

use crate::error::Error;

/// What every fallible export returns: the error becomes a thrown JS `Error`.
pub type WasmResult<T> = Result<T, JsError>;

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
