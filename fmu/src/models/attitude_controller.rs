//! The model behind AttitudeController.fmu: a small PD controller that closes Quadrotor.fmu +
//! RateController.fmu into a hover with a target attitude, for the SSP systems in
//! examples/ssp. It reads the plant's outputs by name (`x y z vx vy vz roll pitch yaw`,
//! FLU/ENU) and writes RateController.fmu's inputs by name (`thrust roll_rate pitch_rate
//! yaw_rate`, PX4's body FRD): PD on height for the thrust, PD on horizontal position for a
//! tilt (small angles: acceleration = g · tilt), P on each Euler angle for the body rates
//! (PX4's attitude loop is a P loop giving rate setpoints the same way). The targets are
//! parameters; the attitude target (added to the position loop's tilt) applies from
//! `step_time` on (level with yaw 0 before it), so one system shows both a hover and an
//! attitude step. Position gains 0 leave a pure attitude controller.
//!
//! It has no state but the time: its outputs are a function of the inputs set and the time,
//! so every output is direct feedthrough of the inputs it reads.

use super::rate_controller::NoStartValues;
use crate::model::{FmuModel, Table};
use crate::table::ModelInfo;
use flyloop_core::params::{ParamSpec, Parameters};
use flyloop_core::snapshot;
use flyloop_core::variables::{InputRow, OutputRow, Rows, VariableTable};
use flyloop_core::{InputError, ParamError, SnapshotError, fixed_shape, param};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::f64::consts::PI;

const SNAPSHOT_TAG: &[u8; 8] = b"FLYATC01";
/// Smallest cos(roll)·cos(pitch) the thrust is divided by (tilt compensation up to 60°).
const MIN_TILT_COSINE: f64 = 0.5;
/// Largest tilt the position loop asks for, rad.
const MAX_TILT: f64 = 0.35;
const G: f64 = 9.81;

/// Gains and targets of the attitude controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AttitudeControllerParams {
    /// East position to hold, m (the plant's `x`). Default 0.
    pub target_x: f64,
    /// North position to hold, m (the plant's `y`). Default 0.
    pub target_y: f64,
    /// Height to hold, m (the plant's `z`). Default 1.
    pub target_z: f64,
    /// Roll to hold from `step_time` on, rad (FLU, about body x forward). Default 0.
    pub target_roll: f64,
    /// Pitch to hold from `step_time` on, rad (FLU: nose down positive, as the plant's
    /// `pitch`). Default 0.
    pub target_pitch: f64,
    /// Yaw to hold from `step_time` on, rad (from east toward north, as the plant's `yaw`).
    /// Default 0.
    pub target_yaw: f64,
    /// Time the attitude target starts, s (before it: level, yaw 0). Default 0.
    pub step_time: f64,
    /// Normalised thrust that hovers the plant: RateController.fmu's `thrust` at which its
    /// motors carry the weight. Default 0.49523 = √(m g / 4 k) for the default 1 kg quad X.
    pub hover_thrust: f64,
    /// Thrust per metre of height error, 1/m. Default 0.1.
    pub altitude_p: f64,
    /// Thrust per m/s of vertical velocity, s/m. Default 0.08.
    pub altitude_d: f64,
    /// Horizontal acceleration per metre of position error, 1/s2. Default 1.
    pub position_p: f64,
    /// Horizontal acceleration per m/s of velocity, 1/s. Default 1.6.
    pub position_d: f64,
    /// Roll and pitch rate per radian of error, 1/s (PX4's `MC_ROLL_P`). Default 6.5.
    pub attitude_p: f64,
    /// Yaw rate per radian of error, 1/s (PX4's `MC_YAW_P`). Default 2.8.
    pub yaw_p: f64,
}

impl Default for AttitudeControllerParams {
    fn default() -> Self {
        AttitudeControllerParams {
            target_x: 0.0,
            target_y: 0.0,
            target_z: 1.0,
            target_roll: 0.0,
            target_pitch: 0.0,
            target_yaw: 0.0,
            step_time: 0.0,
            hover_thrust: (9.81_f64 / 40.0).sqrt(),
            altitude_p: 0.1,
            altitude_d: 0.08,
            position_p: 1.0,
            position_d: 1.6,
            attitude_p: 6.5,
            yaw_p: 2.8,
        }
    }
}

