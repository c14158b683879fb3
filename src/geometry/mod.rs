//! Geometry primitives: planes and frames, running moments and PCA, 2D
//! polygon operations, convex hulls, occupancy footprints with concave
//! outlines, and triangulation.

pub mod footprint;
pub mod hull;
pub mod mask;
mod numeric;
pub mod plane;
pub mod polygon;
pub mod ring;

pub use footprint::{Footprint, Region};
pub use hull::convex_hull;
pub use numeric::floor_i64;
pub(crate) use numeric::{
    bounds, clamp, grow_box, heap_sort_by, insertion_sort_by, pull_range, unit_or_zero,
};
pub use plane::{Frame, Moments, Plane, UP};
pub use polygon::Polygon3;
