//! How a flight task's actions reach its vehicle, and what it observes of it: the action
//! interface, the per-episode randomisation and, on the rates interface, PX4's rate loop and
//! the estimator's view. The vehicle itself lives elsewhere — in a [`super::flight_vehicle::FlightVehicle`]
//! for a lone vehicle, in a [`crate::world::World`] for many — and is handed to every call.
//!
//! **Motor interface** (the default): the action is the motor commands in [0, 1], one per
//! rotor of the vehicle's frame in its motor order (four on the quad X, six on `hexa_x`).
//!
//! **Rates interface** (`rates_action`): the action is what a policy sends PX4 in offboard
//! mode — [collective thrust in [0, 1] (PX4's normalised thrust), roll, pitch, yaw rate in
//! rad/s, body FRD], bounded by the rate loop's `roll_pitch_rate_max` / `yaw_rate_max`. PX4's
//! rate loop ([`crate::rate_loop`]) runs on its own absolute grid of `rate_loop_period`
//! (ticks at k·period from the episode start), each tick reading the gyro (the true body
//! rates) and the setpoint in effect; an action takes effect `action_latency` after its
//! step starts; the motors hold their outputs between ticks. The rate loop assumes the
//! vehicle is flying (integrator on), as PX4's land detector says once airborne.
//!
//! The rates interface observes what an autopilot's estimator gives (16 × f32), in PX4's
//! frames turned by the vehicle's heading: the *heading frame* is world NED rotated by the
//! yaw, x forward and y right (both horizontal), z down. [0:3] target − position (m),
//! [3:6] velocity (m/s), [6:9] the body's down axis (FRD z) in the heading frame (tilt;
//! (0, 0, 1) when level), [9:12] body rates (rad/s, FRD), [12:16] the previous action as
//! applied (clipped). Optional Gaussian noise (`obs_noise_*`) is drawn from a generator of
//! the episode's own, so the same seed gives the same noise.

use super::flight::{FlightParams, base_bounds, base_observation, write_base_observation};
use super::flight_faults::FlightFaults;
use super::randomization::{Randomization, VehicleParams};
use crate::error::ParamError;
use crate::faults::FaultPlan;
use crate::frames::{attitude_ned, enu_to_ned, flu_to_frd};
use crate::params::Parameters;
use crate::quadrotor::{BodyState, multirotor_at};
use crate::rate_loop::{RateLoop, RatesSetpoint};
use crate::rng::SimRng;
use crate::tasks::{ActionError, InfoRef, InfoVisitor, check_action};
use crate::vehicle::AirVehicle;
use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Number of values in the rates interface's observation.
pub const ESTIMATE_OBSERVATION_SIZE: usize = 16;
/// The rates interface's observation groups, in order (see `write_observation`).
pub const ESTIMATE_OBSERVATION: [(&str, usize); 5] = [
    ("target_offset", 3),
    ("velocity", 3),
    ("down_axis", 3),
    ("body_rates", 3),
    ("last_action", 4),
];

/// Salt of the observation noise's generator (independent of the episode's own stream).
const NOISE_STREAM: u64 = 0x0b5e_7e57_1a7e_0002;
/// Times closer than this are the same instant on the rate loop's grid, s.
const TIME_TOLERANCE: f64 = 1e-9;

/// A flight vehicle's action interface and per-episode randomisation, without the vehicle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlightLink {
    nominal: VehicleParams,
    randomization: Randomization,
    /// The values drawn for this episode, in the ranges' order.
    drawn: Vec<f64>,
    /// The flight parameters in effect this episode (latency and noise may be drawn).
    flight: FlightParams,
    rates: Option<RatesLink>,
    /// The episode's faults (`None`: a healthy vehicle, stepped exactly as without faults).
    faults: Option<FlightFaults>,
}

/// The rates interface's state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct RatesLink {
    rate_loop: RateLoop,
    /// Setpoints not yet in effect, with the time they take effect (s since the start).
    pending: VecDeque<(f64, RatesSetpoint)>,
    current: RatesSetpoint,
    last_action: [f64; 4],
    /// Policy steps and rate-loop ticks done this episode.
    steps: u64,
    ticks: u64,
    noise: SimRng,
    /// The observed (noisy) position (ENU), velocity (NED), attitude (FRD → NED), rates (FRD).
    estimate: Estimate,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Estimate {
    position_ned: Vector3<f64>,
    velocity_ned: Vector3<f64>,
    /// Yaw of the estimated attitude (NED, from north toward east), rad.
    yaw: f64,
    /// The body's down axis in the heading frame.
    down_axis: Vector3<f64>,
    rates_frd: Vector3<f64>,
}

