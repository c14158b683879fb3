//! The one parameter set of the pipeline, with units and defaults, and the
//! paper's two configurations as presets.
//!
//! The paper names its two configurations GPP 1 ("only very large polygons,
//! faster") and GPP 2 ("small polygons too"). The authors' public code uses
//! RANSAC distances of 0.3 m (ground) and 0.2 m (other planes), a Euclidean
//! cluster tolerance of 0.9 m, acceptance above 7 m^2 and 48 points/m^2, and
//! expansion steps of 15 m along / 0.3 m across for the ground and 0.2 m along
//! / 0.5 m across for other primitives. Those values were tuned for 2007-era
//! HDL-64E data; the defaults here were re-measured on the simulated HDL-64E
//! scans and the real Ouster scans (see BENCHMARKS.md), and every departure is
//! noted on its field.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// How a primitive's outline is computed (the methods live in
/// [`crate::outline`]).
pub use crate::outline::HullKind;

/// How "solidity", the paper's second acceptance test, is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SolidityKind {
    /// Support points per square metre of polygon (what the authors' code
    /// does). Depends on range and sensor: a wall at 50 m has far fewer
    /// points per m^2 than one at 10 m.
    Density,
    /// Share of the polygon's area whose raster cells hold a support point.
    /// Scale-free as long as the point spacing is below the cell size.
    Occupancy,
}

/// Every tunable of detection and expansion. Distances in metres, areas in
/// square metres, angles in degrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields, default)]
pub struct Params {
    // --- RANSAC plane search ---
    /// Inlier distance to a plane for non-ground planes (m). Default 0.10
    /// (authors: 0.2, for noisier data; 0.2 swallows curbs and door recesses).
    pub distance: f64,
    /// Inlier distance for ground planes (m). Default 0.08, below half a
    /// curb (authors: 0.3, which merges the road with 0.15 m high sidewalks).
    pub ground_distance: f64,
    /// Largest tilt from horizontal for a plane to count as ground (deg).
    /// Default 15.
    pub ground_max_tilt: f64,
    /// Ground lies at least this far below the sensor (m); a horizontal
    /// plane higher up (a car's roof or bonnet, a table) is an ordinary
    /// primitive. Default 1.3 (sensors on a car roof sit 1.7-2 m up).
    pub ground_depth: f64,
    /// Sensor position for one-shot detection (world, m): normals of
    /// non-horizontal planes point towards it, it decides what is ground,
    /// and a plane through it (seen edge-on: laser rings) is dropped unless
    /// it reaches within 1 m of it; one-shot detection does not even try
    /// such a plane unless 10 of its points lie within 1.5 m of the
    /// viewpoint. Default `[0, 0, 0]`: a scan in its own sensor frame. The
    /// scenario uses each scan's pose instead.
    pub viewpoint: [f64; 3],
    /// Fewest inliers a plane needs, and fewest support points a primitive
    /// needs; the cascade stops when the best plane has fewer. gpp2 default
    /// 150, gpp1 400.
    pub min_inliers: usize,
    /// Most plane hypotheses scored per round of one-shot detection (a
    /// bound on work). Default 200. The scenario's detection on each scan's
    /// leftover points, whose sampler keeps sliver triples, scores up to
    /// twice as many. A longer search is not a better one here: with 400,
    /// one-shot detection took 1.6 times the work on the real scans and
    /// mapped less of the simulated locations (completeness 0.854 against
    /// 0.867 over eight seeds).
    pub max_hypotheses: usize,
    /// Confidence that the best plane was sampled, for the adaptive stop
    /// (0..1). Default 0.995.
    pub confidence: f64,
    /// Radius of the neighbourhood the 2nd and 3rd sample points are drawn
    /// from (m). Default 1.0.
    pub sample_radius: f64,
    /// Seed of the random generator; same seed, same result. Default 7.
    pub seed: u64,

