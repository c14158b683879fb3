//! Geometry primitives: planes and frames, running moments and PCA, 2D
//! polygon operations, convex hulls, occupancy footprints with concave
//! outlines, and triangulation.

pub mod footprint;
pub mod hull;
pub mod mask;
pub mod plane;
pub mod polygon;

pub use footprint::{Footprint, Region};
pub use hull::convex_hull;
pub use plane::{Frame, Moments, Plane, UP};
pub use polygon::Polygon3;
