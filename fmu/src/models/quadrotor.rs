//! The quadrotor behind Quadrotor.fmu: a communication step of h seconds is one
//! `Quadrotor::step(h)`, which integrates on the model's fixed physics grid (`max_substep`,
//! contact substeps inside each grid interval) and cuts the step at the turbulence's own
//! sample times (`turbulence_dt`), so any h on the grid gives the same bits at the shared
//! times and h does not change the weather.
//!
//! Model Exchange integrates the same right-hand side (`flyloop_core::quadrotor::continuous`):
//! 25 continuous states (the 17 body outputs x .. motor_state_3 and 8 local bristle
//! stretches), their derivatives as locals `der(..)`, the four foot heights as event
//! indicators and the turbulence samples as time events.

use crate::error::FmuError;
use crate::model::{Access, FmuModel, Hybrid, Table};
use crate::table::{Array, ModelExchangeTable, ModelInfo, local};
use flyloop_core::CommandError;
use flyloop_core::number::Compact;
use flyloop_core::quadrotor::continuous::{BODY_STATE_OUTPUTS, BRISTLES, EVENT_INDICATORS};
use flyloop_core::quadrotor::dynamics::state_len;
use flyloop_core::quadrotor::{Quadrotor, QuadrotorInitial, wind};
use flyloop_core::variables::{self, Variable};
use flyloop_core::vehicle::Vehicle;
use flyloop_core::{ParamError, SnapshotError};
use std::sync::OnceLock;

const WIND_INPUTS: &[&str] = &["wind_input_x", "wind_input_y", "wind_input_z"];

static INFO: ModelInfo = ModelInfo {
    identifier: "Quadrotor",
    description: "flyloop quadrotor: 3D rigid body (ENU world, FLU body), four lagged motors, \
                  quadratic drag, Ornstein-Uhlenbeck wind; RK4",
    default_experiment: (0.0, 10.0, 0.01),
    // Acceleration includes drag, which reacts to the wind input at once; the wind output
    // is the episode wind plus the input. Everything else moves only with a step.
    direct_feedthrough: &[
        ("ax", WIND_INPUTS),
        ("ay", WIND_INPUTS),
        ("az", WIND_INPUTS),
        ("wind_x", &["wind_input_x"]),
        ("wind_y", &["wind_input_y"]),
        ("wind_z", &["wind_input_z"]),
    ],
    // The wind is the episode wind plus the input: turbulence is a discrete state.
    state_free_outputs: &["wind_x", "wind_y", "wind_z"],
    arrays: &[
        Array {
            name: "motor_command",
            description: "Commands of the four motors, 0 .. 1 each: front-right (CCW), \
                          rear-left (CCW), front-left (CW), rear-right (CW)",
            first: "motor_command_0",
            len: 4,
        },
        Array {
            name: "motor_state",
            description: "Lagged states of the four motors (order of motor_command)",
            first: "motor_state_0",
            len: 4,
        },
        Array {
            name: "der(motor_state)",
            description: DERIVATIVE_TEXT,
            first: "der(motor_state_0)",
            len: 4,
        },
    ],
    event_indicators: &[
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
    ],
};

/// Value references of the bristle states (locals) and of the 25 derivatives.
const BRISTLE_VR: u32 = 700;
const DERIVATIVE_VR: u32 = 800;

const DERIVATIVE_TEXT: &str = "Time derivative of the state";

/// The continuous states' names in state-vector order.
fn state_names() -> impl Iterator<Item = &'static str> {
    BODY_STATE_OUTPUTS.into_iter().chain(BRISTLES.map(|b| b.0))
}

/// A name or unit for a variable: the table is built once per process, so the text lives as
/// long as the process.
fn leak(text: String) -> &'static str {
    Box::leak(text.into_boxed_str())
}

