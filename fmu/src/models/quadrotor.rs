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
use crate::model::{Access, FmuModel, Hybrid, StepRequest, Table};
use crate::table::{Array, ModelExchangeTable, ModelInfo};
use flyloop_core::number::Compact;
use flyloop_core::params::ValueKind;
use flyloop_core::quadrotor::continuous::{BODY_STATE_OUTPUTS, BRISTLES, EVENT_INDICATORS};
use flyloop_core::quadrotor::dynamics::STATE_LEN;
use flyloop_core::quadrotor::{Quadrotor, QuadrotorInitial, wind};
use flyloop_core::variables::{self, Causality, Variability, Variable};
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
            description: Some(
                "Commands of the four motors, 0 .. 1 each: front-right (CCW), rear-left (CCW), \
                 front-left (CW), rear-right (CW)",
            ),
            first: "motor_command_0",
            len: 4,
        },
        Array {
            name: "motor_state",
            description: Some("Lagged states of the four motors (order of motor_command)"),
            first: "motor_state_0",
            len: 4,
        },
        Array {
            name: "der(motor_state)",
            description: None,
            first: "der(motor_state_0)",
            len: 4,
        },
    ],
    event_indicators: &[
        (
            "foot_height_0",
            "m",
            "Height of foot 0 (front-right) above the ground; 1 with the ground off (event indicator)",
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

/// The derivative variables in state-vector order: name and unit.
const DERIVATIVES: [(&str, &str); STATE_LEN] = [
    ("der(x)", "m/s"),
    ("der(y)", "m/s"),
    ("der(z)", "m/s"),
    ("der(vx)", "m/s2"),
    ("der(vy)", "m/s2"),
    ("der(vz)", "m/s2"),
    ("der(qw)", "1/s"),
    ("der(qx)", "1/s"),
    ("der(qy)", "1/s"),
    ("der(qz)", "1/s"),
    ("der(wx)", "rad/s2"),
    ("der(wy)", "rad/s2"),
    ("der(wz)", "rad/s2"),
    ("der(motor_state_0)", "1/s"),
    ("der(motor_state_1)", "1/s"),
    ("der(motor_state_2)", "1/s"),
    ("der(motor_state_3)", "1/s"),
    ("der(gear_stretch_0_x)", "m/s"),
    ("der(gear_stretch_0_y)", "m/s"),
    ("der(gear_stretch_1_x)", "m/s"),
    ("der(gear_stretch_1_y)", "m/s"),
    ("der(gear_stretch_2_x)", "m/s"),
    ("der(gear_stretch_2_y)", "m/s"),
    ("der(gear_stretch_3_x)", "m/s"),
    ("der(gear_stretch_3_y)", "m/s"),
];

fn local(name: &'static str, vr: u32, unit: &'static str, description: &'static str) -> Variable {
    Variable {
        name,
        value_reference: vr,
        kind: ValueKind::Real,
        causality: Causality::Local,
        variability: Variability::Continuous,
        unit,
        description,
        start: None,
        min: None,
        max: None,
    }
}

/// The core's variables, then the bristle states and the derivatives.
fn table() -> Table<Quadrotor> {
    let bristle = |at| Access::Local {
        read: |q: &Quadrotor, at| q.continuous_state()[at],
        at: BODY_STATE_OUTPUTS.len() + at,
    };
    let derivative = |at| Access::Local {
        read: |q: &Quadrotor, at| q.state_derivative()[at],
        at,
    };
    let text = "Time derivative of the state";
    let bristles = (BRISTLES.iter().zip(BRISTLE_VR..).enumerate())
        .map(|(i, (&(name, text), vr))| (local(name, vr, "m", text), bristle(i)));
    let derivatives = (DERIVATIVES.iter().zip(DERIVATIVE_VR..).enumerate())
        .map(|(i, (&(name, unit), vr))| (local(name, vr, unit, text), derivative(i)));
    let locals: Vec<_> = bristles.chain(derivatives).collect();
    let core = variables::variables::<Quadrotor>();
    let vr_of = |name: &str| {
        core.iter()
            .chain(locals.iter().map(|(v, _)| v))
            .find(|v| v.name == name)
            .map(|v| v.value_reference)
    };
    let states = BODY_STATE_OUTPUTS
        .iter()
        .copied()
        .chain(BRISTLES.iter().map(|b| b.0))
        .filter_map(vr_of)
        .collect();
    let me = ModelExchangeTable {
        states,
        derivatives: (DERIVATIVE_VR..).take(STATE_LEN).collect(),
        event_indicators: EVENT_INDICATORS,
    };
    Table::new(&INFO, locals, Some(me))
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

    fn internal_steps(&self, step: &StepRequest) -> f64 {
        (step.step_size / self.params.max_substep).ceil()
            + wind::segment_count(&self.params, step.step_size)
    }

    fn advance(&mut self, step: &StepRequest) {
        self.step(step.step_size);
    }

    fn is_finite(&self) -> bool {
        let b = &self.body;
        b.position
            .iter()
            .chain(b.velocity.iter())
            .chain(b.body_rates.iter())
            .chain(b.attitude.coords.iter())
            .chain(b.motors.iter())
            .all(|v| v.is_finite())
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
        let mut state = [0.0; STATE_LEN];
        state.copy_from_slice(x);
        self.set_continuous_state(&state).map_err(|e| {
            // The state's name is its derivative's without "der( )".
            let name = DERIVATIVES[e.index].0;
            let name = name.trim_start_matches("der(").trim_end_matches(')');
            FmuError::InvalidArgument(format!(
                "x[{}] (state `{name}`) is {}, not a finite number; nothing was set",
                e.index,
                Compact(e.value)
            ))
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

    fn event_update(&mut self, elapsed: f64) {
        Quadrotor::event_update(self, elapsed);
    }
}
