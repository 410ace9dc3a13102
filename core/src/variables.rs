//! The variable table of a model: every input, output and parameter with its value
//! reference, unit, causality, variability, start and range. The FMU writes its
//! modelDescription.xml from it and dispatches get/set through it; the SITL serves it over
//! the MAVLink parameter protocol.

use crate::error::{InputError, ParamError, Role};
use crate::params::{ParamSpec, Parameters, ValueKind};

/// FMI 2.0 causality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
    /// Visible but not part of the interface (Model Exchange's extra states, derivatives).
    Local,
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

/// One input of a model: a Real, range-checked before `set` sees it.
#[derive(Debug)]
pub struct InputRow<M> {
    pub name: &'static str,
    pub unit: &'static str,
    pub description: &'static str,
    /// Inclusive range; a value outside (or NaN) is refused with [`ParamError::OutOfRange`].
    pub min: f64,
    pub max: f64,
    /// What the model reads before anything is set.
    pub start: f64,
    pub get: fn(&M) -> f64,
    /// Writes a finite value inside `[min, max]`.
    pub set: fn(&mut M, f64) -> Result<(), InputError>,
}

impl<M> InputRow<M> {
    /// An input with its `[min, max]` range and `start` value.
    pub const fn new(
        name: &'static str,
        unit: &'static str,
        description: &'static str,
        [min, max, start]: [f64; 3],
        get: fn(&M) -> f64,
        set: fn(&mut M, f64) -> Result<(), InputError>,
    ) -> Self {
        InputRow {
            name,
            unit,
            description,
            min,
            max,
            start,
            get,
            set,
        }
    }
}

/// One output of a model: read only.
#[derive(Debug)]
pub struct OutputRow<M> {
    pub name: &'static str,
    /// Real, or Boolean for flags (read as 0 / 1).
    pub kind: ValueKind,
    pub unit: &'static str,
    pub description: &'static str,
    pub get: fn(&M) -> f64,
}

impl<M> OutputRow<M> {
    /// A Real output.
    pub const fn real(
        name: &'static str,
        unit: &'static str,
        description: &'static str,
        get: fn(&M) -> f64,
    ) -> Self {
        OutputRow {
            name,
            kind: ValueKind::Real,
            unit,
            description,
            get,
        }
    }

    /// A Boolean output (a flag without unit).
    pub const fn flag(name: &'static str, description: &'static str, get: fn(&M) -> f64) -> Self {
        OutputRow {
            name,
            kind: ValueKind::Boolean,
            unit: "",
            description,
            get,
        }
    }
}

/// A model with a variable table: inputs and outputs as rows, physical parameters and start
/// values as [`Parameters`]. [`variables`], [`get`] and [`set`] serve every such model.
pub trait VariableTable: Sized + 'static {
    /// The physical parameters (value references from [`vr_block::PARAMETER`]).
    type Params: Parameters;
    /// The start values that are not physical parameters (from [`vr_block::INITIAL`]).
    type Initial: Parameters;
    /// Inputs in value-reference order from [`vr_block::INPUT`].
    const INPUTS: &'static [InputRow<Self>];
    /// Outputs in value-reference order from [`vr_block::OUTPUT`].
    const OUTPUTS: &'static [OutputRow<Self>];

    fn params(&self) -> &Self::Params;
    /// Sets one physical parameter (range-checked; nothing changes when it is refused).
    fn set_parameter(&mut self, name: &'static str, value: f64) -> Result<(), ParamError>;
}