    // --- Clustering ---
    /// Euclidean clustering tolerance (m): inliers of a non-ground plane
    /// closer than this (measured in the plane) are connected. Default 0.5
    /// (authors: 0.9, for every plane; 0.9 joins uniform clutter inside a
    /// plane's slab into one sheet).
    pub cluster_tolerance: f64,
    /// Euclidean clustering tolerance for ground planes (m). The ground is
    /// seen at grazing angles: its laser rings lie farther apart with range
    /// (a metre apart 20 m out for an HDL-64E), and a tight tolerance cuts a
    /// road into a polygon per group of rings, or drops the far rings.
    /// Default 0.5, as for other planes; one-shot detection lets it grow
    /// beyond `groundClusterRange`. 1.0 (the ground outline's radius) was
    /// better for one-shot detection with the paper's cascade (simulated
    /// scans and locations: higher recall and completeness, lower error,
    /// fewer rounds; see BENCHMARKS.md, session 5) but costs the incremental
    /// scenario some sidewalk and curb coverage.
    pub ground_cluster_tolerance: f64,
    /// Range (m) beyond which the ground's clustering tolerance grows with
    /// range (measured in the ground plane from the point under the
    /// viewpoint), as the gaps between laser rings do: at range `r` it is
    /// `groundClusterTolerance * (r / groundClusterRange)^2` along the
    /// line of sight and about `groundClusterTolerance * r / (2 *
    /// groundClusterRange)` across it (the points are clustered after
    /// pulling them towards the viewpoint, `r -> 2R - R^2 / r` beyond `R`).
    /// So the far rings of a road stay one surface. Default 20; a value
    /// beyond the cloud's extent turns it off. One-shot detection only: the
    /// scenario detects its leftovers with the paper's cascade and fixed
    /// tolerances (with this growth there it measured neutral, see
    /// BENCHMARKS.md, session 8). The ground's footprint then fills the
    /// gaps along the line of sight that this clustering bridged (those
    /// wider than `groundAlpha`'s closing fills), so its outline follows
    /// every ring the clustering joined.
    pub ground_cluster_range: f64,

    // --- Outline ---
    /// Convex or concave outlines. Default concave.
    pub hull: HullKind,
    /// Concave outline radius for non-ground primitives (m): gaps and notches
    /// narrower than `2 * alpha` are filled. Default 0.5.
    pub alpha: f64,
    /// Concave outline radius for ground primitives (m); the ground is seen
    /// at grazing angles with wide gaps between laser rings. Default 1.0.
    pub ground_alpha: f64,
    /// Raster cell size of footprints (m): the resolution of concave
    /// outlines; the occupancy test counts blocks of 2 x 2 cells. Default
    /// 0.2.
    pub cell: f64,
    /// Raster cell size of ground footprints (m): the ground is large and
    /// seen at grazing angles; a coarser cell makes its outline cheaper.
    /// Default 0.2.
    pub ground_cell: f64,
    /// Outline simplification tolerance (m). Default 0.1.
    pub simplify: f64,
    /// Most vertices of an outline (the tolerance is raised to meet it).
    /// Default 256: a simulated location's road takes 100-120 at the
    /// default tolerance, and a sidewalk mapped over a whole drive more;
    /// with 64 their raised tolerance cut corners, across the road's edge
    /// and through the buildings behind a sidewalk.
    pub max_vertices: usize,

    // --- Acceptance ---
    /// Smallest polygon area accepted (m^2), the paper's A_t. gpp2 default
    /// 1.5, gpp1 7 (authors).
    pub min_area: f64,
    /// Smallest width of a polygon (m), across its narrowest direction:
    /// rejects the thin strips a plane cuts out of a crossing surface.
    /// Default 0.4.
    pub min_width: f64,
    /// Largest RMS distance of the support from its plane, as a fraction of
    /// the inlier distance. A real surface sits within the sensor noise;
    /// points spread evenly through the inlier slab (a plane slicing through
    /// objects) give about 0.58. Default 0.45.
    pub max_roughness: f64,
    /// Least share of the support's local patches (cells of `2 * cell`)
    /// whose own normal agrees with the plane's within 15 degrees. A plane
    /// cutting through crossing surfaces (a horizontal slab through parked
    /// cars' sides) collects points whose local normals are perpendicular to
    /// it. Default 0.6.
    pub min_normal_consistency: f64,
    /// Which solidity test to apply. Default occupancy.
    pub solidity: SolidityKind,
    /// Least support points per m^2 with `solidity: density`. Default 48
    /// (authors).
    pub min_density: f64,
    /// Least occupied share of the area with `solidity: occupancy` (0..1):
    /// the share of the outline's area in blocks of 2 x 2 footprint cells
    /// that hold support (a far facade's laser rings lie more than a cell
    /// apart). Default 0.5.
    pub min_occupancy: f64,

