//! A model's variable table as the FMI layer looks it up on every call, with the FMI 3.0 view
//! of the same variables ([`Fmi3View`]: arrays, `time`, one variable per event indicator).

use crate::error::FmuError;
use crate::guid;
use flyloop_core::params::ValueKind;
use flyloop_core::variables::{Causality, Variability, Variable};
use std::ffi::CString;

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
}

/// The type an fmi2Get*/fmi2Set* or fmi3Get*/fmi3Set* function works with: the kind of the
/// variables it reaches, or none for a type no variable has (String, Float32, Binary...).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ValueType {
    pub api: Api,
    pub kind: Option<ValueKind>,
    pub name: &'static str,
}

impl ValueType {
    pub const fn of(api: Api, kind: ValueKind) -> Self {
        ValueType {
            api,
            kind: Some(kind),
            name: api.type_name(kind),
        }
    }

    pub const fn none(api: Api, name: &'static str) -> Self {
        ValueType {
            api,
            kind: None,
            name,
        }
    }

    /// Fails unless a variable `name` (value reference `vr`) of `kind` is of this type.
    pub fn check(self, name: &'static str, vr: u32, kind: ValueKind) -> Result<(), FmuError> {
        if self.kind == Some(kind) {
            return Ok(());
        }
        Err(FmuError::WrongType {
            name,
            vr,
            actual: self.api.type_name(kind),
            requested: self.name,
            api: self.api.prefix(),
        })
    }
}

/// FMI 3.0: a run of consecutive variables shown as one array.
#[derive(Debug)]
pub struct Array {
    pub name: &'static str,
    /// The array's description; `None` takes the first element's.
    pub description: Option<&'static str>,
    /// The name of element 0; the other elements follow it in the table.
    pub first: &'static str,
    pub len: usize,
}

/// Facts about a model that its variable table does not hold.
#[derive(Debug)]
pub struct ModelInfo {
    /// modelIdentifier and modelName: the FMU is `<identifier>.fmu`, its binary
    /// `binaries/linux64/<identifier>.so`.
    pub identifier: &'static str,
    pub description: &'static str,
    /// DefaultExperiment: start, stop, step size (s).
    pub default_experiment: (f64, f64, f64),
    /// Inputs (by name) each output depends on directly, without a step in between
    /// (ModelStructure/Outputs/Unknown/@dependencies). Outputs not listed depend on none.
    pub direct_feedthrough: &'static [(&'static str, &'static [&'static str])],
    /// Outputs that do not depend on the continuous states (Model Exchange dependencies).
    pub state_free_outputs: &'static [&'static str],
    pub arrays: &'static [Array],
    /// FMI 3.0: a variable for each event indicator (name, unit, description), in order.
    pub event_indicators: &'static [(&'static str, &'static str, &'static str)],
}

/// What a Model-Exchange capable model adds to its table: value references of its continuous
/// states and their derivatives (in state-vector order).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelExchangeTable {
    pub states: Vec<u32>,
    pub derivatives: Vec<u32>,
    pub event_indicators: usize,
}

/// Value reference → position in a variable list: a dense table up to the largest value
/// reference (about a thousand entries here).
#[derive(Debug, Default)]
pub struct VrIndex(Vec<u32>);

impl VrIndex {
    const NONE: u32 = u32::MAX;

    pub fn new(vrs: impl Iterator<Item = u32> + Clone) -> Self {
        let len = vrs.clone().max().map_or(0, |m| m as usize + 1);
        let mut table = vec![Self::NONE; len];
        for (i, vr) in vrs.enumerate() {
            table[vr as usize] = i as u32;
        }
        VrIndex(table)
    }

    pub fn get(&self, vr: u32) -> Option<usize> {
        let at = *self.0.get(vr as usize)?;
        (at != Self::NONE).then_some(at as usize)
    }
}

#[derive(Debug)]
pub struct ModelTable {
    pub info: &'static ModelInfo,
    /// Every variable in value-reference order (the modelDescription's order).
    pub variables: Vec<Variable>,
    /// FMI 2.0's GUID and FMI 3.0's instantiationToken (of its own interface: arrays, `time`,
    /// event indicators); hex digits, dashes and braces, never a NUL.
    pub guid: CString,
    pub token3: CString,
    pub fmi3: Fmi3View,
    /// Value reference → position in `variables`.
    pub by_vr: VrIndex,
    pub model_exchange: Option<ModelExchangeTable>,
}

