//! Waypoints: fly through a sequence of waypoints as fast as possible (seed 001's
//! SequentialWaypointEnv, docs/reference/quadrotor.md), paying the checkpoint bonus the reference
//! never paid.
//!
//! Observation (37 × f32 on the motor interface, 20 on the rates interface): the vehicle's
//! observation with the current waypoint as target ([`super::flight_vehicle`]), then
//! next waypoint − position (m, in the same frame) and seconds since the last checkpoint.
//!
//! Reward on the step that comes within `waypoint_reach_threshold` of the current waypoint:
//! max(checkpoint_bonus − bonus_decay_rate · t_since_checkpoint, 1); otherwise
//! tanh(v·d̂ / velocity_scale). A positive reward gets + ½ · mean(motor states).
//! Terminated on a crash or beyond 2·√3·side from the current waypoint; truncated at
//! max_steps or when every waypoint is reached.

use super::flight::{
    FlightParams, FlightStatus, distance_and_direction, is_crashed, sample_start, sample_target,
    velocity_reward, visit_flight_info,
};
use super::flight_vehicle::FlightVehicle;
use super::randomization::{Randomization, VehicleParams};
use super::{ActionError, InfoRef, InfoVisitor, StepOutcome, Task, clip_f32};
use crate::error::ParamError;
use crate::param;
use crate::params::{ParamSpec, Parameters};
use crate::quadrotor::QuadrotorParams;
use crate::rng::SimRng;
use crate::vehicle::AirVehicle;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Arguments specific to the waypoint task (the flight arguments come in [`FlightParams`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct WaypointParams {
    /// Waypoints per episode. Default 15.
    pub max_num_waypoints: u32,
    /// A waypoint is reached within this distance, m. Default 0.1.
    pub waypoint_reach_threshold_m: f64,
    /// Reward for reaching a waypoint at once. Default 10.
    pub checkpoint_bonus: f64,
    /// Bonus lost per second since the last checkpoint, 1/s. Default 2.
    pub bonus_decay_rate_per_sec: f64,
}

impl Default for WaypointParams {
    fn default() -> Self {
        WaypointParams {
            max_num_waypoints: 15,
            waypoint_reach_threshold_m: 0.1,
            checkpoint_bonus: 10.0,
            bonus_decay_rate_per_sec: 2.0,
        }
    }
}

static WAYPOINT_SPECS: [ParamSpec<WaypointParams>; 4] = [
    param!(integer max_num_waypoints, "", 1, 10_000, "Waypoints per episode"),
    param!(real waypoint_reach_threshold_m, "m", 1e-3, 1e3, "Distance at which a waypoint counts as reached"),
    param!(real checkpoint_bonus, "", 0.0, 1e6, "Reward for reaching a waypoint at once"),
    param!(real bonus_decay_rate_per_sec, "1/s", 0.0, 1e6, "Bonus lost per second since the last checkpoint"),
];

impl Parameters for WaypointParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &WAYPOINT_SPECS
    }
}

/// Number of observation values the task adds to its vehicle's.
pub const WAYPOINT_EXTRA_SIZE: usize = 4;

/// The Waypoints task. Plain data: clone it to snapshot an episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Waypoints {
    flight: FlightParams,
    params: WaypointParams,
    vehicle: FlightVehicle,
    waypoints: Vec<Vector3<f64>>,
    current: usize,
    reached: u32,
    /// Steps since the last checkpoint (time = steps · dt, never summed).
    steps_since_checkpoint: u32,
    status: FlightStatus,
    obs_low: Vec<f32>,
    obs_high: Vec<f32>,
}

/// Out-of-bounds radius around the current waypoint: 2·√3·side.
pub fn waypoint_out_of_bounds_distance(flight: &FlightParams) -> f64 {
    2.0 * 3f64.sqrt() * flight.space_side_length
}

impl Waypoints {
    /// A Waypoints task on the motor or rates interface (as `flight.rates_action` says) with
    /// PX4's default rate loop and no randomisation, reset with seed 0.
    pub fn new(
        model: QuadrotorParams,
        flight: FlightParams,
        params: WaypointParams,
    ) -> Result<Self, ParamError> {
        let nominal = VehicleParams {
            quadrotor: model,
            flight,
            ..VehicleParams::default()
        };
        Waypoints::with_vehicle(nominal, params, Randomization::none())
    }

    /// A Waypoints task on the vehicle `nominal` describes (its `flight` set is the
    /// task's), randomised per episode by `randomization`, reset with seed 0. Every set is
    /// validated.
    pub fn with_vehicle(
        nominal: VehicleParams,
        params: WaypointParams,
        randomization: Randomization,
    ) -> Result<Self, ParamError> {
        params.validate()?;
        let flight = nominal.flight.clone();
        let vehicle = FlightVehicle::new(nominal, randomization)?;
        let bound = waypoint_out_of_bounds_distance(&flight);
        let (mut obs_low, mut obs_high) = vehicle.observation_bounds(bound);
        let max_time = flight.episode_duration();
        obs_low.extend([-bound as f32; 3]);
        obs_high.extend([bound as f32; 3]);
        obs_low.push(0.0);
        obs_high.push(max_time as f32);
        let mut task = Waypoints {
            flight,
            params,
            vehicle,
            waypoints: Vec::new(),
            current: 0,
            reached: 0,
            steps_since_checkpoint: 0,
            status: FlightStatus::default(),
            obs_low,
            obs_high,
        };
        task.reset(0);
        Ok(task)
    }