    // --- Cascade budget ---
    /// Most primitives one detection returns. gpp2 default 200, gpp1 60.
    pub max_primitives: usize,
    /// The cascade stops after this many rounds in a row accepted nothing
    /// (none of the round's plane's clusters: what is left is clutter).
    /// Default 10.
    pub max_rejections: usize,
    /// Work budget of one detection, in point-to-plane distance evaluations
    /// (about a nanosecond each natively). Default 2e9.
    pub max_work: u64,

    // --- Expansion (incremental update) ---
    /// Grow existing primitives with each scan before detecting new ones.
    /// Default true; false gives the paper's "without expansion" mode.
    pub expansion: bool,
    /// Perpendicular gate of expansion, ground (m): at most this, and at
    /// most three times the primitive's own RMS residual (never below
    /// 0.03 m), so a primitive takes what continues it, not the edges of
    /// surfaces crossing it. Default 0.08 (authors 0.3, which swallows
    /// 0.15 m curbs).
    pub ground_expand_across: f64,
    /// Longitudinal growth reach per step, ground (m). Default 2.0 (authors
    /// 15, with a convex hull; with connectivity-based growth a smaller
    /// reach avoids jumping onto unrelated surfaces at the same height).
    pub ground_expand_along: f64,
    /// Perpendicular gate of expansion, other primitives (m), adapted to the
    /// primitive's residual like the ground's. Default 0.08 (authors 0.5).
    pub expand_across: f64,
    /// Longitudinal growth reach per step, other primitives (m). Default 0.6
    /// (authors 0.2).
    pub expand_along: f64,
    /// Largest angle between two primitives' planes for a merge (deg):
    /// the scenario's after every scan, and one-shot detection's final
    /// pass over the pieces it found. Default 8.
    pub merge_angle: f64,
    /// Largest RMS distance of the smaller primitive's outline vertices and
    /// centroid from the larger one's plane for a merge (m); keep it below
    /// the height of a curb. Default 0.08.
    pub merge_distance: f64,
    /// Outlines closer than this are "touching" for a merge (m). Default 0.3.
    pub merge_gap: f64,
}

impl Default for Params {
    fn default() -> Self {
        Params::gpp2()
    }
}

impl Params {
    /// The paper's GPP 2: small polygons too, more accurate, slower.
    pub fn gpp2() -> Self {
        Params {
            distance: 0.10,
            ground_distance: 0.08,
            ground_max_tilt: 15.0,
            ground_depth: 1.3,
            viewpoint: [0.0; 3],
            min_inliers: 150,
            max_hypotheses: 200,
            confidence: 0.995,
            sample_radius: 1.0,
            seed: 7,
            cluster_tolerance: 0.5,
            ground_cluster_tolerance: 0.5,
            ground_cluster_range: 20.0,
            hull: HullKind::Concave,
            alpha: 0.5,
            ground_alpha: 1.0,
            cell: 0.2,
            ground_cell: 0.2,
            simplify: 0.1,
            max_vertices: 256,
            min_area: 1.5,
            min_width: 0.4,
            max_roughness: 0.45,
            min_normal_consistency: 0.6,
            solidity: SolidityKind::Occupancy,
            min_density: 48.0,
            min_occupancy: 0.5,
            max_primitives: 200,
            max_rejections: 10,
            max_work: 2_000_000_000,
            expansion: true,
            ground_expand_across: 0.08,
            ground_expand_along: 2.0,
            expand_across: 0.08,
            expand_along: 0.6,
            merge_angle: 8.0,
            merge_distance: 0.08,
            merge_gap: 0.3,
        }
    }

    /// The paper's GPP 1: only large polygons (A_t = 7 m^2), faster.
    pub fn gpp1() -> Self {
        Params {
            min_inliers: 400,
            min_area: 7.0,
            max_primitives: 60,
            ..Params::gpp2()
        }
    }

    /// A preset by name: `"gpp1"` or `"gpp2"`.
    pub fn preset(name: &str) -> Result<Self> {
        match name {
            "gpp1" => Ok(Params::gpp1()),
            "gpp2" => Ok(Params::gpp2()),
            other => Err(Error::BadOption {
                key: "preset".into(),
                reason: format!("unknown preset '{other}', expected 'gpp1' or 'gpp2'"),
            }),
        }
    }

    /// The option keys, camelCase as in JSON and the JS options (`preset`
    /// not included), sorted.
    pub fn keys() -> Vec<String> {
        Params::gpp2().as_map().keys().cloned().collect()
    }

