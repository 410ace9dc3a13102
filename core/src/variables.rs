//! The variable table of a model: every input, output and parameter with its value
//! reference, unit, causality, variability, start and range. The FMU writes its
//! modelDescription.xml from it and dispatches get/set through it; the SITL serves it over
//! the MAVLink parameter protocol.
//!
//! A table is built for a shape ([`VariableTable::Shape`]): a multirotor has one motor
//! command and one motor state per rotor of its frame, so its [`Rows`] are made from the
//! frame, and an FMU for another frame is the same code with another table.

use crate::error::{InputError, ParamError, Role};
use crate::params::{ParamSpec, Parameters, ValueKind};
use std::borrow::Cow;

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
    /// Fixed text, or text made from the shape (a rotor's place in its frame).
    pub description: Cow<'static, str>,
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
            description: Cow::Borrowed(s.description),
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
    pub description: Cow<'static, str>,
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
            description: Cow::Borrowed(description),
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
    pub description: Cow<'static, str>,
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
            description: Cow::Borrowed(description),
            get,
        }
    }

    /// A Boolean output (a flag without unit).
    pub const fn flag(name: &'static str, description: &'static str, get: fn(&M) -> f64) -> Self {
        OutputRow {
            name,
            kind: ValueKind::Boolean,
            unit: "",
            description: Cow::Borrowed(description),
            get,
        }
    }
}

// By hand: a row is cloneable whatever the model (derive would ask `M: Clone`).
impl<M> Clone for InputRow<M> {
    fn clone(&self) -> Self {
        InputRow {
            description: self.description.clone(),
            ..*self
        }
    }
}

impl<M> Clone for OutputRow<M> {
    fn clone(&self) -> Self {
        OutputRow {
            description: self.description.clone(),
            ..*self
        }
    }
}

/// A model with a variable table: inputs and outputs as rows for its shape, physical
/// parameters and start values as [`Parameters`]. [`Rows`] serves every such model.
pub trait VariableTable: Sized + 'static {
    /// The physical parameters (value references from [`vr_block::PARAMETER`]).
    type Params: Parameters;
    /// The start values that are not physical parameters (from [`vr_block::INITIAL`]).
    type Initial: Parameters;
    /// What sizes and names the rows: a multirotor's frame (one motor command and one motor
    /// state per rotor); `()` for a model whose table is always the same.
    type Shape;

    /// Inputs in value-reference order from [`vr_block::INPUT`].
    fn inputs(shape: &Self::Shape) -> Vec<InputRow<Self>>;
    /// Outputs in value-reference order from [`vr_block::OUTPUT`].
    fn outputs(shape: &Self::Shape) -> Vec<OutputRow<Self>>;
    /// The shape of this instance (its table is `Rows::of(model.shape())`).
    fn shape(&self) -> &Self::Shape;

    fn params(&self) -> &Self::Params;
    /// Sets one physical parameter (range-checked; nothing changes when it is refused).
    fn set_parameter(&mut self, name: &'static str, value: f64) -> Result<(), ParamError>;
}

/// The members of a [`VariableTable`] impl that are the same for every model whose table
/// never changes (`Shape = ()`): its rows are copies of the slices `$inputs` and `$outputs`.
/// The impl adds `Params`, `Initial`, `params` and `set_parameter`, e.g.
/// `impl VariableTable for M { type Params = P; type Initial = I; fixed_shape!(INPUTS, OUTPUTS); … }`.
#[macro_export]
macro_rules! fixed_shape {
    ($inputs:expr, $outputs:expr) => {
        type Shape = ();

        fn inputs(_: &()) -> Vec<$crate::variables::InputRow<Self>> {
            $inputs.to_vec()
        }

        fn outputs(_: &()) -> Vec<$crate::variables::OutputRow<Self>> {
            $outputs.to_vec()
        }

        fn shape(&self) -> &() {
            &()
        }
    };
}