    /// The vehicle flown (through the seam, [`AirVehicle`]).
    pub fn air_vehicle(&self) -> &dyn AirVehicle {
        self.vehicle.air_vehicle()
    }

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

    /// The episode's waypoints, in order.
    pub fn waypoints(&self) -> &[Vector3<f64>] {
        &self.waypoints
    }

    pub fn waypoints_reached(&self) -> u32 {
        self.reached
    }

    /// The waypoint being flown to (the last one once all are reached).
    pub fn current_waypoint(&self) -> Vector3<f64> {
        self.waypoints[self.current.min(self.waypoints.len() - 1)]
    }

    /// The waypoint after the current one (the current one if it is the last).
    pub fn next_waypoint(&self) -> Vector3<f64> {
        self.waypoints[(self.current + 1).min(self.waypoints.len() - 1)]
    }

    /// Seconds since the last checkpoint (or the start).
    pub fn time_since_checkpoint(&self) -> f64 {
        f64::from(self.steps_since_checkpoint) * self.flight.dt
    }
}

impl Task for Waypoints {
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
        let mut layout = self.vehicle.observation_layout();
        layout.extend([("next_waypoint_offset", 3), ("time_since_checkpoint", 1)]);
        layout
    }

    fn reset(&mut self, seed: u64) {
        let mut rng = SimRng::new(seed);
        let hover = self.vehicle.draw(seed);
        let body = sample_start(&self.flight, hover, &mut rng);
        let mut from = body.position;
        self.waypoints.clear();
        for _ in 0..self.params.max_num_waypoints {
            from = sample_target(&self.flight, &from, &mut rng);
            self.waypoints.push(from);
        }
        if let Some(faults) = self.vehicle.faults_mut() {
            faults.set_waypoint(0);
        }
        self.vehicle.restart(body, rng, seed);
        self.current = 0;
        self.reached = 0;
        self.steps_since_checkpoint = 0;
        self.status = FlightStatus {
            initial_distance: (self.current_waypoint() - self.air_vehicle().body().position).norm(),
            ..FlightStatus::default()
        };
    }

    fn step(&mut self, action: &[f64]) -> Result<StepOutcome, ActionError> {
        if let Some(faults) = self.vehicle.faults_mut() {
            faults.set_waypoint(self.current as u32);
        }
        self.vehicle.apply(action, self.flight.dt)?;
        self.status.step_count += 1;
        self.steps_since_checkpoint += 1;

        let waypoint = self.current_waypoint();
        let (d, _) = distance_and_direction(self.air_vehicle().body(), &waypoint);
        let all_reached = self.reached >= self.params.max_num_waypoints;
        let mut reward = if d < self.params.waypoint_reach_threshold_m && !all_reached {
            let bonus = self.params.checkpoint_bonus
                - self.params.bonus_decay_rate_per_sec * self.time_since_checkpoint();
            self.reached += 1;
            self.current += 1;
            self.steps_since_checkpoint = 0;
            self.status.initial_distance =
                (self.current_waypoint() - self.air_vehicle().body().position).norm();
            bonus.max(1.0)
        } else {
            velocity_reward(&self.flight, self.air_vehicle().body(), &waypoint)
        };
        if reward > 0.0 {
            let mean_motor = self.air_vehicle().body().motors.iter().sum::<f64>() / 4.0;
            reward += 0.5 * mean_motor;
        }

        let d_now = (self.current_waypoint() - self.air_vehicle().body().position).norm();
        let quad = self.vehicle.air_vehicle();
        let status = &mut self.status;
        status.crashed = self.flight.enable_crash_detection
            && is_crashed(&self.flight, quad.params(), quad.body());
        status.out_of_bounds = self.flight.enable_out_of_bounds_detection
            && d_now > waypoint_out_of_bounds_distance(&self.flight);
        let truncated = status.step_count >= self.flight.max_steps
            || self.reached >= self.params.max_num_waypoints;
        Ok(StepOutcome {
            reward,
            terminated: status.crashed || status.out_of_bounds,
            truncated,
        })
    }

    fn write_observation(&self, out: &mut [f32]) {
        let current = self.current_waypoint();
        self.vehicle
            .write_observation(&current, &self.obs_low, &self.obs_high, out);
        let base = self.vehicle.observation_size();
        let next = self.vehicle.observed_offset(&self.next_waypoint());
        for i in 0..3 {
            let k = base + i;
            out[k] = clip_f32(next[i], self.obs_low[k], self.obs_high[k]);
        }
        let k = base + 3;
        out[k] = clip_f32(
            self.time_since_checkpoint(),
            self.obs_low[k],
            self.obs_high[k],
        );
    }

    fn visit_info(&self, visit: &mut InfoVisitor<'_>) {
        let current = self.current_waypoint();
        let (quad, dt) = (self.air_vehicle(), self.flight.dt);
        visit_flight_info(quad, &current, &self.status, dt, visit);
        visit(
            "waypoints_reached",
            InfoRef::Integer(i64::from(self.reached)),
        );
        visit("current_waypoint_pos", InfoRef::Vector(current.as_slice()));
        let next = self.next_waypoint();
        visit("next_waypoint_pos", InfoRef::Vector(next.as_slice()));
        visit(
            "steps_since_checkpoint",
            InfoRef::Real(self.time_since_checkpoint()),
        );
        self.vehicle.visit_info(visit);
    }

    fn dt(&self) -> f64 {
        self.flight.dt
    }
}