static SPECS: [ParamSpec<AttitudeControllerParams>; 14] = [
    param!(real target_x, "m", -1e4, 1e4, "East position to hold (the plant's x)"),
    param!(real target_y, "m", -1e4, 1e4, "North position to hold (the plant's y)"),
    param!(real target_z, "m", -1e4, 1e4, "Height to hold (the plant's z)"),
    param!(real target_roll, "rad", -1.0, 1.0, "Roll to hold from step_time on (FLU)"),
    param!(real target_pitch, "rad", -1.0, 1.0, "Pitch to hold from step_time on (FLU: nose down positive)"),
    param!(real target_yaw, "rad", -PI, PI, "Yaw to hold from step_time on (from east toward north)"),
    param!(real step_time, "s", 0.0, 1e6, "Time the attitude target starts (level, yaw 0 before it)"),
    param!(real hover_thrust, "1", 0.0, 1.0, "Normalised thrust that hovers the plant (RateController's thrust)"),
    param!(real altitude_p, "1/m", 0.0, 10.0, "Thrust per metre of height error"),
    param!(real altitude_d, "s/m", 0.0, 10.0, "Thrust per m/s of vertical velocity"),
    param!(real position_p, "1/s2", 0.0, 100.0, "Horizontal acceleration per metre of position error (0: no position hold)"),
    param!(real position_d, "1/s", 0.0, 100.0, "Horizontal acceleration per m/s of velocity"),
    param!(real attitude_p, "1/s", 0.0, 100.0, "Roll and pitch rate per radian of error (PX4's MC_ROLL_P)"),
    param!(real yaw_p, "1/s", 0.0, 100.0, "Yaw rate per radian of error (PX4's MC_YAW_P)"),
];

impl Parameters for AttitudeControllerParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &SPECS
    }
}

/// The controller: its parameters, the plant's outputs as set, and the time.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AttitudeController {
    params: AttitudeControllerParams,
    /// The plant's `x y z vx vy vz roll pitch yaw` as set.
    plant: [f64; 9],
    /// Seconds since the start time.
    now: f64,
}

/// The four setpoints of RateController.fmu: thrust, then body FRD roll, pitch, yaw rate.
fn setpoint(c: &AttitudeController) -> [f64; 4] {
    let p = &c.params;
    let [x, y, z, vx, vy, vz, roll, pitch, yaw] = c.plant;
    let stepped = c.now >= p.step_time;
    let target = |v: f64| if stepped { v } else { 0.0 };
    // The position loop's acceleration (world ENU), turned into the body's forward and left
    // and then into a tilt: nose down (FLU pitch > 0) goes forward, roll > 0 goes right.
    let ax = p.position_p * (p.target_x - x) - p.position_d * vx;
    let ay = p.position_p * (p.target_y - y) - p.position_d * vy;
    let (forward, left) = (
        yaw.cos() * ax + yaw.sin() * ay,
        -yaw.sin() * ax + yaw.cos() * ay,
    );
    let tilt_pitch = (forward / G).clamp(-MAX_TILT, MAX_TILT);
    let tilt_roll = (-left / G).clamp(-MAX_TILT, MAX_TILT);
    let tilt = (roll.cos() * pitch.cos()).max(MIN_TILT_COSINE);
    let thrust = (p.hover_thrust + p.altitude_p * (p.target_z - z) - p.altitude_d * vz) / tilt;
    // The yaw error the short way round.
    let yaw_error = (target(p.target_yaw) - yaw + PI).rem_euclid(2.0 * PI) - PI;
    // Rates in FLU, then PX4's FRD (y and z flip).
    let roll_rate = p.attitude_p * (tilt_roll + target(p.target_roll) - roll);
    let pitch_rate = p.attitude_p * (tilt_pitch + target(p.target_pitch) - pitch);
    let yaw_rate = p.yaw_p * yaw_error;
    [thrust.clamp(0.0, 1.0), roll_rate, -pitch_rate, -yaw_rate]
}

fn set_plant<const I: usize>(c: &mut AttitudeController, v: f64) -> Result<(), InputError> {
    if !v.is_finite() {
        return Err(InputError {
            input: INPUT_NAMES[I],
            index: 0,
            value: v,
        });
    }
    c.plant[I] = v;
    Ok(())
}

const INPUT_NAMES: [&str; 9] = ["x", "y", "z", "vx", "vy", "vz", "roll", "pitch", "yaw"];
/// Largest value an input takes (the plant's are far inside).
const RANGE: f64 = 1e6;

