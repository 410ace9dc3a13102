//! The model behind Policy.fmu: a loaded policy ([`Loaded`]: recipe and network) acting on
//! its own grid `k · sample_period` from the start time, whatever the communication step.
//!
//! As RateController.fmu does, a tick at a communication point reads the inputs set there: the
//! outputs (motor commands or RateController's setpoint) are direct feedthrough of the
//! plant's outputs at a tick (the master sets the plant's outputs into the policy, reads the
//! outputs, sets them on the plant or RateController and steps all), which is what the gym
//! does each control step. Between ticks the outputs of the last tick hold. The observation's
//! previous action is the policy's own previous outputs (the gym's `quad.command()`, or the
//! rates interface's last action as applied): before the first tick `initial_motor` on every
//! motor, or the setpoint (thrust `initial_motor`, zero rates) the gym starts with.

use crate::catalog;
use crate::network::Network;
use crate::observation::{MOTOR_STATES, commands, normalised, observation};
use crate::ports;
use crate::recipe::Recipe;
use flyloop_core::params::{ParamSpec, Parameters};
use flyloop_core::snapshot;
use flyloop_core::variables::{InputRow, OutputRow, VariableTable};
use flyloop_core::{InputError, ParamError, SnapshotError, param};
use flyloop_fmu::model::FmuModel;
use serde::{Deserialize, Serialize};
use std::cell::RefCell;
use std::fmt;
use std::sync::Arc;

/// Times closer than this are the same instant on the policy's grid, s.
const TIME_TOLERANCE: f64 = 1e-9;
const SNAPSHOT_TAG: &[u8; 8] = b"FLYPOL01";
/// Most motors a plant has (the core's frames): the most outputs a policy has.
const MAX_ROTORS: usize = flyloop_core::quadrotor::frame::MAX_ROTORS;
const MAX_INPUTS: usize = MOTOR_STATES + MAX_ROTORS;

/// A policy loaded from an FMU's resources (or a policy folder): its recipe and network,
/// under the folder it came from (the key FMU states name it by).
#[derive(Debug)]
pub struct Loaded {
    pub key: String,
    pub recipe: Recipe,
    pub network: Network,
}

/// The shape of a Policy.fmu: the policy it runs (equal when it is the same load).
#[derive(Clone)]
pub struct Shape(pub Arc<Loaded>);

impl PartialEq for Shape {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl fmt::Debug for Shape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let recipe = &self.0.recipe;
        write!(f, "Policy({}, {})", self.0.key, recipe.observation)
    }
}

/// The target in the plant's frame (world ENU), m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Target {
    /// East, m. Default 0.
    pub target_x: f64,
    /// North, m. Default 0.
    pub target_y: f64,
    /// Height, m. Default 1.5 (the hover task's start height).
    pub target_z: f64,
}

impl Default for Target {
    fn default() -> Self {
        Target {
            target_x: 0.0,
            target_y: 0.0,
            target_z: 1.5,
        }
    }
}

/// Farthest target from the origin the parameters take, m.
const TARGET_RANGE: f64 = 1e4;

static TARGET_SPECS: [ParamSpec<Target>; 3] = [
    param!(real target_x, "m", -TARGET_RANGE, TARGET_RANGE, "Target east in the plant's frame (world ENU)"),
    param!(real target_y, "m", -TARGET_RANGE, TARGET_RANGE, "Target north in the plant's frame (world ENU)"),
    param!(real target_z, "m", -TARGET_RANGE, TARGET_RANGE, "Target height in the plant's frame (world ENU)"),
];

impl Parameters for Target {
    fn specs() -> &'static [ParamSpec<Self>] {
        &TARGET_SPECS
    }
}

/// Start values: the command the plant holds at the start.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PolicyStart {
    /// The previous motor command the first observation holds, 0 .. 1 (set it to the plant's
    /// `initial_motor`; a rates policy's first previous thrust, as the gym's hover thrust).
    /// Default 0.
    pub initial_motor: f64,
}

static START_SPECS: [ParamSpec<PolicyStart>; 1] = [
    param!(real initial_motor, "1", 0.0, 1.0, "Motor command before the first tick (the plant's initial_motor)"),
];

