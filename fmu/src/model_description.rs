//! Writes a model's modelDescription.xml, FMI 2.0 or FMI 3.0, from its table: one writer,
//! the versions differ only where the standards do. Deterministic output (no date), so the
//! checked-in copies under modelDescription/ can be compared byte for byte.

use crate::api::Api;
use crate::log::CATEGORIES;
use crate::table::{ModelExchangeTable, ModelTable, Source, Variable3};
use crate::units::{self, BASE_UNITS};
use flyloop_core::params::ValueKind;
use flyloop_core::variables::Causality;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

/// Escapes text for an XML attribute value.
fn escape(text: &str) -> String {
    let text = text.replace('&', "&amp;").replace('<', "&lt;");
    let text = text.replace('>', "&gt;").replace('"', "&quot;");
    text.replace('\'', "&apos;")
}

/// A value as XML text; a real as an xs:double, the shortest text that reads back to the same
/// f64.
fn value_text(kind: ValueKind, value: f64) -> String {
    match kind {
        ValueKind::Integer => format!("{}", value as i64),
        ValueKind::Boolean => (value != 0.0).to_string(),
        ValueKind::Real if value.is_nan() => "NaN".to_string(),
        ValueKind::Real if value == f64::INFINITY => "INF".to_string(),
        ValueKind::Real if value == f64::NEG_INFINITY => "-INF".to_string(),
        ValueKind::Real => format!("{value:?}"),
    }
}

/// The capability attributes of ModelExchange and CoSimulation in `api`: each element's own
/// between the ones both share.
fn capabilities(api: Api) -> [String; 2] {
    let (first, me, cs, last) = match api {
        Api::Fmi2 => (
            "",
            "completedIntegratorStepNotNeeded=\"true\"",
            "canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" \
             maxOutputDerivativeOrder=\"0\" canRunAsynchronuously=\"false\"",
            "canBeInstantiatedOnlyOncePerProcess=\"false\" \
             canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" \
             canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"",
        ),
        Api::Fmi3 => (
            " canBeInstantiatedOnlyOncePerProcess=\"false\" canGetAndSetFMUState=\"true\" \
             canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"false\" \
             providesAdjointDerivatives=\"false\" providesPerElementDependencies=\"false\"",
            "needsCompletedIntegratorStep=\"false\"",
            "canHandleVariableCommunicationStepSize=\"true\" maxOutputDerivativeOrder=\"0\" \
             providesIntermediateUpdate=\"false\" mightReturnEarlyFromDoStep=\"false\" \
             canReturnEarlyAfterIntermediateUpdate=\"false\" hasEventMode=\"false\"",
            "providesEvaluateDiscreteStates=\"false\"",
        ),
    };
    [me, cs].map(|own| format!("needsExecutionTool=\"false\"{first} {own} {last}"))
}

/// `<UnitDefinitions>` for the units of the Real variables.
///
/// # Panics
/// On a unit `units.rs` has no entry for (a fault of the model's table, found by the crate's
/// tests).
fn write_units(out: &mut String, variables: &[Variable3]) {
    let real = variables.iter().rev();
    let real = real.filter(|v| v.kind == ValueKind::Real && !v.unit.is_empty());
    // Each unit with the first variable that has it.
    let used: BTreeMap<&str, &str> = real.map(|v| (v.unit, v.name)).collect();
    out.push_str("  <UnitDefinitions>\n");
    for (unit, name) in used {
        let exponents = units::exponents(unit).unwrap_or_else(|| {
            panic!("unit `{unit}` of variable `{name}` has no entry in fmu/src/units.rs")
        });
        let _ = write!(out, "    <Unit name=\"{}\"", escape(unit));
        match exponents {
            Some(exponents) => {
                out.push_str(">\n      <BaseUnit");
                for (name, e) in BASE_UNITS.iter().zip(exponents).filter(|(_, e)| *e != 0) {
                    let _ = write!(out, " {name}=\"{e}\"");
                }
                if let Some(factor) = units::factor(unit) {
                    let _ = write!(out, " factor=\"{factor:?}\"");
                }
                out.push_str("/>\n    </Unit>\n");
            }
            None => out.push_str("/>\n"),
        }
    }
    out.push_str("  </UnitDefinitions>\n");
}