impl ModelTable {
    /// # Panics
    /// If a declared array's elements are not in the table (a fault of the model's
    /// [`ModelInfo::arrays`], found by the crate's tests).
    pub fn new(
        info: &'static ModelInfo,
        variables: Vec<Variable>,
        model_exchange: Option<ModelExchangeTable>,
    ) -> Self {
        let token = |api| CString::new(guid::of_interface(api, info.identifier, &variables));
        ModelTable {
            info,
            guid: token(Api::Fmi2).unwrap_or_default(),
            token3: token(Api::Fmi3).unwrap_or_default(),
            fmi3: Fmi3View::new(info, &variables),
            by_vr: VrIndex::new(variables.iter().map(|v| v.value_reference)),
            variables,
            model_exchange,
        }
    }

    pub fn token(&self, api: Api) -> &str {
        let token = match api {
            Api::Fmi2 => &self.guid,
            Api::Fmi3 => &self.token3,
        };
        token.to_str().unwrap_or_default()
    }

    /// The position of value reference `vr`, after checking that it is of type `ty`.
    pub fn lookup(&self, vr: u32, ty: ValueType) -> Result<usize, FmuError> {
        let index = self
            .by_vr
            .get(vr)
            .ok_or(FmuError::UnknownValueReference(vr))?;
        let v = &self.variables[index];
        ty.check(v.name, vr, v.kind)?;
        Ok(index)
    }

    pub fn by_name(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }
}

/// Value reference of the FMI 3.0 independent variable `time` (above every model's own).
pub const TIME_VR: u32 = 1000;
/// Value reference of the first FMI 3.0 event-indicator variable; the others follow.
pub const EVENT_INDICATOR_VR: u32 = 1001;

/// Where an FMI 3.0 variable's values come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// Positions in [`ModelTable::variables`] (one for a scalar).
    Model(Vec<usize>),
    Time,
    EventIndicator(usize),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Variable3 {
    pub name: String,
    pub description: String,
    pub value_reference: u32,
    pub kind: ValueKind,
    /// The model's causality; `None` for the independent variable `time`.
    pub causality: Option<Causality>,
    pub variability: Variability,
    pub unit: &'static str,
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// Of each element (empty when there is none).
    pub start: Vec<f64>,
    /// `None` for a scalar, else the array's length.
    pub dimension: Option<usize>,
    pub source: Source,
}

impl Variable3 {
    pub(crate) fn len(&self) -> usize {
        self.dimension.unwrap_or(1)
    }

    /// The positions in [`ModelTable::variables`] behind this variable.
    pub fn elements(&self) -> &[usize] {
        match &self.source {
            Source::Model(elements) => elements,
            _ => &[],
        }
    }

    /// A real local without start or range (`time`, the event indicators).
    fn computed(name: &str, vr: u32, unit: &'static str, text: &str, source: Source) -> Self {
        Variable3 {
            name: name.to_string(),
            description: text.to_string(),
            value_reference: vr,
            kind: ValueKind::Real,
            causality: Some(Causality::Local),
            variability: Variability::Continuous,
            unit,
            min: None,
            max: None,
            start: Vec::new(),
            dimension: None,
            source,
        }
    }

    /// The model's variables `run` (at positions from `first`) as one variable: a scalar, or
    /// the array `array`.
    pub(crate) fn of(run: &[Variable], first: usize, array: Option<&Array>) -> Self {
        let v = &run[0];
        Variable3 {
            name: array.map_or(v.name, |a| a.name).to_string(),
            description: array
                .and_then(|a| a.description)
                .unwrap_or(v.description)
                .to_string(),
            value_reference: v.value_reference,
            kind: v.kind,
            causality: Some(v.causality),
            variability: v.variability,
            unit: v.unit,
            min: v.min,
            max: v.max,
            start: run.iter().filter_map(|e| e.start).collect(),
            dimension: array.map(|a| a.len),
            source: Source::Model((first..first + run.len()).collect()),
        }
    }
}

/// The FMI 3.0 variables of a model. An array takes the value reference of its first element.
#[derive(Debug)]
pub struct Fmi3View {
    /// In modelDescription order: `time` first, then the model's variables, then the event
    /// indicators.
    pub variables: Vec<Variable3>,
    /// Value reference → position in `variables`.
    by_vr: VrIndex,
    /// Value references of the event-indicator variables, in order.
    pub event_indicators: Vec<u32>,
    /// Model value reference → (FMI 3.0 value reference, element index), sorted.
    element_of: Vec<(u32, (u32, usize))>,
}

