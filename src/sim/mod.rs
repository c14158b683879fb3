//! The built-in LiDAR test bed: procedural street scenes with known answers.
//!
//! A [`Scene`] is a set of ground-truth planar polygons ([`GtPolygon`]: road,
//! sidewalks, curbs, facades, doors, walls, vehicle sides, ramps) plus
//! non-planar clutter (poles, tree trunks and crowns). A [`Drive`] moves a
//! simulated Velodyne HDL-64E ([`SensorModel`]) through the scene at about
//! 10 m/s, 10 scans per second, and ray-casts scan `k` on demand: every point
//! comes with the id of the polygon it lies on, or [`CLUTTER`].
//!
//! Everything is deterministic: the same layout, seed, sensor and options give
//! bit-identical scans on every platform (native or wasm), and scan `k` does
//! not depend on which scans were generated before it. Ray casting is exact
//! (noise-free points lie on their polygon to float precision) and fast: a
//! 120k-point HDL-64E scan takes about 3.5 ms on one core (native release).
//!
//! The HDL-64E's highest laser looks 2° up, so from 1.8 m it sees facades
//! only up to a few metres: the upper parts of buildings (and so their
//! stepped rooflines) are in the ground truth but never in the scans.
//!
//! ```
//! use polyscene::sim::{Drive, DriveOptions, Layout, SensorModel};
//! let drive = Drive::new(Layout::Street, 1, SensorModel::default(), DriveOptions::default())?;
//! let scan = drive.scan(0)?;
//! assert_eq!(scan.points.len(), 4 * scan.labels.len());
//! assert!(drive.scene().polygons.len() > 100);
//! # Ok::<(), polyscene::Error>(())
//! ```
//!
//! Datasets on disk (KITTI layout plus labels and ground truth) are written
//! by [`write_dataset`] and read by [`read_dataset`].

mod builder;
mod caster;
mod crossing;
mod dataset;
mod drive;
mod normal;
mod parts;
mod scene;
mod sensor;
mod street;
#[cfg(test)]
mod tests;
mod truth;

pub use builder::Clutter;
pub use dataset::{read_dataset, write_dataset, Dataset, DatasetScan};
pub use drive::{Drive, DriveOptions, Location, Scan, LOCATION_SCANS};
pub use scene::Scene;
pub use sensor::{hdl64_elevations_deg, SensorModel, MAX_RAYS};
pub use truth::{GroundTruth, GtPolygon, Layout, SurfaceKind, CLUTTER};
