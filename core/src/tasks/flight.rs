//! What the quadrotor tasks share: their common parameters (the seed's DroneEnv arguments),
//! start and target sampling, crash detection and the base observation (33 values on a quad,
//! 25 + 2 per rotor on any frame).

use crate::error::ParamError;
use crate::param;
use crate::params::{ParamSpec, Parameters};
use crate::quadrotor::contact::foot_heights;
use crate::quadrotor::{BodyState, QuadrotorParams};
use crate::rng::SimRng;
use crate::tasks::{InfoRef, InfoVisitor, clip_f32};
use crate::vehicle::AirVehicle;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Arguments of a quadrotor flight task (seed 001's DroneEnv, docs/reference/quadrotor.md). Wind
/// settings (`use_wind`, `wind_strength_range`) are the model's `wind_enabled` / `wind_speed_min` /
/// `wind_speed_max`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FlightParams {
    /// Control period, s. Default 0.01 (100 Hz).
    pub dt: f64,
    /// Steps after which the episode is truncated. Default 1000.
    pub max_steps: u32,
    /// Steps between new targets; 0 = the target stays for the episode. Default 0.
    pub target_change_interval: u32,
    /// Side of the cube targets are drawn in: x, y in ±side/2, z in [0, side], m. Default 3.
    pub space_side_length: f64,
    /// Start height, m. Default 1.5.
    pub start_height: f64,
    /// Start roll, pitch and yaw are each uniform in ±this, rad. Default 0.1.
    pub start_attitude_range: f64,
    /// A new target is at least this far from the vehicle, m. Default 1.0.
    pub min_target_distance: f64,
    /// Speed scale of the velocity reward tanh(v·d̂ / scale), m/s. Default 3.
    pub velocity_scale: f64,
    /// End the episode on a crash. Default true.
    pub enable_crash_detection: bool,
    /// End the episode when too far from the target. Default true.
    pub enable_out_of_bounds_detection: bool,
    /// Crash when the vertical velocity is below this, m/s. Default −20.
    pub crash_z_vel_threshold: f64,
    /// Crash when |roll| or |pitch| exceeds this, degrees. Default 80.
    pub crash_tilt_threshold: f64,
    /// Actions are collective thrust + body rates flown through PX4's rate loop
    /// ([`crate::rate_loop`]) instead of motor commands; the observation is then the
    /// estimator's view (see [`crate::tasks::flight_vehicle`]). Default false.
    pub rates_action: bool,
    /// Rates interface: time from an action to the rate loop using it, s. Default 0.
    pub action_latency: f64,
    /// Rates interface: standard deviation of the observed position's noise, m. Default 0.
    pub obs_noise_position: f64,
    /// Rates interface: standard deviation of the observed velocity's noise, m/s. Default 0.
    pub obs_noise_velocity: f64,
    /// Rates interface: standard deviation of the observed roll, pitch and yaw noise, rad.
    /// Default 0.
    pub obs_noise_attitude: f64,
    /// Rates interface: standard deviation of the observed body rates' noise, rad/s. Default 0.
    pub obs_noise_rates: f64,
}

impl Default for FlightParams {
    fn default() -> Self {
        FlightParams {
            dt: 0.01,
            max_steps: 1000,
            target_change_interval: 0,
            space_side_length: 3.0,
            start_height: 1.5,
            start_attitude_range: 0.1,
            min_target_distance: 1.0,
            velocity_scale: 3.0,
            enable_crash_detection: true,
            enable_out_of_bounds_detection: true,
            crash_z_vel_threshold: -20.0,
            crash_tilt_threshold: 80.0,
            rates_action: false,
            action_latency: 0.0,
            obs_noise_position: 0.0,
            obs_noise_velocity: 0.0,
            obs_noise_attitude: 0.0,
            obs_noise_rates: 0.0,
        }
    }
}

