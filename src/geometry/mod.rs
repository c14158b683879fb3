//! Geometry primitives: planes and frames, running moments and PCA, 2D
//! polygon operations, hulls and outlines, and triangulation.

pub mod plane;
pub mod polygon;

pub use plane::{Frame, Moments, Plane, UP};
pub use polygon::Polygon3;
