//! A quadrotor instance: parameters, state, command, wind and its random generator — what
//! an FMU instance or a SITL vehicle holds.

use super::contact::{foot_heights, rest_height};
use super::dynamics::{ConstantsCache, Surroundings, accelerations, integrate_with};
use super::frame::Frame;
use super::params::{QuadrotorInitial, QuadrotorParams};
use super::state::{BodyState, Motors, WindState};
use super::wind::{GRID_SLACK, OuCache, apply_transition, reset_wind};
use crate::error::{CommandError, ParamError, check_finite};
use crate::params::Parameters;
use crate::rng::SimRng;
use crate::snapshot::{self, SnapshotError};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// One simulated multirotor: its frame (the rotor table, [`Frame`]), parameters, state,
/// command, wind and random generator. Plain data: clone it to save it, serde it to store it.
/// Built as the quad X ([`Frame::quad_x`]); [`Quadrotor::with_frame`] gives it another.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quadrotor {
    pub params: QuadrotorParams,
    frame: Frame,
    pub body: BodyState,
    pub wind: WindState,
    /// Wind added from outside (the FMU's wind input, a world's wind field), world ENU, m/s.
    pub external_wind: Vector3<f64>,
    /// Force from outside the vehicle (a world's contact between vehicles and downwash),
    /// world ENU, N, held until changed. Not saved with the vehicle: whoever applies it (the
    /// world) keeps and saves it, and sets it again after a restore.
    #[serde(skip)]
    pub external_force: Vector3<f64>,
    /// Motor commands in [0, 1], one per rotor, held until changed.
    command: Motors,
    /// Per-rotor effectiveness η in [0, 1] (the FMU's `motor_effectiveness_i` inputs; see
    /// `effectiveness.rs`); `None`: every rotor healthy, the motors get the command itself.
    pub(super) effectiveness: Option<Motors>,
    /// Time since the last point of the physics grid, s, in [0, max_substep): 0 after any
    /// step that ends on the grid (see [`Quadrotor::step`]).
    grid_phase: f64,
    rng: SimRng,
    #[serde(skip)]
    ou_cache: OuCache,
    #[serde(skip)]
    constants: ConstantsCache,
}

impl Quadrotor {
    /// A vehicle in `body` state with the episode's wind drawn from `rng`.
    pub fn new(
        params: QuadrotorParams,
        body: BodyState,
        mut rng: SimRng,
    ) -> Result<Self, ParamError> {
        params.validate()?;
        let wind = reset_wind(&params, &mut rng);
        let body = body.with_motor_count(4).unwrap_or(body);
        Ok(Quadrotor {
            params,
            frame: Frame::quad_x(),
            body,
            wind,
            external_wind: Vector3::zeros(),
            external_force: Vector3::zeros(),
            command: Motors::from([0.0; 4]),
            effectiveness: None,
            grid_phase: 0.0,
            rng,
            ou_cache: OuCache::default(),
            constants: ConstantsCache::default(),
        })
    }

    /// This vehicle with `frame`'s rotors: as many motors as it has rotors, each at the state
    /// and command of the first one (nothing else changes).
    pub fn with_frame(mut self, frame: Frame) -> Self {
        let n = frame.rotor_count();
        self.body = self.body.with_motor_count(n).unwrap_or(self.body);
        self.command = Motors::uniform(n, self.command[0]).unwrap_or(self.command);
        self.effectiveness = None;
        self.frame = frame;
        self.constants = ConstantsCache::default();
        self
    }

    /// The rotor table.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// Total rotor thrust now, N: Σ kᵢ mᵢ² over the motor states.
    pub fn thrust(&self) -> f64 {
        let k = self.params.thrust_coefficient;
        (self.frame.rotors().iter().zip(self.body.motors.iter()))
            .map(|(r, m)| r.thrust_coefficient.unwrap_or(k) * m * m)
            .sum()
    }

