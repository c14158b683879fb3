//! Simulated drives: a trajectory through a scene and the scans along it.

use super::caster::Caster;
use super::scene::Scene;
use super::sensor::{Beams, SensorModel};
use super::truth::Layout;
use crate::error::{Error, Result};
use crate::rng::Rng;
use glam::{DMat4, DVec3, DVec4};

/// Scans accumulated by a "location" by default (as in the paper: one
/// location is about 10 consecutive scans, about 1.2 million points).
pub const LOCATION_SCANS: usize = 10;

/// Options of a [`Drive`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DriveOptions {
    /// World position of the scene's local origin, metres; default zero. Set
    /// it far away (e.g. UTM-like `(500000, 4500000, 50)`) to test large
    /// coordinates: the scans in the sensor frame do not change, only the
    /// poses and the ground truth move.
    pub origin: DVec3,
    /// Distance driven between scans, metres; default 1.0 (10 m/s at 10 Hz).
    /// Must be in `[0.05, 10]`.
    pub step: f64,
}

impl Default for DriveOptions {
    fn default() -> Self {
        DriveOptions {
            origin: DVec3::ZERO,
            step: 1.0,
        }
    }
}

/// One simulated scan.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    /// Points `x, y, z, intensity` (stride 4) in the sensor frame (metres;
    /// intensity in `[0, 1]`).
    pub points: Vec<f32>,
    /// World-from-sensor pose (rigid; the sensor's z axis is vertical).
    pub pose: DMat4,
    /// Per point: the id of the ground-truth polygon it lies on, or
    /// [`CLUTTER`](super::CLUTTER).
    pub labels: Vec<u32>,
}

impl Scan {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// No points?
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// World coordinates of the points (f64, through the pose).
    pub fn world_points(&self) -> Vec<DVec3> {
        self.points
            .chunks_exact(4)
            .map(|p| {
                self.pose
                    .transform_point3(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
            })
            .collect()
    }
}

/// Consecutive scans accumulated in the world frame (a "location").
#[derive(Clone, Debug, PartialEq)]
pub struct Location {
    /// Index of the first scan.
    pub start: usize,
    /// World coordinates of all points, scan after scan (metres).
    pub points: Vec<DVec3>,
    /// Intensity of each point, in `[0, 1]`.
    pub intensities: Vec<f32>,
    /// Label of each point (polygon id or [`CLUTTER`](super::CLUTTER)).
    pub labels: Vec<u32>,
    /// World-from-sensor pose of each scan.
    pub poses: Vec<DMat4>,
}

impl Location {
    /// The mean position of the scans' poses, a viewpoint to detect the
    /// location from as if one scan had seen it all. It stands for none of
    /// them: [`crate::detect::detect_from`] with every pose's position
    /// judges the location as the map it is.
    pub fn viewpoint(&self) -> DVec3 {
        crate::io::mean_position(&self.poses).unwrap_or(DVec3::ZERO)
    }
}

/// A simulated drive: a scene, a sensor and a trajectory at about 10 m/s,
/// with scan `k` generated on demand (independently of other scans: its
/// noise comes from `Rng::derive(seed, k)`).
#[derive(Clone, Debug)]
pub struct Drive {
    scene: Scene,
    sensor: SensorModel,
    options: DriveOptions,
    beams: Beams,
    caster: Caster,
    len: usize,
}

impl Drive {
    /// Generate the scene of `layout` and `seed` and prepare the drive.
    /// Errors on an invalid sensor model or options.
    pub fn new(
        layout: Layout,
        seed: u64,
        sensor: SensorModel,
        options: DriveOptions,
    ) -> Result<Drive> {
        sensor.validate()?;
        if !(options.step.is_finite() && (0.05..=10.0).contains(&options.step)) {
            return Err(Error::BadOption {
                key: "step".into(),
                reason: format!("expected 0.05 to 10 metres per scan, got {}", options.step),
            });
        }
        let scene = Scene::new(layout, seed, options.origin)?;
        let caster = Caster::new(&scene);
        let beams = Beams::new(&sensor);
        let len = libm::floor(scene.route.length / options.step + 1e-9) as usize + 1;
        Ok(Drive {
            scene,
            sensor,
            options,
            beams,
            caster,
            len,
        })
    }

