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

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::BadLength { len, stride } => write!(
                f,
                "point buffer length {len} is not a multiple of the stride {stride} \
                 (expected interleaved x, y, z{} values)",
                if *stride == 4 { ", intensity" } else { "" }
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
                "point {point} lies more than {limit:e} m from the world origin (after the \
                 pose, for a scan); coordinates are metres"
            ),
            Error::TooManyPoints { points, limit } => write!(
                f,
                "{points} points is more than the {limit} one cloud may hold \
                 (the memory of a wasm instance is 4 GiB); split the cloud"
            ),
            Error::BadPose(why) => write!(f, "invalid pose: {why}"),
            Error::BadOption { key, reason } => write!(f, "option '{key}': {reason}"),
            Error::Io(why) => write!(f, "{why}"),
            Error::Invalid(why) => write!(f, "{why}"),
        }
    }
}

impl std::error::Error for Error {}

/// Shorthand for results with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