    /// Motor state at which every rotor at the same state carries the weight: √(m g / Σ kᵢ)
    /// (the quad X's is [`QuadrotorParams::hover_motor_state`]). `None` when no motor state
    /// in [0, 1] can hover.
    pub fn hover_motor_state(&self) -> Option<f64> {
        hover_motor_state(&self.params, &self.frame)
    }

    /// The vehicle standing level on its landing gear at the origin, facing north, with the
    /// episode's wind drawn from `SimRng::new(seed)`: where an autopilot's flight starts. The
    /// centre of mass is at the rest height, the feet carrying m·g, so the first sensor
    /// sample already feels the ground carrying it (−g, not free fall).
    pub fn standing(params: QuadrotorParams, seed: u64) -> Result<Self, ParamError> {
        let position = Vector3::new(0.0, 0.0, rest_height(&params));
        let body = BodyState::at_rest(position, 0.0, 0.0, std::f64::consts::FRAC_PI_2, 0.0);
        Quadrotor::new(params, body, SimRng::new(seed))
    }

    /// Starts a new episode in place: the vehicle at `body`, a fresh wind drawn from `rng`,
    /// no external wind, healthy motors commanded to hold their state. The parameters stay as
    /// they are (validated when the vehicle was built), so a restart cannot fail; the result
    /// is the vehicle `new(params, body, rng)` with that command.
    pub fn restart(&mut self, body: BodyState, mut rng: SimRng) {
        self.wind = reset_wind(&self.params, &mut rng);
        let n = self.frame.rotor_count();
        let body = body.with_motor_count(n).unwrap_or(body);
        self.command = Motors::uniform(n, body.motors[0].clamp(0.0, 1.0)).unwrap_or(self.command);
        self.body = body;
        self.effectiveness = None;
        self.external_wind = Vector3::zeros();
        self.external_force = Vector3::zeros();
        self.grid_phase = 0.0;
        self.rng = rng;
        self.ou_cache = OuCache::default();
    }

    /// A vehicle from start values (the FMU's parameters), command = initial motor state.
    pub fn from_initial(
        params: QuadrotorParams,
        initial: &QuadrotorInitial,
    ) -> Result<Self, ParamError> {
        initial.validate()?;
        let i = initial;
        let mut body = BodyState::at_rest(
            Vector3::new(i.initial_x, i.initial_y, i.initial_z),
            i.initial_roll,
            i.initial_pitch,
            i.initial_yaw,
            i.initial_motor,
        );
        body.velocity = Vector3::new(i.initial_vx, i.initial_vy, i.initial_vz);
        body.body_rates = Vector3::new(i.initial_wx, i.initial_wy, i.initial_wz);
        let mut quad = Quadrotor::new(params, body, SimRng::new(u64::from(i.seed)))?;
        quad.command = Motors::from([i.initial_motor; 4]);
        Ok(quad)
    }

    /// Sets the motor commands, one per rotor in the frame's motor order. Each must be
    /// finite; values are clamped into [0, 1]. Nothing changes on an error.
    pub fn set_command(&mut self, command: impl AsRef<[f64]>) -> Result<(), CommandError> {
        let command = command.as_ref();
        let expected = self.frame.rotor_count();
        if command.len() != expected {
            return Err(CommandError::WrongLength {
                what: "motor command",
                expected,
                got: command.len(),
            });
        }
        check_finite("motor command", command)?;
        for (slot, c) in self.command.iter_mut().zip(command) {
            *slot = c.clamp(0.0, 1.0);
        }
        Ok(())
    }

    /// Sets motor `index`'s command to finite `value`, clamped into [0, 1]; the variable
    /// tables call it for the rotors their frame has (an index past them changes nothing).
    pub(crate) fn set_motor_command(&mut self, index: usize, value: f64) {
        if let Some(slot) = self.command.get_mut(index) {
            *slot = value.clamp(0.0, 1.0);
        }
    }

    /// The motor commands in effect, each in [0, 1], one per rotor.
    pub fn command(&self) -> Motors {
        self.command
    }

