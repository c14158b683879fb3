//! Columnar polygons: every outline of a list of primitives in a few flat
//! arrays, one row per polygon, as deck.gl's binary attributes and
//! GeoArrow-style columns want them (no object per polygon or per vertex).
//!
//! Layout (n polygons, v vertices in all):
//! - `positions`: `x, y, z` per vertex (world, metres, f64), the polygons one
//!   after the other, each ring open (its first vertex is not repeated) and
//!   counter-clockwise seen from the normal side;
//! - `ring_offsets`: n + 1 vertex indices; polygon `i` is vertices
//!   `ring_offsets[i] .. ring_offsets[i + 1]` (deck.gl's `startIndices`, in
//!   vertices; GeoArrow's ring offsets, for rings left open);
//! - `ids`, `areas`, `kinds`: one per polygon; `normals`: `x, y, z` per polygon.
//!
//! ```
//! use polyscene::{cloud::Cloud, detect::detect, flat::{flatten, PolygonKind}, params::Params};
//! // A 10 m x 10 m floor seen from 1.8 m above its centre.
//! let mut pts = Vec::new();
//! for i in 0..100 {
//!     for j in 0..100 {
//!         pts.extend_from_slice(&[i as f32 * 0.1, j as f32 * 0.1, 0.0]);
//!     }
//! }
//! let cloud = Cloud::from_flat(&pts, 3).unwrap();
//! let params = Params { viewpoint: Some([5.0, 5.0, 1.8]), ..Params::gpp2() };
//! let found = detect(&cloud, &params).unwrap();
//! let flat = flatten(&found.primitives);
//! assert_eq!(flat.len(), found.primitives.len());
//! assert_eq!(flat.kinds[0], PolygonKind::Ground as u8);
//! assert_eq!(flat.positions.len(), 3 * flat.ring_offsets[flat.len()] as usize);
//! ```

use crate::primitive::Primitive;

/// What a polygon is, as stored in [`FlatPolygons::kinds`] (`u8`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum PolygonKind {
    /// `0`: the ground (road, sidewalk): [`Primitive::ground`].
    Ground = 0,
    /// `1`: a wall: not ground, normal within [`WALL_MAX_TILT_DEG`] of
    /// horizontal (facades, fences, vehicle sides).
    Wall = 1,
    /// `2`: anything else (roofs, car tops, ramps, slanted surfaces).
    Other = 2,
}

/// Largest angle between a wall's normal and the horizontal plane (degrees).
pub const WALL_MAX_TILT_DEG: f64 = 20.0;

impl PolygonKind {
    /// The kind of a primitive (see the variants).
    pub fn of(p: &Primitive) -> Self {
        if p.ground {
            PolygonKind::Ground
        } else if p.plane.normal.z.abs() <= WALL_MAX_TILT_DEG.to_radians().sin() {
            PolygonKind::Wall
        } else {
            PolygonKind::Other
        }
    }

    /// The kind's name: `"ground"`, `"wall"` or `"other"`.
    pub fn as_str(self) -> &'static str {
        match self {
            PolygonKind::Ground => "ground",
            PolygonKind::Wall => "wall",
            PolygonKind::Other => "other",
        }
    }
}

/// Polygons as columns (see the module documentation for the layout).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlatPolygons {
    /// Vertex `x, y, z` (world, metres), polygon after polygon, rings open.
    pub positions: Vec<f64>,
    /// n + 1 offsets into the vertices (not the numbers): polygon `i` is
    /// vertices `ring_offsets[i] .. ring_offsets[i + 1]`; starts with 0.
    pub ring_offsets: Vec<u32>,
    /// Per polygon: its stable id.
    pub ids: Vec<u32>,
    /// Per polygon: unit normal `x, y, z`.
    pub normals: Vec<f64>,
    /// Per polygon: outline area (m^2).
    pub areas: Vec<f64>,
    /// Per polygon: a [`PolygonKind`] as `u8`.
    pub kinds: Vec<u8>,
}

impl FlatPolygons {
    /// Number of polygons.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// No polygons.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }
}

