//! An FMU of the multirotor is a declaration, [`Multirotor`]: a name and a frame. Its
//! table follows from the frame's rotor table: the core's variables for the frame (one
//! `motor_command_i` and one `motor_state_i` per rotor), the FMI 3.0 arrays, the Model
//! Exchange states (13 + n + 8 for n rotors: the body outputs x .. wz, the motor states and 8
//! local bristle stretches) with their derivatives `der(..)`, and the texts that count the
//! motors. Quadrotor.fmu is the declaration with `quad_x`, Hexacopter.fmu with `hexa_x`.

use crate::model::{Access, Table};
use crate::table::{Array, ModelExchangeTable, ModelInfo, local};
use flyloop_core::quadrotor::continuous::{
    BRISTLES, EVENT_INDICATORS, RIGID_BODY_STATE_OUTPUTS, body_state_outputs,
};
use flyloop_core::quadrotor::dynamics::state_len;
use flyloop_core::quadrotor::{Frame, Quadrotor};
use flyloop_core::variables::{Rows, Variable};
use std::borrow::Cow;

/// An FMU of the multirotor: its name, what its description calls the vehicle, and its
/// frame. Declaring one is all a new frame's FMU takes.
#[derive(Debug, Clone)]
pub struct Multirotor {
    /// modelIdentifier and modelName: the FMU is `<identifier>.fmu`.
    pub identifier: &'static str,
    /// The vehicle in the model's description ("quadrotor").
    pub noun: &'static str,
    pub frame: Frame,
}

const WIND_INPUTS: &[&str] = &["wind_input_x", "wind_input_y", "wind_input_z"];

// Acceleration includes drag, which reacts to the wind input at once; the wind output is the
// episode wind plus the input. Everything else moves only with a step.
const DIRECT_FEEDTHROUGH: &[(&str, &[&str])] = &[
    ("ax", WIND_INPUTS),
    ("ay", WIND_INPUTS),
    ("az", WIND_INPUTS),
    ("wind_x", &["wind_input_x"]),
    ("wind_y", &["wind_input_y"]),
    ("wind_z", &["wind_input_z"]),
];

// The landing gear has four feet whatever the frame.
const FEET: &[(&str, &str, &str)] = &[
    (
        "foot_height_0",
        "m",
        "Height of foot 0 (front-right) above the ground; 1 with the ground off \
         (event indicator)",
    ),
    (
        "foot_height_1",
        "m",
        "Height of foot 1 (rear-left) above the ground (event indicator)",
    ),
    (
        "foot_height_2",
        "m",
        "Height of foot 2 (front-left) above the ground (event indicator)",
    ),
    (
        "foot_height_3",
        "m",
        "Height of foot 3 (rear-right) above the ground (event indicator)",
    ),
];

/// Value references of the bristle states (locals) and of the derivatives.
const BRISTLE_VR: u32 = 700;
const DERIVATIVE_VR: u32 = 800;

const DERIVATIVE_TEXT: &str = "Time derivative of the state";

/// "six" for 6: how the texts count a frame's motors (4 to 12).
fn count_word(n: usize) -> Cow<'static, str> {
    const WORDS: [&str; 9] = [
        "four", "five", "six", "seven", "eight", "nine", "ten", "eleven", "twelve",
    ];
    n.checked_sub(4)
        .and_then(|i| WORDS.get(i))
        .map_or_else(|| Cow::Owned(n.to_string()), |w| Cow::Borrowed(*w))
}

/// A name or unit for a variable: a table is built once per FMU in a process, so the text
/// lives as long as the process.
fn leak(text: String) -> &'static str {
    Box::leak(text.into_boxed_str())
}

