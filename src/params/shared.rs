//! What the options table's two readers share: the crate (`params/mod.rs`)
//! and `build.rs`, which includes this file as a module of its own. Plain
//! Rust with no dependencies, so that it builds in both.

/// The valid range of an option, checked by [`Params::validate`] and shown
/// in its documentation.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Check {
    /// Any value of the type.
    Any,
    /// Null, or finite numbers (every element of an array).
    FiniteOrNull,
    /// A finite number in (0, max].
    Positive(f64),
    /// A finite number in [lo, hi].
    Between(f64, f64),
    /// A finite number >= 0.
    NonNegative,
    /// A finite number in [0, 1].
    Fraction,
    /// A finite number in (0, 1).
    Open01,
    /// An integer in [lo, hi].
    Count(usize, usize),
    /// An integer >= 1.
    AtLeastOne,
}

impl Check {
    /// The range in words, or `None` when any value of the type is valid.
    #[allow(dead_code)] // used by build.rs
    pub(crate) fn describe(self) -> Option<String> {
        Some(match self {
            Check::Any => return None,
            Check::FiniteOrNull => "finite numbers or null".into(),
            Check::Positive(max) => format!("(0, {max}]"),
            Check::Between(lo, hi) => format!("[{lo}, {hi}]"),
            Check::NonNegative => ">= 0".into(),
            Check::Fraction => "[0, 1]".into(),
            Check::Open01 => "(0, 1)".into(),
            Check::Count(lo, hi) => format!("integer in [{lo}, {hi}]"),
            Check::AtLeastOne => "integer >= 1".into(),
        })
    }
}

/// `snake_case` to `camelCase`. ASCII only: option names are ASCII, and
/// the Unicode case tables would add 14 KB to the wasm.
pub(crate) fn camel(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    let mut upper = false;
    for c in name.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.push(c.to_ascii_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}