/// One modelDescription being written: the version and the variables in ModelVariables order
/// (FMI 2.0: the table's, each a scalar; FMI 3.0: the FMI 3.0 view's).
struct Writer<'a> {
    api: Api,
    table: &'a ModelTable,
    variables: &'a [Variable3],
    /// The model's, or an empty one for a Co-Simulation-only model.
    me: ModelExchangeTable,
    out: String,
}

impl Writer<'_> {
    /// How ModelStructure names the variable at position `i`: FMI 2.0 by its 1-based index,
    /// FMI 3.0 by its value reference.
    fn id(&self, i: usize) -> u32 {
        match self.api {
            Api::Fmi2 => i as u32 + 1,
            Api::Fmi3 => self.variables[i].value_reference,
        }
    }

    /// The positions of the variables that hold the model variables `vrs`, in order.
    fn holders<'v>(&self, vrs: impl IntoIterator<Item = &'v u32>) -> BTreeSet<usize> {
        let positions = vrs.into_iter().filter_map(|&vr| self.table.by_vr.get(vr));
        let holder = |at| {
            self.variables
                .iter()
                .position(|v| v.elements().contains(&at))
        };
        positions.filter_map(holder).collect()
    }

    /// The ids output `i` depends on: its elements' direct-feedthrough inputs and, under
    /// Model Exchange, the continuous states (none for a state itself, its own known).
    fn dependencies(&self, i: usize) -> String {
        let (table, info) = (self.table, &self.table.info);
        let mut vrs = Vec::new();
        for output in &table.variables[self.variables[i].elements()] {
            let feedthrough = info.direct_feedthrough.iter();
            let inputs = feedthrough.filter(|(name, _)| *name == output.name);
            let inputs = inputs.flat_map(|(_, inputs)| inputs.iter());
            vrs.extend(inputs.filter_map(|name| Some(table.by_name(name)?.value_reference)));
            let is_state = self.me.states.contains(&output.value_reference);
            if !is_state && !info.state_free_outputs.contains(&output.name) {
                vrs.extend(&self.me.states);
            }
        }
        let ids: Vec<String> = (self.holders(&vrs).into_iter())
            .map(|i| self.id(i).to_string())
            .collect();
        ids.join(" ")
    }

    /// Everything before ModelVariables: the root element, ModelExchange and CoSimulation, the
    /// units, LogCategories and DefaultExperiment.
    fn header(&mut self) {
        let (api, table, info) = (self.api, self.table, &self.table.info);
        let n = self.me.event_indicators;
        let (version, token, events) = match api {
            Api::Fmi2 => ("2.0", "guid", format!(" numberOfEventIndicators=\"{n}\"")),
            Api::Fmi3 => ("3.0", "instantiationToken", String::new()),
        };
        let _ = writeln!(
            self.out,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription \
             fmiVersion=\"{version}\" modelName=\"{}\" {token}=\"{}\" description=\"{}\" \
             version=\"{}\" generationTool=\"flyloop\" variableNamingConvention=\"flat\"{events}>",
            info.identifier,
            table.token(api),
            escape(&info.description),
            env!("CARGO_PKG_VERSION"),
        );
        let ([me, cs], id) = (capabilities(api), info.identifier);
        if table.model_exchange.is_some() {
            let _ = writeln!(self.out, "  <ModelExchange modelIdentifier=\"{id}\" {me}/>");
        }
        let _ = writeln!(self.out, "  <CoSimulation modelIdentifier=\"{id}\" {cs}/>");
        write_units(&mut self.out, self.variables);
        self.out.push_str("  <LogCategories>\n");
        for (name, text) in CATEGORIES {
            let (name, text) = (name.to_string_lossy(), escape(text));
            let _ = writeln!(
                self.out,
                "    <Category name=\"{name}\" description=\"{text}\"/>"
            );
        }
        let (start, stop, step) = self.table.info.default_experiment;
        let [start, stop, step] = [start, stop, step].map(|x| value_text(ValueKind::Real, x));
        let _ = writeln!(
            self.out,
            "  </LogCategories>\n  <DefaultExperiment startTime=\"{start}\" stopTime=\"{stop}\" \
             stepSize=\"{step}\"/>"
        );
    }

    /// A variable with its unit (Real only), range (not for Booleans), start values (every
    /// element's, for an FMI 3.0 array) and the state it is the derivative of.
    fn variable(&mut self, i: usize, v: &Variable3) {
        let ty = self.api.type_name(v.kind);
        let (element, open) = match self.api {
            Api::Fmi2 => (
                format!("<!-- Index {} -->\n    <ScalarVariable", i + 1),
                format!(">\n      <{ty}"),
            ),
            Api::Fmi3 => (format!("<{ty}"), String::new()),
        };
        let (name, vr, text) = (escape(v.name), v.value_reference, escape(&v.description));
        let causality = match v.source {
            Source::Time => "independent".to_string(),
            _ => format!("{:?}", v.causality).to_lowercase(),
        };
        let variability = format!("{:?}", v.variability).to_lowercase();
        let out = &mut self.out;
        let _ = write!(
            out,
            "    {element} name=\"{name}\" valueReference=\"{vr}\" description=\"{text}\" \
             causality=\"{causality}\" variability=\"{variability}\"{open}",
        );
        if v.kind == ValueKind::Real && !v.unit.is_empty() {
            let _ = write!(out, " unit=\"{}\"", escape(v.unit));
        }
        if v.kind != ValueKind::Boolean {
            for (name, bound) in [("min", v.min), ("max", v.max)] {
                if let Some(b) = bound {
                    let _ = write!(out, " {name}=\"{}\"", value_text(v.kind, b));
                }
            }
        }
        let starts = self.table.variables[v.elements()]
            .iter()
            .filter_map(|e| e.start);
        let starts: Vec<String> = starts.map(|s| value_text(v.kind, s)).collect();
        if !starts.is_empty() {
            let _ = write!(out, " start=\"{}\"", starts.join(" "));
        }
        let derivative = self.me.derivatives.iter().position(|&d| d == vr);
        let state = derivative.and_then(|k| self.holders(&self.me.states[k..=k]).pop_first());
        if let Some(state) = state {
            let _ = write!(self.out, " derivative=\"{}\"", self.id(state));
        }
        let _ = match (self.api, v.dimension) {
            (Api::Fmi2, _) => writeln!(self.out, "/>\n    </ScalarVariable>"),
            (Api::Fmi3, Some(n)) => {
                writeln!(self.out, ">\n      <Dimension start=\"{n}\"/>\n    </{ty}>")
            }
            (Api::Fmi3, None) => writeln!(self.out, "/>"),
        };
    }

    /// ModelStructure: FMI 2.0 `<Unknown index=..>`s in groups, FMI 3.0 elements by value
    /// reference; the outputs with their dependencies.
    fn model_structure(&mut self) {
        let positions = |keep: fn(&Variable3) -> bool| -> BTreeSet<usize> {
            (0..self.variables.len())
                .filter(|&i| keep(&self.variables[i]))
                .collect()
        };
        let outputs = positions(|v| v.causality == Causality::Output);
        let derivatives = self.holders(&self.me.derivatives);
        // Calculated during initialisation: every output, every derivative, the local states.
        let mut initial = &outputs | &derivatives;
        initial.extend(self.holders(&self.me.states));
        let events = positions(|v| matches!(v.source, Source::EventIndicator(_)));
        self.out.push_str("  <ModelStructure>\n");
        for (group, element, unknowns) in [
            ("Outputs", "Output", outputs),
            ("Derivatives", "ContinuousStateDerivative", derivatives),
            ("InitialUnknowns", "InitialUnknown", initial),
            ("EventIndicators", "EventIndicator", events),
        ] {
            // FMI 2.0 has no empty groups (and FMI 3.0 no event indicators either).
            if unknowns.is_empty() {
                continue;
            }
            let (indent, element, id) = match self.api {
                Api::Fmi2 => ("      ", "Unknown", "index"),
                Api::Fmi3 => ("    ", element, "valueReference"),
            };
            if self.api == Api::Fmi2 {
                let _ = writeln!(self.out, "    <{group}>");
            }
            for i in unknowns {
                let _ = write!(self.out, "{indent}<{element} {id}=\"{}\"", self.id(i));
                if group == "Outputs" {
                    let _ = write!(self.out, " dependencies=\"{}\"", self.dependencies(i));
                }
                self.out.push_str("/>\n");
            }
            if self.api == Api::Fmi2 {
                let _ = writeln!(self.out, "    </{group}>");
            }
        }
        self.out.push_str("  </ModelStructure>\n");
    }
}

