//! Scenes: a layout's ground-truth polygons and clutter, placed in the world.
//! The layout dispatch lives here, above the layouts and their builder.

use super::builder::{Builder, Clutter, Route, Surface};
use super::truth::{self, GtPolygon, Layout, SurfaceKind, CLUTTER};
use super::{crossing, street};
use crate::error::{Error, Result};
use crate::geometry::Polygon3;
use glam::DVec3;

/// A procedural scene: ground-truth polygons, clutter and small non-ground-
/// truth surfaces, in world coordinates (scene-local coordinates plus
/// `origin`).
#[derive(Clone, Debug)]
pub struct Scene {
    /// The layout it was generated from.
    pub layout: Layout,
    /// The seed it was generated from.
    pub seed: u64,
    /// World position of the scene's local origin (metres); the road of the
    /// drive lies at `origin.z`.
    pub origin: DVec3,
    /// Ground-truth polygons; `polygons[i].id == i`.
    pub polygons: Vec<GtPolygon>,
    /// Poles, tree trunks and crowns (world coordinates).
    pub clutter: Vec<Clutter>,
    /// Small planar surfaces that are not ground truth (door reveals, wall
    /// end faces); hits on them are labelled [`CLUTTER`].
    pub minor: Vec<Polygon3>,
    /// Scene-local surfaces with their labels, for the ray caster.
    pub(crate) local: Vec<(u32, Surface)>,
    /// Scene-local clutter, for the ray caster.
    pub(crate) local_clutter: Vec<Clutter>,
    /// The drive's path, scene-local.
    pub(crate) route: Route,
}

impl Scene {
    /// Generate the scene of `layout` and `seed`, placed at `origin` (world
    /// coordinates of its local origin; `DVec3::ZERO` for most uses). Errors
    /// only on a non-finite or huge (beyond 1e9 m) origin.
    pub fn new(layout: Layout, seed: u64, origin: DVec3) -> Result<Scene> {
        if !origin.is_finite() || origin.abs().max_element() > 1e9 {
            return Err(Error::BadOption {
                key: "origin".into(),
                reason: format!("expected finite coordinates within 1e9 m, got {origin}"),
            });
        }
        let mut b = Builder::new(seed);
        let route = match layout {
            Layout::Street => street::build(&mut b),
            Layout::Crossing => crossing::build(&mut b),
        };
        let mut polygons = Vec::new();
        let mut minor = Vec::new();
        let mut local = Vec::new();
        for s in b.surfaces {
            let world: Vec<DVec3> = s.verts.iter().map(|&v| v + origin).collect();
            let Some(poly) = Polygon3::from_world(&world) else {
                continue;
            };
            let label = match s.kind {
                Some(kind) => {
                    let id = polygons.len() as u32;
                    polygons.push(GtPolygon {
                        id,
                        kind,
                        polygon: poly,
                    });
                    id
                }
                None => {
                    minor.push(poly);
                    CLUTTER
                }
            };
            local.push((label, s));
        }
        let clutter = b.clutter.iter().map(|c| c.translated(origin)).collect();
        Ok(Scene {
            layout,
            seed,
            origin,
            polygons,
            clutter,
            minor,
            local,
            local_clutter: b.clutter,
            route,
        })
    }

    /// The ground-truth polygon with label `id`, if any.
    pub fn polygon(&self, id: u32) -> Option<&GtPolygon> {
        self.polygons.get(id as usize)
    }

    /// Number of ground-truth polygons of each kind, in [`SurfaceKind::ALL`]
    /// order.
    pub fn kind_counts(&self) -> Vec<(SurfaceKind, usize)> {
        SurfaceKind::ALL
            .iter()
            .map(|&k| (k, self.polygons.iter().filter(|p| p.kind == k).count()))
            .collect()
    }

    /// The ground truth as JSON: `{"layout", "seed", "polygons": [{"id",
    /// "kind", "normal", "offset", "vertices"}]}` with world vertices in
    /// outline order and `normal · x + offset = 0` on the polygon.
    pub fn ground_truth_json(&self) -> String {
        truth::ground_truth_json(self.layout.as_str(), self.seed, &self.polygons)
    }
}