impl Parameters for PolicyStart {
    fn specs() -> &'static [ParamSpec<Self>] {
        &START_SPECS
    }
}

/// The policy with its inputs and its place on its grid.
#[derive(Debug, Clone)]
pub struct Policy {
    shape: Shape,
    state: State,
    /// The commands of a tick due now with the inputs as they are (the tick itself is done
    /// in the next step); cleared whenever an input or the target changes.
    due: RefCell<Option<Vec<f64>>>,
}

/// Everything but the network (what FMU states hold).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct State {
    key: String,
    target: Target,
    /// The plant's outputs as set, in input order.
    inputs: Vec<f64>,
    /// The outputs of the last tick (before the first: [`ports::initial_outputs`]).
    held: Vec<f64>,
    ticks: u64,
    /// Seconds since the start time of the last communication point.
    now: f64,
    /// Why the network failed, once it has (the commands then hold).
    failure: Option<String>,
}

impl Policy {
    pub fn new(shape: Shape, target: Target, start: &PolicyStart) -> Self {
        let recipe = &shape.0.recipe;
        let inputs = ports::inputs(recipe).len();
        Policy {
            state: State {
                key: shape.0.key.clone(),
                target,
                inputs: vec![0.0; inputs],
                held: ports::initial_outputs(recipe, start.initial_motor),
                ticks: 0,
                now: 0.0,
                failure: None,
            },
            shape,
            due: RefCell::new(None),
        }
    }

    fn recipe(&self) -> &Recipe {
        &self.shape.0.recipe
    }

    /// The observation of the inputs as set (the gym's, float32).
    pub fn observation(&self) -> Vec<f32> {
        let t = &self.state.target;
        let target = [t.target_x, t.target_y, t.target_z];
        observation(self.recipe(), &self.state.inputs, target, &self.state.held)
    }

    /// One tick's commands for the inputs as set, or why the network failed.
    fn act(&self) -> Result<Vec<f64>, String> {
        let input = normalised(self.recipe(), &self.observation());
        let action = self.shape.0.network.run(&input)?;
        Ok(commands(self.recipe(), &action))
    }

    fn tick_is_due(&self) -> bool {
        let period = self.recipe().sample_period;
        (self.state.ticks as f64) * period < self.state.now + TIME_TOLERANCE
    }

    /// The motor commands now: a tick due now with the inputs as they are, else the last.
    pub fn commands(&self) -> Vec<f64> {
        if !self.tick_is_due() || self.state.failure.is_some() {
            return self.state.held.clone();
        }
        if let Some(c) = self.due.borrow().as_ref() {
            return c.clone();
        }
        let c = self.act().unwrap_or_else(|_| self.state.held.clone());
        *self.due.borrow_mut() = Some(c.clone());
        c
    }

    fn command(&self, i: usize) -> f64 {
        self.commands().get(i).copied().unwrap_or(0.0)
    }

    /// Runs the ticks before `end` (seconds since the start time); a failing network holds
    /// the commands and is reported by [`FmuModel::is_finite`].
    pub fn advance_to(&mut self, end: f64) {
        let period = self.recipe().sample_period;
        // The commands of the tick due now, if an output read computed them already.
        let mut due = if self.tick_is_due() {
            self.due.borrow_mut().take()
        } else {
            None
        };
        while (self.state.ticks as f64) * period < end - TIME_TOLERANCE {
            if self.state.failure.is_none() {
                match due.take().map_or_else(|| self.act(), Ok) {
                    Ok(c) => self.state.held = c,
                    Err(e) => self.state.failure = Some(e),
                }
            }
            self.state.ticks += 1;
        }
        self.state.now = end;
        *self.due.borrow_mut() = None;
    }

    fn set_input(&mut self, at: usize, value: f64) -> Result<(), InputError> {
        if !value.is_finite() {
            return Err(InputError {
                input: "policy input",
                index: at,
                value,
            });
        }
        if let Some(slot) = self.state.inputs.get_mut(at) {
            *slot = value;
        }
        *self.due.borrow_mut() = None;
        Ok(())
    }
}

