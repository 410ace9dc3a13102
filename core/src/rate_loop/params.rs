//! Parameters of PX4's inner loop as the model flies it: PX4's names in each field's
//! documentation, PX4 v1.16.0's values for airframe 10016 `none_iris` as defaults. The rotor
//! geometry is not here: the allocator mixes for the vehicle's frame ([`super::px4_rotors`]).

use crate::param;
use crate::params::{ParamSpec, Parameters};
use serde::{Deserialize, Serialize};

const DEG: f64 = std::f64::consts::PI / 180.0;
/// PX4's simulated gyro: radians(2000 / 32768) per count.
const GYRO_QUANTUM: f64 = 2000.0 / 32768.0 * DEG;

/// PX4's rate controller, gyro filters and control allocation. Rates and torques are body
/// FRD; torques are normalised (PX4's units: 1 = the allocator's full authority).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RateLoopParams {
    /// Period of the rate loop: one gyro sample, one controller and allocator run, s.
    /// PX4 in SITL runs it on every HIL_SENSOR, 4 ms. Default 0.004.
    pub rate_loop_period: f64,
    /// `MC_ROLLRATE_P`. Default 0.15.
    pub roll_rate_p: f64,
    /// `MC_ROLLRATE_I`. Default 0.2.
    pub roll_rate_i: f64,
    /// `MC_ROLLRATE_D`. Default 0.003.
    pub roll_rate_d: f64,
    /// `MC_ROLLRATE_FF`. Default 0.
    pub roll_rate_ff: f64,
    /// `MC_ROLLRATE_K`: multiplies P, I and D. Default 1.
    pub roll_rate_k: f64,
    /// `MC_RR_INT_LIM`. Default 0.3.
    pub roll_rate_int_lim: f64,
    /// `MC_PITCHRATE_P`. Default 0.15.
    pub pitch_rate_p: f64,
    /// `MC_PITCHRATE_I`. Default 0.2.
    pub pitch_rate_i: f64,
    /// `MC_PITCHRATE_D`. Default 0.003.
    pub pitch_rate_d: f64,
    /// `MC_PITCHRATE_FF`. Default 0.
    pub pitch_rate_ff: f64,
    /// `MC_PITCHRATE_K`. Default 1.
    pub pitch_rate_k: f64,
    /// `MC_PR_INT_LIM`. Default 0.3.
    pub pitch_rate_int_lim: f64,
    /// `MC_YAWRATE_P`. Default 0.2.
    pub yaw_rate_p: f64,
    /// `MC_YAWRATE_I`. Default 0.1.
    pub yaw_rate_i: f64,
    /// `MC_YAWRATE_D`. Default 0.
    pub yaw_rate_d: f64,
    /// `MC_YAWRATE_FF`. Default 0.
    pub yaw_rate_ff: f64,
    /// `MC_YAWRATE_K`. Default 1.
    pub yaw_rate_k: f64,
    /// `MC_YR_INT_LIM`. Default 0.3.
    pub yaw_rate_int_lim: f64,
    /// Largest roll and pitch rate setpoint, rad/s (`MC_ROLLRATE_MAX`, `MC_PITCHRATE_MAX`:
    /// 220 deg/s); bounds the rates action. Default 3.8397.
    pub roll_pitch_rate_max: f64,
    /// Largest yaw rate setpoint, rad/s (`MC_YAWRATE_MAX`: 200 deg/s). Default 3.4907.
    pub yaw_rate_max: f64,
    /// Gyro low-pass cutoff, Hz (`IMU_GYRO_CUTOFF`; 0 = off). Default 40.
    pub gyro_cutoff: f64,
    /// Cutoff of the first-order low-pass on the filtered gyro's derivative (the D term's
    /// input), Hz (`IMU_DGYRO_CUTOFF`; 0 = off). Default 30.
    pub gyro_derivative_cutoff: f64,
    /// Cutoff of the first-order low-pass on the yaw torque, Hz (`MC_YAW_TQ_CUTOFF`;
    /// 0 = off). Default 2.
    pub yaw_torque_cutoff: f64,
    /// Step of the gyro samples PX4's simulator interface reads (int16 at ±2000 deg/s,
    /// truncated toward zero), rad/s; 0 = exact. Default 1.0652644e-3.
    pub gyro_quantum: f64,
    /// Step of the motor outputs (PX4's PWM: 1000 steps from 1000 to 2000 µs); 0 = exact.
    /// Default 0.001.
    pub output_quantum: f64,
    /// Thrust model factor (`THR_MDL_FAC`): relative thrust f·u² + (1 − f)·u. Default 0.
    pub thrust_model_factor: f64,
}