static FLIGHT_SPECS: [ParamSpec<FlightParams>; 18] = [
    param!(real dt, "s", 1e-4, 1.0, "Control period"),
    param!(integer max_steps, "", 1, 100_000_000, "Steps after which the episode is truncated"),
    param!(integer target_change_interval, "", 0, 100_000_000, "Steps between new targets (0 = never)"),
    param!(real space_side_length, "m", 0.1, 1e4, "Side of the cube targets are drawn in"),
    param!(real start_height, "m", 0.0, 1e4, "Start height"),
    param!(real start_attitude_range, "rad", 0.0, 1.0, "Start roll/pitch/yaw uniform in +-this"),
    param!(real min_target_distance, "m", 0.0, 1e4, "Minimum distance of a new target from the vehicle"),
    param!(real velocity_scale, "m/s", 1e-3, 1e3, "Speed scale of the velocity reward"),
    param!(boolean enable_crash_detection, "End the episode on a crash"),
    param!(boolean enable_out_of_bounds_detection, "End the episode when too far from the target"),
    param!(real crash_z_vel_threshold, "m/s", -1e3, 0.0, "Crash below this vertical velocity"),
    param!(real crash_tilt_threshold, "deg", 0.0, 180.0, "Crash beyond this |roll| or |pitch|"),
    param!(boolean rates_action, "Actions are thrust + body rates through PX4's rate loop (else motor commands)"),
    param!(real action_latency, "s", 0.0, 1.0, "Rates interface: delay from an action to the rate loop"),
    param!(real obs_noise_position, "m", 0.0, 100.0, "Rates interface: observed position noise (std)"),
    param!(real obs_noise_velocity, "m/s", 0.0, 100.0, "Rates interface: observed velocity noise (std)"),
    param!(real obs_noise_attitude, "rad", 0.0, 1.0, "Rates interface: observed roll/pitch/yaw noise (std)"),
    param!(real obs_noise_rates, "rad/s", 0.0, 100.0, "Rates interface: observed body rate noise (std)"),
];

impl FlightParams {
    /// An episode's length at the time limit, `max_steps · dt`, s.
    pub fn episode_duration(&self) -> f64 {
        f64::from(self.max_steps) * self.dt
    }
}

impl Parameters for FlightParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &FLIGHT_SPECS
    }

    fn check_relations(&self) -> Result<(), ParamError> {
        // A target must be drawable: the farthest point of the cube from the start is at
        // least as far as the minimum distance.
        let half = self.space_side_length / 2.0;
        let farthest = (2.0 * half * half
            + (self.space_side_length - self.start_height)
                .abs()
                .max(self.start_height)
                .powi(2))
        .sqrt();
        if self.min_target_distance > farthest {
            return Err(ParamError::Relation {
                name: "min_target_distance",
                requirement: format!(
                    "min_target_distance ({}) must not exceed the farthest point of the target cube from the start ({farthest:.3} m)",
                    self.min_target_distance
                ),
            });
        }
        Ok(())
    }
}