    /// The parameters as a JSON object. (Through the JSON text: the same
    /// serde code as snapshots, which keeps the wasm build small.)
    fn as_map(&self) -> serde_json::Map<String, serde_json::Value> {
        serde_json::to_string(self)
            .ok()
            .and_then(|text| serde_json::from_str(&text).ok())
            .unwrap_or_default()
    }

    /// Parameters from an options object (the JS options): start from the
    /// preset named by the `preset` key (default `"gpp2"`), override it with
    /// every other key, then [`Params::validate`]. An unknown key, a value of
    /// the wrong type or out of range is an [`Error::BadOption`] naming the
    /// key.
    ///
    /// ```
    /// use polyscene::params::Params;
    /// let opts = serde_json::json!({ "preset": "gpp1", "hull": "convex", "minArea": 3 });
    /// let p = Params::from_options(opts.as_object().unwrap()).unwrap();
    /// assert_eq!((p.min_area, p.min_inliers), (3.0, Params::gpp1().min_inliers));
    /// let bad = serde_json::json!({ "minAreaa": 3 });
    /// let e = Params::from_options(bad.as_object().unwrap()).unwrap_err();
    /// assert!(e.to_string().contains("minAreaa"));
    /// ```
    pub fn from_options(options: &serde_json::Map<String, serde_json::Value>) -> Result<Params> {
        use serde_json::Value;
        let base = match options.get("preset") {
            None => Params::gpp2(),
            Some(Value::String(name)) => Params::preset(name)?,
            Some(other) => {
                return Err(Error::BadOption {
                    key: "preset".into(),
                    reason: format!("expected 'gpp1' or 'gpp2', got {other}"),
                })
            }
        };
        let mut merged = base.as_map();
        for (key, value) in options {
            if key == "preset" {
                continue;
            }
            if !merged.contains_key(key) {
                let keys = Params::keys();
                let hint = closest_key(key, &keys)
                    .map(|k| format!(" (did you mean '{k}'?)"))
                    .unwrap_or_default();
                return Err(Error::BadOption {
                    key: key.clone(),
                    reason: format!(
                        "unknown option{hint}; the options are preset, {}",
                        keys.join(", ")
                    ),
                });
            }
            // Check this key alone (missing keys take defaults), so that a
            // type error is attributed to it.
            let single = Value::Object(serde_json::Map::from_iter([(key.clone(), value.clone())]));
            if let Err(e) = serde_json::from_str::<Params>(&single.to_string()) {
                return Err(Error::BadOption {
                    key: key.clone(),
                    reason: plain_serde_message(&e.to_string()),
                });
            }
            merged.insert(key.clone(), value.clone());
        }
        let params: Params = serde_json::from_str(&Value::Object(merged).to_string())
            .map_err(|e| Error::Invalid(format!("options: {e}")))?;
        params.validate()?;
        Ok(params)
    }