/// The row a value reference points at: what reads and writes the variable in the model.
#[derive(Debug)]
pub enum Row<M: VariableTable> {
    Input(&'static InputRow<M>),
    Output(&'static OutputRow<M>),
    Parameter(&'static ParamSpec<M::Params>),
    Initial(&'static ParamSpec<M::Initial>),
}

impl<M: VariableTable> Clone for Row<M> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<M: VariableTable> Copy for Row<M> {}

/// The row of value reference `vr` of `M`.
pub fn row<M: VariableTable>(vr: u32) -> Result<Row<M>, ParamError> {
    let unknown = ParamError::UnknownValueReference(vr);
    let index = |first: u32| (vr - first) as usize;
    Ok(if vr >= vr_block::INITIAL {
        Row::Initial(parameter_at::<M::Initial>(vr, vr_block::INITIAL)?)
    } else if vr >= vr_block::PARAMETER {
        Row::Parameter(parameter_at::<M::Params>(vr, vr_block::PARAMETER)?)
    } else if vr >= vr_block::OUTPUT {
        Row::Output(M::OUTPUTS.get(index(vr_block::OUTPUT)).ok_or(unknown)?)
    } else {
        Row::Input(M::INPUTS.get(index(vr_block::INPUT)).ok_or(unknown)?)
    })
}

impl<M: VariableTable> Row<M> {
    /// The variable's value in `model` (start values from `initial`).
    pub fn get(self, model: &M, initial: &M::Initial) -> f64 {
        match self {
            Row::Input(r) => (r.get)(model),
            Row::Output(r) => (r.get)(model),
            Row::Parameter(spec) => (spec.get)(model.params()),
            Row::Initial(spec) => (spec.get)(initial),
        }
    }

    /// Writes the variable; the value is checked against its range and nothing changes when
    /// it is refused. Outputs cannot be set.
    pub fn set(
        self,
        model: &mut M,
        initial: &mut M::Initial,
        value: f64,
    ) -> Result<(), ParamError> {
        match self {
            Row::Input(r) => {
                let out_of_range = ParamError::OutOfRange {
                    role: Role::Input,
                    name: r.name,
                    value,
                    min: r.min,
                    max: r.max,
                    unit: r.unit,
                };
                if !(value >= r.min && value <= r.max) {
                    return Err(out_of_range);
                }
                (r.set)(model, value).map_err(|_| out_of_range)
            }
            Row::Output(r) => Err(ParamError::NotSettable(r.name)),
            Row::Parameter(spec) => model.set_parameter(spec.name, value),
            Row::Initial(spec) => initial.set(spec.name, value),
        }
    }
}

/// Every variable of `M`, in value-reference order.
pub fn variables<M: VariableTable>() -> Vec<Variable> {
    let inputs = M::INPUTS
        .iter()
        .zip(vr_block::INPUT..)
        .map(|(r, vr)| Variable {
            name: r.name,
            value_reference: vr,
            kind: ValueKind::Real,
            causality: Causality::Input,
            variability: Variability::Continuous,
            unit: r.unit,
            description: r.description,
            start: Some(r.start),
            min: Some(r.min),
            max: Some(r.max),
        });
    let outputs = M::OUTPUTS
        .iter()
        .zip(vr_block::OUTPUT..)
        .map(|(r, vr)| Variable {
            name: r.name,
            value_reference: vr,
            kind: r.kind,
            causality: Causality::Output,
            variability: if r.kind == ValueKind::Real {
                Variability::Continuous
            } else {
                Variability::Discrete
            },
            unit: r.unit,
            description: r.description,
            start: None,
            min: None,
            max: None,
        });
    inputs
        .chain(outputs)
        .chain(parameter_variables::<M::Params>(
            vr_block::PARAMETER,
            Variability::Fixed,
        ))
        .chain(parameter_variables::<M::Initial>(
            vr_block::INITIAL,
            Variability::Fixed,
        ))
        .collect()
}

/// Reads variable `vr` of `model` (start values from `initial`).
pub fn get<M: VariableTable>(model: &M, initial: &M::Initial, vr: u32) -> Result<f64, ParamError> {
    Ok(row::<M>(vr)?.get(model, initial))
}

/// Writes variable `vr` (see [`Row::set`]).
pub fn set<M: VariableTable>(
    model: &mut M,
    initial: &mut M::Initial,
    vr: u32,
    value: f64,
) -> Result<(), ParamError> {
    row::<M>(vr)?.set(model, initial, value)
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

/// Test helper: the value reference of the variable `name` of `M`'s table.
#[cfg(test)]
pub(crate) fn value_reference<M: VariableTable>(name: &str) -> u32 {
    variables::<M>()
        .into_iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}"))
        .value_reference
}

/// Test helper: `M`'s table is well formed (see
/// [`assert_names_and_value_references_are_unique`]), every variable reads a finite value and
/// (inputs only when `inputs_read_start`) its start value, and value references outside the
/// table are refused.
#[cfg(test)]
pub(crate) fn assert_every_variable_reads<M: VariableTable>(
    model: &M,
    initial: &M::Initial,
    inputs_read_start: bool,
) {
    let vars = variables::<M>();
    assert_names_and_value_references_are_unique(&vars);
    for v in &vars {
        let value = get(model, initial, v.value_reference).unwrap();
        assert!(value.is_finite(), "{} = {value}", v.name);
        let checked = inputs_read_start || v.causality != Causality::Input;
        if let (Some(start), true) = (v.start, checked) {
            assert_eq!(value, start, "{} does not read its start value", v.name);
        }
    }
    for vr in [99, 10_000] {
        assert_eq!(
            get(model, initial, vr),
            Err(ParamError::UnknownValueReference(vr))
        );
    }
}
