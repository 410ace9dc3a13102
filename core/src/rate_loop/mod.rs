//! PX4's multicopter inner loop as a model: what PX4 does between a body-rate + thrust
//! setpoint (offboard `SET_ATTITUDE_TARGET`) and the motor outputs it sends the simulator.
//!
//! Each period (PX4 SITL: every 4 ms gyro sample) the gyro (body FRD, in the simulator
//! interface's steps) is low-pass filtered ([`filter`]) and its derivative filtered again for
//! the D term; the rate PID ([`rate_control`]) turns the rate error into a normalised torque,
//! whose yaw part is low-passed; the allocator ([`allocation`]) mixes torque and collective
//! thrust into four motor outputs in [0, 1] (in PWM steps), and every 5 ms reports what it
//! saturated to the PID's integrator. Defaults are PX4 v1.16.0's for airframe 10016 `none_iris`
//! ([`params`]). Pure and deterministic: no clock, no randomness of its own.

pub mod allocation;
pub mod filter;
pub mod params;
pub mod px4_rotors;
pub mod rate_control;

pub use params::RateLoopParams;
pub use px4_rotors::{Px4Rotor, px4_rotors};

use crate::error::ParamError;
use crate::params::Parameters;
use allocation::{Allocation, Outputs};
use filter::{LowPass1p, LowPass2p};
use nalgebra::Vector3;
use rate_control::{RateControl, RateGains, Saturation};
use serde::{Deserialize, Serialize};

/// What the policy (or PX4's offboard input) asks of the inner loop.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RatesSetpoint {
    /// Collective thrust in [0, 1], PX4's normalised thrust (all motors at `thrust` when no
    /// torque is asked for).
    pub thrust: f64,
    /// Body rates roll, pitch, yaw, body FRD, rad/s.
    pub rates: Vector3<f64>,
}

/// PX4's rate loop and allocator with their state (filters, integrator, saturation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateLoop {
    params: RateLoopParams,
    control: RateControl,
    allocation: Allocation,
    gyro_filter: [LowPass2p; 3],
    derivative_filter: [LowPass1p; 3],
    yaw_torque_filter: LowPass1p,
    /// The previous filtered gyro sample, for the derivative.
    previous_rate: Vector3<f64>,
    /// Time since the allocator last reported its saturation, s.
    since_status: f64,
}

/// PX4's allocator reports its saturation at most every 5 ms (every 2nd tick at 250 Hz).
const STATUS_INTERVAL: f64 = 0.005;

impl RateLoop {
    /// A rate loop from checked parameters mixing for `rotors` (PX4's `CA_ROTOR*` of the
    /// frame, [`px4_rotors`]), at rest (filters settled on zero rates).
    pub fn new(params: RateLoopParams, rotors: &[Px4Rotor]) -> Result<Self, ParamError> {
        params.validate()?;
        let allocation =
            Allocation::new(rotors, params.thrust_model_factor).ok_or_else(|| {
                ParamError::Relation {
                    name: "frame",
                    requirement: format!(
                        "PX4's allocator needs 4 to {} rotors with positive thrust that control roll, pitch, yaw and thrust independently; got {} rotors",
                        crate::quadrotor::frame::MAX_ROTORS,
                        rotors.len()
                    ),
                }
            })?;
        let p = &params;
        let k = Vector3::new(p.roll_rate_k, p.pitch_rate_k, p.yaw_rate_k);
        let gains = RateGains {
            p: k.component_mul(&Vector3::new(p.roll_rate_p, p.pitch_rate_p, p.yaw_rate_p)),
            i: k.component_mul(&Vector3::new(p.roll_rate_i, p.pitch_rate_i, p.yaw_rate_i)),
            d: k.component_mul(&Vector3::new(p.roll_rate_d, p.pitch_rate_d, p.yaw_rate_d)),
            ff: Vector3::new(p.roll_rate_ff, p.pitch_rate_ff, p.yaw_rate_ff),
            integrator_limit: Vector3::new(
                p.roll_rate_int_lim,
                p.pitch_rate_int_lim,
                p.yaw_rate_int_lim,
            ),
        };
        let dt = p.rate_loop_period;
        let mut rate_loop = RateLoop {
            control: RateControl::new(gains),
            allocation,
            gyro_filter: [LowPass2p::new(1.0 / dt, p.gyro_cutoff); 3],
            derivative_filter: [LowPass1p::new(dt, p.gyro_derivative_cutoff); 3],
            yaw_torque_filter: LowPass1p::new(dt, p.yaw_torque_cutoff),
            previous_rate: Vector3::zeros(),
            since_status: 0.0,
            params,
        };
        rate_loop.reset(&Vector3::zeros());
        Ok(rate_loop)
    }

