//! Triangle meshes of the primitives' outlines, ready for a GPU: each outline
//! is triangulated in its own 2D frame by a constrained Delaunay
//! triangulation (spade), the triangles inside the outline are kept, and the
//! vertices are moved to 3D relative to one shared origin so that they fit in
//! `f32` without losing precision far from the world origin.
//!
//! ```
//! use polyscene::{cloud::Cloud, detect::detect, mesh::triangulate, params::Params};
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
//! let mesh = triangulate(&found.primitives);
//! assert_eq!(mesh.polygon_ids.len() * 3, mesh.indices.len());
//! assert!((mesh.area() - found.primitives[0].area).abs() < 1e-3);
//! ```

use crate::primitive::Primitive;
use glam::{DVec2, DVec3};
use spade::handles::{FixedFaceHandle, InnerTag};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::collections::VecDeque;

/// Triangles of many outlines, with flat buffers in the layout WebGL wants.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions `x, y, z` relative to [`Mesh::origin`] (metres).
    pub positions: Vec<f32>,
    /// Three vertex indices per triangle, counter-clockwise seen from the
    /// polygon's normal side.
    pub indices: Vec<u32>,
    /// Per triangle: the id of the primitive it belongs to.
    pub polygon_ids: Vec<u32>,
    /// World position that `positions` are relative to (metres): the first
    /// triangulated primitive's frame origin rounded to whole metres, or zero.
    pub origin: DVec3,
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.polygon_ids.len()
    }

    /// Total area of the triangles (m^2), computed from the `f32` positions.
    pub fn area(&self) -> f64 {
        let p = |i: u32| {
            let k = 3 * i as usize;
            DVec3::new(
                self.positions[k] as f64,
                self.positions[k + 1] as f64,
                self.positions[k + 2] as f64,
            )
        };
        self.indices
            .chunks_exact(3)
            .map(|t| 0.5 * (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).length())
            .sum()
    }
}

/// Triangulate every primitive's outline (see the module docs). Outlines
/// that cannot be triangulated (fewer than three distinct vertices, zero
/// area, non-finite coordinates, self-intersections) are skipped; this never
/// panics.
pub fn triangulate(primitives: &[Primitive]) -> Mesh {
    let mut mesh = Mesh::default();
    let mut origin: Option<DVec3> = None;
    for prim in primitives {
        let frame = &prim.frame;
        let finite_frame = frame.origin.is_finite()
            && frame.u.is_finite()
            && frame.v.is_finite()
            && frame.normal.is_finite();
        if !finite_frame {
            continue;
        }
        let Some(tri) = triangulate_ring(&prim.outline) else {
            continue;
        };
        let o = *origin.get_or_insert_with(|| frame.origin.round());
        let base = (mesh.positions.len() / 3) as u32;
        for &q in &tri.vertices {
            let w = frame.to_world(q) - o;
            mesh.positions
                .extend_from_slice(&[w.x as f32, w.y as f32, w.z as f32]);
        }
        for t in &tri.triangles {
            mesh.indices.extend(t.iter().map(|&i| base + i));
            mesh.polygon_ids.push(prim.id);
        }
    }
    mesh.origin = origin.unwrap_or(DVec3::ZERO);
    mesh
}

/// The triangles of one 2D ring.
#[derive(Clone, Debug, PartialEq)]
pub struct RingTriangles {
    /// The distinct vertices of the ring (in ring order of first appearance).
    pub vertices: Vec<DVec2>,
    /// Counter-clockwise triangles (indices into `vertices`) covering the
    /// inside of the ring.
    pub triangles: Vec<[u32; 3]>,
}

