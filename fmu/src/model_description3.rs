//! Writes a model's FMI 3.0 modelDescription.xml from its table's FMI 3.0 view
//! ([`crate::table::Fmi3View`]): Co-Simulation for every model, Model Exchange for one that
//! offers it; the same units, log categories, default experiment and dependencies as the FMI
//! 2.0 description, with arrays, `time` and the event-indicator variables. Deterministic.

use crate::model_description::{
    UnknownUnit, categories_and_experiment, escape, output_dependencies, value_attributes,
    variability, write_units,
};
use crate::table::{Api, Causality3, Fmi3View, ModelTable, Source, Variable3};
use flyloop_core::params::ValueKind;
use flyloop_core::variables::Causality;
use std::fmt::Write;

/// The FMI 3.0 value reference of model variable `vr`'s derivative, when it is a state
/// derivative (the `derivative` attribute names the state's value reference).
fn state_of_derivative(table: &ModelTable, v: &Variable3) -> Option<u32> {
    let me = table.model_exchange.as_ref()?;
    let Source::Model(elements) = &v.source else {
        return None;
    };
    let vr = table.variables[elements[0]].value_reference;
    let k = me.derivatives.iter().position(|&d| d == vr)?;
    table.fmi3.element(me.states[k]).map(|(vr, _)| vr)
}

fn variable(out: &mut String, table: &ModelTable, v: &Variable3) {
    let element = Api::Fmi3.type_name(v.kind);
    let _ = write!(
        out,
        "    <{element} name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" \
         variability=\"{}\"",
        escape(&v.name),
        v.value_reference,
        escape(&v.description),
        v.causality.name(),
        variability(v.variability)
    );
    value_attributes(out, v.kind, v.unit, [v.min, v.max], &v.start);
    if let Some(state) = state_of_derivative(table, v) {
        let _ = write!(out, " derivative=\"{state}\"");
    }
    match v.dimension {
        Some(n) => {
            let _ = write!(
                out,
                ">\n      <Dimension start=\"{n}\"/>\n    </{element}>\n"
            );
        }
        None => out.push_str("/>\n"),
    }
}

/// The FMI 3.0 value references `v` depends on (an output's inputs and states).
fn dependencies(table: &ModelTable, v: &Variable3) -> String {
    let Source::Model(elements) = &v.source else {
        return String::new();
    };
    let mut model_vrs = Vec::new();
    for &element in elements {
        model_vrs.extend(output_dependencies(table, &table.variables[element]));
    }
    let vrs: Vec<String> = table
        .fmi3
        .collapse(&model_vrs)
        .iter()
        .map(u32::to_string)
        .collect();
    vrs.join(" ")
}

fn model_structure(out: &mut String, table: &ModelTable) {
    let layout: &Fmi3View = &table.fmi3;
    out.push_str("  <ModelStructure>\n");
    let outputs: Vec<&Variable3> = layout
        .variables
        .iter()
        .filter(|v| v.causality == Causality3::Model(Causality::Output))
        .collect();
    for v in &outputs {
        let _ = writeln!(
            out,
            "    <Output valueReference=\"{}\" dependencies=\"{}\"/>",
            v.value_reference,
            dependencies(table, v)
        );
    }
    for vr in &layout.derivatives {
        let _ = writeln!(
            out,
            "    <ContinuousStateDerivative valueReference=\"{vr}\"/>"
        );
    }
    // Calculated during initialisation: every output, every derivative, the local states.
    let mut initial: Vec<u32> = outputs.iter().map(|v| v.value_reference).collect();
    initial.extend(&layout.derivatives);
    initial.extend(&layout.states);
    let position = |vr: &u32| {
        layout
            .variables
            .iter()
            .position(|v| v.value_reference == *vr)
    };
    initial.sort_by_key(position);
    initial.dedup();
    for vr in initial {
        let _ = writeln!(out, "    <InitialUnknown valueReference=\"{vr}\"/>");
    }
    for vr in &layout.event_indicators {
        let _ = writeln!(out, "    <EventIndicator valueReference=\"{vr}\"/>");
    }
    out.push_str("  </ModelStructure>\n");
}

/// The FMI 3.0 modelDescription.xml of `table`'s model.
pub fn generate(table: &ModelTable) -> Result<String, UnknownUnit> {
    let info = table.info;
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        out,
        "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{}\" instantiationToken=\"{}\" \
         description=\"{}\" version=\"{}\" generationTool=\"flyloop\" \
         variableNamingConvention=\"flat\">",
        info.identifier,
        table.token3,
        escape(info.description),
        env!("CARGO_PKG_VERSION"),
    );
    let capabilities = "needsExecutionTool=\"false\" \
                        canBeInstantiatedOnlyOncePerProcess=\"false\" \
                        canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\" \
                        providesDirectionalDerivatives=\"false\" \
                        providesAdjointDerivatives=\"false\" \
                        providesPerElementDependencies=\"false\"";
    if table.model_exchange.is_some() {
        let _ = writeln!(
            out,
            "  <ModelExchange modelIdentifier=\"{}\" {capabilities} \
             needsCompletedIntegratorStep=\"false\" providesEvaluateDiscreteStates=\"false\"/>",
            info.identifier
        );
    }
    let _ = writeln!(
        out,
        "  <CoSimulation modelIdentifier=\"{}\" {capabilities} \
         canHandleVariableCommunicationStepSize=\"true\" maxOutputDerivativeOrder=\"0\" \
         providesIntermediateUpdate=\"false\" mightReturnEarlyFromDoStep=\"false\" \
         canReturnEarlyAfterIntermediateUpdate=\"false\" hasEventMode=\"false\" \
         providesEvaluateDiscreteStates=\"false\"/>",
        info.identifier
    );
    let units: Vec<(&str, &str)> = table
        .fmi3
        .variables
        .iter()
        .filter(|v| v.kind == ValueKind::Real && !v.unit.is_empty())
        .map(|v| (v.unit, v.name.as_str()))
        .collect();
    write_units(&mut out, &units)?;
    categories_and_experiment(&mut out, info);
    out.push_str("  <ModelVariables>\n");
    for v in &table.fmi3.variables {
        variable(&mut out, table, v);
    }
    out.push_str("  </ModelVariables>\n");
    model_structure(&mut out, table);
    out.push_str("</fmiModelDescription>\n");
    Ok(out)
}