impl FlightLink {
    /// The interface from checked parameter sets, and the nominal vehicle (at rest at the
    /// origin) it flies; the randomisation's ranges are checked against them (both corners
    /// must be valid vehicles).
    pub fn new(
        nominal: VehicleParams,
        randomization: Randomization,
    ) -> Result<(Self, Box<dyn AirVehicle>), ParamError> {
        nominal.quadrotor.validate()?;
        nominal.rate_loop.validate()?;
        nominal.flight.validate()?;
        randomization.check(&nominal)?;
        let body = BodyState::at_rest(Vector3::zeros(), 0.0, 0.0, 0.0, 0.0);
        let quad = multirotor_at(
            nominal.quadrotor.clone(),
            nominal.frame.clone(),
            body,
            SimRng::new(0),
        )?;
        let rates = if nominal.flight.rates_action {
            Some(RatesLink {
                rate_loop: RateLoop::new(nominal.rate_loop.clone(), &nominal.mixer())?,
                pending: VecDeque::new(),
                current: RatesSetpoint::default(),
                last_action: [0.0; 4],
                steps: 0,
                ticks: 0,
                noise: SimRng::new(NOISE_STREAM),
                estimate: Estimate {
                    position_ned: Vector3::zeros(),
                    velocity_ned: Vector3::zeros(),
                    yaw: 0.0,
                    down_axis: Vector3::z(),
                    rates_frd: Vector3::zeros(),
                },
            })
        } else {
            None
        };
        let faults = if nominal.faults.is_empty() {
            None
        } else {
            let duration = nominal.flight.episode_duration();
            let rotors = nominal.frame.rotor_count();
            Some(FlightFaults::new(nominal.faults.clone(), rotors, duration)?)
        };
        let link = FlightLink {
            faults,
            flight: nominal.flight.clone(),
            nominal,
            randomization,
            drawn: Vec::new(),
            rates,
        };
        Ok((link, quad))
    }

    /// The nominal parameter sets.
    pub fn nominal(&self) -> &VehicleParams {
        &self.nominal
    }

    /// Draws the vehicle of the episode with `seed` (nominal when randomisation is off) into
    /// `quad`'s parameters, for the task to sample its start from.
    pub fn draw(&mut self, quad: &mut dyn AirVehicle, seed: u64) {
        let (params, drawn) = self.randomization.draw(&self.nominal, seed);
        self.drawn = drawn;
        *quad.params_mut() = params.quadrotor;
        self.flight = params.flight;
        if let Some(link) = &mut self.rates {
            // PX4's mixer is set up for the nominal vehicle (its CA_ROTOR* do not follow
            // a drawn arm length). Both corners of every range build (checked in `new`); a
            // draw between them that did not would keep the nominal loop.
            let mixer = self.nominal.mixer();
            if let Ok(rate_loop) = RateLoop::new(params.rate_loop, &mixer) {
                link.rate_loop = rate_loop;
            } else if let Ok(rate_loop) = RateLoop::new(self.nominal.rate_loop.clone(), &mixer) {
                link.rate_loop = rate_loop;
            }
        }
    }

    /// Starts the episode (after [`FlightLink::draw`]): `quad` at `body` with the episode's
    /// generator `rng`; `seed` seeds the observation noise.
    pub fn restart(&mut self, quad: &mut dyn AirVehicle, body: BodyState, rng: SimRng, seed: u64) {
        quad.restart(body, rng);
        let hover = quad.hover_motor_state().unwrap_or(0.0);
        if let Some(link) = &mut self.rates {
            link.rate_loop.reset(&flu_to_frd(&quad.body().body_rates));
            link.pending.clear();
            link.current = RatesSetpoint {
                thrust: hover,
                rates: Vector3::zeros(),
            };
            link.last_action = [hover, 0.0, 0.0, 0.0];
            link.steps = 0;
            link.ticks = 0;
            link.noise = SimRng::new(seed ^ NOISE_STREAM);
            link.estimate = estimate(quad, &self.flight, &mut link.noise);
        }
        if let Some(faults) = &mut self.faults {
            faults.restart(seed, quad, self.flight.dt);
        }
    }

