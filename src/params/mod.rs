//! The one parameter set of the pipeline, with units and defaults, and the
//! paper's two configurations as presets.
//!
//! Every option is declared once, in `table.rs`: its flat camelCase key
//! (JSON snapshots and the JS options), where it lives in [`Params`], its
//! unit, its valid range and its documentation. From that table come the
//! serde form, [`Params::validate`], the TypeScript `PipelineOptions` (by
//! `build.rs`) and the options table of docs/API.md (from the TypeScript).
//!
//! In Rust the parameters that differ between the ground and other
//! surfaces are grouped in a [`SurfaceParams`] each, chosen by
//! [`Params::surface`].
//!
//! The paper names its two configurations GPP 1 ("only very large
//! polygons, faster") and GPP 2 ("small polygons too"). The authors' public
//! code uses RANSAC distances of 0.3 m (ground) and 0.2 m (other planes), a
//! cluster tolerance of 0.9 m, acceptance above 7 m^2 and 48 points/m^2,
//! and expansion steps of 15 m along / 0.3 m across for the ground and
//! 0.2 m along / 0.5 m across for other primitives, tuned for 2007-era
//! HDL-64E data. The defaults here are measured on simulated HDL-64E drives
//! and real Ouster scans (BENCHMARKS.md): tighter distances keep curbs and
//! door recesses apart, a smaller clustering tolerance keeps clutter in a
//! plane's slab from joining into one sheet.

use crate::error::{Error, Result};
pub use crate::outline::HullKind;
use serde::{Deserialize, Serialize};
use shared::{camel, Check};

mod shared;

/// How "solidity", the paper's second acceptance test, is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SolidityKind {
    /// Support points per square metre of polygon (the authors' code).
    /// Depends on range and sensor: a wall at 50 m has far fewer points per
    /// m^2 than one at 10 m.
    Density,
    /// Share of the polygon's area whose raster cells hold a support point.
    /// Scale-free as long as the point spacing is below the cell size.
    Occupancy,
}

/// The parameters that differ between the ground and other surfaces (the
/// option keys: `distance` and `groundDistance`, and so on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceParams {
    /// RANSAC inlier distance (m); also what counts as support.
    pub distance: f64,
    /// Euclidean clustering tolerance in the plane (m).
    pub cluster_tolerance: f64,
    /// Concave outline radius (m).
    pub alpha: f64,
    /// Footprint raster cell size (m).
    pub cell: f64,
    /// Perpendicular gate of expansion (m).
    pub expand_across: f64,
    /// Longitudinal growth reach of expansion per step (m).
    pub expand_along: f64,
}