impl Fmi3View {
    fn new(info: &ModelInfo, model: &[Variable]) -> Self {
        let time = Variable3 {
            causality: None,
            ..Variable3::computed("time", TIME_VR, "s", "Simulation time", Source::Time)
        };
        let mut variables = vec![time];
        let mut at = 0;
        while at < model.len() {
            let array = info.arrays.iter().find(|a| a.first == model[at].name);
            let len = array.map_or(1, |a| a.len);
            let run = model
                .get(at..at + len)
                .unwrap_or_else(|| panic!("array {array:?}"));
            variables.push(Variable3::of(run, at, array));
            at += len;
        }
        let event_indicators = (EVENT_INDICATOR_VR..).zip(info.event_indicators);
        for (i, (vr, &(name, unit, text))) in event_indicators.enumerate() {
            let source = Source::EventIndicator(i);
            variables.push(Variable3::computed(name, vr, unit, text, source));
        }
        let mut element_of: Vec<(u32, (u32, usize))> = Vec::new();
        for v in &variables {
            let elements = v.elements().iter().enumerate();
            element_of.extend(
                elements.map(|(i, &at)| (model[at].value_reference, (v.value_reference, i))),
            );
        }
        element_of.sort_unstable_by_key(|&(vr, _)| vr);
        Fmi3View {
            by_vr: VrIndex::new(variables.iter().map(|v| v.value_reference)),
            variables,
            event_indicators: (EVENT_INDICATOR_VR..)
                .take(info.event_indicators.len())
                .collect(),
            element_of,
        }
    }

    /// The FMI 3.0 variable (value reference) and element index holding model variable `vr`.
    pub fn element(&self, vr: u32) -> Option<(u32, usize)> {
        let at = self
            .element_of
            .binary_search_by_key(&vr, |&(v, _)| v)
            .ok()?;
        Some(self.element_of[at].1)
    }

    /// The variable with FMI 3.0 value reference `vr`.
    pub fn variable(&self, vr: u32) -> Option<&Variable3> {
        self.variables.get(self.by_vr.get(vr)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::tables;

    fn by_name<'a>(view: &'a Fmi3View, name: &str) -> &'a Variable3 {
        view.variables.iter().find(|v| v.name == name).unwrap()
    }

    #[test]
    fn motor_commands_are_one_array_and_every_model_value_has_one_home() {
        let [quad, lander] = tables();
        let layout = &quad.fmi3;
        let command = by_name(layout, "motor_command");
        assert_eq!(command.value_reference, 0);
        assert_eq!(command.dimension, Some(4));
        assert_eq!(command.source, Source::Model(vec![0, 1, 2, 3]));
        assert_eq!(command.start, [0.0; 4]);
        assert_eq!(
            layout.variable(1),
            None,
            "element 1 has no value reference of its own"
        );
        assert_eq!(by_name(layout, "der(motor_state)").len(), 4);
        assert_eq!(layout.element(2), Some((0, 2)));
        // 25 states: 13 body scalars + motor_state[4] + 8 bristles = 22 variables.
        let me = quad.model_exchange.as_ref().unwrap();
        for vrs in [&me.states, &me.derivatives] {
            let firsts = vrs.iter().filter(|&&vr| layout.element(vr).unwrap().1 == 0);
            assert_eq!(firsts.count(), 22);
        }
        assert_eq!(layout.event_indicators, [1001, 1002, 1003, 1004]);
        for table in [quad, lander] {
            let layout = &table.fmi3;
            assert_eq!(layout.variables[0].source, Source::Time);
            let elements: usize = layout
                .variables
                .iter()
                .filter(|v| matches!(v.source, Source::Model(_)))
                .map(Variable3::len)
                .sum();
            assert_eq!(elements, table.variables.len(), "{}", table.info.identifier);
            for v in &table.variables {
                assert!(layout.element(v.value_reference).is_some(), "{}", v.name);
            }
            let mut vrs: Vec<u32> = layout.variables.iter().map(|v| v.value_reference).collect();
            vrs.sort_unstable();
            vrs.dedup();
            assert_eq!(
                vrs.len(),
                layout.variables.len(),
                "value references are unique"
            );
        }
    }
}
