//! A few points far from the rest never change the planes found: grids,
//! indices and the local origin are sized from robust extents, and a far
//! point just has no neighbours.

mod common;

use common::*;
use glam::DVec3;
use polyscene::cloud::Cloud;
use polyscene::detect::{detect, Detection};
use polyscene::internals::Rng;
use polyscene::params::Params;
use std::path::Path;

/// The polygons of a detection, for comparison: plane, area and outline
/// in world coordinates.
fn polygons(det: &Detection) -> Vec<(DVec3, f64, f64, Vec<DVec3>)> {
    det.primitives
        .iter()
        .map(|p| (p.plane.normal, p.plane.offset, p.area, p.vertices()))
        .collect()
}

/// `with` is `without` plus outliers: the same polygons (to rounding of
/// the world coordinates) and the same labels for the shared points.
fn assert_same(without: &Detection, with: &Detection, what: &str) {
    let (a, b) = (polygons(without), polygons(with));
    assert!(!a.is_empty(), "{what}: the clean cloud gives polygons");
    assert_eq!(a.len(), b.len(), "{what}: polygon count");
    for (k, (pa, pb)) in a.iter().zip(&b).enumerate() {
        assert!(
            (pa.0 - pb.0).length() < 1e-9,
            "{what}: normal of {k}: {} {}",
            pa.0,
            pb.0
        );
        assert!((pa.1 - pb.1).abs() < 1e-6, "{what}: offset of {k}");
        assert!(
            (pa.2 - pb.2).abs() < 1e-6 * pa.2.max(1.0),
            "{what}: area of {k}"
        );
        assert_eq!(pa.3.len(), pb.3.len(), "{what}: outline of {k}");
        for (va, vb) in pa.3.iter().zip(&pb.3) {
            assert!((*va - *vb).length() < 1e-6, "{what}: vertex of {k}");
        }
    }
    assert_eq!(
        without.labels[..],
        with.labels[..without.labels.len()],
        "{what}: labels"
    );
}

#[test]
fn a_point_1e9_m_away_leaves_a_plane_alone() {
    let mut rng = Rng::new(7);
    let mut pts = Vec::new();
    // 5,151 points on a 10 x 5 m plane, every 10 cm, 5 mm noise.
    rect(
        &mut pts,
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        10.0,
        5.0,
        0.1,
        0.005,
        &mut rng,
    );
    assert!(pts.len() >= 5000, "{}", pts.len());
    let params = Params::gpp2();
    let clean = detect(&Cloud::from_world_f64(&pts).unwrap(), &params).unwrap();
    for far in [
        DVec3::new(1e9, 0.0, 0.0),
        DVec3::new(-1e9, 1e9, 1e9),
        DVec3::new(0.0, 0.0, -3e8),
    ] {
        let mut with = pts.clone();
        with.push(far);
        let det = detect(&Cloud::from_world_f64(&with).unwrap(), &params).unwrap();
        assert_same(&clean, &det, &format!("plane + {far}"));
        assert_eq!(det.labels[pts.len()], polyscene::detect::NO_PRIMITIVE);
    }
}

#[test]
fn a_far_point_leaves_a_real_scan_alone() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("www/data/ouster_os1_64_legacy_f12073.bin");
    let values = polyscene::io::read_bin(&path, 4).expect("the scan is in the repository");
    let params = Params::gpp2();
    let clean = detect(&Cloud::from_flat(&values, 4).unwrap(), &params).unwrap();
    for far in [[1e7f32, 1e7, 1e7, 0.0], [-5e8, 3e8, 1e8, 0.5]] {
        let mut with = values.clone();
        with.extend_from_slice(&far);
        let det = detect(&Cloud::from_flat(&with, 4).unwrap(), &params).unwrap();
        assert_same(&clean, &det, &format!("scan + {far:?}"));
    }
}