fn get_input<const I: usize>(p: &Policy) -> f64 {
    p.state.inputs.get(I).copied().unwrap_or(0.0)
}

fn set_input<const I: usize>(p: &mut Policy, v: f64) -> Result<(), InputError> {
    p.set_input(I, v)
}

fn get_command<const I: usize>(p: &Policy) -> f64 {
    p.command(I)
}

type Getter = fn(&Policy) -> f64;
type Setter = fn(&mut Policy, f64) -> Result<(), InputError>;

macro_rules! by_index {
    ($f:ident, $t:ty; $($i:literal)*) => { [$($f::<$i> as $t),*] };
}

static INPUT_GET: [Getter; MAX_INPUTS] = by_index!(get_input, Getter;
    0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32 33);
static INPUT_SET: [Setter; MAX_INPUTS] = by_index!(set_input, Setter;
    0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32 33);
static COMMAND_GET: [Getter; MAX_ROTORS] =
    by_index!(get_command, Getter; 0 1 2 3 4 5 6 7 8 9 10 11);

/// Largest plant output the inputs take (the observation clips far inside).
const INPUT_RANGE: f64 = 1e9;

impl VariableTable for Policy {
    type Params = Target;
    type Initial = PolicyStart;
    type Shape = Shape;

    fn inputs(shape: &Shape) -> Vec<InputRow<Self>> {
        ports::inputs(&shape.0.recipe)
            .into_iter()
            .enumerate()
            .map(|(i, port)| InputRow {
                name: port.name,
                unit: port.unit,
                description: port.description,
                min: -INPUT_RANGE,
                max: INPUT_RANGE,
                start: if port.name == "qw" { 1.0 } else { 0.0 },
                get: INPUT_GET[i],
                set: INPUT_SET[i],
            })
            .collect()
    }

    fn outputs(shape: &Shape) -> Vec<OutputRow<Self>> {
        ports::outputs(&shape.0.recipe)
            .into_iter()
            .enumerate()
            .map(|(i, port)| OutputRow {
                description: port.description,
                ..OutputRow::real(port.name, port.unit, "", COMMAND_GET[i])
            })
            .collect()
    }

    fn shape(&self) -> &Shape {
        &self.shape
    }

    fn params(&self) -> &Target {
        &self.state.target
    }

    fn set_parameter(&mut self, name: &'static str, value: f64) -> Result<(), ParamError> {
        self.state.target.set(name, value)?;
        *self.due.borrow_mut() = None;
        Ok(())
    }
}

impl FmuModel for Policy {
    fn build(
        shape: &Shape,
        previous: Option<&Self>,
        start: &PolicyStart,
    ) -> Result<Self, ParamError> {
        let target = previous.map(|p| p.state.target.clone()).unwrap_or_default();
        let mut policy = Policy::new(shape.clone(), target, start);
        if let Some(p) = previous {
            policy.state.inputs.clone_from(&p.state.inputs);
        }
        Ok(policy)
    }

    fn internal_steps(&self, end: f64, _h: f64) -> f64 {
        ((end - self.state.now).max(0.0) / self.recipe().sample_period).ceil() + 1.0
    }

    fn advance(&mut self, end: f64, _h: f64) {
        self.advance_to(end);
    }

    fn is_finite(&self) -> bool {
        self.state.failure.is_none() && self.state.held.iter().all(|c| c.is_finite())
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        snapshot::encode(SNAPSHOT_TAG, &self.state)
    }

    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        let state: State = snapshot::decode(SNAPSHOT_TAG, "Policy", bytes)?;
        let loaded = catalog::loaded(&state.key).ok_or_else(|| {
            SnapshotError::Invalid(format!("the policy in {} is not loaded", state.key))
        })?;
        let recipe = &loaded.recipe;
        let (inputs, outputs) = (ports::inputs(recipe).len(), recipe.action_size());
        if state.inputs.len() != inputs || state.held.len() != outputs {
            return Err(SnapshotError::Invalid(format!(
                "not a state of a policy of {inputs} inputs and {outputs} outputs"
            )));
        }
        Ok(Policy {
            shape: Shape(loaded),
            state,
            due: RefCell::new(None),
        })
    }
}