    /// Check every field's range; the error names the offending key (in the
    /// camelCase spelling the JS options use).
    pub fn validate(&self) -> Result<()> {
        fn pos(key: &str, v: f64, max: f64) -> Result<()> {
            if !(v.is_finite() && v > 0.0 && v <= max) {
                return Err(Error::BadOption {
                    key: key.into(),
                    reason: format!("must be a number in (0, {max}], got {v}"),
                });
            }
            Ok(())
        }
        fn frac(key: &str, v: f64, lo_open: bool) -> Result<()> {
            let ok = v.is_finite() && v <= 1.0 && if lo_open { v > 0.0 } else { v >= 0.0 };
            if !ok {
                return Err(Error::BadOption {
                    key: key.into(),
                    reason: format!("must be a number between 0 and 1, got {v}"),
                });
            }
            Ok(())
        }
        fn count(key: &str, v: usize, lo: usize, hi: usize) -> Result<()> {
            if v < lo || v > hi {
                return Err(Error::BadOption {
                    key: key.into(),
                    reason: format!("must be an integer in [{lo}, {hi}], got {v}"),
                });
            }
            Ok(())
        }
        pos("distance", self.distance, 100.0)?;
        pos("groundDistance", self.ground_distance, 100.0)?;
        if !(self.ground_max_tilt.is_finite() && (0.0..=90.0).contains(&self.ground_max_tilt)) {
            return Err(Error::BadOption {
                key: "groundMaxTilt".into(),
                reason: format!("must be in [0, 90] degrees, got {}", self.ground_max_tilt),
            });
        }
        if !(self.ground_depth.is_finite() && self.ground_depth >= 0.0) {
            return Err(Error::BadOption {
                key: "groundDepth".into(),
                reason: format!("must be a number >= 0, got {}", self.ground_depth),
            });
        }
        if self.viewpoint.iter().any(|v| !v.is_finite()) {
            return Err(Error::BadOption {
                key: "viewpoint".into(),
                reason: "must be three finite numbers".into(),
            });
        }
        pos("maxRoughness", self.max_roughness, 10.0)?;
        frac("minNormalConsistency", self.min_normal_consistency, false)?;
        count("minInliers", self.min_inliers, 3, 100_000_000)?;
        count("maxHypotheses", self.max_hypotheses, 1, 1_000_000)?;
        frac("confidence", self.confidence, true)?;
        if self.confidence >= 1.0 {
            return Err(Error::BadOption {
                key: "confidence".into(),
                reason: "must be below 1".into(),
            });
        }
        pos("sampleRadius", self.sample_radius, 1000.0)?;
        pos("clusterTolerance", self.cluster_tolerance, 1000.0)?;
        pos(
            "groundClusterTolerance",
            self.ground_cluster_tolerance,
            1000.0,
        )?;
        pos("groundClusterRange", self.ground_cluster_range, 1e9)?;
        pos("alpha", self.alpha, 1000.0)?;
        pos("groundAlpha", self.ground_alpha, 1000.0)?;
        pos("cell", self.cell, 100.0)?;
        if self.cell < 0.01 {
            return Err(Error::BadOption {
                key: "cell".into(),
                reason: format!("must be at least 0.01 m, got {}", self.cell),
            });
        }
        pos("groundCell", self.ground_cell, 100.0)?;
        if self.ground_cell < 0.01 {
            return Err(Error::BadOption {
                key: "groundCell".into(),
                reason: format!("must be at least 0.01 m, got {}", self.ground_cell),
            });
        }
        if !(self.simplify.is_finite() && (0.0..=100.0).contains(&self.simplify)) {
            return Err(Error::BadOption {
                key: "simplify".into(),
                reason: format!("must be in [0, 100] m, got {}", self.simplify),
            });
        }
        count("maxVertices", self.max_vertices, 4, 100_000)?;
        if !(self.min_area.is_finite() && self.min_area >= 0.0) {
            return Err(Error::BadOption {
                key: "minArea".into(),
                reason: format!("must be a number >= 0, got {}", self.min_area),
            });
        }
        if !(self.min_width.is_finite() && self.min_width >= 0.0) {
            return Err(Error::BadOption {
                key: "minWidth".into(),
                reason: format!("must be a number >= 0, got {}", self.min_width),
            });
        }
        if !(self.min_density.is_finite() && self.min_density >= 0.0) {
            return Err(Error::BadOption {
                key: "minDensity".into(),
                reason: format!("must be a number >= 0, got {}", self.min_density),
            });
        }
        frac("minOccupancy", self.min_occupancy, false)?;
        count("maxPrimitives", self.max_primitives, 1, 100_000)?;
        count("maxRejections", self.max_rejections, 1, 1_000_000)?;
        if self.max_work == 0 {
            return Err(Error::BadOption {
                key: "maxWork".into(),
                reason: "must be positive".into(),
            });
        }
        pos("groundExpandAcross", self.ground_expand_across, 100.0)?;
        pos("groundExpandAlong", self.ground_expand_along, 1000.0)?;
        pos("expandAcross", self.expand_across, 100.0)?;
        pos("expandAlong", self.expand_along, 1000.0)?;
        pos("mergeAngle", self.merge_angle, 90.0)?;
        pos("mergeDistance", self.merge_distance, 100.0)?;
        if !(self.merge_gap.is_finite() && (0.0..=100.0).contains(&self.merge_gap)) {
            return Err(Error::BadOption {
                key: "mergeGap".into(),
                reason: format!("must be in [0, 100] m, got {}", self.merge_gap),
            });
        }
        Ok(())
    }
}

/// The known key an unknown `key` was probably meant to be: the same up to
/// case and `_`/`-` (`min_area` for `minArea`), or at most two edits away.
fn closest_key<'a>(key: &str, keys: &'a [String]) -> Option<&'a str> {
    let norm = |s: &str| -> Vec<char> {
        s.chars()
            .filter(|c| *c != '_' && *c != '-')
            .map(|c| c.to_ascii_lowercase())
            .collect()
    };
    let edits = |a: &[char], b: &[char]| {
        let mut row: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.iter().enumerate() {
            let mut prev = row[0];
            row[0] = i + 1;
            for (j, cb) in b.iter().enumerate() {
                let cur = row[j + 1];
                row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
                prev = cur;
            }
        }
        row[b.len()]
    };
    let k = norm(key);
    keys.iter()
        .map(|c| (edits(&k, &norm(c)), c))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c.as_str())
}

