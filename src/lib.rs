//! # polyscene
//!
//! Incremental maps of large planar polygons (road, sidewalks, facades, walls,
//! vehicle sides) from a stream of LiDAR scans, after Oliveira et al.,
//! "Incremental scenario representations for autonomous driving using
//! geometric polygonal primitives" (Robotics and Autonomous Systems, 2016).
// Unsafe code is denied everywhere but in `detect::kernels` (SIMD loads and
// AVX dispatch, measured 1.7-3.3x on the RANSAC scoring loop; see there).
#![deny(unsafe_code)]
#![warn(missing_docs)]

// The rooms of the house, in the order of the pipeline. What a user needs
// is public; the workshop (clocks, hashing, the random generator, the
// command line's logic, merging, rasters) is private, and what the
// project's own tests, benches and binary need of it is in `internals`.
pub mod cloud;
pub mod detect;
pub mod error;
pub mod eval;
pub mod flat;
pub mod geometry;
pub mod io;
pub mod mesh;
pub mod outline;
pub mod params;
pub mod primitive;
pub mod scenario;
pub mod sim;
// The JS binding, in wasm32 builds with either of its features (Cargo.toml).
#[cfg(all(
    target_arch = "wasm32",
    any(feature = "wasm-main", feature = "wasm-sim")
))]
pub mod wasm;

mod clock;
mod floor;
mod hash;
mod merge;
mod primindex;
mod raster;
mod rng;

pub use cloud::Cloud;
pub use detect::{detect, CascadePolicy, Detection, Detector, NO_PRIMITIVE};
pub use error::{Error, Result};
pub use params::{HullKind, Params, SolidityKind, SurfaceParams};
pub use primitive::Primitive;
pub use scenario::{MergeEvent, ScanReport, Scenario};

#[doc(hidden)]
pub mod internals;
