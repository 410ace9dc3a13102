//! The variable table of a model: every input, output and parameter with its value
//! reference, unit, causality, variability, start and range. The FMU writes its
//! modelDescription.xml from it and dispatches get/set through it; the SITL serves it over
//! the MAVLink parameter protocol.

use crate::error::ParamError;
use crate::params::{ParamSpec, Parameters, ValueKind};

/// FMI 2.0 causality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
}

/// FMI 2.0 variability.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    /// Set before initialisation only.
    Fixed,
    /// Settable between steps.
    Tunable,
    /// Changes continuously in time (inputs/outputs of the dynamics).
    Continuous,
    /// Changes only at steps (flags, counters).
    Discrete,
}

/// One variable of a model.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    pub name: &'static str,
    pub value_reference: u32,
    pub kind: ValueKind,
    pub causality: Causality,
    pub variability: Variability,
    pub unit: &'static str,
    pub description: &'static str,
    /// Start value (inputs and parameters; FMI forbids one on continuous outputs).
    pub start: Option<f64>,
    pub min: Option<f64>,
    pub max: Option<f64>,
}

/// Value references are grouped in blocks so that adding a variable to one group does not
/// renumber the others.
pub mod vr_block {
    pub const INPUT: u32 = 0;
    pub const OUTPUT: u32 = 100;
    pub const PARAMETER: u32 = 300;
    pub const INITIAL: u32 = 500;
}

/// The parameter rows of `P` as variables numbered from `first_vr`.
pub fn parameter_variables<P: Parameters>(
    first_vr: u32,
    variability: Variability,
) -> impl Iterator<Item = Variable> {
    let defaults = P::default();
    P::specs()
        .iter()
        .zip(first_vr..)
        .map(move |(s, vr)| Variable {
            name: s.name,
            value_reference: vr,
            kind: s.kind,
            causality: Causality::Parameter,
            variability,
            unit: s.unit,
            description: s.description,
            start: Some((s.get)(&defaults)),
            min: (s.kind != ValueKind::Boolean).then_some(s.min),
            max: (s.kind != ValueKind::Boolean).then_some(s.max),
        })
}

/// Looks up the parameter row behind `vr` in a block that starts at `first_vr`.
pub fn parameter_at<P: Parameters>(
    vr: u32,
    first_vr: u32,
) -> Result<&'static ParamSpec<P>, ParamError> {
    vr.checked_sub(first_vr)
        .and_then(|i| P::specs().get(i as usize))
        .ok_or(ParamError::UnknownValueReference(vr))
}

/// Test helper: every variable of a table has a unique name, a unique value reference and a
/// description.
#[cfg(test)]
pub(crate) fn assert_names_and_value_references_are_unique(vars: &[Variable]) {
    let mut names = std::collections::HashSet::new();
    let mut vrs = std::collections::HashSet::new();
    for v in vars {
        assert!(names.insert(v.name), "duplicate name {}", v.name);
        assert!(
            vrs.insert(v.value_reference),
            "duplicate vr {}",
            v.value_reference
        );
        assert!(!v.description.is_empty(), "{} has no description", v.name);
    }
}
