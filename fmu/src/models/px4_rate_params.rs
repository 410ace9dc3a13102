//! RateController.fmu's 39 parameters under PX4 v1.16.0's names and units (deg/s where PX4
//! sets rates in deg/s), with airframe 10016 `none_iris`'s values as defaults: the 27 fields of
//! the core's [`RateLoopParams`] and the allocator's rotor geometry `CA_ROTORn_PX/PY/KM`.
//!
//! Three fields have no PX4 parameter and keep the core's name: `rate_loop_period` (PX4 SITL
//! runs the loop on every HIL_SENSOR), `gyro_quantum` (the int16 gyro of PX4's simulator
//! interface) and `output_quantum` (PX4's 1000-step PWM). PX4 bounds roll and pitch rates
//! apart (`MC_ROLLRATE_MAX`, `MC_PITCHRATE_MAX`); the core has one bound for both, so
//! `MC_ROLLRATE_MAX` sets it and PX4's pitch name is not offered. `CA_ROTORn_CT` is not
//! offered either: the allocator counts thrust coefficients relative to the largest, so the
//! quad X's common 6.5 cancels in PX4's normalisation.

use flyloop_core::ParamError;
use flyloop_core::params::{ParamSpec, Parameters, ValueKind};
use flyloop_core::rate_loop::px4_rotors::{NONE_IRIS, Px4Rotor};
use flyloop_core::rate_loop::{RateLoop, RateLoopParams};
use serde::{Deserialize, Serialize};

const DEG: f64 = std::f64::consts::PI / 180.0;
/// Upper bound of the gains, as the core's table bounds them.
const GAIN: f64 = 100.0;
/// Largest rotor offset from the centre of mass, m (PX4 allows 100; no multirotor is 10 m).
const ARM: f64 = 10.0;

/// One rotor's place and yaw moment as PX4's allocator reads them (body FRD).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotorGeometry {
    /// `CA_ROTORn_PX`: forward of the centre of mass, m.
    pub px: f64,
    /// `CA_ROTORn_PY`: right of the centre of mass, m.
    pub py: f64,
    /// `CA_ROTORn_KM`: yaw moment per unit thrust, m; positive for a counter-clockwise rotor.
    pub km: f64,
}

/// The core's rate loop parameters and the quad X's rotors, seen through PX4's names.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Px4RateParams {
    /// The rate loop's fields (`MC_*`, `IMU_*`, `THR_MDL_FAC`). Default: none_iris.
    pub rate_loop: RateLoopParams,
    /// `CA_ROTOR0..3_*` in PX4's motor order (front right, rear left, front left, rear right).
    /// Default: none_iris (0.1515 m fore/aft, 0.245 / 0.1875 m to the side, KM ±0.05).
    pub rotors: [RotorGeometry; 4],
}

impl Default for Px4RateParams {
    fn default() -> Self {
        Px4RateParams {
            rate_loop: RateLoopParams::default(),
            rotors: NONE_IRIS.map(|r| RotorGeometry {
                px: r.px,
                py: r.py,
                km: r.km,
            }),
        }
    }
}

impl Px4RateParams {
    /// The rotors as the core's allocator takes them (none_iris's common thrust coefficient).
    pub fn px4_rotors(&self) -> Vec<Px4Rotor> {
        (self.rotors.iter().zip(NONE_IRIS))
            .map(|(g, iris)| Px4Rotor {
                px: g.px,
                py: g.py,
                km: g.km,
                ct: iris.ct,
            })
            .collect()
    }

    /// The rate loop these parameters describe, at rest.
    pub fn rate_loop(&self) -> Result<RateLoop, ParamError> {
        RateLoop::new(self.rate_loop.clone(), &self.px4_rotors()).map_err(|e| match e {
            // The allocator refuses the geometry, not a frame: name PX4's parameters.
            ParamError::Relation { name: "frame", .. } => ParamError::Relation {
                name: "CA_ROTOR0..3_PX/PY/KM",
                requirement: "the four rotors must control roll, pitch, yaw and thrust \
                              independently (PX4's allocator)"
                    .to_string(),
            },
            other => other,
        })
    }
}

/// A row over one field of the rate loop, in the field's own unit.
macro_rules! px4 {
    ($name:literal, $field:ident, $unit:literal, $min:expr, $max:expr, $doc:literal) => {
        ParamSpec {
            name: $name,
            unit: $unit,
            kind: ValueKind::Real,
            min: $min,
            max: $max,
            description: $doc,
            get: |p: &Px4RateParams| p.rate_loop.$field,
            set: |p: &mut Px4RateParams, v| p.rate_loop.$field = v,
        }
    };
}