    /// The episode's faults, if the vehicle has any.
    pub fn faults(&self) -> Option<&FlightFaults> {
        self.faults.as_ref()
    }

    /// Mutable access to the faults (the task's waypoint, run-time injection).
    pub fn faults_mut(&mut self) -> Option<&mut FlightFaults> {
        self.faults.as_mut()
    }

    /// Injects PX4's failure code (`unit`, `failure`, `instance`: 1 = first motor, 0 = all)
    /// now; a healthy vehicle gets an empty fault state first. Returns what was done (the
    /// fault's label, or what was cleared). An error names the field of a code the catalogue
    /// has no fault for, or a motor the frame lacks.
    pub fn inject_px4(
        &mut self,
        unit: u8,
        failure: u8,
        instance: u8,
    ) -> Result<String, ParamError> {
        let rotors = self.rotor_count();
        let injection = crate::faults::px4::from_px4(unit, failure, instance, rotors)?;
        let faults = match &mut self.faults {
            Some(f) => f,
            None => {
                let duration = self.nominal.flight.episode_duration();
                self.faults
                    .insert(FlightFaults::new(FaultPlan::default(), rotors, duration)?)
            }
        };
        let done = injection.describe();
        faults.inject(injection, self.flight.dt);
        Ok(done)
    }

    /// Number of rotors (motor commands of the motor interface).
    pub fn rotor_count(&self) -> usize {
        self.nominal.frame.rotor_count()
    }

    /// Number of action values: one per rotor (motor interface) or four (rates interface).
    pub fn action_size(&self) -> usize {
        if self.rates.is_some() {
            4
        } else {
            self.rotor_count()
        }
    }

    /// Whether actions are thrust + body rates.
    pub fn rates_interface(&self) -> bool {
        self.rates.is_some()
    }