/// Every tunable of detection and expansion. Distances in metres, areas in
/// square metres, angles in degrees. The documentation of each option, its
/// default and its range is in the options table (`table.rs`, shown in the
/// docs/API.md and the TypeScript `PipelineOptions`); the fields name their
/// option key.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(into = "Wire")]
pub struct Params {
    /// Non-ground planes: `distance`, `clusterTolerance`, `alpha`, `cell`,
    /// `expandAcross`, `expandAlong`.
    pub other: SurfaceParams,
    /// Ground planes: `groundDistance`, `groundClusterTolerance`,
    /// `groundAlpha`, `groundCell`, `groundExpandAcross`,
    /// `groundExpandAlong`.
    pub ground: SurfaceParams,
    /// `groundMaxTilt` (deg).
    pub ground_max_tilt: f64,
    /// `groundDepth` (m).
    pub ground_depth: f64,
    /// `viewpoint` (world, m); `None`: see [`crate::detect()`].
    pub viewpoint: Option<[f64; 3]>,
    /// `minInliers`.
    pub min_inliers: usize,
    /// `maxHypotheses`.
    pub max_hypotheses: usize,
    /// `confidence` (0..1).
    pub confidence: f64,
    /// `sampleRadius` (m).
    pub sample_radius: f64,
    /// `seed`.
    pub seed: u64,
    /// `groundClusterRange` (m).
    pub ground_cluster_range: f64,
    /// `hull`.
    pub hull: HullKind,
    /// `simplify` (m).
    pub simplify: f64,
    /// `maxVertices`.
    pub max_vertices: usize,
    /// `minArea` (m^2).
    pub min_area: f64,
    /// `minWidth` (m).
    pub min_width: f64,
    /// `maxRoughness` (fraction of the inlier distance).
    pub max_roughness: f64,
    /// `minNormalConsistency` (0..1).
    pub min_normal_consistency: f64,
    /// `solidity`.
    pub solidity: SolidityKind,
    /// `minDensity` (points/m^2).
    pub min_density: f64,
    /// `minOccupancy` (0..1).
    pub min_occupancy: f64,
    /// `maxPrimitives`.
    pub max_primitives: usize,
    /// `maxRejections`.
    pub max_rejections: usize,
    /// `maxWork` (distance evaluations).
    pub max_work: u64,
    /// `expansion`.
    pub expansion: bool,
    /// `alignScans`.
    pub align_scans: bool,
    /// `alignReach` (m).
    pub align_reach: f64,
    /// `mergeAngle` (deg).
    pub merge_angle: f64,
    /// `mergeDistance` (m).
    pub merge_distance: f64,
    /// `mergeGap` (m).
    pub merge_gap: f64,
    /// `poolScans` (scans; 0: no pool).
    pub pool_scans: usize,
    /// `poolVoxel` (m).
    pub pool_voxel: f64,
    /// `poolMaxPoints`.
    pub pool_max_points: usize,
}

impl Check {
    /// Check `v` (numbers as f64); the error names the option, given by
    /// its snake_case `name`, by its camelCase key. Not inlined: it is
    /// called once per option, and the messages' formatting is large.
    #[inline(never)]
    fn check(self, name: &str, v: f64) -> Result<()> {
        let reason = match self {
            Check::Any => None,
            Check::FiniteOrNull => (!v.is_finite()).then(|| "must be finite numbers".to_string()),
            Check::Positive(max) => (!(v.is_finite() && v > 0.0 && v <= max))
                .then(|| format!("must be a number in (0, {max}], got {v}")),
            Check::Between(lo, hi) => (!(v.is_finite() && (lo..=hi).contains(&v)))
                .then(|| format!("must be a number in [{lo}, {hi}], got {v}")),
            Check::NonNegative => {
                (!(v.is_finite() && v >= 0.0)).then(|| format!("must be a number >= 0, got {v}"))
            }
            Check::Fraction => (!(v.is_finite() && (0.0..=1.0).contains(&v)))
                .then(|| format!("must be a number between 0 and 1, got {v}")),
            Check::Open01 => (!(v.is_finite() && v > 0.0 && v < 1.0))
                .then(|| format!("must be a number between 0 and 1, below 1, got {v}")),
            Check::Count(lo, hi) => (!(v >= lo as f64 && v <= hi as f64))
                .then(|| format!("must be an integer in [{lo}, {hi}], got {v}")),
            Check::AtLeastOne => (v < 1.0).then(|| format!("must be positive, got {v}")),
        };
        match reason {
            None => Ok(()),
            Some(reason) => Err(Error::BadOption {
                key: camel(name),
                reason,
            }),
        }
    }
}

