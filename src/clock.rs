//! Wall-clock milliseconds for the timing fields of reports. `std::time`
//! does not exist on `wasm32-unknown-unknown`, so the binding installs a
//! clock (`performance.now()`); natively `Instant` is used. Timings are
//! reported, never used for decisions, so results stay deterministic.

use std::sync::OnceLock;

static CLOCK: OnceLock<fn() -> f64> = OnceLock::new();

/// Install the millisecond clock (first call wins). Only the JS binding
/// calls it (wasm32 builds with a binding feature).
#[cfg_attr(
    not(all(
        target_arch = "wasm32",
        any(feature = "wasm-main", feature = "wasm-sim")
    )),
    allow(dead_code)
)]
pub fn install(now_ms: fn() -> f64) {
    let _ = CLOCK.set(now_ms);
}

/// Milliseconds since an arbitrary epoch (0 on wasm until a clock is installed).
pub fn now_ms() -> f64 {
    if let Some(f) = CLOCK.get() {
        return f();
    }
    native_now()
}

#[cfg(not(target_arch = "wasm32"))]
fn native_now() -> f64 {
    use std::time::Instant;
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_secs_f64() * 1e3
}

#[cfg(target_arch = "wasm32")]
fn native_now() -> f64 {
    0.0
}
