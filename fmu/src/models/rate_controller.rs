//! The model behind RateController.fmu: the core's PX4 rate loop and allocation
//! ([`flyloop_core::rate_loop`]) between a collective thrust + body-rate setpoint and the four
//! motor commands, as the gym's rates interface runs it.
//!
//! The loop ticks on its own grid `k · rate_loop_period` from the start time whatever the
//! communication step. A tick at a communication point reads the inputs set there: the motor
//! commands are direct feedthrough of the inputs at a tick (the master sets the plant's body
//! rates and the setpoint, reads the commands, steps both), which is what the gym does at each
//! tick. Ticks inside a longer communication step hold the inputs of its start. The first tick
//! settles the loop's filters on the body rates it reads, as the gym's episode start does.
//!
//! Inputs are the plant's names: `wx wy wz` are the body rates of Quadrotor.fmu (FLU), turned
//! to PX4's FRD here; the setpoint is PX4's (thrust in [0, 1], rates body FRD) and is clipped
//! into the rates action's bounds as the gym clips an action.

use super::px4_rate_params::Px4RateParams;
use crate::model::{FmuModel, Table};
use crate::table::{Array, ModelInfo};
use flyloop_core::params::{ParamSpec, Parameters};
use flyloop_core::rate_loop::{RateLoop, RatesSetpoint};
use flyloop_core::snapshot;
use flyloop_core::variables::{InputRow, OutputRow, Rows, VariableTable};
use flyloop_core::{InputError, ParamError, SnapshotError, fixed_shape};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::cell::Cell;

/// Times closer than this are the same instant on the loop's grid, s (the gym's tolerance).
const TIME_TOLERANCE: f64 = 1e-9;
// 02: the parameters under PX4's names (with the rotor geometry) are kept next to the loop.
const SNAPSHOT_TAG: &[u8; 8] = b"FLYRTC02";

/// The rate loop with the inputs in effect and its place on its grid.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RateController {
    /// The loop as it is before its next tick.
    rate_loop: RateLoop,
    /// The loop's parameters as the FMU names them (PX4's names), equal to `rate_loop`'s.
    px4_params: Px4RateParams,
    /// Ticks done since the start (the next is at `ticks · rate_loop_period`).
    ticks: u64,
    /// Seconds since the start time of the last communication point.
    now: f64,
    /// Thrust, roll, pitch, yaw rate as set (clipped when read).
    setpoint: [f64; 4],
    /// Body rates as set, FLU (the plant's `wx wy wz`), rad/s.
    rates_flu: [f64; 3],
    /// Motor commands of the last tick done.
    held: [f64; 4],
    /// The commands of a tick due at `now` with the inputs as they are (the tick itself runs
    /// in the next step); cleared whenever an input changes.
    #[serde(skip)]
    due: Cell<Option<[f64; 4]>>,
}

/// No start values besides the parameters (RateController.fmu, AttitudeController.fmu).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct NoStartValues;

static NO_SPECS: [ParamSpec<NoStartValues>; 0] = [];

impl Parameters for NoStartValues {
    fn specs() -> &'static [ParamSpec<Self>] {
        &NO_SPECS
    }
}

impl RateController {
    pub fn new(params: Px4RateParams) -> Result<Self, ParamError> {
        Ok(RateController {
            rate_loop: params.rate_loop()?,
            px4_params: params,
            ticks: 0,
            now: 0.0,
            setpoint: [0.0; 4],
            rates_flu: [0.0; 3],
            held: [0.0; 4],
            due: Cell::new(None),
        })
    }

    fn period(&self) -> f64 {
        self.rate_loop.params().rate_loop_period
    }

    /// The setpoint clipped into the rates action's bounds, as the gym clips an action.
    fn clipped_setpoint(&self) -> RatesSetpoint {
        let p = self.rate_loop.params();
        let (rp, y) = (p.roll_pitch_rate_max, p.yaw_rate_max);
        let s = &self.setpoint;
        RatesSetpoint {
            thrust: s[0].clamp(0.0, 1.0),
            rates: Vector3::new(s[1].clamp(-rp, rp), s[2].clamp(-rp, rp), s[3].clamp(-y, y)),
        }
    }