/// From the options table: the flat serde form of [`Params`] (`Wire`, the
/// keys in table order) and the range checks.
macro_rules! options {
    ($( $(#[doc = $doc:literal])* $key:ident : $ty:ty = $($path:ident).+ , $unit:literal , $check:expr ; )*) => {
        /// The flat form of [`Params`]: one camelCase key per option, as in
        /// snapshots and the JS options.
        #[derive(Serialize)]
        #[serde(rename_all = "camelCase")]
        struct Wire {
            $( $key: $ty, )*
        }

        impl Wire {
            /// From a JSON object of options: a key missing takes GPP 2's
            /// value, an unknown key is an error, and each value is read
            /// as its option's type (serde's messages).
            fn from_map(
                map: serde_json::Map<String, serde_json::Value>,
            ) -> std::result::Result<Wire, serde_json::Error> {
                let mut w = Wire::default();
                type Set = fn(&mut Wire, serde_json::Value) -> std::result::Result<(), serde_json::Error>;
                const SETTERS: &[(&str, Set)] = &[$(
                    (stringify!($key), |w, v| {
                        w.$key = read(v)?;
                        Ok(())
                    }),
                )*];
                for (key, value) in map {
                    let name = split_camel(&key, '_');
                    match SETTERS.iter().find(|(n, _)| *n == name) {
                        Some((_, set)) if camel(&name) == key => set(&mut w, value)?,
                        _ => return Err(unknown_field(&key)),
                    }
                }
                Ok(w)
            }
        }

        impl From<Params> for Wire {
            fn from(p: Params) -> Self {
                Wire { $( $key: p.$($path).+, )* }
            }
        }

        impl From<Wire> for Params {
            fn from(w: Wire) -> Self {
                let mut p = Params::gpp2();
                $( p.$($path).+ = w.$key; )*
                p
            }
        }

        /// Every option's snake_case name and range, in table order.
        const CHECKS: &[(&str, Check)] = &[$( (stringify!($key), $check), )*];
    };
}

include!("table.rs");

/// A camelCase key with its words split by `sep` and lowercased:
/// `minArea` -> `min_area` (`sep` `_`), `min-area` (`-`).
pub(crate) fn split_camel(key: &str, sep: char) -> String {
    let mut out = String::with_capacity(key.len() + 4);
    for c in key.chars() {
        if c.is_ascii_uppercase() {
            out.push(sep);
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}

/// One option's value as its type. Not inlined: one copy per type, not
/// per option.
#[inline(never)]
fn read<T: serde::de::DeserializeOwned>(
    value: serde_json::Value,
) -> std::result::Result<T, serde_json::Error> {
    serde_json::from_value(value)
}

/// serde's error for an unknown key, listing the keys.
fn unknown_field(key: &str) -> serde_json::Error {
    let keys: Vec<String> = CHECKS.iter().map(|(name, _)| camel(name)).collect();
    serde::de::Error::custom(format_args!(
        "unknown field `{key}`, expected one of `{}`",
        keys.join("`, `")
    ))
}

/// The serde form is the flat one of `Wire` (snapshots, the JS options),
/// read as a JSON object and then field by field: the same as
/// `#[derive(Deserialize)]` with `default` and `deny_unknown_fields`,
/// except that a key given twice takes its last value (as in JS's
/// `JSON.parse`) and that a JSON array is no `Params`, in 1.6 kB (gzipped)
/// less wasm than the derived visitor of 40 fields.
impl<'de> Deserialize<'de> for Params {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let map = serde_json::Map::<String, serde_json::Value>::deserialize(d)?;
        Wire::from_map(map)
            .map(Params::from)
            .map_err(serde::de::Error::custom)
    }
}

impl Default for Wire {
    fn default() -> Self {
        Params::gpp2().into()
    }
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
            other: SurfaceParams {
                distance: 0.10,
                cluster_tolerance: 0.5,
                alpha: 0.5,
                cell: 0.2,
                expand_across: 0.08,
                expand_along: 0.6,
            },
            ground: SurfaceParams {
                distance: 0.08,
                cluster_tolerance: 0.5,
                alpha: 1.0,
                cell: 0.2,
                expand_across: 0.08,
                expand_along: 2.0,
            },
            ground_max_tilt: 15.0,
            ground_depth: 1.3,
            viewpoint: None,
            min_inliers: 150,
            max_hypotheses: 200,
            confidence: 0.995,
            sample_radius: 1.0,
            seed: 7,
            ground_cluster_range: 20.0,
            hull: HullKind::Concave,
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
            align_scans: true,
            align_reach: 0.3,
            merge_angle: 8.0,
            merge_distance: 0.08,
            merge_gap: 0.3,
            pool_scans: 20,
            pool_voxel: 0.1,
            pool_max_points: 100_000,
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

    /// The parameters of ground planes or of other planes.
    pub fn surface(&self, ground: bool) -> &SurfaceParams {
        if ground {
            &self.ground
        } else {
            &self.other
        }
    }

    /// How far apart two overlapping near-parallel primitives may lie and
    /// still be merged as layers of one surface (m): twice the inlier
    /// distance of non-ground planes, the closest two parallel planes can be
    /// while one plane between them holds the points of both within the
    /// inlier distance, so that RANSAC cannot tell them apart.
    pub(crate) fn layer_distance(&self) -> f64 {
        2.0 * self.other.distance
    }

    /// How far apart (m, per axis) the outline boxes of two primitives
    /// that can merge may be: `mergeGap` plus the larger of `mergeDistance`
    /// and [`Params::layer_distance`].
    pub(crate) fn merge_box_pad(&self) -> f64 {
        self.merge_gap + self.merge_distance.max(self.layer_distance())
    }

    /// Check every option's range (declared in the options table);
    /// the error names the camelCase key. The values are read from the
    /// serde form, where a non-finite number is `null` (and fails every
    /// numeric range): one loop over a table instead of code per option,
    /// which keeps the wasm small.
    pub fn validate(&self) -> Result<()> {
        use serde_json::Value;
        let map = self.as_map();
        for &(name, check) in CHECKS {
            let value = map.get(&camel(name)).ok_or_else(|| {
                Error::Invalid(format!(
                    "option '{}' missing from the serde form",
                    camel(name)
                ))
            })?;
            let number = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
            match value {
                Value::Array(items) => {
                    for v in items {
                        check.check(name, number(v))?;
                    }
                }
                Value::Null if matches!(check, Check::FiniteOrNull) => {}
                Value::Number(_) | Value::Null => check.check(name, number(value))?,
                _ => {}
            }
        }
        Ok(())
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

    /// The parameters as a JSON object.
    fn as_map(&self) -> serde_json::Map<String, serde_json::Value> {
        match serde_json::to_value(self) {
            Ok(serde_json::Value::Object(map)) => map,
            _ => serde_json::Map::new(),
        }
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
            let single = serde_json::Map::from_iter([(key.clone(), value.clone())]);
            if let Err(e) = Wire::from_map(single) {
                return Err(Error::BadOption {
                    key: key.clone(),
                    reason: plain_serde_message(&e.to_string()),
                });
            }
            merged.insert(key.clone(), value.clone());
        }
        let params = Params::from(
            Wire::from_map(merged).map_err(|e| Error::Invalid(format!("options: {e}")))?,
        );
        params.validate()?;
        Ok(params)
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

/// A serde type error in the words of the options' documentation, up to
/// its " at line ". One scan with prefix tests: `str::replace` and
/// `str::split` with a string pattern would bring core's two-way string
/// searcher into the wasm for these few short messages.
fn plain_serde_message(msg: &str) -> String {
    const PLAIN: [(&str, &str); 5] = [
        ("expected f64", "expected a number"),
        ("expected u64", "expected a non-negative integer"),
        ("expected usize", "expected a non-negative integer"),
        ("expected a boolean", "expected true or false"),
        (
            "expected an array of length 3",
            "expected an array of 3 numbers",
        ),
    ];
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    'scan: while let Some(c) = rest.chars().next() {
        if rest.starts_with(" at line ") {
            break;
        }
        for (from, to) in PLAIN {
            if let Some(r) = rest.strip_prefix(from) {
                out.push_str(to);
                rest = r;
                continue 'scan;
            }
        }
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate_and_errors_name_the_key() {
        Params::gpp1().validate().unwrap();
        Params::gpp2().validate().unwrap();
        assert!(Params::preset("gpp3").is_err());
        let mut bad = Params::gpp2();
        bad.other.cluster_tolerance = f64::NAN;
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
                viewpoint: Some([1.0, 2.5, 3.0]),
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
    fn serde_messages_are_reworded_up_to_their_position() {
        // The same text as chained `str::replace` calls give.
        for msg in [
            "invalid type: string \"\u{e9}t\u{e9}\", expected f64 at line 1 column 12",
            "invalid type: integer `1`, expected a boolean",
            "invalid length 2, expected an array of length 3 at line 1 column 20",
            "expected usize, expected u64, expected f64",
            "nothing to reword",
            "",
        ] {
            let plain = msg
                .split(" at line ")
                .next()
                .unwrap()
                .replace("expected f64", "expected a number")
                .replace("expected u64", "expected a non-negative integer")
                .replace("expected usize", "expected a non-negative integer")
                .replace("expected a boolean", "expected true or false")
                .replace(
                    "expected an array of length 3",
                    "expected an array of 3 numbers",
                );
            assert_eq!(plain_serde_message(msg), plain);
        }
    }

    #[test]
    fn serde_rejects_unknown_keys_and_fills_defaults() {
        let p: Params = serde_json::from_str(r#"{"minArea": 3.0, "hull": "convex"}"#).unwrap();
        assert_eq!(p.min_area, 3.0);
        assert_eq!(p.hull, HullKind::Convex);
        assert_eq!(p.other.alpha, Params::gpp2().other.alpha);
        let e = serde_json::from_str::<Params>(r#"{"minAreaa": 3.0}"#).unwrap_err();
        assert!(e.to_string().contains("minAreaa"));
        // Keys are camelCase only; the form is an object, not a list.
        let e = serde_json::from_str::<Params>(r#"{"min_area": 3.0}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `min_area`"), "{e}");
        assert!(serde_json::from_str::<Params>("[1.5]").is_err());
        let e = serde_json::from_str::<Params>(r#"{"seed": 1.5}"#).unwrap_err();
        assert!(e.to_string().contains("expected u64"), "{e}");
        // A key given twice takes its last value, as in JSON.parse.
        let p: Params = serde_json::from_str(r#"{"seed": 3, "seed": 4}"#).unwrap();
        assert_eq!(p.seed, 4);
    }

    #[test]
    fn surface_keys_reach_their_surface_and_round_trip() {
        let p: Params =
            serde_json::from_str(r#"{"groundAlpha": 3.0, "alpha": 0.7, "groundCell": 0.4}"#)
                .unwrap();
        assert_eq!(p.surface(true).alpha, 3.0);
        assert_eq!(p.surface(false).alpha, 0.7);
        assert_eq!(p.ground.cell, 0.4);
        assert_eq!(p.other.cell, Params::gpp2().other.cell);
        let text = serde_json::to_string(&p).unwrap();
        assert!(
            text.starts_with(r#"{"distance":0.1,"groundDistance":0.08,"#),
            "{text}"
        );
        assert_eq!(serde_json::from_str::<Params>(&text).unwrap(), p);
    }

    #[test]
    fn every_checked_option_rejects_a_value_out_of_its_range() {
        for key in Params::keys() {
            let v = serde_json::to_value(Params::gpp2()).unwrap()[&key].clone();
            if !v.is_number() || key == "seed" {
                continue;
            }
            let bad = serde_json::json!({ key.clone(): -1e300 });
            let got = serde_json::from_value::<Params>(bad)
                .map_err(|e| e.to_string())
                .and_then(|p| p.validate().map_err(|e| e.to_string()));
            assert!(got.is_err(), "{key} accepted -1e300");
        }
    }
}
