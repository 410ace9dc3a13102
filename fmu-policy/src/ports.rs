//! Policy.fmu's inputs and outputs for a recipe, named like the variables they connect to:
//! the inputs like the plant's outputs, the outputs like the plant's inputs ("hover-motors":
//! `motor_command_i`) or RateController.fmu's ("rates-estimate": the setpoint).

use crate::estimate::{ESTIMATE_INPUTS, SETPOINT_OUTPUTS};
use crate::observation::PLANT_OUTPUTS;
use crate::recipe::{Interface, Recipe};
use flyloop_core::quadrotor::variables::{MOTOR_COMMAND_NAMES, MOTOR_STATE_NAMES};
use std::borrow::Cow;

/// One input or output: its name, unit and description.
#[derive(Debug, Clone)]
pub struct Port {
    pub name: &'static str,
    pub unit: &'static str,
    pub description: Cow<'static, str>,
}

fn fixed(rows: &[(&'static str, &'static str, &'static str)]) -> Vec<Port> {
    rows.iter()
        .map(|(name, unit, text)| Port {
            name,
            unit,
            description: Cow::Borrowed(*text),
        })
        .collect()
}

/// The inputs, in the order the observation reads them.
pub fn inputs(recipe: &Recipe) -> Vec<Port> {
    match recipe.interface() {
        Interface::RatesEstimate => {
            let hover = fixed(&PLANT_OUTPUTS);
            let by_name = |name: &str| hover.iter().find(|p| p.name == name).cloned();
            ESTIMATE_INPUTS.iter().filter_map(|n| by_name(n)).collect()
        }
        Interface::HoverMotors => {
            let motors = (0..recipe.rotors).map(|i| Port {
                name: MOTOR_STATE_NAMES[i],
                unit: "1",
                description: Cow::Owned(format!(
                    "State of motor {i}, 0 .. 1: the plant's motor_state_{i}"
                )),
            });
            fixed(&PLANT_OUTPUTS).into_iter().chain(motors).collect()
        }
    }
}

/// The outputs, in the order the network gives them.
pub fn outputs(recipe: &Recipe) -> Vec<Port> {
    match recipe.interface() {
        Interface::RatesEstimate => fixed(&SETPOINT_OUTPUTS),
        Interface::HoverMotors => (0..recipe.rotors)
            .map(|i| Port {
                name: MOTOR_COMMAND_NAMES[i],
                unit: "1",
                description: Cow::Owned(format!(
                    "Command of motor {i}, 0 .. 1: the plant's motor_command_{i}"
                )),
            })
            .collect(),
    }
}

/// The previous outputs the first observation holds: `initial_motor` on every motor, or the
/// gym's first setpoint (hover thrust `initial_motor`, zero rates).
pub fn initial_outputs(recipe: &Recipe, initial_motor: f64) -> Vec<f64> {
    match recipe.interface() {
        Interface::HoverMotors => vec![initial_motor; recipe.rotors],
        Interface::RatesEstimate => {
            let mut setpoint = vec![0.0; SETPOINT_OUTPUTS.len()];
            setpoint[0] = initial_motor;
            setpoint
        }
    }
}
