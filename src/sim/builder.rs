//! The scene builder the layouts draw with: scene-local surfaces and
//! clutter, the placement helpers, and the drive's route. A leaf below the
//! layouts (`street`, `crossing`, `parts`) and the scene that runs them.

use super::truth::SurfaceKind;
use crate::rng::Rng;
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// Stream number of the scene generator's RNG (scans use their index).
const SCENE_STREAM: u64 = 0x5CE9_E000_0000_0001;

/// A non-planar object of a scene. Points on clutter are labelled
/// [`CLUTTER`](super::CLUTTER).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Clutter {
    /// A vertical cylindrical pole (street light, traffic sign).
    Pole {
        /// Centre of the bottom disc, world (metres).
        base: DVec3,
        /// Radius, metres.
        radius: f64,
        /// Height above `base`, metres.
        height: f64,
    },
    /// A vertical cylindrical tree trunk.
    Trunk {
        /// Centre of the bottom disc, world (metres).
        base: DVec3,
        /// Radius, metres.
        radius: f64,
        /// Height above `base`, metres.
        height: f64,
    },
    /// A spherical tree crown.
    Crown {
        /// Centre, world (metres).
        centre: DVec3,
        /// Radius, metres.
        radius: f64,
    },
}

impl Clutter {
    pub(crate) fn translated(self, d: DVec3) -> Clutter {
        match self {
            Clutter::Pole {
                base,
                radius,
                height,
            } => Clutter::Pole {
                base: base + d,
                radius,
                height,
            },
            Clutter::Trunk {
                base,
                radius,
                height,
            } => Clutter::Trunk {
                base: base + d,
                radius,
                height,
            },
            Clutter::Crown { centre, radius } => Clutter::Crown {
                centre: centre + d,
                radius,
            },
        }
    }
}

/// Length of the drive along the road, metres (200 scans at 1 m): the
/// street's, and the crossing's along its long arm.
pub(crate) const DRIVE_LENGTH: f64 = 199.0;

/// A planar surface of the scene in scene-local coordinates (before the
/// origin offset), outline oriented so that its Newell normal faces the open
/// side. `kind: None` marks a small surface that is not ground truth.
#[derive(Clone, Debug)]
pub(crate) struct Surface {
    pub kind: Option<SurfaceKind>,
    pub verts: Vec<DVec3>,
}

/// The path the vehicle drives, in scene-local coordinates: along +x from
/// `x0` for `length` metres, at `y = lane_y + amp sin(2π (x - x0) / wavelength
/// + phase)`, on a road at z = 0.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Route {
    pub x0: f64,
    pub length: f64,
    pub lane_y: f64,
    pub amp: f64,
    pub wavelength: f64,
    pub phase: f64,
}

impl Route {
    /// Position (z = 0) and yaw at distance `s` along x.
    pub fn at(&self, s: f64) -> (DVec3, f64) {
        let k = std::f64::consts::TAU / self.wavelength;
        let a = k * s + self.phase;
        let y = self.lane_y + self.amp * libm::sin(a);
        let slope = self.amp * k * libm::cos(a);
        (DVec3::new(self.x0 + s, y, 0.0), libm::atan(slope))
    }
}

/// A rigid 2D placement of a local `(u, v)` frame in the scene's xy plane
/// (rotation and translation; z is unchanged).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Place {
    c: f64,
    s: f64,
    t: DVec2,
}

impl Place {
    /// Rotation by `k` quarter turns (exact) then translation by `t`.
    pub fn quarter(k: u32, t: DVec2) -> Place {
        let (c, s) = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][(k % 4) as usize];
        Place { c, s, t }
    }

    /// Rotation by `angle` radians then translation by `t`.
    pub fn rotation(angle: f64, t: DVec2) -> Place {
        Place {
            c: libm::cos(angle),
            s: libm::sin(angle),
            t,
        }
    }

    /// The scene xy of local `(u, v)`.
    pub fn xy(&self, u: f64, v: f64) -> DVec2 {
        DVec2::new(
            self.c * u - self.s * v + self.t.x,
            self.s * u + self.c * v + self.t.y,
        )
    }

    /// The scene point of local `(u, v)` at height `z`.
    pub fn at(&self, u: f64, v: f64, z: f64) -> DVec3 {
        self.xy(u, v).extend(z)
    }

    /// A horizontal scene direction of local direction `(du, dv)`.
    pub fn dir(&self, du: f64, dv: f64) -> DVec3 {
        DVec3::new(self.c * du - self.s * dv, self.s * du + self.c * dv, 0.0)
    }

    /// This placement applied after `inner`: local coordinates of `inner`
    /// map through `inner`, then through `self`.
    pub fn after(&self, inner: &Place) -> Place {
        Place {
            c: self.c * inner.c - self.s * inner.s,
            s: self.s * inner.c + self.c * inner.s,
            t: self.xy(inner.t.x, inner.t.y),
        }
    }
}