/// The core's variables, then the bristle states and the derivatives.
fn table() -> Table<Quadrotor> {
    let core = variables::variables::<Quadrotor>();
    let bristles =
        (BRISTLES.iter().zip(BRISTLE_VR..)).map(|(&(name, text), vr)| local(name, vr, "m", text));
    let bristles: Vec<Variable> = bristles.collect();
    let state = |name: &str| core.iter().chain(&bristles).find(|v| v.name == name);
    let states: Vec<&Variable> = state_names().filter_map(state).collect();
    // d/dt of a state has its unit per second: m → m/s, m/s → m/s2, 1 → 1/s.
    let derivatives = (states.iter().zip(DERIVATIVE_VR..)).map(|(state, vr)| {
        let unit = (state.unit.strip_suffix("/s"))
            .map_or(format!("{}/s", state.unit), |u| format!("{u}/s2"));
        let name = leak(format!("der({})", state.name));
        local(name, vr, leak(unit), DERIVATIVE_TEXT)
    });
    let me = ModelExchangeTable {
        states: states.iter().map(|v| v.value_reference).collect(),
        derivatives: (DERIVATIVE_VR..).take(state_len(4)).collect(),
        event_indicators: EVENT_INDICATORS,
    };
    // Each reads its value at its position in the state vector.
    let bristles = (bristles.iter().zip(BODY_STATE_OUTPUTS.len()..)).map(|(v, at)| {
        let read = |q: &Quadrotor, at: usize| q.continuous_state()[at];
        (v.clone(), Access::Local { read, at })
    });
    let derivatives = derivatives.enumerate().map(|(at, v)| {
        let read = |q: &Quadrotor, at: usize| q.state_derivative()[at];
        (v, Access::Local { read, at })
    });
    Table::new(&INFO, bristles.chain(derivatives).collect(), Some(me))
}

impl FmuModel for Quadrotor {
    fn table() -> &'static Table<Self> {
        static TABLE: OnceLock<Table<Quadrotor>> = OnceLock::new();
        TABLE.get_or_init(table)
    }

    fn build(previous: Option<&Self>, initial: &QuadrotorInitial) -> Result<Self, ParamError> {
        let params = previous.map(|q| q.params.clone()).unwrap_or_default();
        Quadrotor::from_initial(params, initial)
    }

    fn internal_steps(&self, _end: f64, h: f64) -> f64 {
        (h / self.params.max_substep).ceil() + wind::segment_count(&self.params, h)
    }

    fn advance(&mut self, _end: f64, h: f64) {
        self.step(h);
    }

    fn is_finite(&self) -> bool {
        Vehicle::is_finite(self)
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        Quadrotor::save(self)
    }

    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        Quadrotor::restore(bytes)
    }

    fn hybrid(&self) -> Option<&dyn Hybrid> {
        Some(self)
    }

    fn hybrid_mut(&mut self) -> Option<&mut dyn Hybrid> {
        Some(self)
    }
}

impl Hybrid for Quadrotor {
    fn states(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.continuous_state());
    }

    fn set_states(&mut self, x: &[f64]) -> Result<(), FmuError> {
        self.set_continuous_state(x).map_err(|e| match e {
            CommandError::NotFinite(e) => {
                let name = state_names().nth(e.index).unwrap_or_default();
                FmuError::InvalidArgument(format!(
                    "x[{}] (state `{name}`) is {}, not a finite number; nothing was set",
                    e.index,
                    Compact(e.value)
                ))
            }
            e => FmuError::InvalidArgument(format!("{e}; nothing was set")),
        })
    }

    fn derivatives(&self, dx: &mut [f64]) {
        dx.copy_from_slice(&self.state_derivative());
    }

    fn event_indicators(&self, z: &mut [f64]) {
        z.copy_from_slice(&Quadrotor::event_indicators(self));
    }

    fn time_event_after(&self) -> Option<f64> {
        self.time_to_turbulence_sample()
    }

    fn event_update(&mut self, elapsed: f64) -> bool {
        let before = self.continuous_state();
        Quadrotor::event_update(self, elapsed);
        let after = self.continuous_state();
        before
            .iter()
            .zip(&after)
            .any(|(a, b)| a.to_bits() != b.to_bits())
    }
}