    /// The gyro as the loop reads it: the plant's FLU rates in FRD.
    fn gyro_frd(&self) -> Vector3<f64> {
        let [x, y, z] = self.rates_flu;
        Vector3::new(x, -y, -z)
    }

    /// One tick of `rate_loop` with the inputs in effect (the first settles its filters).
    fn tick(&self, rate_loop: &mut RateLoop) -> [f64; 4] {
        let gyro = self.gyro_frd();
        if self.ticks == 0 {
            rate_loop.reset(&gyro);
        }
        let motors = rate_loop.step(&self.clipped_setpoint(), &gyro, false);
        // The allocator's outputs are in [0, 1]; a non-finite gyro is refused as an input.
        std::array::from_fn(|i| motors.get(i).copied().unwrap_or(0.0).clamp(0.0, 1.0))
    }

    fn tick_is_due(&self) -> bool {
        self.ticks as f64 * self.period() < self.now + TIME_TOLERANCE
    }

    /// The motor commands now: a tick due now with the inputs as they are, else the last.
    pub fn motors(&self) -> [f64; 4] {
        if !self.tick_is_due() {
            return self.held;
        }
        if let Some(motors) = self.due.get() {
            return motors;
        }
        let motors = self.tick(&mut self.rate_loop.clone());
        self.due.set(Some(motors));
        motors
    }

    /// Runs the ticks before `end` (seconds since the start time).
    pub fn advance_to(&mut self, end: f64) {
        let period = self.period();
        while (self.ticks as f64 * period) < end - TIME_TOLERANCE {
            let mut rate_loop = self.rate_loop.clone();
            self.held = self.tick(&mut rate_loop);
            self.rate_loop = rate_loop;
            self.ticks += 1;
        }
        self.now = end;
        self.due.set(None);
    }

    fn set_input(&mut self, write: impl FnOnce(&mut Self), value: f64) -> Result<(), InputError> {
        if !value.is_finite() {
            return Err(InputError {
                input: "rate controller input",
                index: 0,
                value,
            });
        }
        write(self);
        self.due.set(None);
        Ok(())
    }
}

fn set_setpoint<const I: usize>(c: &mut RateController, v: f64) -> Result<(), InputError> {
    c.set_input(|c| c.setpoint[I] = v, v)
}

fn set_rate<const I: usize>(c: &mut RateController, v: f64) -> Result<(), InputError> {
    c.set_input(|c| c.rates_flu[I] = v, v)
}

/// Largest body rate the inputs take, rad/s (the plant's gyro range is far inside).
const RATE_RANGE: f64 = 1e4;

static INPUTS: [InputRow<RateController>; 7] = [
    InputRow::new(
        "thrust",
        "1",
        "Collective thrust setpoint, PX4's normalised thrust (clipped into [0, 1])",
        [-1e3, 1e3, 0.0],
        |c| c.setpoint[0],
        set_setpoint::<0>,
    ),
    InputRow::new(
        "roll_rate",
        "rad/s",
        "Roll rate setpoint, body FRD (clipped into +-MC_ROLLRATE_MAX)",
        [-RATE_RANGE, RATE_RANGE, 0.0],
        |c| c.setpoint[1],
        set_setpoint::<1>,
    ),
    InputRow::new(
        "pitch_rate",
        "rad/s",
        "Pitch rate setpoint, body FRD (clipped into +-MC_ROLLRATE_MAX)",
        [-RATE_RANGE, RATE_RANGE, 0.0],
        |c| c.setpoint[2],
        set_setpoint::<2>,
    ),
    InputRow::new(
        "yaw_rate",
        "rad/s",
        "Yaw rate setpoint, body FRD (clipped into +-MC_YAWRATE_MAX)",
        [-RATE_RANGE, RATE_RANGE, 0.0],
        |c| c.setpoint[3],
        set_setpoint::<3>,
    ),
    InputRow::new(
        "wx",
        "rad/s",
        "Measured body rate about x (forward), FLU: the plant's wx",
        [-RATE_RANGE, RATE_RANGE, 0.0],
        |c| c.rates_flu[0],
        set_rate::<0>,
    ),
    InputRow::new(
        "wy",
        "rad/s",
        "Measured body rate about y (left), FLU: the plant's wy",
        [-RATE_RANGE, RATE_RANGE, 0.0],
        |c| c.rates_flu[1],
        set_rate::<1>,
    ),
    InputRow::new(
        "wz",
        "rad/s",
        "Measured body rate about z (up), FLU: the plant's wz",
        [-RATE_RANGE, RATE_RANGE, 0.0],
        |c| c.rates_flu[2],
        set_rate::<2>,
    ),
];