/// Newell normal (not normalised) of a vertex ring.
pub(crate) fn newell(verts: &[DVec3]) -> DVec3 {
    let n = verts.len();
    if n == 0 {
        return DVec3::ZERO;
    }
    let c = verts.iter().copied().sum::<DVec3>() / n as f64;
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        normal += (verts[i] - c).cross(verts[(i + 1) % n] - c);
    }
    normal
}

/// Remove repeated vertices, straight-through vertices and spikes.
fn clean_ring(verts: &mut Vec<DVec3>) {
    let mut changed = true;
    while changed && verts.len() >= 3 {
        changed = false;
        let n = verts.len();
        let mut out: Vec<DVec3> = Vec::with_capacity(n);
        for i in 0..n {
            let prev = match out.last() {
                Some(&p) => p,
                None => verts[(i + n - 1) % n],
            };
            let cur = verts[i];
            let next = verts[(i + 1) % n];
            let (a, b) = (cur - prev, next - cur);
            let scale = a.length() * b.length();
            if a.length_squared() < 1e-18 || a.cross(b).length() <= 1e-12 * scale {
                changed = true;
                continue;
            }
            out.push(cur);
        }
        *verts = out;
    }
}

/// Collects a layout's surfaces and clutter.
pub(crate) struct Builder {
    pub rng: Rng,
    pub surfaces: Vec<Surface>,
    pub clutter: Vec<Clutter>,
}

impl Builder {
    pub fn new(seed: u64) -> Self {
        Builder {
            rng: Rng::derive(seed, SCENE_STREAM),
            surfaces: Vec::new(),
            clutter: Vec::new(),
        }
    }

    /// Add a planar surface; the outline is reversed if needed so that its
    /// normal has a positive component along `toward`. Degenerate outlines
    /// are dropped.
    pub fn add(&mut self, kind: Option<SurfaceKind>, mut verts: Vec<DVec3>, toward: DVec3) {
        clean_ring(&mut verts);
        if verts.len() < 3 {
            return;
        }
        let n = newell(&verts);
        if n.length_squared() <= 1e-18 {
            return;
        }
        if n.dot(toward) < 0.0 {
            verts.reverse();
        }
        self.surfaces.push(Surface { kind, verts });
    }

    /// Add a horizontal surface (normal up) from an xy outline at height `z`.
    pub fn add_flat(&mut self, kind: SurfaceKind, ring: &[DVec2], z: f64) {
        let verts = ring.iter().map(|p| p.extend(z)).collect();
        self.add(Some(kind), verts, DVec3::Z);
    }

    /// Add a vertical rectangle over the segment `a b` (scene xy) from `z0`
    /// to `z1`, facing `toward`.
    pub fn add_wall(
        &mut self,
        kind: Option<SurfaceKind>,
        a: DVec2,
        b: DVec2,
        z0: f64,
        z1: f64,
        toward: DVec3,
    ) {
        let verts = vec![a.extend(z0), b.extend(z0), b.extend(z1), a.extend(z1)];
        self.add(kind, verts, toward);
    }

    /// Add a box over a counter-clockwise xy footprint from `z0` to `z1`:
    /// its vertical sides (outward normals) and its top; the bottom is not
    /// added (no sensor can see it from above the ground).
    pub fn add_box(&mut self, kind: Option<SurfaceKind>, footprint: &[DVec2], z0: f64, z1: f64) {
        let n = footprint.len();
        for i in 0..n {
            let (a, b) = (footprint[i], footprint[(i + 1) % n]);
            let e = b - a;
            let out = DVec3::new(e.y, -e.x, 0.0);
            self.add_wall(kind, a, b, z0, z1, out);
        }
        let top = footprint.iter().map(|p| p.extend(z1)).collect();
        self.add(kind, top, DVec3::Z);
    }

    pub fn pole(&mut self, base: DVec3, radius: f64, height: f64) {
        self.clutter.push(Clutter::Pole {
            base,
            radius,
            height,
        });
    }

    pub fn tree(&mut self, base: DVec3, trunk_radius: f64, trunk_height: f64, crown_radius: f64) {
        let centre_z = trunk_height + 0.7 * crown_radius;
        self.clutter.push(Clutter::Trunk {
            base,
            radius: trunk_radius,
            height: centre_z,
        });
        self.clutter.push(Clutter::Crown {
            centre: base + DVec3::Z * centre_z,
            radius: crown_radius,
        });
    }
}
