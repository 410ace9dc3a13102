//! Writes a model's modelDescription.xml (FMI 2.0 Co-Simulation, and Model Exchange for a
//! model that offers it: states, derivatives, event indicators) from its table: every
//! variable with unit, description, start and range; unit definitions for every unit used;
//! log categories; the default experiment; the model structure. Deterministic output (no
//! date), so the checked-in copies under modelDescription/ can be compared byte for byte.

use crate::log::CATEGORIES;
use crate::table::{Api, Causality3, ModelInfo, ModelTable};
use crate::units::{self, BASE_UNITS};
use flyloop_core::params::ValueKind;
use flyloop_core::variables::{Causality, Variability, Variable};
use std::collections::BTreeSet;
use std::fmt::Write;

/// A unit string the generator has no base-unit entry for (add it to `units.rs`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unit `{unit}` of variable `{variable}` has no entry in fmu/src/units.rs")]
pub struct UnknownUnit {
    pub unit: String,
    pub variable: String,
}

/// Escapes text for an XML attribute value.
pub(crate) fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in text.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// An xs:double: the shortest text that reads back to the same f64.
pub(crate) fn real(value: f64) -> String {
    if value.is_nan() {
        "NaN".to_string()
    } else if value.is_infinite() {
        if value > 0.0 { "INF" } else { "-INF" }.to_string()
    } else {
        format!("{value:?}")
    }
}

/// A value of `kind` as its XML attribute text.
pub(crate) fn value_text(kind: ValueKind, value: f64) -> String {
    match kind {
        ValueKind::Real => real(value),
        ValueKind::Integer => format!("{}", value as i64),
        ValueKind::Boolean => (value != 0.0).to_string(),
    }
}

pub(crate) fn variability(v: Variability) -> &'static str {
    match v {
        Variability::Fixed => "fixed",
        Variability::Tunable => "tunable",
        Variability::Continuous => "continuous",
        Variability::Discrete => "discrete",
    }
}

/// The units of Real variables, sorted.
#[cfg(test)]
fn units_used(variables: &[Variable]) -> BTreeSet<&'static str> {
    variables
        .iter()
        .filter(|v| v.kind == ValueKind::Real && !v.unit.is_empty())
        .map(|v| v.unit)
        .collect()
}

fn unit_definitions(out: &mut String, variables: &[Variable]) -> Result<(), UnknownUnit> {
    let units: Vec<(&str, &str)> = variables
        .iter()
        .filter(|v| v.kind == ValueKind::Real && !v.unit.is_empty())
        .map(|v| (v.unit, v.name))
        .collect();
    write_units(out, &units)
}

/// `<UnitDefinitions>` for the units of `used` ((unit, a variable that has it) pairs).
pub(crate) fn write_units(out: &mut String, used: &[(&str, &str)]) -> Result<(), UnknownUnit> {
    let units: BTreeSet<&str> = used.iter().map(|&(unit, _)| unit).collect();
    out.push_str("  <UnitDefinitions>\n");
    for unit in units {
        let exponents = units::exponents(unit).ok_or_else(|| UnknownUnit {
            unit: unit.to_string(),
            variable: used
                .iter()
                .find(|&&(u, _)| u == unit)
                .map_or_else(String::new, |&(_, name)| name.to_string()),
        })?;
        match exponents {
            Some(exponents) => {
                let _ = write!(out, "    <Unit name=\"{}\">\n      <BaseUnit", escape(unit));
                for (name, e) in BASE_UNITS.iter().zip(exponents) {
                    if e != 0 {
                        let _ = write!(out, " {name}=\"{e}\"");
                    }
                }
                out.push_str("/>\n    </Unit>\n");
            }
            None => {
                let _ = writeln!(out, "    <Unit name=\"{}\"/>", escape(unit));
            }
        }
    }
    out.push_str("  </UnitDefinitions>\n");
    Ok(())
}

/// `<LogCategories>` and `<DefaultExperiment>` (the same in FMI 2.0 and 3.0).
pub(crate) fn categories_and_experiment(out: &mut String, info: &ModelInfo) {
    out.push_str("  <LogCategories>\n");
    for (_, name, description) in CATEGORIES {
        let _ = writeln!(
            out,
            "    <Category name=\"{}\" description=\"{}\"/>",
            name.to_string_lossy(),
            escape(description)
        );
    }
    out.push_str("  </LogCategories>\n");
    let (start, stop, step) = info.default_experiment;
    let _ = writeln!(
        out,
        "  <DefaultExperiment startTime=\"{}\" stopTime=\"{}\" stepSize=\"{}\"/>",
        real(start),
        real(stop),
        real(step)
    );
}

/// The unit (Real variables only), range (not for Booleans) and start attributes (every
/// element's, for an FMI 3.0 array).
pub(crate) fn value_attributes(
    out: &mut String,
    kind: ValueKind,
    unit: &str,
    [min, max]: [Option<f64>; 2],
    start: &[f64],
) {
    if kind == ValueKind::Real && !unit.is_empty() {
        let _ = write!(out, " unit=\"{}\"", escape(unit));
    }
    if kind != ValueKind::Boolean {
        for (name, bound) in [("min", min), ("max", max)] {
            if let Some(b) = bound {
                let _ = write!(out, " {name}=\"{}\"", value_text(kind, b));
            }
        }
    }
    if !start.is_empty() {
        let starts: Vec<String> = start.iter().map(|&s| value_text(kind, s)).collect();
        let _ = write!(out, " start=\"{}\"", starts.join(" "));
    }
}

