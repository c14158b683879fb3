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

// Native only: the command line (and clap) stay out of the wasm build.
#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
pub mod clock;
pub mod cloud;
pub mod detect;
pub mod error;
pub mod eval;
pub mod geometry;
pub mod hash;
pub mod io;
mod merge;
pub mod mesh;
pub mod outline;
pub mod params;
pub mod primitive;
pub(crate) mod raster;
pub mod rng;
pub mod scenario;
pub mod sim;
#[cfg(target_arch = "wasm32")]
pub mod wasm;

pub use error::{Error, Result};