    /// The scene driven through.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The sensor model.
    pub fn sensor(&self) -> &SensorModel {
        &self.sensor
    }

    /// The options.
    pub fn options(&self) -> &DriveOptions {
        &self.options
    }

    /// Number of scans of the drive (200 for both layouts at 1 m per scan).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Never true: a drive has at least one scan.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn check(&self, k: usize) -> Result<()> {
        if k < self.len {
            Ok(())
        } else {
            Err(Error::BadOption {
                key: "scan".into(),
                reason: format!(
                    "scan {k} is out of range: this drive has {} scans (0 to {})",
                    self.len,
                    self.len - 1
                ),
            })
        }
    }

    /// Scene-local sensor position and heading `(cos, sin)` of scan `k`.
    fn local_pose(&self, k: usize) -> (DVec3, (f64, f64)) {
        let (p, yaw) = self.scene.route.at(k as f64 * self.options.step);
        let pos = p + DVec3::Z * self.sensor.mount_height;
        (pos, (libm::cos(yaw), libm::sin(yaw)))
    }

    /// World-from-sensor pose of scan `k`.
    pub fn pose(&self, k: usize) -> Result<DMat4> {
        self.check(k)?;
        let (pos, (c, s)) = self.local_pose(k);
        Ok(DMat4::from_cols(
            DVec4::new(c, s, 0.0, 0.0),
            DVec4::new(-s, c, 0.0, 0.0),
            DVec4::new(0.0, 0.0, 1.0, 0.0),
            (pos + self.scene.origin).extend(1.0),
        ))
    }

    /// All poses, in scan order.
    pub fn poses(&self) -> Vec<DMat4> {
        (0..self.len).filter_map(|k| self.pose(k).ok()).collect()
    }

    /// Simulate scan `k` (`0..len()`).
    pub fn scan(&self, k: usize) -> Result<Scan> {
        let pose = self.pose(k)?;
        let (pos, yaw) = self.local_pose(k);
        let mut rng = Rng::derive(self.scene.seed, k as u64);
        let cast = self
            .caster
            .cast(&self.beams, &self.sensor, pos, yaw, &mut rng);
        Ok(Scan {
            points: cast.points,
            pose,
            labels: cast.labels,
        })
    }

    /// Every scan in order, simulated lazily.
    pub fn scans(&self) -> impl ExactSizeIterator<Item = Scan> + '_ {
        ScanIter {
            drive: self,
            next: 0,
        }
    }

    /// Scans `start .. start + count` accumulated in the world frame (use
    /// [`LOCATION_SCANS`] for `count` to follow the paper).
    pub fn location(&self, start: usize, count: usize) -> Result<Location> {
        let end = start.saturating_add(count);
        if count == 0 || end > self.len {
            return Err(Error::BadOption {
                key: "location".into(),
                reason: format!(
                    "scans {start}..{end} are not a non-empty range within the drive's {} scans",
                    self.len
                ),
            });
        }
        let mut loc = Location {
            start,
            points: Vec::new(),
            intensities: Vec::new(),
            labels: Vec::new(),
            poses: Vec::with_capacity(count),
        };
        for k in start..end {
            let scan = self.scan(k)?;
            loc.points.extend(scan.world_points());
            loc.intensities
                .extend(scan.points.chunks_exact(4).map(|p| p[3]));
            loc.labels.extend_from_slice(&scan.labels);
            loc.poses.push(scan.pose);
        }
        Ok(loc)
    }
}

/// Iterator over a drive's scans.
struct ScanIter<'a> {
    drive: &'a Drive,
    next: usize,
}

impl Iterator for ScanIter<'_> {
    type Item = Scan;

    fn next(&mut self) -> Option<Scan> {
        let scan = self.drive.scan(self.next).ok()?;
        self.next += 1;
        Some(scan)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.drive.len.saturating_sub(self.next);
        (n, Some(n))
    }
}

impl ExactSizeIterator for ScanIter<'_> {}