    /// Advances the vehicle by `dt` seconds on a fixed physics grid.
    ///
    /// The physics lives on the grid k·`max_substep` from the vehicle's start (its time 0):
    /// each grid interval is one RK4 step in the air, or `ceil(max_substep /
    /// contact_substep)` equal RK4 substeps when a foot may touch the ground (decided at the
    /// interval's start). The turbulence lives on its own grid of `turbulence_dt` and holds
    /// between samples. A step is cut at every grid point and sample time it crosses and
    /// each piece integrated under the command and wind of its start, so any step that is a
    /// multiple of `max_substep` integrates exactly the same intervals: h = 0.005, 0.01 and
    /// 0.02 s give the same bits at their shared times, on the ground as in the air. A step
    /// that ends between grid points ends with a partial piece (a shorter RK4 step), and the
    /// next step completes that grid interval first; the path then differs from a gridded
    /// one by the integrator's error. Points within 1e-9 of an interval count as on it.
    pub fn step(&mut self, dt: f64) {
        let p = &self.params;
        let grid = p.max_substep;
        let grid_slack = GRID_SLACK * grid;
        let sample_slack = GRID_SLACK * p.turbulence_dt;
        let wind_enabled = p.wind_enabled;
        let mut remaining = dt;
        // Weak motors get a weakened command (`effectiveness.rs`); healthy ones the command
        // itself, with no copy made.
        let weak = (self.effectiveness.as_ref()).map(|eta| Self::weaken(&self.command, eta));
        loop {
            if grid - self.grid_phase <= grid_slack {
                self.grid_phase = 0.0;
            }
            let to_grid = grid - self.grid_phase;
            let (mut piece, mut at_grid, mut at_sample) = (remaining, false, false);
            if to_grid <= remaining + grid_slack {
                (piece, at_grid) = (to_grid, true);
            }
            if wind_enabled {
                let to_sample = self.params.turbulence_dt - self.wind.since_sample;
                if to_sample < piece - sample_slack {
                    (piece, at_grid, at_sample) = (to_sample, false, true);
                } else if to_sample <= piece + sample_slack {
                    at_sample = true;
                }
            }
            let air = self.surroundings();
            let constants = self.constants.get(&self.params, &self.frame);
            integrate_with(
                &self.params,
                &self.frame,
                constants,
                &mut self.body,
                weak.as_ref().unwrap_or(&self.command),
                &air,
                piece,
            );
            self.grid_phase = if at_grid {
                0.0
            } else {
                self.grid_phase + piece
            };
            if wind_enabled {
                self.wind.since_sample += piece;
                if at_sample {
                    self.sample_turbulence();
                }
            }
            remaining -= piece;
            if remaining <= grid_slack {
                return;
            }
        }
    }

    /// Draws the next turbulence sample (one OU transition of `turbulence_dt`) and restarts
    /// the time since the last sample.
    pub(super) fn sample_turbulence(&mut self) {
        let transition = self.ou_cache.get(&self.params, self.params.turbulence_dt);
        apply_transition(&transition, &mut self.wind, &mut self.rng);
        self.wind.since_sample = 0.0;
    }

    /// Total wind at the vehicle (episode wind + external), world ENU, m/s.
    pub fn wind_velocity(&self) -> Vector3<f64> {
        self.wind.velocity() + self.external_wind
    }

    /// The wind at the vehicle and the push of the external force (none when it is zero).
    pub fn surroundings(&self) -> Surroundings {
        let f = &self.external_force;
        let push = (*f != Vector3::zeros()).then(|| f / self.params.mass);
        Surroundings {
            wind: self.wind_velocity(),
            push,
        }
    }

    /// Velocity relative to the air (the vehicle's minus the wind's), world ENU, m/s.
    pub fn air_velocity(&self) -> Vector3<f64> {
        self.body.velocity - self.wind_velocity()
    }

    /// Whether a foot touches the ground (ground enabled and a foot height ≤ 0).
    pub fn is_grounded(&self) -> bool {
        self.params.ground_enabled && self.foot_heights().iter().any(|&h| h <= 0.0)
    }

