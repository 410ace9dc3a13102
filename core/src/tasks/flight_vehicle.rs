//! The vehicle a flight task flies, and how actions reach it.
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
//! vehicle is flying (integrator on), as PX4's land detector says once airborne. It mixes for
//! the frame as PX4 would ([`crate::rate_loop::px4_rotors`]), so the rates action has four
//! values on every frame.
//!
//! The rates interface observes what an autopilot's estimator gives (16 × f32), in PX4's
//! frames turned by the vehicle's heading: the *heading frame* is world NED rotated by the
//! yaw, x forward and y right (both horizontal), z down. [0:3] target − position (m),
//! [3:6] velocity (m/s), [6:9] the body's down axis (FRD z) in the heading frame (tilt;
//! (0, 0, 1) when level), [9:12] body rates (rad/s, FRD), [12:16] the previous action as
//! applied (clipped). Optional Gaussian noise (`obs_noise_*`) is drawn from a generator of
//! the episode's own, so the same seed gives the same noise.

use super::flight::{base_bounds, base_observation, write_base_observation};
use super::randomization::{Randomization, VehicleParams};
use crate::error::ParamError;
use crate::frames::{attitude_ned, enu_to_ned, flu_to_frd};
use crate::params::Parameters;
use crate::quadrotor::model::hover_motor_state;
use crate::quadrotor::{BodyState, Quadrotor};
use crate::rate_loop::{RateLoop, RatesSetpoint};
use crate::rng::SimRng;
use crate::tasks::{ActionError, InfoRef, InfoVisitor, check_action};
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

/// A multirotor with its action interface and per-episode randomisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlightVehicle {
    nominal: VehicleParams,
    randomization: Randomization,
    /// The values drawn for this episode, in the ranges' order.
    drawn: Vec<f64>,
    /// The flight parameters in effect this episode (latency and noise may be drawn).
    flight: super::flight::FlightParams,
    quad: Quadrotor,
    rates: Option<RatesLink>,
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

impl FlightVehicle {
    /// A vehicle from checked parameter sets; the randomisation's ranges are checked against
    /// them (both corners must be valid vehicles).
    pub fn new(nominal: VehicleParams, randomization: Randomization) -> Result<Self, ParamError> {
        nominal.quadrotor.validate()?;
        nominal.rate_loop.validate()?;
        nominal.flight.validate()?;
        randomization.check(&nominal)?;
        let body = BodyState::at_rest(Vector3::zeros(), 0.0, 0.0, 0.0, 0.0);
        let quad = Quadrotor::new(nominal.quadrotor.clone(), body, SimRng::new(0))?
            .with_frame(nominal.frame.clone());
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
        Ok(FlightVehicle {
            flight: nominal.flight.clone(),
            nominal,
            randomization,
            drawn: Vec::new(),
            quad,
            rates,
        })
    }

    /// Draws the vehicle of the episode with `seed` (nominal when randomisation is off) and
    /// returns its hover motor state (0 if it cannot hover), for the task's start.
    pub fn draw(&mut self, seed: u64) -> f64 {
        let (params, drawn) = self.randomization.draw(&self.nominal, seed);
        self.drawn = drawn;
        self.quad.params = params.quadrotor;
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
        self.hover_motor_state()
    }

    /// Motor state at which the vehicle of this episode hovers (0 if it cannot).
    fn hover_motor_state(&self) -> f64 {
        hover_motor_state(&self.quad.params, self.quad.frame()).unwrap_or(0.0)
    }

    /// Number of rotors (motor commands of the motor interface).
    pub fn rotor_count(&self) -> usize {
        self.quad.frame().rotor_count()
    }

    /// Number of action values: one per rotor (motor interface) or four (rates interface).
    pub fn action_size(&self) -> usize {
        if self.rates.is_some() {
            4
        } else {
            self.rotor_count()
        }
    }

    /// Starts the episode (after [`FlightVehicle::draw`]) at `body` with the episode's
    /// generator `rng`; `seed` seeds the observation noise.
    pub fn restart(&mut self, body: BodyState, rng: SimRng, seed: u64) {
        self.quad.restart(body, rng);
        let hover = self.hover_motor_state();
        if let Some(link) = &mut self.rates {
            link.rate_loop
                .reset(&flu_to_frd(&self.quad.body.body_rates));
            link.pending.clear();
            link.current = RatesSetpoint {
                thrust: hover,
                rates: Vector3::zeros(),
            };
            link.last_action = [hover, 0.0, 0.0, 0.0];
            link.steps = 0;
            link.ticks = 0;
            link.noise = SimRng::new(seed ^ NOISE_STREAM);
            link.estimate = estimate(&self.quad, &self.flight, &mut link.noise);
        }
    }

