//! What the simulator's answers are made of: the layouts, the kinds of
//! ground-truth surface, the ground-truth polygons and the label of clutter,
//! and the ground truth's JSON form (`ground_truth.json`: `{"layout", "seed",
//! "polygons": [{"id", "kind", "normal", "offset", "vertices"}]}`, world
//! coordinates, vertices in outline order, counter-clockwise seen from the
//! normal side, `normal · x + offset = 0`). A leaf: every other module of the
//! simulator builds on it.

use crate::error::{Error, Result};
use crate::geometry::Polygon3;
use glam::DVec3;
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

/// The ground truth of a dataset.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundTruth {
    /// Layout name as written (`"street"`, `"crossing"`).
    pub layout: String,
    /// Seed of the scene.
    pub seed: u64,
    /// Polygons sorted by id; `polygons[i].id == i`.
    pub polygons: Vec<GtPolygon>,
}

#[derive(Serialize, Deserialize)]
struct GtFile {
    layout: String,
    seed: u64,
    polygons: Vec<GtRecord>,
}

#[derive(Serialize, Deserialize)]
struct GtRecord {
    id: u32,
    kind: SurfaceKind,
    normal: [f64; 3],
    offset: f64,
    vertices: Vec<[f64; 3]>,
}

/// The ground-truth JSON text of polygons.
pub(crate) fn ground_truth_json(layout: &str, seed: u64, polygons: &[GtPolygon]) -> String {
    let file = GtFile {
        layout: layout.to_string(),
        seed,
        polygons: polygons
            .iter()
            .map(|p| {
                let plane = p.polygon.plane();
                GtRecord {
                    id: p.id,
                    kind: p.kind,
                    normal: plane.normal.to_array(),
                    offset: plane.offset,
                    vertices: p.polygon.vertices().iter().map(|v| v.to_array()).collect(),
                }
            })
            .collect(),
    };
    // Serialising plain numbers and strings cannot fail.
    serde_json::to_string(&file).unwrap_or_default()
}

/// Parse ground-truth JSON (see [`ground_truth_json`]).
pub(crate) fn parse_ground_truth(text: &str) -> Result<GroundTruth> {
    let file: GtFile =
        serde_json::from_str(text).map_err(|e| Error::Invalid(format!("invalid JSON: {e}")))?;
    let mut polygons = Vec::with_capacity(file.polygons.len());
    for r in file.polygons {
        let verts: Vec<DVec3> = r.vertices.iter().map(|&v| DVec3::from_array(v)).collect();
        let polygon = Polygon3::from_world(&verts).ok_or_else(|| {
            Error::Invalid(format!(
                "polygon {} has fewer than 3 vertices, a non-finite vertex or zero area",
                r.id
            ))
        })?;
        let normal = DVec3::from_array(r.normal);
        if !(normal.is_finite() && r.offset.is_finite()) || normal.dot(polygon.frame.normal) < 0.5 {
            return Err(Error::Invalid(format!(
                "polygon {}: its normal {normal} does not match its vertex order \
                 (counter-clockwise seen from the normal side)",
                r.id
            )));
        }
        polygons.push(GtPolygon {
            id: r.id,
            kind: r.kind,
            polygon,
        });
    }
    polygons.sort_by_key(|p| p.id);
    if let Some((i, p)) = polygons
        .iter()
        .enumerate()
        .find(|(i, p)| p.id as usize != *i)
    {
        return Err(Error::Invalid(format!(
            "polygon ids must be 0 to {} without repeats; found id {} at position {i}",
            polygons.len().saturating_sub(1),
            p.id
        )));
    }
    Ok(GroundTruth {
        layout: file.layout,
        seed: file.seed,
        polygons,
    })
}
