//! Errors of the core: a parameter out of its bound, a parameter file that does not parse,
//! an unknown name or value reference.

use std::fmt;

/// Why a parameter set, a parameter file or a variable access was refused.
///
/// Every variant names the parameter (or variable) it is about, so a user can fix the input
/// without reading code.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamError {
    /// A value outside its inclusive range `[min, max]` (NaN is always out of range).
    OutOfRange {
        name: &'static str,
        value: f64,
        min: f64,
        max: f64,
        unit: &'static str,
    },
    /// An integer or boolean parameter given a value that is not one.
    WrongKind {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// A relation between two parameters does not hold (e.g. `wind_speed_min <= wind_speed_max`).
    Relation {
        name: &'static str,
        requirement: String,
    },
    /// No parameter or variable of that name.
    UnknownName(String),
    /// No variable with that value reference.
    UnknownValueReference(u32),
    /// The variable exists but cannot be set (an output, or a constant).
    NotSettable(&'static str),
    /// A TOML or JSON parameter file that does not parse; the message names the key or line.
    Parse(String),
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamError::OutOfRange {
                name,
                value,
                min,
                max,
                unit,
            } => {
                let unit = if unit.is_empty() {
                    String::new()
                } else {
                    format!(" {unit}")
                };
                write!(
                    f,
                    "parameter `{name}` = {value}{unit} is out of range: it must be in [{min}, {max}]{unit}"
                )
            }
            ParamError::WrongKind {
                name,
                value,
                expected,
            } => write!(f, "parameter `{name}` = {value} is not {expected}"),
            ParamError::Relation { name, requirement } => {
                write!(f, "parameter `{name}` is invalid: {requirement}")
            }
            ParamError::UnknownName(name) => write!(f, "unknown parameter `{name}`"),
            ParamError::UnknownValueReference(vr) => write!(f, "unknown value reference {vr}"),
            ParamError::NotSettable(name) => write!(f, "variable `{name}` cannot be set"),
            ParamError::Parse(message) => write!(f, "invalid parameter file: {message}"),
        }
    }
}

impl std::error::Error for ParamError {}

impl From<toml::de::Error> for ParamError {
    fn from(e: toml::de::Error) -> Self {
        ParamError::Parse(e.to_string())
    }
}

impl From<serde_json::Error> for ParamError {
    fn from(e: serde_json::Error) -> Self {
        ParamError::Parse(e.to_string())
    }
}