    pub fn quadrotor(&self) -> &Quadrotor {
        &self.quad
    }

    pub fn quadrotor_mut(&mut self) -> &mut Quadrotor {
        &mut self.quad
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

    /// Applies an action of [`FlightVehicle::action_size`] values (clipped into the bounds)
    /// for `dt` seconds.
    pub fn apply(&mut self, action: &[f64], dt: f64) -> Result<(), ActionError> {
        check_action(action, self.action_size())?;
        let Some(link) = &mut self.rates else {
            // Finite and clipped into [0, 1] by the motors, as the bounds say.
            let _ = self.quad.set_command(action);
            self.quad.step(dt);
            return Ok(());
        };
        let p = &self.nominal.rate_loop;
        let (rp, y) = (p.roll_pitch_rate_max, p.yaw_rate_max);
        let (lo, hi) = ([0.0, -rp, -rp, -y], [1.0, rp, rp, y]);
        let a: [f64; 4] = std::array::from_fn(|i| action[i].clamp(lo[i], hi[i]));
        let period = link.rate_loop.params().rate_loop_period;
        let start = link.steps as f64 * dt;
        let end = (link.steps + 1) as f64 * dt;
        link.last_action = a;
        let setpoint = RatesSetpoint {
            thrust: a[0],
            rates: Vector3::new(a[1], a[2], a[3]),
        };
        link.pending
            .push_back((start + self.flight.action_latency, setpoint));
        let mut now = start;
        loop {
            let tick = link.ticks as f64 * period;
            if tick >= end - TIME_TOLERANCE {
                break;
            }
            if tick > now {
                self.quad.step(tick - now);
                now = tick;
            }
            while let Some(&(at, sp)) = link.pending.front() {
                if at > tick + TIME_TOLERANCE {
                    break;
                }
                link.current = sp;
                link.pending.pop_front();
            }
            let gyro = flu_to_frd(&self.quad.body.body_rates);
            let motors = link.rate_loop.step(&link.current, &gyro, false);
            let _ = self.quad.set_command(&motors[..]);
            link.ticks += 1;
        }
        if end > now {
            self.quad.step(end - now);
        }
        link.steps += 1;
        link.estimate = estimate(&self.quad, &self.flight, &mut link.noise);
        Ok(())
    }

    /// `point` (world ENU) relative to the observed position, in the observation's frame:
    /// world ENU for the motor interface, the heading frame for the rates interface.
    pub fn observed_offset(&self, point: &Vector3<f64>) -> Vector3<f64> {
        match &self.rates {
            None => point - self.quad.body.position,
            Some(link) => {
                let e = &link.estimate;
                heading_frame(e.yaw, &(enu_to_ned(point) - e.position_ned))
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

    /// Writes the interface's observation for `target` (world ENU) into `out`, each value
    /// clipped into `lo..=hi`: the base values (motor interface: 25 + 2 per rotor, 33 on a
    /// quad) or the 16 estimator values (rates interface, see the module docs).
    pub fn write_observation(
        &self,
        target: &Vector3<f64>,
        lo: &[f32],
        hi: &[f32],
        out: &mut [f32],
    ) {
        let Some(link) = &self.rates else {
            write_base_observation(&self.quad, target, lo, hi, out);
            return;
        };
        let e = &link.estimate;
        let relative = self.observed_offset(target);
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

    /// Info entries of the vehicle: the values drawn this episode, when randomised.
    pub fn visit_info(&self, visit: &mut InfoVisitor<'_>) {
        if !self.randomization.is_off() {
            visit("randomized", InfoRef::Vector(&self.drawn));
        }
    }
}

/// A world NED vector in the heading frame of `yaw`.
fn heading_frame(yaw: f64, v: &Vector3<f64>) -> Vector3<f64> {
    let (s, c) = yaw.sin_cos();
    Vector3::new(c * v.x + s * v.y, -s * v.x + c * v.y, v.z)
}

/// What the estimator reports now: the true state plus the configured noise.
fn estimate(quad: &Quadrotor, flight: &super::flight::FlightParams, rng: &mut SimRng) -> Estimate {
    let b = &quad.body;
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