/// Triangulate the inside of a simple ring (either orientation) with a
/// constrained Delaunay triangulation whose constraints are the ring's edges.
/// A triangle is inside when a path from the unbounded face to it crosses an
/// odd number of ring edges. `None` when the ring has fewer than three
/// distinct vertices, a non-finite coordinate, edges that cross, or nothing
/// inside.
pub fn triangulate_ring(ring: &[DVec2]) -> Option<RingTriangles> {
    if ring.len() < 3 || ring.iter().any(|p| !p.is_finite()) {
        return None;
    }
    // Consecutive repeats would become zero-length constraints.
    let mut points: Vec<Point2<f64>> = Vec::with_capacity(ring.len());
    for p in ring {
        if points.last() != Some(&Point2::new(p.x, p.y)) {
            points.push(Point2::new(p.x, p.y));
        }
    }
    while points.len() > 1 && points.first() == points.last() {
        points.pop();
    }
    let n = points.len();
    if n < 3 {
        return None;
    }
    // Built one vertex and one edge at a time, in ring order: spade's bulk
    // loader re-inserts what it skipped in the order of a hash set with a
    // randomly seeded hasher, and nothing in the mesh may depend on that.
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(n);
    for p in points {
        handles.push(cdt.insert(p).ok()?);
    }
    for i in 0..n {
        let (from, to) = (handles[i], handles[(i + 1) % n]);
        // An edge that crosses an earlier one: the ring is not simple.
        if from != to && cdt.try_add_constraint(from, to).is_empty() {
            return None;
        }
    }
    if cdt.num_vertices() < 3 || cdt.num_inner_faces() == 0 {
        return None;
    }
    // 0-1 breadth-first search over the inner faces from the outside: crossing
    // a constraint edge costs 1, so a face's cost is the number of ring edges
    // between it and the unbounded face.
    let mut depth = vec![u32::MAX; cdt.num_all_faces()];
    let mut queue = VecDeque::new();
    fn relax(
        depth: &mut [u32],
        queue: &mut VecDeque<(FixedFaceHandle<InnerTag>, u32)>,
        face: FixedFaceHandle<InnerTag>,
        d: u32,
        cost: u32,
    ) {
        let k = face.index();
        if d + cost < depth[k] {
            depth[k] = d + cost;
            if cost == 0 {
                queue.push_front((face, d));
            } else {
                queue.push_back((face, d + cost));
            }
        }
    }
    for e in cdt.convex_hull() {
        let cost = u32::from(e.is_constraint_edge());
        for side in [e.face(), e.rev().face()] {
            if let Some(inner) = side.as_inner() {
                relax(&mut depth, &mut queue, inner.fix(), 0, cost);
            }
        }
    }
    while let Some((f, d)) = queue.pop_front() {
        if d > depth[f.index()] {
            continue;
        }
        for e in cdt.face(f).adjacent_edges() {
            if let Some(next) = e.rev().face().as_inner() {
                let cost = u32::from(e.is_constraint_edge());
                relax(&mut depth, &mut queue, next.fix(), d, cost);
            }
        }
    }
    let vertices: Vec<DVec2> = cdt
        .vertices()
        .map(|v| DVec2::new(v.position().x, v.position().y))
        .collect();
    let triangles: Vec<[u32; 3]> = cdt
        .inner_faces()
        .filter(|f| depth[f.fix().index()] % 2 == 1)
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    if triangles.is_empty() {
        return None;
    }
    Some(RingTriangles {
        vertices,
        triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polygon::{contains, signed_area};
    use crate::geometry::{Footprint, Frame, Moments, Plane};

    fn tri_area(v: &[DVec2], t: &[u32; 3]) -> f64 {
        let (a, b, c) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
        0.5 * (b - a).perp_dot(c - a)
    }

    fn l_shape() -> Vec<DVec2> {
        [
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ]
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect()
    }

    fn primitive(id: u32, frame: Frame, outline: Vec<DVec2>) -> Primitive {
        Primitive {
            id,
            plane: frame.plane(),
            frame,
            area: signed_area(&outline),
            outline,
            support: 100,
            ground: false,
            moments: Moments::new(frame.origin),
            footprint: Footprint::new(0.2),
            born_scan: 0,
            last_scan: 0,
        }
    }

    #[test]
    fn l_shape_is_covered_exactly_and_nothing_outside() {
        let ring = l_shape();
        let t = triangulate_ring(&ring).unwrap();
        // The convex hull of the L has one more triangle's worth of area:
        // only what is inside is kept.
        let total: f64 = t.triangles.iter().map(|tr| tri_area(&t.vertices, tr)).sum();
        assert!((total - 6.0).abs() < 1e-12, "area {total}");
        assert_eq!(t.triangles.len(), ring.len() - 2);
        for tr in &t.triangles {
            assert!(tri_area(&t.vertices, tr) > 0.0, "counter-clockwise");
            let c = tr.iter().map(|&i| t.vertices[i as usize]).sum::<DVec2>() / 3.0;
            assert!(contains(&ring, c), "centroid {c} outside the L");
        }
        // Clockwise input gives the same, counter-clockwise, triangles.
        let mut cw = ring.clone();
        cw.reverse();
        let t2 = triangulate_ring(&cw).unwrap();
        let total2: f64 = t2
            .triangles
            .iter()
            .map(|tr| tri_area(&t2.vertices, tr))
            .sum();
        assert!((total2 - 6.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_rings_are_skipped() {
        let p = |x: f64, y: f64| DVec2::new(x, y);
        assert!(triangulate_ring(&[]).is_none());
        assert!(triangulate_ring(&[p(0.0, 0.0), p(1.0, 0.0)]).is_none());
        // Collinear, duplicates, a single repeated point.
        assert!(triangulate_ring(&[p(0.0, 0.0), p(1.0, 0.0), p(2.0, 0.0)]).is_none());
        assert!(triangulate_ring(&[p(1.0, 1.0); 5]).is_none());
        // Non-finite.
        assert!(triangulate_ring(&[p(0.0, 0.0), p(f64::NAN, 0.0), p(0.0, 1.0)]).is_none());
        assert!(triangulate_ring(&[p(0.0, 0.0), p(f64::INFINITY, 0.0), p(0.0, 1.0)]).is_none());
        // A bow tie crosses itself.
        let bow = [p(0.0, 0.0), p(2.0, 2.0), p(2.0, 0.0), p(0.0, 2.0)];
        assert!(triangulate_ring(&bow).is_none());
        // Huge and tiny coordinates do not panic.
        let _ = triangulate_ring(&[p(0.0, 0.0), p(1e300, 0.0), p(0.0, 1e300)]);
        let _ = triangulate_ring(&[p(0.0, 0.0), p(1e-300, 0.0), p(0.0, 1e-300)]);
        // A repeated consecutive vertex is harmless.
        let t = triangulate_ring(&[p(0.0, 0.0), p(1.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)]).unwrap();
        assert_eq!(t.triangles.len(), 1);
        // A vertex lying on another edge (the constraint is split) still
        // covers exactly the area.
        let ring = [
            p(0.0, 0.0),
            p(2.0, 0.0),
            p(2.0, 2.0),
            p(1.0, 0.0),
            p(0.0, 2.0),
        ];
        let t = triangulate_ring(&ring).unwrap();
        let total: f64 = t.triangles.iter().map(|tr| tri_area(&t.vertices, tr)).sum();
        assert!((total - signed_area(&ring).abs()).abs() < 1e-9);
    }

    /// The same ring gives the same triangles, in the same order, every
    /// time (spade's bulk loader left part of its order to a randomly
    /// seeded hash set).
    #[test]
    fn the_same_ring_gives_the_same_triangles_every_time() {
        let mut rng = crate::rng::Rng::new(5);
        let mut rings: Vec<Vec<DVec2>> = (0..100)
            .map(|_| {
                let n = 3 + rng.below(200);
                (0..n)
                    .map(|i| {
                        let a = std::f64::consts::TAU * (i as f64 + rng.range(0.0, 0.9)) / n as f64;
                        let r = rng.range(0.2, 5.0);
                        // On a 5 cm grid, as traced outlines are: many
                        // collinear and cocircular vertices.
                        (DVec2::new(r * a.cos(), r * a.sin()) / 0.05).round() * 0.05
                    })
                    .collect()
            })
            .collect();
        rings.retain(|r| triangulate_ring(r).is_some());
        assert!(rings.len() > 50, "{} rings triangulated", rings.len());
        for ring in &rings {
            let first = triangulate_ring(ring).unwrap();
            for _ in 0..3 {
                let again = triangulate_ring(ring).unwrap();
                assert_eq!(again.vertices, first.vertices);
                assert_eq!(again.triangles, first.triangles);
            }
        }
    }

    #[test]
    fn random_star_polygons_and_grid_outlines_are_covered_exactly() {
        let mut rng = crate::rng::Rng::new(11);
        for case in 0..200 {
            let n = 3 + rng.below(60);
            let ring: Vec<DVec2> = (0..n)
                .map(|i| {
                    let a = std::f64::consts::TAU * (i as f64 + rng.range(0.0, 0.9)) / n as f64;
                    let r = rng.range(0.2, 5.0);
                    DVec2::new(r * a.cos(), r * a.sin()) + DVec2::new(1e3, -2e3)
                })
                .collect();
            let t = triangulate_ring(&ring).unwrap_or_else(|| panic!("case {case}"));
            let total: f64 = t.triangles.iter().map(|tr| tri_area(&t.vertices, tr)).sum();
            let want = signed_area(&ring);
            assert!((total - want).abs() < 1e-9 * want.max(1.0), "case {case}");
            assert!(t.triangles.iter().all(|tr| tri_area(&t.vertices, tr) > 0.0));
        }
        // Outlines traced along raster cell edges have many collinear
        // vertices: a staircase.
        let mut ring = vec![DVec2::new(0.0, 0.0)];
        for k in 0..10 {
            let k = k as f64;
            ring.push(DVec2::new(k + 1.0, k));
            ring.push(DVec2::new(k + 1.0, k + 1.0));
        }
        ring.push(DVec2::new(0.0, 10.0));
        let t = triangulate_ring(&ring).unwrap();
        let total: f64 = t.triangles.iter().map(|tr| tri_area(&t.vertices, tr)).sum();
        assert!((total - signed_area(&ring)).abs() < 1e-9);
    }

    #[test]
    fn mesh_is_in_world_coordinates_around_a_shared_origin() {
        // A wall far from the world origin (UTM-like), facing -y, and a floor.
        let far = DVec3::new(500_000.3, 4_500_000.7, 50.2);
        let wall = Frame::on_plane(
            &Plane::from_point_normal(far, DVec3::new(0.0, -1.0, 0.0)),
            far,
        );
        let floor = Frame::on_plane(&Plane::from_point_normal(far, DVec3::Z), far);
        let bad = Frame {
            origin: DVec3::splat(f64::NAN),
            ..floor
        };
        let prims = vec![
            primitive(3, wall, l_shape()),
            primitive(4, bad, l_shape()),
            primitive(9, floor, l_shape()),
            primitive(11, floor, vec![DVec2::ZERO; 3]),
        ];
        let mesh = triangulate(&prims);
        assert_eq!(mesh.origin, far.round());
        assert_eq!(mesh.triangle_count(), 8);
        assert_eq!(mesh.polygon_ids, vec![3, 3, 3, 3, 9, 9, 9, 9]);
        assert_eq!(mesh.indices.len(), 3 * mesh.triangle_count());
        let nv = (mesh.positions.len() / 3) as u32;
        assert!(mesh.indices.iter().all(|&i| i < nv));
        assert!((mesh.area() - 12.0).abs() < 1e-3, "{}", mesh.area());
        // Each triangle faces the way of its polygon's normal, and every
        // vertex is the world position of an outline vertex.
        for (k, t) in mesh.indices.chunks_exact(3).enumerate() {
            let p = |i: u32| {
                let j = 3 * i as usize;
                mesh.origin
                    + DVec3::new(
                        mesh.positions[j] as f64,
                        mesh.positions[j + 1] as f64,
                        mesh.positions[j + 2] as f64,
                    )
            };
            let n = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
            let prim = if mesh.polygon_ids[k] == 3 {
                &prims[0]
            } else {
                &prims[2]
            };
            assert!(n.dot(prim.frame.normal) > 0.0);
            for &i in t {
                let w = p(i);
                assert!(prim.vertices().iter().any(|v| (*v - w).length() < 1e-5));
            }
        }
        assert_eq!(triangulate(&[]), Mesh::default());
    }
}