    /// Height of each landing-gear foot above the ground, m, in rotor order (the contact's
    /// event indicators).
    pub fn foot_heights(&self) -> [f64; 4] {
        foot_heights(&self.params, &self.body)
    }

    /// Linear acceleration (world, total force / mass) and angular acceleration (body) now.
    pub fn accelerations(&self) -> (Vector3<f64>, Vector3<f64>) {
        let weak = (self.effectiveness.as_ref()).map(|eta| Self::weaken(&self.command, eta));
        accelerations(
            &self.params,
            &self.frame,
            &self.body,
            weak.as_ref().unwrap_or(&self.command),
            &self.surroundings(),
        )
    }

    /// Attitude as a unit quaternion (body → world).
    pub fn attitude(&self) -> UnitQuaternion<f64> {
        UnitQuaternion::new_unchecked(self.body.attitude)
    }

    /// Replaces the attitude (normalised).
    pub fn set_attitude(&mut self, q: Quaternion<f64>) {
        self.body.attitude = q.normalize();
    }

    /// The instance's random generator (for tasks that sample from the same stream).
    pub fn rng_mut(&mut self) -> &mut SimRng {
        &mut self.rng
    }

    /// The whole state as bytes (frame, parameters, body, wind, command, RNG); every f64 is kept
    /// bit for bit, so a restored instance continues exactly as this one would.
    pub fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        snapshot::encode(SNAPSHOT_TAG, self)
    }

    /// An instance from [`Quadrotor::save`] bytes. Foreign or damaged bytes, or bytes that
    /// decode into invalid parameters or a non-finite state, are an error, never a panic.
    pub fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        let quad: Quadrotor = snapshot::decode(SNAPSHOT_TAG, "Quadrotor", bytes)?;
        quad.params
            .validate()
            .map_err(|e| SnapshotError::Invalid(e.to_string()))?;
        let b = &quad.body;
        let finite = b.position.iter().all(|v| v.is_finite())
            && b.velocity.iter().all(|v| v.is_finite())
            && b.body_rates.iter().all(|v| v.is_finite())
            && b.attitude.coords.iter().all(|v| v.is_finite())
            && b.attitude.norm() > 0.0
            && b.motors.len() == quad.frame.rotor_count()
            && quad.command.len() == quad.frame.rotor_count()
            && b.motors
                .iter()
                .chain(quad.command.iter())
                .all(|v| v.is_finite())
            && b.gear_stretch.iter().flatten().all(|v| v.is_finite())
            && (0.0..quad.params.turbulence_dt).contains(&quad.wind.since_sample)
            && (0.0..quad.params.max_substep).contains(&quad.grid_phase);
        if !finite {
            return Err(SnapshotError::Invalid(
                "state holds a non-finite value, a zero quaternion, a motor count unlike its frame's, or a wind sample or physics grid time off its grid"
                    .into(),
            ));
        }
        Ok(quad)
    }
}

/// Motor state at which every rotor of `frame` at the same state carries the weight of the
/// vehicle `params`: √(m g / Σ kᵢ), the rotors that take the vehicle's coefficient counted as
/// one product (n·k, so a quad X's is bit for bit [`QuadrotorParams::hover_motor_state`]).
/// `None` when no motor state in [0, 1] can hover.
pub fn hover_motor_state(params: &QuadrotorParams, frame: &Frame) -> Option<f64> {
    let (mut shared, mut own) = (0u32, 0.0);
    for r in frame.rotors() {
        match r.thrust_coefficient {
            Some(k) => own += k,
            None => shared += 1,
        }
    }
    let total = f64::from(shared) * params.thrust_coefficient + own;
    let m = (params.mass * params.gravity / total).sqrt();
    (m.is_finite() && m <= 1.0).then_some(m)
}

/// Format tag of a Quadrotor snapshot (name and version; 02 added the gear's bristles, 03 the
/// time since the last turbulence sample, 04 the time since the last physics grid point, 05
/// the frame and one motor per rotor).
const SNAPSHOT_TAG: &[u8; 8] = b"FLYQUA05";