    /// Inclusive action bounds of the interface.
    pub fn action_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        if self.rates.is_some() {
            let p = &self.nominal.rate_loop;
            let (rp, y) = (p.roll_pitch_rate_max, p.yaw_rate_max);
            (vec![0.0, -rp, -rp, -y], vec![1.0, rp, rp, y])
        } else {
            let n = self.rotor_count();
            (vec![0.0; n], vec![1.0; n])
        }
    }

    /// The control period `dt` this policy step spans, s: from the episode start on the
    /// rates interface (the rate loop's grid is absolute), [0, dt] on the motor interface.
    pub fn window(&self, dt: f64) -> (f64, f64) {
        match &self.rates {
            Some(link) => (link.steps as f64 * dt, (link.steps + 1) as f64 * dt),
            None => (0.0, dt),
        }
    }

    /// Takes an action of [`FlightLink::action_size`] values (clipped into the bounds) for the
    /// step of `dt` seconds that
    /// starts: the motor interface commands `quad`'s motors; the rates interface queues the
    /// setpoint for the rate loop's ticks ([`FlightLink::next_tick`], [`FlightLink::tick`]).
    pub fn begin(
        &mut self,
        quad: &mut dyn AirVehicle,
        action: &[f64],
        dt: f64,
    ) -> Result<(), ActionError> {
        check_action(action, self.action_size())?;
        if let Some(faults) = &mut self.faults {
            faults.begin_step(quad, dt);
        }
        let (start, _) = self.window(dt);
        let (lo, hi) = self.action_bounds();
        let Some(link) = &mut self.rates else {
            // Finite and clipped into [0, 1] by the motors, as the bounds say.
            let _ = quad.set_actuators(action);
            return Ok(());
        };
        let a: [f64; 4] = std::array::from_fn(|i| action[i].clamp(lo[i], hi[i]));
        link.last_action = a;
        let setpoint = RatesSetpoint {
            thrust: a[0],
            rates: Vector3::new(a[1], a[2], a[3]),
        };
        link.pending
            .push_back((start + self.flight.action_latency, setpoint));
        Ok(())
    }

    /// Time of the rate loop's next tick if it falls before `end` (the step's end), s.
    pub fn next_tick(&self, end: f64) -> Option<f64> {
        let link = self.rates.as_ref()?;
        let tick = link.ticks as f64 * link.rate_loop.params().rate_loop_period;
        (tick < end - TIME_TOLERANCE).then_some(tick)
    }

    /// Runs the rate-loop tick at [`FlightLink::next_tick`] (`quad` brought to that time):
    /// the setpoints due take effect, the loop reads the gyro and commands the motors.
    pub fn tick(&mut self, quad: &mut dyn AirVehicle) {
        let Some(link) = &mut self.rates else {
            return;
        };
        let tick = link.ticks as f64 * link.rate_loop.params().rate_loop_period;
        while let Some(&(at, sp)) = link.pending.front() {
            if at > tick + TIME_TOLERANCE {
                break;
            }
            link.current = sp;
            link.pending.pop_front();
        }
        let gyro = flu_to_frd(&quad.body().body_rates);
        let motors = link.rate_loop.step(&link.current, &gyro, false);
        let _ = quad.set_actuators(&motors[..]);
        link.ticks += 1;
    }

    /// Before `quad` advances by `dt` within the step: the actuator faults put what the
    /// motors get in place of its command (nothing without faults).
    pub fn before_advance(&mut self, quad: &mut dyn AirVehicle, dt: f64) {
        if let Some(faults) = &mut self.faults {
            faults.before_advance(quad, dt);
        }
    }

    /// After `quad` advanced: it holds the commanded values again.
    pub fn after_advance(&mut self, quad: &mut dyn AirVehicle) {
        if let Some(faults) = &mut self.faults {
            faults.after_advance(quad);
        }
    }

    /// Advances a lone `quad` by `dt` within the step, through the actuator fault path when
    /// it has faults (a world steps its vehicles together between
    /// [`FlightLink::before_advance`] and [`FlightLink::after_advance`]).
    pub fn advance(&mut self, quad: &mut dyn AirVehicle, dt: f64) {
        self.before_advance(quad, dt);
        quad.advance(dt);
        self.after_advance(quad);
    }

    /// Ends the step (`quad` at the step's end): the estimator's view is updated.
    pub fn finish(&mut self, quad: &dyn AirVehicle) {
        if let Some(link) = &mut self.rates {
            link.steps += 1;
            link.estimate = estimate(quad, &self.flight, &mut link.noise);
        }
        if let Some(faults) = &mut self.faults {
            faults.end_step();
        }
    }

    /// `point` (world ENU) relative to the observed position, in the observation's frame:
    /// world ENU for the motor interface, the heading frame for the rates interface.
    pub fn observed_offset(&self, quad: &dyn AirVehicle, point: &Vector3<f64>) -> Vector3<f64> {
        match &self.rates {
            None => point - quad.body().position,
            Some(link) => {
                let e = &link.estimate;
                heading_frame(e.yaw, &(enu_to_ned(point) - e.position_ned))
            }
        }
    }

    /// `velocity` (world ENU) relative to the observed velocity, in the observation's frame
    /// (as [`FlightLink::observed_offset`]).
    pub fn observed_relative_velocity(
        &self,
        quad: &dyn AirVehicle,
        velocity: &Vector3<f64>,
    ) -> Vector3<f64> {
        match &self.rates {
            None => velocity - quad.body().velocity,
            Some(link) => {
                let e = &link.estimate;
                heading_frame(e.yaw, &(enu_to_ned(velocity) - e.velocity_ned))
            }
        }
    }

    /// Number of values of the interface's observation.
    pub fn observation_size(&self) -> usize {
        self.observation_layout().iter().map(|(_, n)| n).sum()
    }

    /// The interface's observation groups: (name, number of values), in order.
    pub fn observation_layout(&self) -> Vec<(&'static str, usize)> {
        if self.rates.is_some() {
            ESTIMATE_OBSERVATION.to_vec()
        } else {
            base_observation(self.rotor_count()).to_vec()
        }
    }

    /// Bounds of the interface's observation; `position_bound` bounds target − position.
    /// The wind's bound (motor interface) holds for every randomised vehicle.
    pub fn observation_bounds(&self, position_bound: f64) -> (Vec<f32>, Vec<f32>) {
        if self.rates.is_some() {
            return self.estimate_bounds(position_bound);
        }
        let (upper, _) = self.randomization.corner(&self.nominal, 1.0);
        base_bounds(&upper.quadrotor, self.rotor_count(), position_bound)
    }

    /// Writes the interface's observation of `quad` for `target` (world ENU) into `out`, each
    /// value clipped into `lo..=hi`: the base values (motor interface: 25 + 2 per rotor, 33 on
    /// a quad) or the 16
    /// estimator values (rates interface, see the module docs).
    pub fn write_observation(
        &self,
        quad: &dyn AirVehicle,
        target: &Vector3<f64>,
        lo: &[f32],
        hi: &[f32],
        out: &mut [f32],
    ) {
        let Some(link) = &self.rates else {
            write_base_observation(quad, target, lo, hi, out);
            return;
        };
        let e = &link.estimate;
        let relative = self.observed_offset(quad, target);
        let velocity = heading_frame(e.yaw, &e.velocity_ned);
        let groups: [&[f64]; 5] = [
            relative.as_slice(),
            velocity.as_slice(),
            e.down_axis.as_slice(),
            e.rates_frd.as_slice(),
            &link.last_action,
        ];
        for (i, &v) in groups.iter().flat_map(|g| g.iter()).enumerate() {
            out[i] = super::clip_f32(v, lo[i], hi[i]);
        }
    }

    fn estimate_bounds(&self, position_bound: f64) -> (Vec<f32>, Vec<f32>) {
        let (alo, ahi) = self.action_bounds();
        let mut lo = Vec::with_capacity(ESTIMATE_OBSERVATION_SIZE);
        let mut hi = Vec::with_capacity(ESTIMATE_OBSERVATION_SIZE);
        for (n, b) in [(3, position_bound), (3, 40.0), (3, 1.0), (3, 20.0)] {
            lo.extend(std::iter::repeat_n(-b as f32, n));
            hi.extend(std::iter::repeat_n(b as f32, n));
        }
        lo.extend(alo.iter().map(|&v| v as f32));
        hi.extend(ahi.iter().map(|&v| v as f32));
        (lo, hi)
    }

    /// Info entries of the vehicle: the values drawn this episode, when randomised; the
    /// faults' slots, when it has faults ([`FlightFaults::visit_info`]).
    pub fn visit_info(&self, visit: &mut InfoVisitor<'_>) {
        if !self.randomization.is_off() {
            visit("randomized", InfoRef::Vector(&self.drawn));
        }
        if let Some(faults) = &self.faults {
            faults.visit_info(visit);
        }
    }
}

