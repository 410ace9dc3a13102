//! The checked-in modelDescription.xml files are exactly what the code generates, and the
//! ModelStructure's direct dependencies are what the models do.
//!
//! To update the checked-in copies after changing a variable table:
//!     UPDATE_MODEL_DESCRIPTION=1 cargo test -p flyloop-fmu --test integration model_description
//! (or: cargo run -p flyloop-fmu --bin flyloop-fmu-pack -- model-descriptions modelDescription)
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_core::params::ValueKind;
use flyloop_core::variables::Causality;
use flyloop_fmu::api::Api;
use flyloop_fmu::fmi2_types::fmi2Status::fmi2OK;
use flyloop_fmu::model_description::generate;
use flyloop_fmu::pack::{model_description_path, write_model_description};
use std::path::{Path, PathBuf};
use support::{Fmu, Model};

fn checked_in_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription")
}

#[test]
fn checked_in_model_descriptions_match_the_generated_ones() {
    let dir = checked_in_dir();
    let update = std::env::var_os("UPDATE_MODEL_DESCRIPTION").is_some_and(|v| v == "1");
    for (model, version) in Model::ALL
        .into_iter()
        .flat_map(|m| Api::ALL.map(|v| (m, v)))
    {
        let table = model.table();
        if update {
            write_model_description(table, version, &dir).unwrap();
        }
        let path = model_description_path(&dir, table, version);
        let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
        let generated = generate(table, version);
        assert!(
            checked_in == generated,
            "{} is out of date with the variable tables; regenerate it with\n    \
             UPDATE_MODEL_DESCRIPTION=1 cargo test -p flyloop-fmu --test integration model_description\n\
             and review the diff",
            path.display()
        );
        let token = match version {
            Api::Fmi2 => format!("guid=\"{}\"", table.token(version)),
            Api::Fmi3 => format!("instantiationToken=\"{}\"", table.token(version)),
        };
        assert!(generated.contains(&token), "{token}");
    }
}

/// Declared dependencies (ModelStructure/Outputs) are exactly the inputs whose change moves
/// an output without a step in between. Checked in a state where everything is in motion.
#[test]
fn direct_feedthrough_is_declared_exactly() {
    for model in Model::PLANTS {
        let table = model.table();
        let fmu = Fmu::started(model, 0.0, &[("seed", 4.0)]);
        let inputs: Vec<_> = table
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Input)
            .collect();
        // Near hover (the quadrotor must stay airborne: on the ground its acceleration is
        // the contact's), a little asymmetric, with some wind from outside.
        for (i, input) in inputs.iter().enumerate() {
            // Healthy motors (an effectiveness input is at most 1).
            let value = if input.name.starts_with("motor_effectiveness") {
                1.0
            } else if input.name.starts_with("motor") {
                0.5
            } else {
                1.0
            };
            let offset = if input.name.starts_with("motor_effectiveness") {
                0.0
            } else {
                0.01 * i as f64
            };
            assert_eq!(fmu.set(input.name, value + offset), fmi2OK);
        }
        for n in 0..25 {
            assert_eq!(fmu.do_step(f64::from(n) * 0.04, 0.04), fmi2OK);
        }
        assert!(
            fmu.get(if model.is_multirotor() { "z" } else { "y" }) > 0.5,
            "airborne"
        );
        let outputs: Vec<_> = table
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output && v.kind == ValueKind::Real)
            .collect();
        for input in &inputs {
            let before: Vec<f64> = outputs.iter().map(|o| fmu.get(o.name)).collect();
            let value = fmu.get(input.name);
            // A weaker motor (an effectiveness input is at most 1), else more of the input.
            let step = if input.name.starts_with("motor_effectiveness") {
                -0.25
            } else {
                0.25
            };
            assert_eq!(fmu.set(input.name, value + step), fmi2OK);
            for (output, old) in outputs.iter().zip(before) {
                let moved = fmu.get(output.name) != old;
                let declared = (table.info.direct_feedthrough.iter())
                    .any(|(o, inputs)| *o == output.name && inputs.contains(&input.name));
                assert_eq!(
                    moved, declared,
                    "{model:?}: {} on {}",
                    output.name, input.name
                );
            }
            assert_eq!(fmu.set(input.name, value), fmi2OK);
        }
    }
}
