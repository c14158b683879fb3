//! What a restored snapshot must satisfy: the state the pipeline could
//! have reached, so that a corrupt or hostile snapshot is refused with a
//! message at [`Scenario::from_json`](super::Scenario::from_json) rather
//! than accepted and left to fail, or to take minutes, at the next scan.
//!
//! Checked per primitive, in order (the first violation is reported):
//!
//! - ids strictly increasing (the primitives sorted by id) and below
//!   `nextId`; `bornScan` at most `lastScan`, which is below `scans`;
//! - the plane: a unit normal (within 1e-6), a finite offset within
//!   [`REACH`] m;
//! - the frame: an origin within [`MAX_COORDINATE`] m of the world origin
//!   in every axis, three orthonormal axes (within 1e-6);
//! - the outline: 3 to `maxVertices` vertices, each finite and, in world
//!   coordinates, within [`REACH`] m; its area, the stored `area`, equal to
//!   the outline's signed area (counter-clockwise, within a relative 1e-9);
//! - the running moments: finite, a count at least 0, a reference point
//!   within [`MAX_COORDINATE`] m;
//! - the footprint: consistent sizes (checked as it is read) and an extent
//!   whose every corner lies within [`REACH`] m in world coordinates.
//!
//! The bounds follow from the pipeline: points lie within
//! [`MAX_COORDINATE`] m, and what is derived from them (outlines grown by
//! a few cells, plane offsets up to |n . p|) within [`REACH`].

use crate::cloud::MAX_COORDINATE;
use crate::error::Sci;
use crate::geometry::polygon::signed_area;
use crate::params::Params;
use crate::primitive::Primitive;
use glam::{DVec2, DVec3};

/// How far from the world origin anything derived from the points may lie
/// (m): twice [`MAX_COORDINATE`], room for an offset |n . p| of a point at
/// the bound (up to sqrt(3) times it) and outlines grown past the points.
pub const REACH: f64 = 2.0 * MAX_COORDINATE;

/// Tolerance on unit lengths and orthogonality.
const UNIT: f64 = 1e-6;

/// Check a snapshot's primitives against its counters and parameters.
pub fn check(prims: &[Primitive], next_id: u32, scans: u64, params: &Params) -> Result<(), String> {
    let mut last_id: Option<u32> = None;
    for p in prims {
        let id = p.id;
        let fail = |what: String| Err(format!("polygon {id}: {what}"));
        if last_id.is_some_and(|l| id <= l) {
            return fail("ids must be unique and sorted in increasing order".into());
        }
        last_id = Some(id);
        if id >= next_id {
            return fail(format!("its id is not below nextId {next_id}"));
        }
        if p.born_scan > p.last_scan || p.last_scan >= scans {
            return fail(format!(
                "bornScan {} and lastScan {} must satisfy bornScan <= lastScan < scans ({scans})",
                p.born_scan, p.last_scan
            ));
        }
        if let Err(e) = check_geometry(p, params) {
            return fail(e);
        }
    }
    Ok(())
}

fn unit(v: DVec3) -> bool {
    v.is_finite() && (v.length() - 1.0).abs() <= UNIT
}

fn within(v: DVec3, bound: f64) -> bool {
    v.is_finite() && v.abs().max_element() <= bound
}

/// The plane, frame, outline, moments and footprint of one primitive.
fn check_geometry(p: &Primitive, params: &Params) -> Result<(), String> {
    let (reach, max) = (Sci(REACH), Sci(MAX_COORDINATE));
    let plane = &p.plane;
    if !unit(plane.normal) || !plane.offset.is_finite() || plane.offset.abs() > REACH {
        return Err(format!(
            "its plane (normal {}, offset {}) must have a unit normal and an offset within {reach} m",
            plane.normal, plane.offset
        ));
    }
    let f = &p.frame;
    let orthonormal = unit(f.u)
        && unit(f.v)
        && unit(f.normal)
        && f.u.dot(f.v).abs() <= UNIT
        && f.u.dot(f.normal).abs() <= UNIT
        && f.v.dot(f.normal).abs() <= UNIT;
    if !within(f.origin, MAX_COORDINATE) || !orthonormal {
        return Err(format!(
            "its frame must have an origin within {max} m and orthonormal axes"
        ));
    }
    let n = p.outline.len();
    if n < 3 || n > params.max_vertices.max(3) {
        return Err(format!(
            "its outline has {n} vertices, expected 3 to maxVertices ({})",
            params.max_vertices
        ));
    }
    for (i, &q) in p.outline.iter().enumerate() {
        if !q.is_finite() || !within(f.to_world(q), REACH) {
            return Err(format!(
                "outline vertex {i} ({}, {}) must be finite and lie within {reach} m of the \
                 world origin",
                q.x, q.y
            ));
        }
    }
    let area = signed_area(&p.outline);
    if !(p.area.is_finite() && p.area >= 0.0 && (p.area - area).abs() <= 1e-9 * area.abs().max(1.0))
    {
        return Err(format!(
            "its area {} must be the area of its outline ({area}, counter-clockwise)",
            p.area
        ));
    }
    let m = &p.moments;
    let finite = m.count.is_finite()
        && m.count >= 0.0
        && m.sum.is_finite()
        && m.sum_sq.iter().all(|x| x.is_finite());
    if !finite || !within(m.reference, MAX_COORDINATE) {
        return Err(format!(
            "its moments must be finite, with a count >= 0 and a reference within \
             {max} m"
        ));
    }
    if let Some((lo, hi)) = p.footprint.extent() {
        for corner in [lo, hi, DVec2::new(lo.x, hi.y), DVec2::new(hi.x, lo.y)] {
            if !within(f.to_world(corner), REACH) {
                return Err(format!(
                    "its footprint reaches ({}, {}) in its frame, beyond {reach} m of the \
                     world origin",
                    corner.x, corner.y
                ));
            }
        }
    }
    Ok(())
}
