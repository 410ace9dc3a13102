//! The FMI 3.0 view of a model's table: the same variables, with runs named `P_0 .. P_n-1`
//! (and their derivatives `der(P_i)`) joined into one array variable `P` where the model
//! asks for it (the four motor commands read better as `motor_command[4]`), the independent
//! variable `time`, and — FMI 3.0 wants every event indicator to be a variable — one local
//! per event indicator. An array takes the value reference of its first element.

use crate::model::{ModelInfo, ModelTable, VrIndex};
use flyloop_core::params::ValueKind;
use flyloop_core::variables::{Causality, Variability, Variable};

/// Value reference of the independent variable `time` (above every model's own).
pub const TIME_VR: u32 = 1000;
/// Value reference of the first event-indicator variable; the others follow.
pub const EVENT_INDICATOR_VR: u32 = 1001;

/// FMI 3.0 causality: the model's, or `independent` for `time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality3 {
    Independent,
    Model(Causality),
}

impl Causality3 {
    /// The attribute's text in the modelDescription.
    pub fn name(self) -> &'static str {
        match self {
            Causality3::Independent => "independent",
            Causality3::Model(Causality::Parameter) => "parameter",
            Causality3::Model(Causality::Input) => "input",
            Causality3::Model(Causality::Output) => "output",
            Causality3::Model(Causality::Local) => "local",
        }
    }
}

/// Where an FMI 3.0 variable's values come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// The model's variables with these value references (one for a scalar).
    Model(Vec<u32>),
    /// The instance's time.
    Time,
    /// Event indicator number `i`.
    EventIndicator(usize),
}

/// One FMI 3.0 variable.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable3 {
    pub name: String,
    pub description: String,
    pub value_reference: u32,
    pub kind: ValueKind,
    pub causality: Causality3,
    pub variability: Variability,
    pub unit: &'static str,
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// Start value of each element (empty when there is none).
    pub start: Vec<f64>,
    /// `None` for a scalar, else the array's length.
    pub dimension: Option<usize>,
    pub source: Source,
}

impl Variable3 {
    /// How many values the variable holds.
    pub fn len(&self) -> usize {
        self.dimension.unwrap_or(1)
    }

    /// Never true: every variable holds at least one value.
    pub fn is_empty(&self) -> bool {
        false
    }

    fn scalar(v: &Variable) -> Self {
        Variable3 {
            name: v.name.to_string(),
            description: v.description.to_string(),
            value_reference: v.value_reference,
            kind: v.kind,
            causality: Causality3::Model(v.causality),
            variability: v.variability,
            unit: v.unit,
            min: v.min,
            max: v.max,
            start: v.start.into_iter().collect(),
            dimension: None,
            source: Source::Model(vec![v.value_reference]),
        }
    }
}

/// The FMI 3.0 variables of a model.
#[derive(Debug)]
pub struct Layout3 {
    /// In modelDescription order: `time` first, then the model's variables, then the event
    /// indicators.
    pub variables: Vec<Variable3>,
    /// Value reference → position in `variables`.
    by_vr: VrIndex,
    /// FMI 3.0 value references of the continuous states and of their derivatives, in
    /// state-vector order (an array once, where its first element comes).
    pub states: Vec<u32>,
    pub derivatives: Vec<u32>,
    /// Value references of the event-indicator variables, in order.
    pub event_indicators: Vec<u32>,
    /// Model value reference → (FMI 3.0 value reference, element index).
    element_of: Vec<(u32, (u32, usize))>,
}

/// `name` as element `i` of array `prefix`, if it is one (`P_i` or `der(P_i)`); returns the
/// array's name and `i`.
fn array_element(info: &ModelInfo, name: &str) -> Option<(String, usize)> {
    let (inner, derivative) = match name.strip_prefix("der(") {
        Some(rest) => (rest.strip_suffix(')')?, true),
        None => (name, false),
    };
    let (prefix, index) = inner.rsplit_once('_')?;
    let index: usize = index.parse().ok()?;
    info.arrays.iter().find(|(p, _)| *p == prefix)?;
    let array = if derivative {
        format!("der({prefix})")
    } else {
        prefix.to_string()
    };
    Some((array, index))
}

impl Layout3 {
    /// No variables (a placeholder while the table is built).
    pub(crate) fn empty() -> Self {
        Layout3 {
            variables: Vec::new(),
            by_vr: VrIndex::default(),
            states: Vec::new(),
            derivatives: Vec::new(),
            event_indicators: Vec::new(),
            element_of: Vec::new(),
        }
    }

