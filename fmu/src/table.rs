//! A model's variable table as the FMI layer looks it up on every call, with the FMI 3.0 view
//! of the same variables ([`Variable3`]: arrays, `time`, one variable per event indicator).

use crate::api::Api;
use crate::error::FmuError;
use crate::guid;
use flyloop_core::params::ValueKind;
use flyloop_core::variables::{Causality, Variability, Variable};
use std::borrow::Cow;
use std::ffi::CString;
use std::ops::{Deref, Range};

/// FMI 3.0: a run of consecutive variables shown as one array.
#[derive(Debug)]
pub struct Array {
    pub name: &'static str,
    pub description: Cow<'static, str>,
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
    pub description: Cow<'static, str>,
    /// DefaultExperiment: start, stop, step size (s).
    pub default_experiment: (f64, f64, f64),
    /// Inputs (by name) each output depends on directly, without a step in between
    /// (ModelStructure/Outputs/Unknown/@dependencies). Outputs not listed depend on none.
    pub direct_feedthrough: &'static [(&'static str, &'static [&'static str])],
    /// Outputs that do not depend on the continuous states (Model Exchange dependencies).
    pub state_free_outputs: &'static [&'static str],
    pub arrays: Vec<Array>,
    /// FMI 3.0: a variable for each event indicator (name, unit, description), in order.
    pub event_indicators: &'static [(&'static str, &'static str, &'static str)],
    /// Descriptions that replace the core table's for this FMU (variable name, text): a
    /// start value described for every motor counts the FMU's motors.
    pub descriptions: Vec<(&'static str, Cow<'static, str>)>,
}

/// What a Model-Exchange capable model adds to its table: value references of its continuous
/// states and their derivatives (in state-vector order).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
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
    pub info: ModelInfo,
    /// Every variable in value-reference order (the modelDescription's order).
    pub variables: Vec<Variable>,
    /// FMI 2.0's GUID and FMI 3.0's instantiationToken (of its own interface: arrays, `time`,
    /// event indicators); hex digits, dashes and braces, never a NUL.
    pub guid: CString,
    pub token3: CString,
    /// Value reference → position in `variables`.
    pub by_vr: VrIndex,
    /// The FMI 3.0 variables in modelDescription order: `time`, the model's (an array takes
    /// the value reference of its first element), the event indicators.
    pub fmi3: Vec<Variable3>,
    /// FMI 3.0 value reference → position in `fmi3`.
    by_vr3: VrIndex,
    pub model_exchange: Option<ModelExchangeTable>,
}

impl ModelTable {
    /// # Panics
    /// If a declared array's elements are not in the table (a fault of the model's
    /// [`ModelInfo::arrays`], found by the crate's tests).
    pub fn new(
        info: ModelInfo,
        mut variables: Vec<Variable>,
        model_exchange: Option<ModelExchangeTable>,
    ) -> Self {
        for (name, text) in &info.descriptions {
            let described = variables.iter_mut().filter(|v| v.name == *name);
            described.for_each(|v| v.description = text.clone());
        }
        let token = |api| CString::new(guid::of_interface(api, info.identifier, &variables));
        let fmi3 = Variable3::fmi3(&info, &variables);
        ModelTable {
            guid: token(Api::Fmi2).unwrap_or_default(),
            token3: token(Api::Fmi3).unwrap_or_default(),
            by_vr: VrIndex::new(variables.iter().map(|v| v.value_reference)),
            by_vr3: VrIndex::new(fmi3.iter().map(|v| v.value_reference)),
            fmi3,
            variables,
            model_exchange,
            info,
        }
    }

    pub fn token(&self, api: Api) -> &str {
        let token = match api {
            Api::Fmi2 => &self.guid,
            Api::Fmi3 => &self.token3,
        };
        token.to_str().unwrap_or_default()
    }

    /// The position of value reference `vr`, after checking that it is of `api`'s type `ty`.
    pub fn lookup(&self, vr: u32, api: Api, ty: &'static str) -> Result<usize, FmuError> {
        let index = self
            .by_vr
            .get(vr)
            .ok_or(FmuError::UnknownValueReference(vr))?;
        api.check(ty, &self.variables[index])?;
        Ok(index)
    }

    pub fn by_name(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// The FMI 3.0 variable with value reference `vr`.
    pub fn variable3(&self, vr: u32) -> Option<&Variable3> {
        self.fmi3.get(self.by_vr3.get(vr)?)
    }
}

/// Value reference of the FMI 3.0 independent variable `time` (above every model's own).
pub const TIME_VR: u32 = 1000;
/// Value reference of the first FMI 3.0 event-indicator variable; the others follow.
pub const EVENT_INDICATOR_VR: u32 = 1001;

/// A real local without start or range (Model Exchange's extra states and derivatives, FMI
/// 3.0's `time` and event indicators).
pub fn local(name: &'static str, vr: u32, unit: &'static str, text: &'static str) -> Variable {
    Variable {
        name,
        value_reference: vr,
        kind: ValueKind::Real,
        causality: Causality::Local,
        variability: Variability::Continuous,
        unit,
        description: Cow::Borrowed(text),
        start: None,
        min: None,
        max: None,
    }
}

/// Where an FMI 3.0 variable's values come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// Positions in [`ModelTable::variables`] (one for a scalar).
    Model(Range<usize>),
    Time,
    EventIndicator(usize),
}

