//! The FMI version a modelDescription, an instance or a message belongs to, and the names
//! each version gives to the same things.

use crate::error::FmuError;
use flyloop_core::params::ValueKind;
use flyloop_core::variables::Variable;

/// The FMI version an instance was created through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Api {
    Fmi2,
    Fmi3,
}

impl Api {
    pub const ALL: [Api; 2] = [Api::Fmi2, Api::Fmi3];

    /// Stage names as this version's standard calls them (FMI 3.0: Step Mode).
    pub fn stage_name(self, names: &str) -> String {
        match self {
            Api::Fmi2 => names.to_string(),
            Api::Fmi3 => names.replace("StepComplete", "StepMode"),
        }
    }

    /// What the modelDescription calls the string that ties it to the binary.
    pub fn token_name(self) -> &'static str {
        match self {
            Api::Fmi2 => "fmuGUID",
            Api::Fmi3 => "instantiationToken",
        }
    }

    pub fn prefix(self) -> &'static str {
        match self {
            Api::Fmi2 => "fmi2",
            Api::Fmi3 => "fmi3",
        }
    }

    /// The name of the type that holds variables of `kind` (modelDescription, messages).
    pub const fn type_name(self, kind: ValueKind) -> &'static str {
        match (self, kind) {
            (Api::Fmi2, ValueKind::Real) => "Real",
            (Api::Fmi2, ValueKind::Integer) => "Integer",
            (Api::Fmi3, ValueKind::Real) => "Float64",
            (Api::Fmi3, ValueKind::Integer) => "Int32",
            (_, ValueKind::Boolean) => "Boolean",
        }
    }

    /// Fails unless variable `v` is of the type this version calls `requested`: the type an
    /// fmi2Get*/fmi3Set*... function works with, perhaps one no variable has (String, Binary).
    pub fn check(self, requested: &'static str, v: &Variable) -> Result<(), FmuError> {
        let actual = self.type_name(v.kind);
        if actual == requested {
            return Ok(());
        }
        Err(FmuError::WrongType {
            name: v.name,
            vr: v.value_reference,
            actual,
            requested,
            api: self.prefix(),
        })
    }
}
