//! A quadrotor instance: parameters, state, command, wind and its random generator — what
//! an FMU instance or a SITL vehicle holds.

use super::contact::foot_heights;
use super::dynamics::{accelerations, integrate};
use super::params::{QuadrotorInitial, QuadrotorParams};
use super::state::{BodyState, WindState};
use super::wind::{OuCache, apply_transition, next_segment, reset_wind};
use crate::error::{InputError, ParamError, check_finite};
use crate::params::Parameters;
use crate::rng::SimRng;
use crate::snapshot::{self, SnapshotError};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// One simulated quadrotor. Plain data: clone it to save it, serde it to store it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quadrotor {
    pub params: QuadrotorParams,
    pub body: BodyState,
    pub wind: WindState,
    /// Wind added from outside (the FMU's wind input), world ENU, m/s.
    pub external_wind: Vector3<f64>,
    /// Motor commands in [0, 1], held until changed.
    command: [f64; 4],
    rng: SimRng,
    #[serde(skip)]
    ou_cache: OuCache,
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
        Ok(Quadrotor {
            params,
            body,
            wind,
            external_wind: Vector3::zeros(),
            command: [0.0; 4],
            rng,
            ou_cache: OuCache::default(),
        })
    }

    /// Starts a new episode in place: the vehicle at `body`, a fresh wind drawn from `rng`,
    /// no external wind, the motors commanded to hold their state. The parameters stay as
    /// they are (validated when the vehicle was built), so a restart cannot fail; the result
    /// is the vehicle `new(params, body, rng)` with that command.
    pub fn restart(&mut self, body: BodyState, mut rng: SimRng) {
        self.wind = reset_wind(&self.params, &mut rng);
        self.command = [body.motors[0].clamp(0.0, 1.0); 4];
        self.body = body;
        self.external_wind = Vector3::zeros();
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
        quad.command = [i.initial_motor; 4];
        Ok(quad)
    }

    /// Sets the motor commands. Each must be finite; values are clamped into [0, 1].
    pub fn set_command(&mut self, command: [f64; 4]) -> Result<(), InputError> {
        check_finite("motor command", &command)?;
        self.command = command.map(|c| c.clamp(0.0, 1.0));
        Ok(())
    }

    /// The motor commands in effect, each in [0, 1].
    pub fn command(&self) -> [f64; 4] {
        self.command
    }

    /// Advances the vehicle by `dt` seconds. The turbulence lives on its own grid of
    /// `turbulence_dt` seconds and holds between samples: the step is cut at each sample time
    /// it crosses, each piece integrated under the wind of its start. So the same seed gives
    /// the same wind for any `dt` (a step of exactly `turbulence_dt` is one piece).
    pub fn step(&mut self, dt: f64) {
        if !self.params.wind_enabled {
            let wind = self.wind_velocity();
            integrate(&self.params, &mut self.body, &self.command, &wind, dt);
            return;
        }
        let mut remaining = dt;
        loop {
            let (segment, sample) = next_segment(&self.params, &self.wind, remaining);
            let wind = self.wind_velocity();
            integrate(&self.params, &mut self.body, &self.command, &wind, segment);
            remaining -= segment;
            if !sample {
                self.wind.since_sample += segment;
                return;
            }
            self.sample_turbulence();
            if remaining <= 0.0 {
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
        accelerations(
            &self.params,
            &self.body,
            &self.command,
            &self.wind_velocity(),
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

    /// The whole state as bytes (parameters, body, wind, command, RNG); every f64 is kept
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
            && b.motors.iter().chain(&quad.command).all(|v| v.is_finite())
            && b.gear_stretch.iter().flatten().all(|v| v.is_finite())
            && (0.0..quad.params.turbulence_dt).contains(&quad.wind.since_sample);
        if !finite {
            return Err(SnapshotError::Invalid(
                "state holds a non-finite value, a zero quaternion or a wind sample time off its grid"
                    .into(),
            ));
        }
        Ok(quad)
    }
}

/// Format tag of a Quadrotor snapshot (name and version; 02 added the gear's bristles, 03 the
/// time since the last turbulence sample).
const SNAPSHOT_TAG: &[u8; 8] = b"FLYQUA03";