    /// The FMI 3.0 view of `table`.
    ///
    /// # Panics
    /// If an array's elements are not consecutive in the table, in index order (a fault of
    /// the model's `ModelInfo::arrays`, found by the crate's tests).
    pub fn new(table: &ModelTable) -> Self {
        let info = table.info;
        let mut variables = vec![Variable3 {
            name: "time".into(),
            description: "Simulation time".into(),
            value_reference: TIME_VR,
            kind: ValueKind::Real,
            causality: Causality3::Independent,
            variability: Variability::Continuous,
            unit: "s",
            min: None,
            max: None,
            start: Vec::new(),
            dimension: None,
            source: Source::Time,
        }];
        for v in &table.variables {
            let Some((array, index)) = array_element(info, v.name) else {
                variables.push(Variable3::scalar(v));
                continue;
            };
            if index == 0 {
                let prefix = array.trim_start_matches("der(").trim_end_matches(')');
                let description = match info.arrays.iter().find(|(p, _)| *p == prefix) {
                    Some((_, text)) if !array.starts_with("der(") => text.to_string(),
                    _ => v.description.to_string(),
                };
                variables.push(Variable3 {
                    name: array,
                    description,
                    dimension: Some(1),
                    ..Variable3::scalar(v)
                });
                continue;
            }
            let last = variables.last_mut().filter(|l| l.name == array);
            let Some(last) = last.filter(|l| l.len() == index) else {
                panic!(
                    "array element {} does not follow element {}",
                    v.name,
                    index - 1
                );
            };
            last.dimension = Some(index + 1);
            if let Source::Model(elements) = &mut last.source {
                elements.push(v.value_reference);
            }
            if let Some(start) = v.start {
                last.start.push(start);
            }
        }
        let indicators = info.event_indicators;
        let event_indicators: Vec<u32> = (EVENT_INDICATOR_VR..).take(indicators.len()).collect();
        for (i, ((name, unit, description), &vr)) in
            indicators.iter().zip(&event_indicators).enumerate()
        {
            variables.push(Variable3 {
                name: name.to_string(),
                description: description.to_string(),
                value_reference: vr,
                kind: ValueKind::Real,
                causality: Causality3::Model(Causality::Local),
                variability: Variability::Continuous,
                unit,
                min: None,
                max: None,
                start: Vec::new(),
                dimension: None,
                source: Source::EventIndicator(i),
            });
        }
        let mut element_of = Vec::new();
        for v in &variables {
            if let Source::Model(elements) = &v.source {
                for (i, &model_vr) in elements.iter().enumerate() {
                    element_of.push((model_vr, (v.value_reference, i)));
                }
            }
        }
        element_of.sort_unstable_by_key(|&(vr, _)| vr);
        let by_vr = VrIndex::new(variables.iter().map(|v| v.value_reference));
        let mut layout = Layout3 {
            variables,
            by_vr,
            states: Vec::new(),
            derivatives: Vec::new(),
            event_indicators,
            element_of,
        };
        if let Some(me) = &table.model_exchange {
            layout.states = layout.collapse(&me.states);
            layout.derivatives = layout.collapse(&me.derivatives);
        }
        layout
    }

    /// The FMI 3.0 variables holding the model variables `vrs`, each once, in order.
    pub fn collapse(&self, vrs: &[u32]) -> Vec<u32> {
        let mut out: Vec<u32> = Vec::new();
        for &vr in vrs {
            if let Some((fmi3, _)) = self.element(vr) {
                if !out.contains(&fmi3) {
                    out.push(fmi3);
                }
            }
        }
        out
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

    /// The variable named `name`.
    pub fn by_name(&self, name: &str) -> Option<&Variable3> {
        self.variables.iter().find(|v| v.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::tables;

    #[test]
    fn motor_commands_are_one_array_and_every_model_value_has_one_home() {
        let [quad, lander] = tables();
        let layout = &quad.fmi3;
        let command = layout.by_name("motor_command").unwrap();
        assert_eq!(command.value_reference, 0);
        assert_eq!(command.dimension, Some(4));
        assert_eq!(command.source, Source::Model(vec![0, 1, 2, 3]));
        assert_eq!(command.start, [0.0; 4]);
        assert_eq!(
            layout.variable(1),
            None,
            "element 1 has no value reference of its own"
        );
        assert_eq!(layout.by_name("der(motor_state)").unwrap().len(), 4);
        assert_eq!(layout.element(2), Some((0, 2)));
        // 25 states: 13 body scalars + motor_state[4] + 8 bristles = 22 variables.
        assert_eq!(layout.states.len(), 22);
        assert_eq!(layout.derivatives.len(), 22);
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