/// A rate bound PX4 sets in deg/s over a field in rad/s.
macro_rules! px4_deg {
    ($name:literal, $field:ident, $doc:literal) => {
        ParamSpec {
            name: $name,
            unit: "deg/s",
            kind: ValueKind::Real,
            // The core's bounds, 0.01 .. 30 rad/s, rounded inward.
            min: 0.6,
            max: 1700.0,
            description: $doc,
            get: |p: &Px4RateParams| p.rate_loop.$field / DEG,
            set: |p: &mut Px4RateParams, v| p.rate_loop.$field = v * DEG,
        }
    };
}

/// A `CA_ROTORn_*` row over rotor `$i`'s `$field`.
macro_rules! rotor {
    ($name:literal, $i:literal, $field:ident, $unit:literal, $bound:expr, $doc:literal) => {
        ParamSpec {
            name: $name,
            unit: $unit,
            kind: ValueKind::Real,
            min: -$bound,
            max: $bound,
            description: $doc,
            get: |p: &Px4RateParams| p.rotors[$i].$field,
            set: |p: &mut Px4RateParams, v| p.rotors[$i].$field = v,
        }
    };
}

static PX4_RATE_SPECS: [ParamSpec<Px4RateParams>; 39] = [
    px4!(
        "rate_loop_period",
        rate_loop_period,
        "s",
        1e-4,
        0.1,
        "Rate loop period (no PX4 name: PX4 SITL runs the loop on every HIL_SENSOR)"
    ),
    px4!(
        "MC_ROLLRATE_P",
        roll_rate_p,
        "1",
        0.0,
        GAIN,
        "Roll rate P gain"
    ),
    px4!(
        "MC_ROLLRATE_I",
        roll_rate_i,
        "1",
        0.0,
        GAIN,
        "Roll rate I gain"
    ),
    px4!(
        "MC_ROLLRATE_D",
        roll_rate_d,
        "1",
        0.0,
        GAIN,
        "Roll rate D gain"
    ),
    px4!(
        "MC_ROLLRATE_FF",
        roll_rate_ff,
        "1",
        0.0,
        GAIN,
        "Roll rate feed-forward"
    ),
    px4!(
        "MC_ROLLRATE_K",
        roll_rate_k,
        "1",
        0.0,
        GAIN,
        "Roll rate gain multiplier (scales P, I and D)"
    ),
    px4!(
        "MC_RR_INT_LIM",
        roll_rate_int_lim,
        "1",
        0.0,
        1.0,
        "Roll rate integrator limit"
    ),
    px4!(
        "MC_PITCHRATE_P",
        pitch_rate_p,
        "1",
        0.0,
        GAIN,
        "Pitch rate P gain"
    ),
    px4!(
        "MC_PITCHRATE_I",
        pitch_rate_i,
        "1",
        0.0,
        GAIN,
        "Pitch rate I gain"
    ),
    px4!(
        "MC_PITCHRATE_D",
        pitch_rate_d,
        "1",
        0.0,
        GAIN,
        "Pitch rate D gain"
    ),
    px4!(
        "MC_PITCHRATE_FF",
        pitch_rate_ff,
        "1",
        0.0,
        GAIN,
        "Pitch rate feed-forward"
    ),
    px4!(
        "MC_PITCHRATE_K",
        pitch_rate_k,
        "1",
        0.0,
        GAIN,
        "Pitch rate gain multiplier (scales P, I and D)"
    ),
    px4!(
        "MC_PR_INT_LIM",
        pitch_rate_int_lim,
        "1",
        0.0,
        1.0,
        "Pitch rate integrator limit"
    ),
    px4!(
        "MC_YAWRATE_P",
        yaw_rate_p,
        "1",
        0.0,
        GAIN,
        "Yaw rate P gain"
    ),
    px4!(
        "MC_YAWRATE_I",
        yaw_rate_i,
        "1",
        0.0,
        GAIN,
        "Yaw rate I gain"
    ),
    px4!(
        "MC_YAWRATE_D",
        yaw_rate_d,
        "1",
        0.0,
        GAIN,
        "Yaw rate D gain"
    ),
    px4!(
        "MC_YAWRATE_FF",
        yaw_rate_ff,
        "1",
        0.0,
        GAIN,
        "Yaw rate feed-forward"
    ),
    px4!(
        "MC_YAWRATE_K",
        yaw_rate_k,
        "1",
        0.0,
        GAIN,
        "Yaw rate gain multiplier (scales P, I and D)"
    ),
    px4!(
        "MC_YR_INT_LIM",
        yaw_rate_int_lim,
        "1",
        0.0,
        1.0,
        "Yaw rate integrator limit"
    ),
    px4_deg!(
        "MC_ROLLRATE_MAX",
        roll_pitch_rate_max,
        "Largest roll and pitch rate setpoint (the core has one bound for both, PX4's MC_PITCHRATE_MAX too; clips the roll_rate and pitch_rate inputs)"
    ),
    px4_deg!(
        "MC_YAWRATE_MAX",
        yaw_rate_max,
        "Largest yaw rate setpoint (clips the yaw_rate input)"
    ),
    px4!(
        "IMU_GYRO_CUTOFF",
        gyro_cutoff,
        "Hz",
        0.0,
        1000.0,
        "Gyro low-pass cutoff (0 = off)"
    ),
    px4!(
        "IMU_DGYRO_CUTOFF",
        gyro_derivative_cutoff,
        "Hz",
        0.0,
        1000.0,
        "Gyro derivative low-pass cutoff (0 = off)"
    ),
    px4!(
        "MC_YAW_TQ_CUTOFF",
        yaw_torque_cutoff,
        "Hz",
        0.0,
        1000.0,
        "Yaw torque low-pass cutoff (0 = off)"
    ),
    px4!(
        "gyro_quantum",
        gyro_quantum,
        "rad/s",
        0.0,
        0.1,
        "Gyro sample step of PX4's simulator interface (no PX4 name: its int16 at 2000 deg/s; 0 = exact)"
    ),
    px4!(
        "output_quantum",
        output_quantum,
        "1",
        0.0,
        0.1,
        "Motor output step (no PX4 name: its PWM's 1000 steps; 0 = exact)"
    ),
    px4!(
        "THR_MDL_FAC",
        thrust_model_factor,
        "1",
        0.0,
        1.0,
        "Thrust model factor: relative thrust f u^2 + (1 - f) u"
    ),
    rotor!(
        "CA_ROTOR0_PX",
        0,
        px,
        "m",
        ARM,
        "Rotor 0 (front right) position forward of the centre of mass"
    ),
    rotor!(
        "CA_ROTOR0_PY",
        0,
        py,
        "m",
        ARM,
        "Rotor 0 (front right) position right of the centre of mass"
    ),
    rotor!(
        "CA_ROTOR0_KM",
        0,
        km,
        "m",
        1.0,
        "Rotor 0 (front right) yaw moment per unit thrust (positive: counter-clockwise)"
    ),
    rotor!(
        "CA_ROTOR1_PX",
        1,
        px,
        "m",
        ARM,
        "Rotor 1 (rear left) position forward of the centre of mass"
    ),
    rotor!(
        "CA_ROTOR1_PY",
        1,
        py,
        "m",
        ARM,
        "Rotor 1 (rear left) position right of the centre of mass"
    ),
    rotor!(
        "CA_ROTOR1_KM",
        1,
        km,
        "m",
        1.0,
        "Rotor 1 (rear left) yaw moment per unit thrust (positive: counter-clockwise)"
    ),
    rotor!(
        "CA_ROTOR2_PX",
        2,
        px,
        "m",
        ARM,
        "Rotor 2 (front left) position forward of the centre of mass"
    ),
    rotor!(
        "CA_ROTOR2_PY",
        2,
        py,
        "m",
        ARM,
        "Rotor 2 (front left) position right of the centre of mass"
    ),
    rotor!(
        "CA_ROTOR2_KM",
        2,
        km,
        "m",
        1.0,
        "Rotor 2 (front left) yaw moment per unit thrust (positive: counter-clockwise)"
    ),
    rotor!(
        "CA_ROTOR3_PX",
        3,
        px,
        "m",
        ARM,
        "Rotor 3 (rear right) position forward of the centre of mass"
    ),
    rotor!(
        "CA_ROTOR3_PY",
        3,
        py,
        "m",
        ARM,
        "Rotor 3 (rear right) position right of the centre of mass"
    ),
    rotor!(
        "CA_ROTOR3_KM",
        3,
        km,
        "m",
        1.0,
        "Rotor 3 (rear right) yaw moment per unit thrust (positive: counter-clockwise)"
    ),
];

impl Parameters for Px4RateParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &PX4_RATE_SPECS
    }

    /// The loop's own relations and an allocator that can mix for the rotors.
    fn check_relations(&self) -> Result<(), ParamError> {
        self.rate_loop().map(|_| ())
    }
}
