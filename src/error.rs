//! The crate's error type: every fallible public function returns
//! [`Result<T>`], and the messages name what was wrong and what was expected
//! (they become the `message` of JS `Error`s in the binding).

use std::fmt;

/// What went wrong.
#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// A flat point buffer whose length is not a multiple of its stride.
    BadLength {
        /// Buffer length in numbers.
        len: usize,
        /// Numbers per point.
        stride: usize,
    },
    /// A stride other than 3 or 4.
    BadStride(usize),
    /// A NaN or infinite coordinate.
    NonFinite {
        /// Index of the point.
        point: usize,
    },
    /// A point farther than [`MAX_COORDINATE`](crate::cloud::MAX_COORDINATE)
    /// from the world origin (after its pose, for a scan).
    OutOfRange {
        /// Index of the point.
        point: usize,
        /// The limit (m).
        limit: f64,
    },
    /// More points in one cloud than [`MAX_POINTS`](crate::cloud::MAX_POINTS).
    TooManyPoints {
        /// Points given.
        points: usize,
        /// The limit.
        limit: usize,
    },
    /// A float32 coordinate beyond
    /// [`MAX_F32_COORDINATE`](crate::cloud::MAX_F32_COORDINATE): float32
    /// cannot hold it to the detection's tolerance; pass float64.
    F32Precision {
        /// Index of the point.
        point: usize,
        /// Its largest absolute coordinate (m).
        value: f64,
        /// The limit (m).
        limit: f64,
    },
    /// A pose that is not a rigid transform, or of the wrong size.
    BadPose(String),
    /// An option out of range or unknown.
    BadOption {
        /// The option's name.
        key: String,
        /// Why it was refused.
        reason: String,
    },
    /// A file that cannot be read or parsed.
    Io(String),
    /// Anything else, with a message.
    Invalid(String),
}

/// A limit in metres as `{:e}` writes a power of ten (`1e9`, `2e9`, `1e5`):
/// an integer mantissa and exponent, formatted as integers. Other values as
/// `{}` writes them. The wasm then carries no exponent formatting of floats
/// with a precision (about 1.5 kB of code).
pub(crate) struct Sci(pub(crate) f64);

impl fmt::Display for Sci {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if (1.0..1e18).contains(&x) && x.fract() == 0.0 {
            let (mut m, mut e) = (x as u64, 0);
            while m % 10 == 0 {
                m /= 10;
                e += 1;
            }
            write!(f, "{m}e{e}")
        } else {
            write!(f, "{x}")
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::BadLength { len, stride } => write!(
                f,
                "point buffer length {len} is not a multiple of the stride {stride} \
                 (expected interleaved x, y, z{} values){}",
                if *stride == 4 { ", intensity" } else { "" },
                if *stride == 3 && len % 4 == 0 {
                    "; for x, y, z, intensity (a KITTI .bin) give stride 4"
                } else {
                    ""
                }
            ),
            Error::BadStride(s) => write!(
                f,
                "stride must be 3 (x, y, z) or 4 (x, y, z, intensity), got {s}"
            ),
            Error::NonFinite { point } => {
                write!(f, "point {point} has a NaN or infinite coordinate")
            }
            Error::OutOfRange { point, limit } => write!(
                f,
                "point {point} lies more than {} m from the world origin (after the \
                 pose, for a scan); coordinates are metres",
                Sci(*limit)
            ),
            Error::TooManyPoints { points, limit } => write!(
                f,
                "{points} points is more than the {limit} one cloud may hold \
                 (the memory of a wasm instance is 4 GiB); split the cloud"
            ),
            Error::F32Precision {
                point,
                value,
                limit,
            } => write!(
                f,
                "point {point} has a coordinate of {value} m in float32, which holds \
                 coordinates beyond {} m only to {} mm steps or coarser (here {} mm): \
                 planes would follow the rounding steps. Pass the points as float64 (a \
                 Float64Array in JS, Cloud::from_flat_f64 or Scenario::add_scan_f64 in \
                 Rust; the CLI keeps LAS, PLY and PCD doubles) or move them near the origin",
                Sci(*limit),
                f32_step_mm(*limit),
                f32_step_mm(*value),
            ),
            Error::BadPose(why) => write!(f, "invalid pose: {why}"),
            Error::BadOption { key, reason } => write!(f, "option '{key}': {reason}"),
            Error::Io(why) => write!(f, "{why}"),
            Error::Invalid(why) => write!(f, "{why}"),
        }
    }
}

impl std::error::Error for Error {}

/// The spacing of float32 values at `x` (m), in millimetres, rounded.
fn f32_step_mm(x: f64) -> f64 {
    let x = (x.abs() as f32).max(f32::MIN_POSITIVE);
    let step = f32::from_bits(x.to_bits() + 1) - x;
    (step as f64 * 1e4).round() / 10.0
}

/// Shorthand for results with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::Sci;

    #[test]
    fn limits_read_as_powers_of_ten() {
        for x in [1e5, 1e9, 2e9, 1.0, 30.0] {
            assert_eq!(Sci(x).to_string(), format!("{x:e}"));
        }
        assert_eq!(Sci(1.5e5).to_string(), "15e4");
        assert_eq!(Sci(0.25).to_string(), "0.25");
        assert_eq!(Sci(-1e5).to_string(), "-100000");
    }
}