/// The base observation's groups (motor interface): (name, number of values), in order, for a
/// frame of `rotors` rotors (the two motor groups have one value per rotor).
pub fn base_observation(rotors: usize) -> [(&'static str, usize); 10] {
    [
        ("target_offset", 3), // target − position, world ENU
        ("velocity", 3),
        ("acceleration", 3),
        ("quaternion", 4),
        ("body_rates", 3),
        ("angular_acceleration", 3),
        ("body_z_axis", 3),
        ("wind", 3),
        ("motor_states", rotors),
        ("motor_commands", rotors),
    ]
}

/// Draws the start state: (0, 0, start_height), roll/pitch/yaw uniform in ±range, at rest,
/// motors at `hover` (the vehicle's hover state, 0 if it cannot hover).
pub fn sample_start(task: &FlightParams, hover: f64, rng: &mut SimRng) -> BodyState {
    let r = task.start_attitude_range;
    let roll = rng.uniform(-r, r);
    let pitch = rng.uniform(-r, r);
    let yaw = rng.uniform(-r, r);
    BodyState::at_rest(
        Vector3::new(0.0, 0.0, task.start_height),
        roll,
        pitch,
        yaw,
        hover,
    )
}

/// Draws a target in the cube (x, y ∈ ±side/2, z ∈ [0, side]) at least `min_target_distance`
/// from `from`, by rejection. After 1000 rejections the last draw is taken (parameters that
/// make that likely are refused by validation).
pub fn sample_target(task: &FlightParams, from: &Vector3<f64>, rng: &mut SimRng) -> Vector3<f64> {
    let half = task.space_side_length / 2.0;
    let mut target = *from;
    for _ in 0..1000 {
        target = Vector3::new(
            rng.uniform(-half, half),
            rng.uniform(-half, half),
            rng.uniform(0.0, task.space_side_length),
        );
        if (target - from).norm() >= task.min_target_distance {
            break;
        }
    }
    target
}

/// The seed's crash test: on or below the ground (the centre of mass or, since the vehicle
/// stands on landing gear, any foot), falling faster than the threshold, or tilted beyond
/// the threshold in roll or pitch.
pub fn is_crashed(task: &FlightParams, model: &QuadrotorParams, body: &BodyState) -> bool {
    let (roll, pitch, _) = body.euler_angles();
    let tilt = task.crash_tilt_threshold.to_radians();
    body.position.z <= 0.0
        || foot_heights(model, body).iter().any(|&h| h <= 0.0)
        || body.velocity.z < task.crash_z_vel_threshold
        || roll.abs() > tilt
        || pitch.abs() > tilt
}

/// Distance to `target` and the unit direction toward it (zero when on it).
pub fn distance_and_direction(body: &BodyState, target: &Vector3<f64>) -> (f64, Vector3<f64>) {
    let offset = target - body.position;
    let d = offset.norm();
    (d, offset / (d + 1e-8))
}

/// Closing speed toward `target` scaled by tanh: in (−1, 1).
pub fn velocity_reward(task: &FlightParams, body: &BodyState, target: &Vector3<f64>) -> f64 {
    let (_, direction) = distance_and_direction(body, target);
    (body.velocity.dot(&direction) / task.velocity_scale).tanh()
}

/// Bound of the wind observation: the largest mean wind plus five stationary standard
/// deviations of the turbulence (at least 1 m/s so the space never collapses).
pub fn wind_bound(model: &QuadrotorParams) -> f64 {
    if !model.wind_enabled {
        return 1.0;
    }
    let stationary_std = model.turbulence_sigma / (2.0 * model.turbulence_theta.max(0.05)).sqrt();
    (model.wind_speed_max + 5.0 * stationary_std).max(1.0)
}

/// Per-value bounds of the base observation of a frame of `rotors` rotors; `position_bound`
/// bounds target − position.
pub fn base_bounds(
    model: &QuadrotorParams,
    rotors: usize,
    position_bound: f64,
) -> (Vec<f32>, Vec<f32>) {
    let wind = wind_bound(model);
    // In the base observation's order.
    let bounds: [(f64, f64); 10] = [
        (-position_bound, position_bound),
        (-40.0, 40.0),
        (-50.0, 50.0),
        (-1.0, 1.0),
        (-10.0, 10.0),
        (-100.0, 100.0),
        (-1.0, 1.0),
        (-wind, wind),
        (0.0, 1.0),
        (0.0, 1.0),
    ];
    let mut lo = Vec::with_capacity(25 + 2 * rotors);
    let mut hi = Vec::with_capacity(25 + 2 * rotors);
    for ((_, n), (l, h)) in base_observation(rotors).into_iter().zip(bounds) {
        lo.extend(std::iter::repeat_n(l as f32, n));
        hi.extend(std::iter::repeat_n(h as f32, n));
    }
    (lo, hi)
}

/// Writes the base values (25 + 2 per rotor) into `out`, each clipped into `lo..=hi`.
pub fn write_base_observation(
    quad: &dyn AirVehicle,
    target: &Vector3<f64>,
    lo: &[f32],
    hi: &[f32],
    out: &mut [f32],
) {
    let b = quad.body();
    let (acceleration, angular_acceleration) = quad.accelerations();
    // q and −q are the same attitude: report the hemisphere w >= 0.
    let q = if b.attitude.w < 0.0 {
        -b.attitude
    } else {
        b.attitude
    };
    let relative = target - b.position;
    let quaternion = [q.w, q.i, q.j, q.k];
    let normal = b.body_z_axis();
    let wind = quad.wind_velocity();
    let command = quad.motor_command();
    let groups: [&[f64]; 10] = [
        relative.as_slice(),
        b.velocity.as_slice(),
        acceleration.as_slice(),
        &quaternion,
        b.body_rates.as_slice(),
        angular_acceleration.as_slice(),
        normal.as_slice(),
        wind.as_slice(),
        &b.motors,
        &command,
    ];
    let values = groups.iter().flat_map(|g| g.iter());
    for (i, &v) in values.enumerate() {
        out[i] = clip_f32(v, lo[i], hi[i]);
    }
}

/// Episode bookkeeping shared by the flight tasks.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct FlightStatus {
    pub step_count: u32,
    /// Distance to the target when it was set (for `distance_progress`), m.
    pub initial_distance: f64,
    pub crashed: bool,
    pub out_of_bounds: bool,
}

/// The info fields every flight task reports (seed 001's DroneEnv info, crash flags always),
/// for a flight towards `target`.
pub fn visit_flight_info(
    quad: &dyn AirVehicle,
    target: &Vector3<f64>,
    status: &FlightStatus,
    dt: f64,
    visit: &mut InfoVisitor<'_>,
) {
    let position = quad.body().position;
    let d = (target - position).norm();
    visit("distance_to_target", InfoRef::Real(d));
    visit("position", InfoRef::Vector(position.as_slice()));
    visit("target_position", InfoRef::Vector(target.as_slice()));
    visit("step_count", InfoRef::Integer(i64::from(status.step_count)));
    visit(
        "episode_time",
        InfoRef::Real(f64::from(status.step_count) * dt),
    );
    visit(
        "distance_progress",
        InfoRef::Real(status.initial_distance - d),
    );
    visit("crashed", InfoRef::Flag(status.crashed));
    visit("out_of_bounds", InfoRef::Flag(status.out_of_bounds));
}
