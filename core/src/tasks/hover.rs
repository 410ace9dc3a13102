//! Hover: fly to a target and hold it (seed 001's DroneEnv), without the reference's bugs.
//!
//! Observation (33 × f32, world ENU / body FLU): [0:3] target − position (m), [3:6] velocity
//! (m/s), [6:9] acceleration = total force / mass (m/s²), [9:13] attitude quaternion w x y z
//! (w ≥ 0), [13:16] body rates (rad/s), [16:19] angular acceleration (rad/s²), [19:22] body z
//! axis in the world, [22:25] wind (m/s), [25:29] motor states, [29:33] motor commands. Each
//! value is clipped to its declared bound (position ±√3·side, i.e. the out-of-bounds radius).
//!
//! Reward: d = ‖target − p‖, r_pos = e^(−d), r_vel = tanh(v·d̂ / velocity_scale),
//! r = r_pos + ½ (1 − r_pos) r_vel. Terminated on a crash or out of bounds (d > √3·side);
//! truncated when step_count ≥ max_steps. A new target every `target_change_interval` steps
//! appears after the step's reward, in the observation that step returns.

use super::flight::{
    BASE_OBSERVATION_SIZE, FlightParams, FlightStatus, apply_action, base_bounds,
    distance_and_direction, flight_info, is_crashed, sample_start, sample_target, velocity_reward,
    write_base_observation,
};
use super::{Info, StepOutcome, Task};
use crate::error::ParamError;
use crate::params::Parameters;
use crate::quadrotor::{BodyState, Quadrotor, QuadrotorParams};
use crate::rng::SimRng;
use crate::tasks::ActionError;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The Hover task. Plain data: clone it to snapshot an episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hover {
    params: FlightParams,
    quad: Quadrotor,
    target: Vector3<f64>,
    status: FlightStatus,
    obs_low: Vec<f32>,
    obs_high: Vec<f32>,
}

impl Hover {
    /// A Hover task, reset with seed 0. Both parameter sets are validated.
    pub fn new(model: QuadrotorParams, params: FlightParams) -> Result<Self, ParamError> {
        params.validate()?;
        model.validate()?;
        let (lo, hi) = base_bounds(&model, out_of_bounds_distance(&params));
        let body = BodyState::at_rest(Vector3::zeros(), 0.0, 0.0, 0.0, 0.0);
        let quad = Quadrotor::new(model, body, SimRng::new(0))?;
        let mut hover = Hover {
            params,
            quad,
            target: Vector3::zeros(),
            status: FlightStatus::default(),
            obs_low: lo.to_vec(),
            obs_high: hi.to_vec(),
        };
        hover.reset(0);
        Ok(hover)
    }

    pub fn params(&self) -> &FlightParams {
        &self.params
    }

    pub fn quadrotor(&self) -> &Quadrotor {
        &self.quad
    }

    /// Mutable access for tests and front ends that place the vehicle by hand.
    pub fn quadrotor_mut(&mut self) -> &mut Quadrotor {
        &mut self.quad
    }

    pub fn target(&self) -> Vector3<f64> {
        self.target
    }

    /// Moves the target (e.g. a user-chosen hover point); distance progress restarts from here.
    pub fn set_target(&mut self, target: Vector3<f64>) {
        self.target = target;
        self.status.initial_distance = (target - self.quad.body.position).norm();
    }

    pub fn step_count(&self) -> u32 {
        self.status.step_count
    }
}

/// Out-of-bounds radius around the target: √3 · side (the cube's diagonal).
pub fn out_of_bounds_distance(params: &FlightParams) -> f64 {
    3f64.sqrt() * params.space_side_length
}

/// The Hover reward at `body` for `target` (see the module docs).
pub fn hover_reward(params: &FlightParams, body: &BodyState, target: &Vector3<f64>) -> f64 {
    let (d, _) = distance_and_direction(body, target);
    let r_pos = (-d).exp();
    r_pos + 0.5 * (1.0 - r_pos) * velocity_reward(params, body, target)
}

impl Task for Hover {
    fn action_size(&self) -> usize {
        4
    }

    fn action_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![0.0; 4], vec![1.0; 4])
    }

    fn observation_size(&self) -> usize {
        BASE_OBSERVATION_SIZE
    }

    fn observation_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        (self.obs_low.clone(), self.obs_high.clone())
    }

    fn reset(&mut self, seed: u64) {
        let mut rng = SimRng::new(seed);
        let body = sample_start(&self.params, &self.quad.params, &mut rng);
        let target = sample_target(&self.params, &body.position, &mut rng);
        self.quad.restart(body, rng);
        self.status = FlightStatus::default();
        self.set_target(target);
    }

    fn step(&mut self, action: &[f64]) -> Result<StepOutcome, ActionError> {
        apply_action(&mut self.quad, action, self.params.dt)?;
        self.status.step_count += 1;

        let body = &self.quad.body;
        let reward = hover_reward(&self.params, body, &self.target);
        let status = &mut self.status;
        status.crashed =
            self.params.enable_crash_detection && is_crashed(&self.params, &self.quad.params, body);
        status.out_of_bounds = self.params.enable_out_of_bounds_detection
            && (self.target - body.position).norm() > out_of_bounds_distance(&self.params);
        let terminated = status.crashed || status.out_of_bounds;
        let truncated = status.step_count >= self.params.max_steps;

        let interval = self.params.target_change_interval;
        if interval > 0 && status.step_count % interval == 0 {
            let from = self.quad.body.position;
            let target = sample_target(&self.params, &from, self.quad.rng_mut());
            self.set_target(target);
        }
        Ok(StepOutcome {
            reward,
            terminated,
            truncated,
        })
    }

    fn write_observation(&self, out: &mut [f32]) {
        write_base_observation(&self.quad, &self.target, &self.obs_low, &self.obs_high, out);
    }

    fn info(&self) -> Info {
        flight_info(&self.quad, &self.target, &self.status, self.params.dt)
    }

    fn dt(&self) -> f64 {
        self.params.dt
    }
}
