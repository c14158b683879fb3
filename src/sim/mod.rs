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

pub use dataset::{read_dataset, write_dataset, Dataset, DatasetScan, GroundTruth};
pub use drive::{Drive, DriveOptions, Location, Scan, LOCATION_SCANS};
pub use scene::{Clutter, Scene};
pub use sensor::{hdl64_elevations_deg, SensorModel, MAX_RAYS};

use crate::error::{Error, Result};
use crate::geometry::Polygon3;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Label of a point that lies on no ground-truth polygon: poles, trees, and
/// small planar surfaces that are not ground truth (door reveals, the end
/// faces of a free-standing wall).
pub const CLUTTER: u32 = u32::MAX;

/// The procedural scene layouts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Layout {
    /// A straight road along +x with raised sidewalks, curbs, a row of
    /// buildings on each side (recessed doors, stepped rooflines, gaps closed
    /// by fences), parked cars, poles and trees.
    Street,
    /// Two roads crossing at right angles: L-shaped corner buildings, a plaza
    /// with a free-standing wall at an odd angle, a ramp leading off one arm,
    /// rows of buildings, parked cars, poles and trees.
    Crossing,
}

impl Layout {
    /// Every layout.
    pub const ALL: [Layout; 2] = [Layout::Street, Layout::Crossing];

    /// The layout's name: `"street"` or `"crossing"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Layout::Street => "street",
            Layout::Crossing => "crossing",
        }
    }
}

impl fmt::Display for Layout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for Layout {
    type Err = Error;

    /// Parse `"street"` or `"crossing"` (case-insensitive, surrounding blanks
    /// ignored); anything else is an [`Error::BadOption`] for `layout`.
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim();
        Layout::ALL
            .into_iter()
            .find(|l| l.as_str().eq_ignore_ascii_case(t))
            .ok_or_else(|| Error::BadOption {
                key: "layout".into(),
                reason: format!("unknown layout '{s}', expected 'street' or 'crossing'"),
            })
    }
}

/// What a ground-truth polygon is (serialised in lowercase).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SurfaceKind {
    /// Road surface (z = 0), normal up.
    Road,
    /// Raised sidewalk top (0.15 m), normal up; it also covers the ground in
    /// the gaps between buildings and a plaza.
    Sidewalk,
    /// Vertical curb face between road and sidewalk, facing the road.
    Curb,
    /// Building wall: front facades (facing the road, with a notch for a
    /// recessed door, possibly a stepped roofline), side walls, roof steps.
    Facade,
    /// A door recessed 0.3 m behind its facade.
    Door,
    /// Free-standing walls and fences, ramp side walls.
    Wall,
    /// A side or the top of a parked car (a box from 0.3 m to about 1.5 m).
    Vehicle,
    /// An inclined driving surface, normal up.
    Ramp,
}

impl SurfaceKind {
    /// Every kind.
    pub const ALL: [SurfaceKind; 8] = [
        SurfaceKind::Road,
        SurfaceKind::Sidewalk,
        SurfaceKind::Curb,
        SurfaceKind::Facade,
        SurfaceKind::Door,
        SurfaceKind::Wall,
        SurfaceKind::Vehicle,
        SurfaceKind::Ramp,
    ];

    /// The lowercase name, as in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            SurfaceKind::Road => "road",
            SurfaceKind::Sidewalk => "sidewalk",
            SurfaceKind::Curb => "curb",
            SurfaceKind::Facade => "facade",
            SurfaceKind::Door => "door",
            SurfaceKind::Wall => "wall",
            SurfaceKind::Vehicle => "vehicle",
            SurfaceKind::Ramp => "ramp",
        }
    }

    /// Is the surface (nearly) horizontal, facing up?
    pub fn is_ground(self) -> bool {
        matches!(
            self,
            SurfaceKind::Road | SurfaceKind::Sidewalk | SurfaceKind::Ramp
        )
    }
}

impl fmt::Display for SurfaceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for SurfaceKind {
    type Err = Error;

    /// Parse a lowercase kind name (case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim();
        SurfaceKind::ALL
            .into_iter()
            .find(|k| k.as_str().eq_ignore_ascii_case(t))
            .ok_or_else(|| Error::BadOption {
                key: "kind".into(),
                reason: format!(
                    "unknown surface kind '{s}', expected one of road, sidewalk, curb, \
                     facade, door, wall, vehicle, ramp"
                ),
            })
    }
}

/// A ground-truth planar polygon of a scene.
///
/// The outline is simple and counter-clockwise seen from the normal side, and
/// the normal faces the open side, where a sensor can see the surface from
/// (up for road, sidewalk and ramp; towards the road for facades and curbs;
/// outwards for vehicle boxes and building side walls).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GtPolygon {
    /// Dense id, `0..scene.polygons.len()`; the point label of hits on it.
    pub id: u32,
    /// What the surface is.
    pub kind: SurfaceKind,
    /// The polygon in world coordinates (metres).
    pub polygon: Polygon3,
}