/// The primitives as columns, in the order given (the scenario's and the
/// detection's lists are sorted by id).
///
/// The vertex count is a `u32`: a list of more than 2^32 - 1 outline vertices
/// (about 100 GB of positions) is cut at the last polygon that fits.
pub fn flatten(prims: &[Primitive]) -> FlatPolygons {
    let total: usize = prims.iter().map(|p| p.outline.len()).sum();
    let mut out = FlatPolygons {
        positions: Vec::with_capacity(3 * total),
        ring_offsets: Vec::with_capacity(prims.len() + 1),
        ids: Vec::with_capacity(prims.len()),
        normals: Vec::with_capacity(3 * prims.len()),
        areas: Vec::with_capacity(prims.len()),
        kinds: Vec::with_capacity(prims.len()),
    };
    out.ring_offsets.push(0);
    let mut count: u32 = 0;
    for p in prims {
        let Some(next) = u32::try_from(p.outline.len())
            .ok()
            .and_then(|n| count.checked_add(n))
        else {
            break;
        };
        for v in p.vertices() {
            out.positions.extend_from_slice(&v.to_array());
        }
        count = next;
        out.ring_offsets.push(count);
        out.ids.push(p.id);
        out.normals.extend_from_slice(&p.plane.normal.to_array());
        out.areas.push(p.area);
        out.kinds.push(PolygonKind::of(p) as u8);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::Cloud;
    use crate::detect::detect;
    use crate::geometry::polygon::signed_area;
    use crate::params::Params;
    use glam::DVec3;

    /// A floor (10 m x 10 m at z = 0), a wall along y = 8 (10 m x 3 m) and a
    /// 45° ramp, seen from (5, 2, 1.8).
    fn scene() -> Vec<Primitive> {
        let mut pts = Vec::new();
        for i in 0..100 {
            for j in 0..70 {
                pts.extend_from_slice(&[i as f32 * 0.1, j as f32 * 0.1, 0.0]);
            }
            for k in 0..30 {
                pts.extend_from_slice(&[i as f32 * 0.1, 8.0, 0.2 + k as f32 * 0.1]);
            }
        }
        for i in 0..40 {
            for j in 0..40 {
                let s = j as f32 * 0.1;
                pts.extend_from_slice(&[-6.0 + i as f32 * 0.1, 1.0 + s, 0.5 + s]);
            }
        }
        let cloud = Cloud::from_flat(&pts, 3).unwrap();
        let params = Params {
            viewpoint: Some([5.0, 2.0, 1.8]),
            ..Params::gpp2()
        };
        detect(&cloud, &params).unwrap().primitives
    }

    #[test]
    fn columns_match_the_primitives() {
        let prims = scene();
        assert!(prims.len() >= 3, "{} primitives", prims.len());
        let flat = flatten(&prims);
        assert_eq!(flat.len(), prims.len());
        assert_eq!(flat.ring_offsets.len(), prims.len() + 1);
        assert_eq!(flat.ring_offsets[0], 0);
        assert_eq!(flat.normals.len(), 3 * prims.len());
        assert_eq!(
            flat.positions.len(),
            3 * *flat.ring_offsets.last().unwrap() as usize
        );
        for (i, p) in prims.iter().enumerate() {
            let (a, b) = (
                flat.ring_offsets[i] as usize,
                flat.ring_offsets[i + 1] as usize,
            );
            assert_eq!(b - a, p.outline.len());
            let ring: Vec<DVec3> = (a..b)
                .map(|k| DVec3::from_slice(&flat.positions[3 * k..3 * k + 3]))
                .collect();
            assert_eq!(ring, p.vertices());
            assert_eq!(flat.ids[i], p.id);
            assert_eq!(flat.areas[i], p.area);
            assert_eq!(&flat.normals[3 * i..3 * i + 3], &p.plane.normal.to_array());
            // The ring's own area, in the polygon's frame, is the area column.
            let local: Vec<_> = ring.iter().map(|&v| p.frame.to_local(v)).collect();
            assert!((signed_area(&local) - p.area).abs() < 1e-6 * p.area.max(1.0));
        }
    }

    #[test]
    fn kinds_tell_ground_walls_and_the_rest() {
        let prims = scene();
        let flat = flatten(&prims);
        let kind_of = |pred: &dyn Fn(&Primitive) -> bool| {
            let i = prims.iter().position(pred).expect("a primitive");
            flat.kinds[i]
        };
        // The floor (largest horizontal), the wall (normal along y), the ramp.
        assert_eq!(
            kind_of(&|p| p.ground && p.area > 50.0),
            PolygonKind::Ground as u8
        );
        assert_eq!(
            kind_of(&|p| p.plane.normal.y.abs() > 0.99 && p.area > 20.0),
            PolygonKind::Wall as u8
        );
        assert_eq!(
            kind_of(&|p| (p.plane.normal.z.abs() - 0.5f64.sqrt()).abs() < 0.05),
            PolygonKind::Other as u8
        );
        assert!(flat.kinds.iter().all(|&k| k <= 2));
        assert_eq!(PolygonKind::Wall.as_str(), "wall");
    }

    #[test]
    fn nothing_in_nothing_out() {
        let flat = flatten(&[]);
        assert!(flat.is_empty());
        assert_eq!(flat.ring_offsets, vec![0]);
        assert!(flat.positions.is_empty() && flat.normals.is_empty());
    }
}