/// The input row of the plant's output `INPUT_NAMES[$i]`.
macro_rules! plant_input {
    ($i:literal, $unit:literal, $doc:literal) => {
        InputRow::new(
            INPUT_NAMES[$i],
            $unit,
            $doc,
            [-RANGE, RANGE, 0.0],
            |c| c.plant[$i],
            set_plant::<$i>,
        )
    };
}

static INPUTS: [InputRow<AttitudeController>; 9] = [
    plant_input!(0, "m", "East position: the plant's x"),
    plant_input!(1, "m", "North position: the plant's y"),
    plant_input!(2, "m", "Height: the plant's z"),
    plant_input!(3, "m/s", "East velocity: the plant's vx"),
    plant_input!(4, "m/s", "North velocity: the plant's vy"),
    plant_input!(5, "m/s", "Vertical velocity: the plant's vz"),
    plant_input!(6, "rad", "Roll: the plant's roll (FLU)"),
    plant_input!(
        7,
        "rad",
        "Pitch: the plant's pitch (FLU, nose down positive)"
    ),
    plant_input!(8, "rad", "Yaw: the plant's yaw"),
];

static OUTPUTS: [OutputRow<AttitudeController>; 4] = [
    OutputRow::real(
        "thrust",
        "1",
        "Collective thrust setpoint in [0, 1]: RateController's thrust",
        |c| setpoint(c)[0],
    ),
    OutputRow::real(
        "roll_rate",
        "rad/s",
        "Roll rate setpoint, body FRD: RateController's roll_rate",
        |c| setpoint(c)[1],
    ),
    OutputRow::real(
        "pitch_rate",
        "rad/s",
        "Pitch rate setpoint, body FRD: RateController's pitch_rate",
        |c| setpoint(c)[2],
    ),
    OutputRow::real(
        "yaw_rate",
        "rad/s",
        "Yaw rate setpoint, body FRD: RateController's yaw_rate",
        |c| setpoint(c)[3],
    ),
];

impl VariableTable for AttitudeController {
    type Params = AttitudeControllerParams;
    type Initial = NoStartValues;
    fixed_shape!(INPUTS, OUTPUTS);

    fn params(&self) -> &AttitudeControllerParams {
        &self.params
    }

    fn set_parameter(&mut self, name: &'static str, value: f64) -> Result<(), ParamError> {
        let mut params = self.params.clone();
        params.set(name, value)?;
        self.params = params;
        Ok(())
    }
}

/// AttitudeController.fmu's table.
pub(super) fn table() -> Table<AttitudeController> {
    Table::new(info(), (), Rows::of(&()), Vec::new(), None)
}

fn info() -> ModelInfo {
    ModelInfo {
        identifier: "AttitudeController",
        description: Cow::Borrowed(
            "flyloop AttitudeController: PD on height and position, P on attitude, from the \
             plant's x y z vx vy vz roll pitch yaw to RateController's thrust and body-rate setpoint; targets \
             as parameters, the attitude target from step_time on",
        ),
        default_experiment: (0.0, 10.0, 0.004),
        direct_feedthrough: &[
            ("thrust", &["z", "vz", "roll", "pitch"]),
            ("roll_rate", &["x", "y", "vx", "vy", "roll", "yaw"]),
            ("pitch_rate", &["x", "y", "vx", "vy", "pitch", "yaw"]),
            ("yaw_rate", &["yaw"]),
        ],
        state_free_outputs: &[],
        arrays: Vec::new(),
        event_indicators: &[],
        descriptions: Vec::new(),
    }
}

impl FmuModel for AttitudeController {
    fn build(_: &(), previous: Option<&Self>, _: &NoStartValues) -> Result<Self, ParamError> {
        Ok(AttitudeController {
            params: previous.map(|c| c.params.clone()).unwrap_or_default(),
            plant: [0.0; 9],
            now: 0.0,
        })
    }

    fn internal_steps(&self, _end: f64, _h: f64) -> f64 {
        1.0
    }

    fn advance(&mut self, end: f64, _h: f64) {
        self.now = end;
    }

    fn is_finite(&self) -> bool {
        self.plant.iter().all(|v| v.is_finite())
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        snapshot::encode(SNAPSHOT_TAG, self)
    }

    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        snapshot::decode(SNAPSHOT_TAG, "AttitudeController", bytes)
    }
}