/// A world NED vector in the heading frame of `yaw`.
fn heading_frame(yaw: f64, v: &Vector3<f64>) -> Vector3<f64> {
    let (s, c) = yaw.sin_cos();
    Vector3::new(c * v.x + s * v.y, -s * v.x + c * v.y, v.z)
}

/// What the estimator reports now: the true state plus the configured noise.
fn estimate(quad: &dyn AirVehicle, flight: &FlightParams, rng: &mut SimRng) -> Estimate {
    let b = quad.body();
    let mut noise = |sigma: f64| -> Vector3<f64> {
        if sigma > 0.0 {
            Vector3::new(rng.normal(), rng.normal(), rng.normal()) * sigma
        } else {
            Vector3::zeros()
        }
    };
    let position_ned = enu_to_ned(&b.position) + noise(flight.obs_noise_position);
    let velocity_ned = enu_to_ned(&b.velocity) + noise(flight.obs_noise_velocity);
    let attitude_noise = noise(flight.obs_noise_attitude);
    let rates_frd = flu_to_frd(&b.body_rates) + noise(flight.obs_noise_rates);
    let q = attitude_ned(&quad.attitude());
    let (roll, pitch, yaw) = q.euler_angles();
    let (roll, pitch, yaw) = (
        roll + attitude_noise.x,
        pitch + attitude_noise.y,
        yaw + attitude_noise.z,
    );
    // Tilt without heading: R_z(−yaw)·R = R_y(pitch)·R_x(roll); its third column.
    let tilt = UnitQuaternion::from_euler_angles(roll, pitch, 0.0);
    Estimate {
        position_ned,
        velocity_ned,
        yaw,
        down_axis: tilt * Vector3::z(),
        rates_frd,
    }
}