/// The modelDescription.xml of `table`'s model in FMI version `api`.
pub fn generate(table: &ModelTable, api: Api) -> String {
    let scalars = Variable3::of(&table.variables, &[]);
    let variables = match api {
        Api::Fmi2 => &scalars,
        Api::Fmi3 => &table.fmi3,
    };
    let mut w = Writer {
        api,
        table,
        variables,
        me: table.model_exchange.clone().unwrap_or_default(),
        out: String::new(),
    };
    w.header();
    w.out.push_str("  <ModelVariables>\n");
    for (i, v) in variables.iter().enumerate() {
        w.variable(i, v);
    }
    w.out.push_str("  </ModelVariables>\n");
    w.model_structure();
    w.out.push_str("</fmiModelDescription>\n");
    w.out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::tables;

    #[test]
    fn every_unit_is_known_and_every_feedthrough_name_is_an_input_of_an_output() {
        for table in tables() {
            for v in &table.variables {
                let unit = v.unit;
                assert!(
                    unit.is_empty() || units::exponents(unit).is_some(),
                    "{unit} missing"
                );
            }
            for (output, inputs) in table.info.direct_feedthrough {
                let o = table.by_name(output).unwrap();
                assert_eq!(o.causality, Causality::Output, "{output}");
                for input in *inputs {
                    let i = table.by_name(input).unwrap();
                    assert_eq!(i.causality, Causality::Input, "{input}");
                }
            }
        }
    }

    #[test]
    fn numbers_read_back_exactly_and_text_is_escaped() {
        for x in [
            0.1,
            1e-7,
            1e16,
            -2.5,
            0.0,
            2147483647.0,
            std::f64::consts::PI,
        ] {
            assert_eq!(value_text(ValueKind::Real, x).parse::<f64>().unwrap(), x);
        }
        assert_eq!(value_text(ValueKind::Real, f64::INFINITY), "INF");
        assert_eq!(value_text(ValueKind::Integer, 7.0), "7");
        assert_eq!(value_text(ValueKind::Boolean, 1.0), "true");
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
    }

    #[test]
    fn structure_lists_every_output_with_its_direct_inputs() {
        let table = crate::models::tables()[0];
        let xml = generate(table, Api::Fmi2);
        let outputs = table
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .count();
        let structure = &xml[xml.find("<ModelStructure>").unwrap()..];
        // Outputs twice (Outputs, InitialUnknowns); 25 derivatives twice, 8 local states once.
        assert_eq!(
            structure.matches("<Unknown ").count(),
            2 * outputs + 2 * 25 + 8
        );
        // wind_x (index after the 7 inputs and 23 outputs before it) depends on wind_input_x.
        let wind_x = table
            .variables
            .iter()
            .position(|v| v.name == "wind_x")
            .unwrap()
            + 1;
        let wind_input_x = table
            .variables
            .iter()
            .position(|v| v.name == "wind_input_x")
            .unwrap()
            + 1;
        assert!(
            structure.contains(&format!(
                "<Unknown index=\"{wind_x}\" dependencies=\"{wind_input_x}\"/>"
            )),
            "{structure}"
        );
    }
}