/// Where a value reference points in a table ([`Rows::row`]): an input or output by its
/// position in the rows, or a parameter row. Plain data, so a front end can look it up once
/// and read through it on every call.
#[derive(Debug)]
pub enum Row<M: VariableTable> {
    Input(usize),
    Output(usize),
    Parameter(&'static ParamSpec<M::Params>),
    Initial(&'static ParamSpec<M::Initial>),
}

impl<M: VariableTable> Clone for Row<M> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<M: VariableTable> Copy for Row<M> {}

/// The variable table of `M` for one shape: its input and output rows (the parameter rows
/// are `M`'s types). Built once per shape; lookups by value reference are index arithmetic.
#[derive(Debug)]
pub struct Rows<M> {
    pub inputs: Vec<InputRow<M>>,
    pub outputs: Vec<OutputRow<M>>,
}

impl<M: VariableTable> Rows<M> {
    /// The table of `M` for `shape`.
    pub fn of(shape: &M::Shape) -> Self {
        Rows {
            inputs: M::inputs(shape),
            outputs: M::outputs(shape),
        }
    }

    /// The table of `model`'s shape.
    pub fn of_model(model: &M) -> Self {
        Rows::of(model.shape())
    }

    /// The row of value reference `vr`.
    pub fn row(&self, vr: u32) -> Result<Row<M>, ParamError> {
        let unknown = ParamError::UnknownValueReference(vr);
        let index = |first: u32| (vr - first) as usize;
        Ok(if vr >= vr_block::INITIAL {
            Row::Initial(parameter_at::<M::Initial>(vr, vr_block::INITIAL)?)
        } else if vr >= vr_block::PARAMETER {
            Row::Parameter(parameter_at::<M::Params>(vr, vr_block::PARAMETER)?)
        } else if vr >= vr_block::OUTPUT {
            let at = index(vr_block::OUTPUT);
            (at < self.outputs.len())
                .then_some(Row::Output(at))
                .ok_or(unknown)?
        } else {
            let at = index(vr_block::INPUT);
            (at < self.inputs.len())
                .then_some(Row::Input(at))
                .ok_or(unknown)?
        })
    }

    /// The value behind `row` in `model` (start values from `initial`).
    ///
    /// # Panics
    /// If `row` is not one of this table's ([`Rows::row`] of another shape).
    pub fn get_at(&self, row: Row<M>, model: &M, initial: &M::Initial) -> f64 {
        match row {
            Row::Input(at) => (self.inputs[at].get)(model),
            Row::Output(at) => (self.outputs[at].get)(model),
            Row::Parameter(spec) => (spec.get)(model.params()),
            Row::Initial(spec) => (spec.get)(initial),
        }
    }

    /// Writes the value behind `row`; it is checked against its range and nothing changes
    /// when it is refused. Outputs cannot be set.
    ///
    /// # Panics
    /// If `row` is not one of this table's ([`Rows::row`] of another shape).
    pub fn set_at(
        &self,
        row: Row<M>,
        model: &mut M,
        initial: &mut M::Initial,
        value: f64,
    ) -> Result<(), ParamError> {
        match row {
            Row::Input(at) => {
                let r = &self.inputs[at];
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
            Row::Output(at) => Err(ParamError::NotSettable(self.outputs[at].name)),
            Row::Parameter(spec) => model.set_parameter(spec.name, value),
            Row::Initial(spec) => initial.set(spec.name, value),
        }
    }

    /// Reads variable `vr` of `model` (start values from `initial`).
    pub fn get(&self, model: &M, initial: &M::Initial, vr: u32) -> Result<f64, ParamError> {
        Ok(self.get_at(self.row(vr)?, model, initial))
    }

    /// Writes variable `vr` (see [`Rows::set_at`]).
    pub fn set(
        &self,
        model: &mut M,
        initial: &mut M::Initial,
        vr: u32,
        value: f64,
    ) -> Result<(), ParamError> {
        self.set_at(self.row(vr)?, model, initial, value)
    }

    /// Every variable, in value-reference order.
    pub fn variables(&self) -> Vec<Variable> {
        let inputs = (self.inputs.iter().zip(vr_block::INPUT..)).map(|(r, vr)| Variable {
            name: r.name,
            value_reference: vr,
            kind: ValueKind::Real,
            causality: Causality::Input,
            variability: Variability::Continuous,
            unit: r.unit,
            description: r.description.clone(),
            start: Some(r.start),
            min: Some(r.min),
            max: Some(r.max),
        });
        let outputs = (self.outputs.iter().zip(vr_block::OUTPUT..)).map(|(r, vr)| Variable {
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
            description: r.description.clone(),
            start: None,
            min: None,
            max: None,
        });
        let fixed = Variability::Fixed;
        inputs
            .chain(outputs)
            .chain(parameter_variables::<M::Params>(vr_block::PARAMETER, fixed))
            .chain(parameter_variables::<M::Initial>(vr_block::INITIAL, fixed))
            .collect()
    }
}

/// Reads variable `vr` of `model` through the table of its shape (built for this one call:
/// for many, build [`Rows`] once).
pub fn get<M: VariableTable>(model: &M, initial: &M::Initial, vr: u32) -> Result<f64, ParamError> {
    Rows::of_model(model).get(model, initial, vr)
}

/// Writes variable `vr` of `model` (see [`get`], [`Rows::set_at`]).
pub fn set<M: VariableTable>(
    model: &mut M,
    initial: &mut M::Initial,
    vr: u32,
    value: f64,
) -> Result<(), ParamError> {
    Rows::of_model(model).set(model, initial, vr, value)
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

/// Test helper: the value reference of the variable `name` of `model`'s table.
#[cfg(test)]
pub(crate) fn value_reference<M: VariableTable>(model: &M, name: &str) -> u32 {
    Rows::of_model(model)
        .variables()
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
    let vars = Rows::of_model(model).variables();
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
