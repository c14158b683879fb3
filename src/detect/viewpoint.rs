//! The rules that need to know where the sensor was: planes seen edge-on
//! and the range-dependent spacing of a LiDAR's rings on the ground.

use crate::geometry::polygon::{contains, distance};
use crate::params::Params;
use crate::primitive::{through_viewpoint, Shaped};
use glam::{DVec2, DVec3};

/// Is this candidate a plane the sensor lies in, away from it? Its plane
/// passes within two inlier distances of the viewpoint, so every ray to it
/// grazes, and the viewpoint's foot point is more than a metre outside its
/// outline (a floor under a sensor standing on it is kept). Such a
/// candidate is the laser rings of the beams near its own elevation,
/// gathered across everything around (horizontal at sensor height, most
/// often); the outline closes them into solid-looking patches, and the
/// arcs they draw on poles and trunks pass the normal-consistency test.
pub(crate) fn seen_edge_on(s: &Shaped, viewpoint: DVec3, p: &Params) -> bool {
    let prim = &s.primitive;
    if !through_viewpoint(prim.plane.signed_distance(viewpoint), p) {
        return false;
    }
    let foot = prim.frame.to_local(viewpoint);
    !contains(&prim.outline, foot) && distance(&prim.outline, foot) > 1.0
}

/// Pull the points farther than `range` from `foot` towards it
/// ([`crate::geometry::pull_range`]; nothing crosses): clustering the pulled
/// points with a fixed tolerance `t` connects, at distance `r`, points
/// `t (r / range)^2` apart along the line from `foot` and about
/// `t r / (2 range)` across it. On the ground, the gap between neighbouring
/// laser rings grows with the square of the range and the spacing along a
/// ring linearly.
pub(crate) fn pull_towards(flat: &mut [DVec2], foot: DVec2, range: f64) {
    for q in flat {
        let d = *q - foot;
        // std sqrt: one instruction in wasm, the same bits everywhere.
        let r = d.length_squared().sqrt();
        if r > range {
            *q = foot + d * (crate::geometry::pull_range(r, range) / r);
        }
    }
}