    pub fn params(&self) -> &RateLoopParams {
        &self.params
    }

    /// The rate PID's integrator (normalised torque, body FRD).
    pub fn integrator(&self) -> Vector3<f64> {
        self.control.integrator()
    }

    /// Restarts the loop on a vehicle turning at `gyro` (body FRD, rad/s): filters settled
    /// there, derivative and yaw torque zero, integrator empty, nothing saturated.
    pub fn reset(&mut self, gyro: &Vector3<f64>) {
        let gyro = self.quantized(gyro);
        for i in 0..3 {
            self.gyro_filter[i].reset(gyro[i]);
            self.derivative_filter[i].reset(0.0);
        }
        self.yaw_torque_filter.reset(0.0);
        self.previous_rate = gyro;
        self.since_status = STATUS_INTERVAL;
        self.control.reset();
    }

    /// The gyro as PX4's simulator interface reads it: whole steps, truncated toward zero.
    fn quantized(&self, gyro: &Vector3<f64>) -> Vector3<f64> {
        let q = self.params.gyro_quantum;
        if q > 0.0 {
            gyro.map(|g| (g / q).trunc() * q)
        } else {
            *gyro
        }
    }

    /// One period: the gyro sample `gyro` (body FRD, rad/s) and the `setpoint` in effect give
    /// the motor outputs in [0, 1], one per rotor in the frame's motor order. `landed` freezes the integrator,
    /// as PX4's land detector does on the ground.
    pub fn step(&mut self, setpoint: &RatesSetpoint, gyro: &Vector3<f64>, landed: bool) -> Outputs {
        let dt = self.params.rate_loop_period;
        let gyro = self.quantized(gyro);
        let mut rate = Vector3::zeros();
        let mut accel = Vector3::zeros();
        for i in 0..3 {
            rate[i] = self.gyro_filter[i].apply(gyro[i]);
            // PX4 differentiates the filtered rate, then low-passes the derivative.
            accel[i] = self.derivative_filter[i].apply((rate[i] - self.previous_rate[i]) / dt);
        }
        self.previous_rate = rate;
        let mut torque = self
            .control
            .update(&rate, &setpoint.rates, &accel, dt, landed);
        torque.z = self.yaw_torque_filter.apply(torque.z);
        let out = self.allocation.allocate(&torque, setpoint.thrust);
        self.since_status += dt;
        if self.since_status >= STATUS_INTERVAL - 1e-9 {
            self.since_status = 0.0;
            self.control
                .set_saturation(saturation(&out.unallocated_torque));
        }
        let q = self.params.output_quantum;
        let mut motors = out.motors;
        if q > 0.0 {
            motors.iter_mut().for_each(|u| *u = (*u / q).round() * q);
        }
        motors
    }
}

/// PX4's saturation flags from the torque the allocator could not produce (none when the
/// whole torque was produced: |unallocated|² < 1e-6).
fn saturation(unallocated: &Vector3<f64>) -> Saturation {
    let mut s = Saturation::default();
    if unallocated.norm_squared() < 1e-6 {
        return s;
    }
    let eps = f64::from(f32::EPSILON);
    for i in 0..3 {
        s.positive[i] = unallocated[i] > eps;
        s.negative[i] = unallocated[i] < -eps;
    }
    s
}
