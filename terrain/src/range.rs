//! Settings outside their allowed range: the one error every settings section returns, so an
//! owner's message always names the key, the value and what is allowed.

/// A setting outside its allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{key} = {value} is out of range (allowed {allowed})")]
pub struct RangeError {
    /// Dotted key, e.g. `layout.ocean_fraction`.
    pub key: String,
    /// The value given, as written.
    pub value: String,
    /// The allowed range, e.g. `0.05..=0.95`.
    pub allowed: String,
}

/// Checks `min <= value <= max`, naming `key` on failure.
pub fn check_range<T: PartialOrd + std::fmt::Display>(key: &str, value: T, min: T, max: T) -> Result<(), RangeError> {
    if value >= min && value <= max {
        Ok(())
    } else {
        Err(RangeError { key: key.to_string(), value: value.to_string(), allowed: format!("{min}..={max}") })
    }
}
