//! Shared helpers for the integration tests: synthetic scenes with known
//! answers and the invariant checks every detection result must pass.
#![allow(dead_code)]

use glam::{DVec2, DVec3};
use polyscene::cloud::Cloud;
use polyscene::detect::{Detection, NO_PRIMITIVE};
use polyscene::geometry::polygon::{distance, is_simple, signed_area};
use polyscene::geometry::Frame;
use polyscene::params::{HullKind, Params};

use polyscene::internals::Rng;
use polyscene::sim::{Scene, SurfaceKind};

/// Sample the rectangle `origin + s*u + t*v`, s in [0, a], t in [0, b], on a
/// grid of `step` with Gaussian noise `sigma` along `u x v`.
#[allow(clippy::too_many_arguments)]
pub fn rect(
    out: &mut Vec<DVec3>,
    origin: DVec3,
    u: DVec3,
    v: DVec3,
    a: f64,
    b: f64,
    step: f64,
    sigma: f64,
    rng: &mut Rng,
) {
    let n = u.cross(v).normalize();
    let (na, nb) = ((a / step) as usize, (b / step) as usize);
    for i in 0..=na {
        for j in 0..=nb {
            let p = origin + u * (i as f64 * step) + v * (j as f64 * step);
            out.push(p + n * rng.gaussian() * sigma);
        }
    }
}

/// Sample a 2D region (given by `inside`) of the plane with frame `f`.
#[allow(clippy::too_many_arguments)]
pub fn region(
    out: &mut Vec<DVec3>,
    f: &Frame,
    lo: DVec2,
    hi: DVec2,
    step: f64,
    sigma: f64,
    rng: &mut Rng,
    inside: impl Fn(DVec2) -> bool,
) {
    let mut y = lo.y;
    while y <= hi.y {
        let mut x = lo.x;
        while x <= hi.x {
            let q = DVec2::new(x, y);
            if inside(q) {
                out.push(f.to_world(q) + f.normal * rng.gaussian() * sigma);
            }
            x += step;
        }
        y += step;
    }
}

/// Flatten to an f32 xyz buffer.
pub fn flat(points: &[DVec3]) -> Vec<f32> {
    points
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect()
}

/// Build a cloud from world points (f64).
pub fn cloud(points: &[DVec3]) -> Cloud {
    Cloud::from_world_f64(points).expect("finite points")
}

/// Check every invariant of a detection on `cloud`:
/// - unit normals; outlines simple and counter-clockwise (in the frame whose
///   normal is the plane normal);
/// - support points within the RANSAC distance of their plane (plus the
///   small shift of the PCA refit) and inside their outline (within the
///   outline's tolerance);
/// - no point in two primitives and support counts that add up.
pub fn check_invariants(cloud: &Cloud, det: &Detection, p: &Params) {
    assert_eq!(det.labels.len(), cloud.len());
    let mut counts = vec![0u64; det.primitives.len()];
    for (i, prim) in det.primitives.iter().enumerate() {
        let n = prim.plane.normal;
        assert!((n.length() - 1.0).abs() < 1e-9, "normal of {i} not unit");
        assert!(
            (prim.frame.u.cross(prim.frame.v) - n).length() < 1e-9,
            "frame of {i}"
        );
        assert!(is_simple(&prim.outline), "outline of {i} not simple");
        assert!(signed_area(&prim.outline) > 0.0, "outline of {i} not ccw");
        assert!((signed_area(&prim.outline) - prim.area).abs() < 1e-6 * prim.area.max(1.0));
    }
    for (i, &l) in det.labels.iter().enumerate() {
        if l == NO_PRIMITIVE {
            continue;
        }
        let prim = &det.primitives[l as usize];
        counts[l as usize] += 1;
        let w = cloud.world(i);
        let thr = p.surface(prim.ground).distance;
        let d = prim.plane.signed_distance(w).abs();
        assert!(d < thr, "point {i} is {d} m from plane of {l}");
        // Concave outlines pass through the centres of the boundary raster
        // cells and are simplified: support may stick out by up to one raster
        // cell plus the simplification tolerance (the documented resolution).
        // Convex hulls contain their support exactly (unless capped at
        // max_vertices, then within the tolerance).
        let tol_out = match p.hull {
            HullKind::Convex => 1e-6 + p.simplify,
            HullKind::Concave => prim.footprint.cell() + p.simplify + 1e-6,
        };
        let q = prim.frame.to_local(w);
        let out = distance(&prim.outline, q);
        assert!(
            out <= tol_out,
            "point {i} is {out} m outside outline of {l}"
        );
    }
    for (i, prim) in det.primitives.iter().enumerate() {
        assert_eq!(prim.support, counts[i], "support count of {i}");
    }
}

/// How many of the eligible ground-truth surfaces of `kind` the metrics
/// `m` (scored against `scene`'s polygons) count as found, and of how many.
pub fn found_of_kind(
    m: &polyscene::eval::Metrics,
    scene: &Scene,
    kind: SurfaceKind,
) -> (usize, usize) {
    let of_kind = m
        .surfaces
        .iter()
        .filter(|s| s.eligible && scene.polygons[s.id as usize].kind == kind);
    (of_kind.clone().filter(|s| s.found).count(), of_kind.count())
}

/// Points every 0.1 m over `x` x `y` at height `z(x, y)`, with Gaussian
/// height noise `sigma`.
pub fn height_field(
    x: [f64; 2],
    y: [f64; 2],
    sigma: f64,
    seed: u64,
    z: impl Fn(f64, f64) -> f64,
) -> Vec<DVec3> {
    let mut rng = Rng::new(seed);
    let mut pts = Vec::new();
    let mut u = x[0];
    while u <= x[1] {
        let mut v = y[0];
        while v <= y[1] {
            pts.push(DVec3::new(u, v, z(u, v) + sigma * rng.gaussian()));
            v += 0.1;
        }
        u += 0.1;
    }
    pts
}
