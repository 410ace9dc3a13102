//! Errors of the core: a parameter out of its bound, a parameter file that does not parse,
//! an unknown name or value reference; an input (motor command, wind) that is not a number.
//!
//! Every error type of the workspace derives `thiserror::Error`: the message sits next to
//! the variant it describes.

use crate::number::Compact;
use std::fmt;

/// What kind of variable a refused value was meant for, as the variable's causality says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    Parameter,
    Input,
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Role::Parameter => "parameter",
            Role::Input => "input",
        })
    }
}

/// Why a parameter set, a parameter file or a variable access was refused.
///
/// Every variant names the parameter (or variable) it is about, so a user can fix the input
/// without reading code.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// A value outside its inclusive range `[min, max]` (NaN is always out of range).
    #[error(
        "{role} `{name}` = {v}{u} is out of range: it must be in [{lo}, {hi}]{u}",
        v = Compact(*.value),
        lo = Compact(*.min),
        hi = Compact(*.max),
        u = spaced(unit)
    )]
    OutOfRange {
        /// Whether the variable is a parameter or an input (for the message).
        role: Role,
        name: &'static str,
        value: f64,
        min: f64,
        max: f64,
        unit: &'static str,
    },
    /// An integer or boolean parameter given a value that is not one.
    #[error("parameter `{name}` = {v} is not {expected}", v = Compact(*.value))]
    WrongKind {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// A relation between two parameters does not hold (e.g. `wind_speed_min <= wind_speed_max`).
    #[error("parameter `{name}` is invalid: {requirement}")]
    Relation {
        name: &'static str,
        requirement: String,
    },
    /// No parameter or variable of that name.
    #[error("unknown parameter `{0}`")]
    UnknownName(String),
    /// No variable with that value reference.
    #[error("unknown value reference {0}")]
    UnknownValueReference(u32),
    /// The variable exists but cannot be set (an output, or a constant).
    #[error("variable `{0}` cannot be set")]
    NotSettable(&'static str),
    /// A TOML or JSON parameter file that does not parse; the message names the key or line.
    #[error("invalid parameter file: {0}")]
    Parse(String),
    /// A frame's rotor table that is not a flyable multirotor; the message names the rotor
    /// and the field.
    #[error(transparent)]
    Frame(#[from] crate::quadrotor::frame::FrameError),
}

/// " unit", or nothing for a dimensionless variable: "1" says nothing after a number.
fn spaced(unit: &str) -> String {
    match unit {
        "" | "1" => String::new(),
        unit => format!(" {unit}"),
    }
}

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

/// An input of a model (a motor command, an external wind) that is not a finite number.
/// Both models take their inputs through [`check_finite`], so both refuse them alike.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{input} {index} is {value}, not a finite number")]
pub struct InputError {
    /// What the input is ("motor command", "wind force").
    pub input: &'static str,
    /// Its position in the input array.
    pub index: usize,
    pub value: f64,
}

/// An input vector (the motor commands, a continuous state) of the wrong length, or with a
/// value that is not a finite number.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum CommandError {
    #[error("{what} has {got} values, the vehicle takes {expected}")]
    WrongLength {
        /// What the vector is ("motor command", "continuous state").
        what: &'static str,
        expected: usize,
        got: usize,
    },
    #[error(transparent)]
    NotFinite(#[from] InputError),
}

/// `Ok` when every value is finite, else an [`InputError`] naming the first one that is not.
pub fn check_finite(input: &'static str, values: &[f64]) -> Result<(), InputError> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(InputError {
            input,
            index,
            value: values[index],
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_parameter_its_value_and_bound() {
        let e = ParamError::OutOfRange {
            role: Role::Parameter,
            name: "mass",
            value: -1.0,
            min: 0.05,
            max: 100.0,
            unit: "kg",
        };
        assert_eq!(
            e.to_string(),
            "parameter `mass` = -1 kg is out of range: it must be in [0.05, 100] kg"
        );
        let e = ParamError::OutOfRange {
            role: Role::Input,
            name: "gain",
            value: 1e300,
            min: 0.0,
            max: 1.0,
            unit: "1",
        };
        assert_eq!(
            e.to_string(),
            "input `gain` = 1e300 is out of range: it must be in [0, 1]"
        );
    }

    #[test]
    fn the_first_non_finite_input_is_named() {
        assert_eq!(check_finite("motor command", &[0.1, 0.2]), Ok(()));
        let e = check_finite("motor command", &[0.1, f64::INFINITY, f64::NAN]).unwrap_err();
        assert_eq!((e.index, e.value), (1, f64::INFINITY));
        assert_eq!(e.to_string(), "motor command 1 is inf, not a finite number");
    }
}