/// `derivative` is the 1-based index of the state a derivative variable belongs to.
fn scalar_variable(out: &mut String, v: &Variable, derivative: Option<usize>) {
    let _ = writeln!(
        out,
        "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{}\" \
         causality=\"{}\" variability=\"{}\">",
        escape(v.name),
        v.value_reference,
        escape(v.description),
        Causality3::Model(v.causality).name(),
        variability(v.variability)
    );
    let _ = write!(out, "      <{}", Api::Fmi2.type_name(v.kind));
    let range = [v.min, v.max];
    value_attributes(out, v.kind, v.unit, range, v.start.as_slice());
    if let Some(state) = derivative {
        let _ = write!(out, " derivative=\"{state}\"");
    }
    out.push_str("/>\n    </ScalarVariable>\n");
}

/// 1-based position (ModelVariables order) of value reference `vr`.
fn index_of(table: &ModelTable, vr: u32) -> Option<usize> {
    table.index(vr).map(|i| i + 1)
}

/// The value references `output` depends on: its direct-feedthrough inputs and, under Model
/// Exchange, the continuous states (none for a state itself, which is its own known).
pub(crate) fn output_dependencies(table: &ModelTable, output: &Variable) -> Vec<u32> {
    let mut dependencies: Vec<u32> = table
        .direct_feedthrough(output.name)
        .iter()
        .filter_map(|name| table.by_name(name))
        .map(|v| v.value_reference)
        .collect();
    if let Some(me) = &table.model_exchange {
        let is_state = me.states.contains(&output.value_reference);
        if !is_state && !table.info.state_free_outputs.contains(&output.name) {
            dependencies.extend(&me.states);
        }
    }
    dependencies
}

fn model_structure(out: &mut String, table: &ModelTable) {
    let outputs: Vec<(usize, &Variable)> = table
        .variables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .collect();
    out.push_str("  <ModelStructure>\n    <Outputs>\n");
    for &(i, v) in &outputs {
        let _ = writeln!(
            out,
            "      <Unknown index=\"{}\" dependencies=\"{}\"/>",
            i + 1,
            output_dependencies(table, v)
                .iter()
                .filter_map(|&vr| index_of(table, vr))
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    out.push_str("    </Outputs>\n");
    // Calculated during initialisation, from any of the start values: every output, and under
    // Model Exchange the local states and every derivative.
    let mut initial: Vec<usize> = outputs.iter().map(|&(i, _)| i + 1).collect();
    if let Some(me) = &table.model_exchange {
        out.push_str("    <Derivatives>\n");
        for &vr in &me.derivatives {
            if let Some(i) = index_of(table, vr) {
                let _ = writeln!(out, "      <Unknown index=\"{i}\"/>");
                initial.push(i);
            }
        }
        out.push_str("    </Derivatives>\n");
        initial.extend(me.states.iter().filter_map(|&vr| index_of(table, vr)));
    }
    initial.sort_unstable();
    initial.dedup();
    out.push_str("    <InitialUnknowns>\n");
    for i in initial {
        let _ = writeln!(out, "      <Unknown index=\"{i}\"/>");
    }
    out.push_str("    </InitialUnknowns>\n  </ModelStructure>\n");
}

/// The modelDescription.xml of `table`'s model.
pub fn generate(table: &ModelTable) -> Result<String, UnknownUnit> {
    let info = table.info;
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        out,
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{}\" guid=\"{}\" \
         description=\"{}\" version=\"{}\" generationTool=\"flyloop\" \
         variableNamingConvention=\"flat\" numberOfEventIndicators=\"{}\">",
        info.identifier,
        table.guid,
        escape(info.description),
        env!("CARGO_PKG_VERSION"),
        table
            .model_exchange
            .as_ref()
            .map_or(0, |me| me.event_indicators)
    );
    if table.model_exchange.is_some() {
        let _ = writeln!(
            out,
            "  <ModelExchange modelIdentifier=\"{}\" needsExecutionTool=\"false\" \
             completedIntegratorStepNotNeeded=\"true\" \
             canBeInstantiatedOnlyOncePerProcess=\"false\" \
             canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" \
             canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"/>",
            info.identifier
        );
    }
    let _ = writeln!(
        out,
        "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" \
         canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" \
         maxOutputDerivativeOrder=\"0\" canRunAsynchronuously=\"false\" \
         canBeInstantiatedOnlyOncePerProcess=\"false\" \
         canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" \
         canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"/>",
        info.identifier
    );
    unit_definitions(&mut out, &table.variables)?;
    categories_and_experiment(&mut out, info);
    out.push_str("  <ModelVariables>\n");
    for (i, v) in table.variables.iter().enumerate() {
        let _ = writeln!(out, "    <!-- Index {} -->", i + 1);
        let derivative = table.model_exchange.as_ref().and_then(|me| {
            let k = me
                .derivatives
                .iter()
                .position(|&d| d == v.value_reference)?;
            index_of(table, me.states[k])
        });
        scalar_variable(&mut out, v, derivative);
    }
    out.push_str("  </ModelVariables>\n");
    model_structure(&mut out, table);
    out.push_str("</fmiModelDescription>\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::tables;

    #[test]
    fn every_unit_is_known_and_every_feedthrough_name_is_an_input_of_an_output() {
        for table in tables() {
            for unit in units_used(&table.variables) {
                assert!(units::exponents(unit).is_some(), "unit {unit} missing");
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
            assert_eq!(real(x).parse::<f64>().unwrap(), x);
        }
        assert_eq!(real(f64::INFINITY), "INF");
        assert_eq!(value_text(ValueKind::Integer, 7.0), "7");
        assert_eq!(value_text(ValueKind::Boolean, 1.0), "true");
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
    }

    #[test]
    fn structure_lists_every_output_with_its_direct_inputs() {
        let table = crate::models::tables()[0];
        let xml = generate(table).unwrap();
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