/// A serde type error in the words of the options' documentation.
fn plain_serde_message(msg: &str) -> String {
    let msg = msg.split(" at line ").next().unwrap_or(msg);
    msg.replace("expected f64", "expected a number")
        .replace("expected u64", "expected a non-negative integer")
        .replace("expected usize", "expected a non-negative integer")
        .replace("expected a boolean", "expected true or false")
        .replace(
            "expected an array of length 3",
            "expected an array of 3 numbers",
        )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate_and_errors_name_the_key() {
        Params::gpp1().validate().unwrap();
        Params::gpp2().validate().unwrap();
        assert!(Params::preset("gpp3").is_err());
        let bad = Params {
            cluster_tolerance: f64::NAN,
            ..Params::gpp2()
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.contains("clusterTolerance"), "{e}");
        let bad = Params {
            min_occupancy: 1.5,
            ..Params::gpp2()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("minOccupancy"));
    }

    #[test]
    fn options_merge_over_the_preset_and_errors_name_the_key() {
        let opts = |v: serde_json::Value| Params::from_options(v.as_object().unwrap());
        assert_eq!(opts(serde_json::json!({})).unwrap(), Params::gpp2());
        assert_eq!(
            opts(serde_json::json!({"preset": "gpp1"})).unwrap(),
            Params::gpp1()
        );
        let p = opts(serde_json::json!({
            "preset": "gpp1", "hull": "convex", "minArea": 3, "seed": 9,
            "viewpoint": [1, 2.5, 3], "expansion": false, "solidity": "density"
        }))
        .unwrap();
        assert_eq!(
            p,
            Params {
                hull: HullKind::Convex,
                min_area: 3.0,
                seed: 9,
                viewpoint: [1.0, 2.5, 3.0],
                expansion: false,
                solidity: SolidityKind::Density,
                ..Params::gpp1()
            }
        );
        for (bad, key, words) in [
            (serde_json::json!({"preset": "gpp3"}), "preset", "gpp3"),
            (serde_json::json!({"preset": 1}), "preset", "gpp1"),
            (
                serde_json::json!({"minAreaa": 1}),
                "minAreaa",
                "did you mean 'minArea'",
            ),
            (
                serde_json::json!({"min_area": 1}),
                "min_area",
                "did you mean 'minArea'",
            ),
            (
                serde_json::json!({"colour": 1}),
                "colour",
                "unknown option; the options",
            ),
            (
                serde_json::json!({"minArea": "big"}),
                "minArea",
                "expected a number",
            ),
            (serde_json::json!({"minArea": -1}), "minArea", ">= 0"),
            (
                serde_json::json!({"minInliers": 2.5}),
                "minInliers",
                "integer",
            ),
            (serde_json::json!({"seed": -1}), "seed", "integer"),
            (serde_json::json!({"hull": "round"}), "hull", "concave"),
            (
                serde_json::json!({"expansion": 1}),
                "expansion",
                "true or false",
            ),
            (serde_json::json!({"viewpoint": [1, 2]}), "viewpoint", "3"),
            (serde_json::json!({"distance": null}), "distance", "null"),
        ] {
            let e = opts(bad.clone()).unwrap_err().to_string();
            assert!(e.contains(&format!("'{key}'")), "{bad}: {e}");
            assert!(e.contains(words), "{bad}: {e}");
        }
        // Every field is an option key (serde_json of the struct lists them).
        let keys = Params::keys();
        let fields = serde_json::to_value(Params::gpp2()).unwrap();
        assert_eq!(keys.len(), fields.as_object().unwrap().len());
        assert!(keys.contains(&"groundExpandAcross".to_string()));
    }

    #[test]
    fn serde_rejects_unknown_keys_and_fills_defaults() {
        let p: Params = serde_json::from_str(r#"{"minArea": 3.0, "hull": "convex"}"#).unwrap();
        assert_eq!(p.min_area, 3.0);
        assert_eq!(p.hull, HullKind::Convex);
        assert_eq!(p.alpha, Params::gpp2().alpha);
        let e = serde_json::from_str::<Params>(r#"{"minAreaa": 3.0}"#).unwrap_err();
        assert!(e.to_string().contains("minAreaa"));
    }
}
