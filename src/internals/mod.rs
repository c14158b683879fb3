//! Internals that the project's own binary, tests and benchmarks use. Not
//! part of the library's API: they change without notice.

// Native only: the command line (and clap) stay out of the wasm build.
#[cfg(not(target_arch = "wasm32"))]
pub mod cli;

pub use crate::detect::kernels;
pub use crate::geometry::floor_i64;
pub use crate::rng::Rng;