impl Multirotor {
    /// The FMU's facts beyond its variable table, worded for its frame.
    fn info(&self) -> ModelInfo {
        let frame = &self.frame;
        let (n, count) = (frame.rotor_count(), count_word(frame.rotor_count()));
        let places: Vec<String> = (frame.rotors().iter())
            .map(|r| format!("{} ({})", r.place(), r.spin.label()))
            .collect();
        ModelInfo {
            identifier: self.identifier,
            description: Cow::Owned(format!(
                "flyloop {}: 3D rigid body (ENU world, FLU body), {count} lagged motors, \
                 quadratic drag, Ornstein-Uhlenbeck wind; RK4",
                self.noun
            )),
            default_experiment: (0.0, 10.0, 0.01),
            direct_feedthrough: DIRECT_FEEDTHROUGH,
            // The wind is the episode wind plus the input: turbulence is a discrete state.
            state_free_outputs: &["wind_x", "wind_y", "wind_z"],
            arrays: vec![
                Array {
                    name: "motor_command",
                    description: Cow::Owned(format!(
                        "Commands of the {count} motors, 0 .. 1 each: {}",
                        places.join(", ")
                    )),
                    first: "motor_command_0",
                    len: n,
                },
                Array {
                    name: "motor_effectiveness",
                    description: Cow::Owned(format!(
                        "Effectiveness of the {count} motors, 0 .. 1 each (order of \
                         motor_command; 1 = healthy): a weak motor gives this fraction of its \
                         thrust and torque at the same command"
                    )),
                    first: "motor_effectiveness_0",
                    len: n,
                },
                Array {
                    name: "motor_state",
                    description: Cow::Owned(format!(
                        "Lagged states of the {count} motors (order of motor_command)"
                    )),
                    first: "motor_state_0",
                    len: n,
                },
                Array {
                    name: "der(motor_state)",
                    description: Cow::Borrowed(DERIVATIVE_TEXT),
                    first: "der(motor_state_0)",
                    len: n,
                },
            ],
            event_indicators: FEET,
            descriptions: vec![(
                "initial_motor",
                Cow::Owned(format!("Initial state of all {count} motors")),
            )],
        }
    }

    /// The FMU's table: the core's variables for the frame, then the bristle states and the
    /// derivatives.
    pub fn table(self) -> Table<Quadrotor> {
        let n = self.frame.rotor_count();
        let rows = Rows::<Quadrotor>::of(&self.frame);
        let core = rows.variables();
        let bristles = (BRISTLES.iter().zip(BRISTLE_VR..))
            .map(|(&(name, text), vr)| local(name, vr, "m", text));
        let bristles: Vec<Variable> = bristles.collect();
        let state = |name: &str| core.iter().chain(&bristles).find(|v| v.name == name);
        let names = body_state_outputs(n).chain(BRISTLES.map(|b| b.0));
        let states: Vec<&Variable> = names.filter_map(state).collect();
        // d/dt of a state has its unit per second: m → m/s, m/s → m/s2, 1 → 1/s.
        let derivatives = (states.iter().zip(DERIVATIVE_VR..)).map(|(state, vr)| {
            let unit = (state.unit.strip_suffix("/s"))
                .map_or(format!("{}/s", state.unit), |u| format!("{u}/s2"));
            let name = leak(format!("der({})", state.name));
            local(name, vr, leak(unit), DERIVATIVE_TEXT)
        });
        let me = ModelExchangeTable {
            states: states.iter().map(|v| v.value_reference).collect(),
            derivatives: (DERIVATIVE_VR..).take(state_len(n)).collect(),
            event_indicators: EVENT_INDICATORS,
        };
        // Each reads its value at its position in the state vector.
        let bristles =
            (bristles.iter().zip(RIGID_BODY_STATE_OUTPUTS.len() + n..)).map(|(v, at)| {
                let read = |q: &Quadrotor, at: usize| q.continuous_state()[at];
                (v.clone(), Access::Local { read, at })
            });
        let derivatives = derivatives.enumerate().map(|(at, v)| {
            let read = |q: &Quadrotor, at: usize| q.state_derivative()[at];
            (v, Access::Local { read, at })
        });
        let locals = bristles.chain(derivatives).collect();
        Table::new(self.info(), self.frame, rows, locals, Some(me))
    }
}