/// A variable as FMI 3.0 shows it: a model's; an array (its first element, renamed; each
/// element's start in [`ModelTable::variables`]); an event indicator; or `time`, the
/// independent variable, which says Local (the core's [`Causality`] has no such value).
#[derive(Debug, Clone, PartialEq)]
pub struct Variable3 {
    pub variable: Variable,
    /// `None` for a scalar, else the array's length.
    pub dimension: Option<usize>,
    pub source: Source,
}

impl Deref for Variable3 {
    type Target = Variable;

    fn deref(&self) -> &Variable {
        &self.variable
    }
}

impl Variable3 {
    pub(crate) fn len(&self) -> usize {
        self.dimension.unwrap_or(1)
    }

    /// The positions in [`ModelTable::variables`] behind this variable.
    pub fn elements(&self) -> Range<usize> {
        match &self.source {
            Source::Model(elements) => elements.clone(),
            _ => 0..0,
        }
    }

    /// The variables of `model`, each run declared in `arrays` as one array.
    pub(crate) fn of(model: &[Variable], arrays: &[Array]) -> Vec<Self> {
        let (mut variables, mut at) = (Vec::new(), 0);
        while at < model.len() {
            let array = arrays.iter().find(|a| a.first == model[at].name);
            let len = array.map_or(1, |a| a.len);
            assert!(at + len <= model.len(), "array {array:?}");
            let description = array.map_or(&model[at].description, |a| &a.description);
            let variable = Variable {
                name: array.map_or(model[at].name, |a| a.name),
                description: description.clone(),
                ..model[at].clone()
            };
            variables.push(Variable3 {
                variable,
                dimension: array.map(|a| a.len),
                source: Source::Model(at..at + len),
            });
            at += len;
        }
        variables
    }

    /// The FMI 3.0 variables of the model `info` with the table `model`.
    fn fmi3(info: &ModelInfo, model: &[Variable]) -> Vec<Self> {
        let computed = |variable, source| Variable3 {
            variable,
            dimension: None,
            source,
        };
        let time = local("time", TIME_VR, "s", "Simulation time");
        let mut variables = vec![computed(time, Source::Time)];
        variables.extend(Variable3::of(model, &info.arrays));
        let event_indicators = (EVENT_INDICATOR_VR..).zip(info.event_indicators);
        for (i, (vr, &(name, unit, text))) in event_indicators.enumerate() {
            let source = Source::EventIndicator(i);
            variables.push(computed(local(name, vr, unit, text), source));
        }
        variables
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::tables;

    fn by_name<'a>(table: &'a ModelTable, name: &str) -> &'a Variable3 {
        table.fmi3.iter().find(|v| v.name == name).unwrap()
    }

    #[test]
    fn motor_commands_are_one_array_and_every_model_value_has_one_home() {
        let [quad, lander, hexa, rates, _attitude] = tables();
        let command = by_name(quad, "motor_command");
        assert_eq!(command.value_reference, 0);
        assert_eq!(command.dimension, Some(4));
        assert_eq!(command.source, Source::Model(0..4));
        assert_eq!(
            quad.variable3(1),
            None,
            "element 1 has no value reference of its own"
        );
        assert_eq!(by_name(quad, "der(motor_state)").len(), 4);
        // 25 states: 13 body scalars + motor_state[4] + 8 bristles = 22 variables.
        let me = quad.model_exchange.as_ref().unwrap();
        for vrs in [&me.states, &me.derivatives] {
            let holders = quad.fmi3.iter().filter(|v| {
                (v.elements()).any(|at| vrs.contains(&quad.variables[at].value_reference))
            });
            assert_eq!(holders.count(), 22);
        }
        let indicators = (quad.fmi3.iter())
            .filter(|v| matches!(v.source, Source::EventIndicator(_)))
            .map(|v| v.value_reference);
        assert_eq!(indicators.collect::<Vec<_>>(), [1001, 1002, 1003, 1004]);
        // The hexacopter: the same layout with six motors (27 states, still 22 variables).
        let command = by_name(hexa, "motor_command");
        assert_eq!((command.value_reference, command.dimension), (0, Some(6)));
        assert_eq!(by_name(hexa, "motor_state").dimension, Some(6));
        assert_eq!(by_name(hexa, "wind_input_x").value_reference, 6);
        let me = hexa.model_exchange.as_ref().unwrap();
        assert_eq!((me.states.len(), me.derivatives.len()), (27, 27));
        for table in [quad, lander, hexa, rates] {
            assert_eq!(table.fmi3[0].source, Source::Time);
            // Every model variable in exactly one FMI 3.0 variable, in table order.
            let elements: Vec<usize> = table.fmi3.iter().flat_map(|v| v.elements()).collect();
            let all: Vec<usize> = (0..table.variables.len()).collect();
            assert_eq!(elements, all, "{}", table.info.identifier);
            let mut vrs: Vec<u32> = table.fmi3.iter().map(|v| v.value_reference).collect();
            vrs.sort_unstable();
            vrs.dedup();
            assert_eq!(vrs.len(), table.fmi3.len(), "value references are unique");
        }
    }
}
