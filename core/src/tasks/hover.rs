//! Hover: fly to a target and hold it (seed 001's DroneEnv), without the reference's bugs
//! (docs/reference/quadrotor.md).
//!
//! Observation (33 × f32, world ENU / body FLU): [0:3] target − position (m), [3:6] velocity
//! (m/s), [6:9] acceleration = total force / mass (m/s²), [9:13] attitude quaternion w x y z
//! (w ≥ 0), [13:16] body rates (rad/s), [16:19] angular acceleration (rad/s²), [19:22] body z
//! axis in the world, [22:25] wind (m/s), [25:29] motor states, [29:33] motor commands. Each
//! value is clipped to its declared bound (position ±√3·side, i.e. the out-of-bounds radius).
//!
//! On the rates interface (`rates_action`) the action is thrust + body rates through PX4's
//! rate loop and the observation is the estimator's 16 values ([`super::flight_vehicle`]).
//!
//! Reward: d = ‖target − p‖, r_pos = e^(−d), r_vel = tanh(v·d̂ / velocity_scale),
//! r = r_pos + ½ (1 − r_pos) r_vel. Terminated on a crash or out of bounds (d > √3·side);
//! truncated when step_count ≥ max_steps. A new target every `target_change_interval` steps
//! appears after the step's reward, in the observation that step returns.

use super::flight::{
    FlightParams, FlightStatus, distance_and_direction, is_crashed, sample_start, sample_target,
    velocity_reward, visit_flight_info,
};
use super::flight_vehicle::FlightVehicle;
use super::randomization::{Randomization, VehicleParams};
use super::{InfoVisitor, StepOutcome, Task};
use crate::error::ParamError;
use crate::quadrotor::{BodyState, QuadrotorParams};
use crate::rng::SimRng;
use crate::tasks::ActionError;
use crate::vehicle::AirVehicle;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The Hover task. Plain data: clone it to snapshot an episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hover {
    params: FlightParams,
    vehicle: FlightVehicle,
    target: Vector3<f64>,
    status: FlightStatus,
    obs_low: Vec<f32>,
    obs_high: Vec<f32>,
}

impl Hover {
    /// A Hover task on the motor or rates interface (as `params.rates_action` says) with
    /// PX4's default rate loop and no randomisation, reset with seed 0.
    pub fn new(model: QuadrotorParams, params: FlightParams) -> Result<Self, ParamError> {
        let nominal = VehicleParams {
            quadrotor: model,
            flight: params,
            ..VehicleParams::default()
        };
        Hover::with_vehicle(nominal, Randomization::none())
    }

    /// A Hover task on the vehicle `nominal` describes (its `flight` set is the task's),
    /// randomised per episode by `randomization`, reset with seed 0. Every set is validated.
    pub fn with_vehicle(
        nominal: VehicleParams,
        randomization: Randomization,
    ) -> Result<Self, ParamError> {
        let params = nominal.flight.clone();
        let bound = out_of_bounds_distance(&params);
        let vehicle = FlightVehicle::new(nominal, randomization)?;
        let (obs_low, obs_high) = vehicle.observation_bounds(bound);
        let mut hover = Hover {
            params,
            vehicle,
            target: Vector3::zeros(),
            status: FlightStatus::default(),
            obs_low,
            obs_high,
        };
        hover.reset(0);
        Ok(hover)
    }

    pub fn params(&self) -> &FlightParams {
        &self.params
    }

    /// The vehicle flown (through the seam, [`AirVehicle`]).
    pub fn air_vehicle(&self) -> &dyn AirVehicle {
        self.vehicle.air_vehicle()
    }

    /// Mutable access for tests and front ends that place the vehicle by hand.
    pub fn air_vehicle_mut(&mut self) -> &mut dyn AirVehicle {
        self.vehicle.air_vehicle_mut()
    }

    pub fn vehicle(&self) -> &FlightVehicle {
        &self.vehicle
    }

    /// The vehicle, for run-time fault injection.
    pub fn vehicle_mut(&mut self) -> &mut FlightVehicle {
        &mut self.vehicle
    }

    pub fn target(&self) -> Vector3<f64> {
        self.target
    }

    /// Moves the target (e.g. a user-chosen hover point); distance progress restarts from here.
    pub fn set_target(&mut self, target: Vector3<f64>) {
        self.target = target;
        self.status.initial_distance = (target - self.air_vehicle().body().position).norm();
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
        self.vehicle.action_size()
    }

    fn action_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        self.vehicle.action_bounds()
    }

    fn observation_size(&self) -> usize {
        self.obs_low.len()
    }

    fn observation_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        (self.obs_low.clone(), self.obs_high.clone())
    }

    fn observation_layout(&self) -> Vec<(&'static str, usize)> {
        self.vehicle.observation_layout()
    }

    fn reset(&mut self, seed: u64) {
        let mut rng = SimRng::new(seed);
        let hover = self.vehicle.draw(seed);
        let body = sample_start(&self.params, hover, &mut rng);
        let target = sample_target(&self.params, &body.position, &mut rng);
        self.vehicle.restart(body, rng, seed);
        self.status = FlightStatus::default();
        self.set_target(target);
    }

    fn step(&mut self, action: &[f64]) -> Result<StepOutcome, ActionError> {
        self.vehicle.apply(action, self.params.dt)?;
        self.status.step_count += 1;

        let quad = self.vehicle.air_vehicle();
        let body = quad.body();
        let reward = hover_reward(&self.params, body, &self.target);
        let status = &mut self.status;
        status.crashed =
            self.params.enable_crash_detection && is_crashed(&self.params, quad.params(), body);
        status.out_of_bounds = self.params.enable_out_of_bounds_detection
            && (self.target - body.position).norm() > out_of_bounds_distance(&self.params);
        let terminated = status.crashed || status.out_of_bounds;
        let truncated = status.step_count >= self.params.max_steps;

        let interval = self.params.target_change_interval;
        if interval > 0 && status.step_count % interval == 0 {
            let from = self.air_vehicle().body().position;
            let rng = self.vehicle.air_vehicle_mut().rng_mut();
            let target = sample_target(&self.params, &from, rng);
            self.set_target(target);
        }
        Ok(StepOutcome {
            reward,
            terminated,
            truncated,
        })
    }

    fn write_observation(&self, out: &mut [f32]) {
        self.vehicle
            .write_observation(&self.target, &self.obs_low, &self.obs_high, out);
    }

    fn visit_info(&self, visit: &mut InfoVisitor<'_>) {
        let (quad, dt) = (self.air_vehicle(), self.params.dt);
        visit_flight_info(quad, &self.target, &self.status, dt, visit);
        self.vehicle.visit_info(visit);
    }

    fn dt(&self) -> f64 {
        self.params.dt
    }
}