impl Default for RateLoopParams {
    fn default() -> Self {
        RateLoopParams {
            rate_loop_period: 0.004,
            roll_rate_p: 0.15,
            roll_rate_i: 0.2,
            roll_rate_d: 0.003,
            roll_rate_ff: 0.0,
            roll_rate_k: 1.0,
            roll_rate_int_lim: 0.3,
            pitch_rate_p: 0.15,
            pitch_rate_i: 0.2,
            pitch_rate_d: 0.003,
            pitch_rate_ff: 0.0,
            pitch_rate_k: 1.0,
            pitch_rate_int_lim: 0.3,
            yaw_rate_p: 0.2,
            yaw_rate_i: 0.1,
            yaw_rate_d: 0.0,
            yaw_rate_ff: 0.0,
            yaw_rate_k: 1.0,
            yaw_rate_int_lim: 0.3,
            roll_pitch_rate_max: 220.0 * DEG,
            yaw_rate_max: 200.0 * DEG,
            gyro_cutoff: 40.0,
            gyro_derivative_cutoff: 30.0,
            yaw_torque_cutoff: 2.0,
            gyro_quantum: GYRO_QUANTUM,
            output_quantum: 0.001,
            thrust_model_factor: 0.0,
        }
    }
}

const GAIN: f64 = 100.0;

static RATE_LOOP_SPECS: [ParamSpec<RateLoopParams>; 27] = [
    param!(real rate_loop_period, "s", 1e-4, 0.1, "Rate loop period (PX4 SITL: every HIL_SENSOR)"),
    param!(real roll_rate_p, "1", 0.0, GAIN, "Roll rate P gain (MC_ROLLRATE_P)"),
    param!(real roll_rate_i, "1", 0.0, GAIN, "Roll rate I gain (MC_ROLLRATE_I)"),
    param!(real roll_rate_d, "1", 0.0, GAIN, "Roll rate D gain (MC_ROLLRATE_D)"),
    param!(real roll_rate_ff, "1", 0.0, GAIN, "Roll rate feed-forward (MC_ROLLRATE_FF)"),
    param!(real roll_rate_k, "1", 0.0, GAIN, "Roll rate gain multiplier (MC_ROLLRATE_K)"),
    param!(real roll_rate_int_lim, "1", 0.0, 1.0, "Roll rate integrator limit (MC_RR_INT_LIM)"),
    param!(real pitch_rate_p, "1", 0.0, GAIN, "Pitch rate P gain (MC_PITCHRATE_P)"),
    param!(real pitch_rate_i, "1", 0.0, GAIN, "Pitch rate I gain (MC_PITCHRATE_I)"),
    param!(real pitch_rate_d, "1", 0.0, GAIN, "Pitch rate D gain (MC_PITCHRATE_D)"),
    param!(real pitch_rate_ff, "1", 0.0, GAIN, "Pitch rate feed-forward (MC_PITCHRATE_FF)"),
    param!(real pitch_rate_k, "1", 0.0, GAIN, "Pitch rate gain multiplier (MC_PITCHRATE_K)"),
    param!(real pitch_rate_int_lim, "1", 0.0, 1.0, "Pitch rate integrator limit (MC_PR_INT_LIM)"),
    param!(real yaw_rate_p, "1", 0.0, GAIN, "Yaw rate P gain (MC_YAWRATE_P)"),
    param!(real yaw_rate_i, "1", 0.0, GAIN, "Yaw rate I gain (MC_YAWRATE_I)"),
    param!(real yaw_rate_d, "1", 0.0, GAIN, "Yaw rate D gain (MC_YAWRATE_D)"),
    param!(real yaw_rate_ff, "1", 0.0, GAIN, "Yaw rate feed-forward (MC_YAWRATE_FF)"),
    param!(real yaw_rate_k, "1", 0.0, GAIN, "Yaw rate gain multiplier (MC_YAWRATE_K)"),
    param!(real yaw_rate_int_lim, "1", 0.0, 1.0, "Yaw rate integrator limit (MC_YR_INT_LIM)"),
    param!(real roll_pitch_rate_max, "rad/s", 0.01, 30.0, "Largest roll/pitch rate setpoint (bounds the rates action)"),
    param!(real yaw_rate_max, "rad/s", 0.01, 30.0, "Largest yaw rate setpoint (bounds the rates action)"),
    param!(real gyro_cutoff, "Hz", 0.0, 1000.0, "Gyro low-pass cutoff (IMU_GYRO_CUTOFF; 0 = off)"),
    param!(real gyro_derivative_cutoff, "Hz", 0.0, 1000.0, "Gyro derivative low-pass cutoff (IMU_DGYRO_CUTOFF; 0 = off)"),
    param!(real yaw_torque_cutoff, "Hz", 0.0, 1000.0, "Yaw torque low-pass cutoff (MC_YAW_TQ_CUTOFF; 0 = off)"),
    param!(real gyro_quantum, "rad/s", 0.0, 0.1, "Gyro sample step of PX4's simulator interface (0 = exact)"),
    param!(real output_quantum, "1", 0.0, 0.1, "Motor output step (PX4 PWM: 0.001; 0 = exact)"),
    param!(real thrust_model_factor, "1", 0.0, 1.0, "Thrust model factor (THR_MDL_FAC)"),
];

impl Parameters for RateLoopParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &RATE_LOOP_SPECS
    }
}