const MOTOR_TEXT: [&str; 4] = [
    "Command of motor 0 (front right), 0 .. 1: the plant's motor_command_0",
    "Command of motor 1 (rear left), 0 .. 1: the plant's motor_command_1",
    "Command of motor 2 (front left), 0 .. 1: the plant's motor_command_2",
    "Command of motor 3 (rear right), 0 .. 1: the plant's motor_command_3",
];

static OUTPUTS: [OutputRow<RateController>; 4] = [
    OutputRow::real("motor_command_0", "1", MOTOR_TEXT[0], |c| c.motors()[0]),
    OutputRow::real("motor_command_1", "1", MOTOR_TEXT[1], |c| c.motors()[1]),
    OutputRow::real("motor_command_2", "1", MOTOR_TEXT[2], |c| c.motors()[2]),
    OutputRow::real("motor_command_3", "1", MOTOR_TEXT[3], |c| c.motors()[3]),
];

impl VariableTable for RateController {
    type Params = Px4RateParams;
    type Initial = NoStartValues;
    fixed_shape!(INPUTS, OUTPUTS);

    fn params(&self) -> &Px4RateParams {
        &self.px4_params
    }

    /// Rebuilds the loop (at rest) with the parameter changed; nothing changes on an error.
    fn set_parameter(&mut self, name: &'static str, value: f64) -> Result<(), ParamError> {
        let mut params = self.px4_params.clone();
        params.set(name, value)?;
        self.rate_loop = params.rate_loop()?;
        self.px4_params = params;
        self.due.set(None);
        Ok(())
    }
}

const ALL_INPUTS: &[&str] = &[
    "thrust",
    "roll_rate",
    "pitch_rate",
    "yaw_rate",
    "wx",
    "wy",
    "wz",
];

/// RateController.fmu's table.
pub(super) fn table() -> Table<RateController> {
    Table::new(info(), (), Rows::of(&()), Vec::new(), None)
}

fn info() -> ModelInfo {
    ModelInfo {
        identifier: "RateController",
        description: Cow::Borrowed(
            "flyloop RateController: PX4 v1.16.0's multicopter rate loop (gyro filters, rate \
             PID, yaw torque filter) and control allocation for the quad X, on its own \
             rate_loop_period grid; thrust + body-rate setpoint and the plant's body rates in, \
             the plant's four motor commands out",
        ),
        default_experiment: (0.0, 10.0, 0.004),
        // A tick at a communication point reads the inputs set there.
        direct_feedthrough: &[
            ("motor_command_0", ALL_INPUTS),
            ("motor_command_1", ALL_INPUTS),
            ("motor_command_2", ALL_INPUTS),
            ("motor_command_3", ALL_INPUTS),
        ],
        state_free_outputs: &[],
        arrays: vec![Array {
            name: "motor_command",
            description: Cow::Borrowed(
                "Commands of the four motors, 0 .. 1 each (the plant's motor_command)",
            ),
            first: "motor_command_0",
            len: 4,
        }],
        event_indicators: &[],
        descriptions: Vec::new(),
    }
}

impl FmuModel for RateController {
    fn build(_: &(), previous: Option<&Self>, _: &NoStartValues) -> Result<Self, ParamError> {
        let params = previous.map(|c| c.px4_params.clone());
        RateController::new(params.unwrap_or_default())
    }

    fn internal_steps(&self, end: f64, _h: f64) -> f64 {
        ((end - self.now).max(0.0) / self.period()).ceil() + 1.0
    }

    fn advance(&mut self, end: f64, _h: f64) {
        self.advance_to(end);
    }

    fn is_finite(&self) -> bool {
        self.held.iter().all(|m| m.is_finite())
            && self.rate_loop.integrator().iter().all(|v| v.is_finite())
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        snapshot::encode(SNAPSHOT_TAG, self)
    }

    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        snapshot::decode(SNAPSHOT_TAG, "RateController", bytes)
    }
}
