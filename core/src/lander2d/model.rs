//! A Lander2D instance: parameters, its scene (the drone alone in free flight, a rapier world
//! near the ground and the pad), battery, wind, contact outcome and its random generator —
//! what an FMU instance, a SITL vehicle or the Landing task holds.

use super::contact::ContactState;
use super::drone::DroneState;
use super::free_body::MassProps;
use super::params::{Lander2dInitial, Lander2dParams};
use super::scene::Scene;
use crate::error::{InputError, ParamError, check_finite};
use crate::params::Parameters;
use crate::rng::SimRng;
use crate::snapshot::{self, SnapshotError};
use serde::{Deserialize, Serialize};

/// One simulated 2D drone over its landing platform.
///
/// Plain data with its whole physics inside: [`Lander2d::save`] stores it and
/// [`Lander2d::restore`] brings back an instance that continues bit-identically.
#[derive(Serialize, Deserialize)]
pub struct Lander2d {
    params: Lander2dParams,
    scene: Scene,
    rng: SimRng,
    /// Motor commands (left, right) in [-1, 1], held until changed.
    command: [f64; 2],
    /// Wind force added from outside (the FMU's input), N.
    external_wind_force: [f64; 2],
    /// The episode's constant wind force, N (derived from `params` and `draws`).
    wind_force: [f64; 2],
    draws: EpisodeDraws,
    /// Thrust of each motor during the last physics step (or piece of one), N.
    thrust: [f64; 2],
    /// The current physics grid step's two normal draws of thrust noise.
    noise: [f64; 2],
    /// Whether the battery held charge at the start of the current grid step: its thrust
    /// flows for the whole grid step (the drain is taken at the start).
    powered: bool,
    battery: f64,
    /// +1 or −1: where a moving platform is heading.
    platform_direction: f64,
    /// Mean acceleration over the last control period, m/s².
    acceleration: [f64; 2],
    contact: ContactState,
    /// Control periods completed since the start.
    steps: u64,
    /// Whole physics grid steps done since the start.
    grid_steps: u64,
    /// Time into the current physics grid step, s, in [0, physics_step): 0 on the grid, more
    /// after a shortened physics step that stopped inside a grid step (a communication point
    /// or a control period end off the grid).
    partial: f64,
    /// Whether the current control period has begun (its start velocity taken, its contact
    /// flags cleared); false on a period boundary.
    period_begun: bool,
    /// Drone velocity at the start of the current control period, m/s (for `acceleration`).
    period_start_velocity: [f64; 2],
}

impl std::fmt::Debug for Lander2d {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lander2d")
            .field("drone", &self.drone())
            .field("platform_x", &self.platform_x())
            .field("battery", &self.battery)
            .field("thrust", &self.thrust)
            .field("contact", &self.contact)
            .field("steps", &self.steps)
            .finish_non_exhaustive()
    }
}

impl Lander2d {
    /// A lander with the drone in `drone` state. The episode's wind direction, the platform's
    /// start direction and (if random) its start x are drawn from `rng`, always in that order
    /// and always all three, so switching an option does not shift the rest of the stream.
    pub fn new(params: Lander2dParams, drone: DroneState, rng: SimRng) -> Result<Self, ParamError> {
        params.validate()?;
        check_start(&drone)?;
        Ok(Self::new_unchecked(params, drone, rng))
    }

    /// A lander from start values (the FMU's parameters).
    pub fn from_initial(
        params: Lander2dParams,
        initial: &Lander2dInitial,
    ) -> Result<Self, ParamError> {
        initial.validate()?;
        let drone = DroneState {
            x: initial.initial_x,
            y: initial.initial_y,
            angle: initial.initial_angle,
            vx: initial.initial_vx,
            vy: initial.initial_vy,
            angular_velocity: initial.initial_angular_velocity,
        };
        Lander2d::new(params, drone, SimRng::new(u64::from(initial.seed)))
    }

    /// [`Lander2d::new`] for parameters and a start already checked.
    pub(crate) fn new_unchecked(
        params: Lander2dParams,
        drone: DroneState,
        mut rng: SimRng,
    ) -> Self {
        let draws = EpisodeDraws {
            wind_angle: rng.uniform(0.0, std::f64::consts::TAU),
            platform_heading: if rng.unit() < 0.5 { 1.0 } else { -1.0 },
            platform_start: rng.unit(),
        };
        let platform_direction = draws.platform_heading;
        let wind_force = draws.wind_force(&params);
        let scene = Scene::new(
            &params,
            &drone,
            draws.platform_start_x(&params),
            platform_direction * params.platform_speed,
            wind_force,
        );
        Lander2d {
            battery: params.initial_battery,
            params,
            scene,
            rng,
            command: [-1.0; 2],
            external_wind_force: [0.0; 2],
            wind_force,
            draws,
            thrust: [0.0; 2],
            noise: [0.0; 2],
            powered: false,
            platform_direction,
            acceleration: [0.0; 2],
            contact: ContactState::default(),
            steps: 0,
            grid_steps: 0,
            partial: 0.0,
            period_begun: false,
            period_start_velocity: [0.0; 2],
        }
    }

    /// Sets the motor commands (left, right). Each must be finite; values are clamped into
    /// [-1, 1], which maps linearly onto [0, max_thrust].
    pub fn set_command(&mut self, command: [f64; 2]) -> Result<(), InputError> {
        check_finite("motor command", &command)?;
        self.command = command.map(|c| c.clamp(-1.0, 1.0));
        Ok(())
    }

    /// The motor commands in effect, each in [-1, 1].
    pub fn command(&self) -> [f64; 2] {
        self.command
    }

    /// Sets the wind force added from outside, N. Each must be finite.
    pub fn set_external_wind_force(&mut self, force: [f64; 2]) -> Result<(), InputError> {
        check_finite("wind force", &force)?;
        self.external_wind_force = force;
        Ok(())
    }

    /// Advances to the end of the current control period, `(steps + 1) · dt` (a whole
    /// period from a period boundary), on the physics grid (see [`Lander2d::advance_to`]).
    pub fn step(&mut self) {
        let end = (self.steps + 1) as f64 * self.params.dt;
        self.advance_to(end);
    }

    /// Advances to `time` seconds since the start, so that the state is the state at `time`.
    ///
    /// The physics lives on the fixed grid k · `physics_step` from the start, independent of
    /// `dt`: one rapier step per grid interval, the thrust noise drawn and the battery
    /// drained (thrust × rate × physics_step) at the start of each. A step is cut at the
    /// grid points, at the control period ends k · `dt` and at `time`; so every `time`
    /// sequence and every `dt` on the grid integrates the same intervals and gives the same
    /// bits at the shared times. A cut inside a grid interval is a shortened rapier step and
    /// the rest of the interval follows as another (the path then differs from a gridded one
    /// by the integrator's error). The thrust of each piece is the command in effect with the
    /// grid step's noise, so a command changed inside a grid step acts for the rest of it.
    /// Points within 1e-6 of the smaller of the two grids count as on them. A `time` at or
    /// before now does nothing.
    pub fn advance_to(&mut self, time: f64) {
        let grid = self.params.physics_step;
        let slack = GRID_SLACK * grid.min(self.params.dt);
        loop {
            let now = self.time();
            let remaining = time - now;
            if remaining.is_nan() || remaining <= slack {
                return;
            }
            if self.partial == 0.0 {
                self.begin_grid_step();
            }
            if !self.period_begun {
                self.begin_period();
            }
            let to_grid = grid - self.partial;
            let to_period = (self.steps + 1) as f64 * self.params.dt - now;
            if remaining >= to_grid - slack && to_period >= to_grid - slack {
                // On the grid from a grid point: the world's own step, the same bits as a
                // run that never stopped in between.
                let length = (self.partial != 0.0).then_some(to_grid);
                self.physics_step(length);
                self.partial = 0.0;
                self.grid_steps += 1;
                if to_period <= to_grid + slack {
                    self.end_period();
                }
            } else {
                let piece = remaining.min(to_period);
                self.physics_step(Some(piece));
                self.partial += piece;
                if to_period <= piece + slack {
                    self.end_period();
                }
            }
        }
    }

    /// The start of a physics grid step: its thrust noise and the battery's drain.
    fn begin_grid_step(&mut self) {
        // The two normal draws happen every grid step, so the stream does not depend on the
        // battery or the command.
        self.noise = [self.rng.normal(), self.rng.normal()];
        self.powered = self.battery > 0.0;
        self.thrust = self.current_thrust();
        if self.battery > 0.0 {
            let drain = (self.thrust[0] + self.thrust[1])
                * self.params.battery_consumption_rate
                * self.params.physics_step;
            self.battery = (self.battery - drain).max(0.0);
        }
        let wind = self.wind_force();
        self.scene.choose_mode(&self.params, wind);
    }

    /// The start of a control period: the velocity its mean acceleration is measured from;
    /// its contact flags start clear.
    fn begin_period(&mut self) {
        self.period_start_velocity = self.scene.velocity();
        self.contact.begin_period();
        self.period_begun = true;
    }

    /// One physics step of the grid's length, or of `length` seconds (a piece of a grid
    /// step), under the current command, with the contacts classified after it.
    fn physics_step(&mut self, length: Option<f64>) {
        self.thrust = self.current_thrust();
        let before = self.drone();
        let platform_vx = self.platform_vx();
        let dt = length.unwrap_or(self.params.physics_step);
        let wind = self.wind_force();
        let (on_platform, on_ground) = self.scene.step(&self.params, dt, self.thrust, wind);
        self.steer_platform();
        self.contact
            .update(&self.params, &before, platform_vx, on_platform, on_ground);
    }

    /// The end of a control period: its mean acceleration; the period count moves on.
    fn end_period(&mut self) {
        let v1 = self.scene.velocity();
        let v0 = self.period_start_velocity;
        self.acceleration = [
            (v1[0] - v0[0]) / self.params.dt,
            (v1[1] - v0[1]) / self.params.dt,
        ];
        self.steps += 1;
        self.period_begun = false;
    }

    /// Thrust of each motor now: commanded level times (1 + the grid step's Gaussian noise of
    /// relative σ = thrust_noise_std / max_thrust), clipped to [0, max_thrust]; zero when the
    /// battery was empty at the grid step's start. The noise scales with the level so that a
    /// stopped motor (command −1) gives exactly zero thrust and drains nothing; at full
    /// thrust σ is thrust_noise_std, the reference's. (The reference added σ at every level:
    /// at command −1 its clipped noise still pushed ≈ 0.6 N per motor and drained the
    /// battery.)
    fn current_thrust(&self) -> [f64; 2] {
        let p = &self.params;
        if !self.powered || p.max_thrust <= 0.0 {
            return [0.0; 2];
        }
        let relative_std = p.thrust_noise_std / p.max_thrust;
        [0, 1].map(|i| {
            let level = (self.command[i] + 1.0) / 2.0 * p.max_thrust;
            (level * (1.0 + relative_std * self.noise[i])).clamp(0.0, p.max_thrust)
        })
    }

    /// Turns a moving platform around once its centre reaches either end of its travel.
    fn steer_platform(&mut self) {
        if !self.params.moving_platform {
            return;
        }
        let (lo, hi) = self.params.platform_travel();
        let x = self.platform_x();
        if x <= lo && self.platform_direction < 0.0 {
            self.platform_direction = 1.0;
        } else if x >= hi && self.platform_direction > 0.0 {
            self.platform_direction = -1.0;
        }
        self.scene
            .set_platform_vx(self.platform_direction * self.params.platform_speed);
    }

    /// The drone's position, angle and velocities now.
    pub fn drone(&self) -> DroneState {
        self.scene.drone()
    }

    /// Whether a rapier world steps the drone now (it is within reach of a contact), rather
    /// than the free-flight integrator.
    pub fn in_contact_world(&self) -> bool {
        self.scene.in_contact_world()
    }

    /// Platform centre x, m.
    pub fn platform_x(&self) -> f64 {
        self.scene.platform_x()
    }

    /// Platform velocity along x, m/s (0 for a fixed platform).
    pub fn platform_vx(&self) -> f64 {
        self.scene.platform_vx()
    }

    /// The platform's top centre, the landing target, m.
    pub fn platform_target(&self) -> (f64, f64) {
        (self.platform_x(), self.params.platform_top())
    }

    /// Total wind force on the drone (episode wind + external), N.
    pub fn wind_force(&self) -> [f64; 2] {
        [
            self.wind_force[0] + self.external_wind_force[0],
            self.wind_force[1] + self.external_wind_force[1],
        ]
    }

    /// Velocity relative to the air, m/s. The lander's wind is a force on the drone, not a
    /// moving air mass, so the air is still and this is the drone's own velocity.
    pub fn air_velocity(&self) -> [f64; 2] {
        let d = self.drone();
        [d.vx, d.vy]
    }

    /// The wind force added from outside, N.
    pub fn external_wind_force(&self) -> [f64; 2] {
        self.external_wind_force
    }

    /// Thrust of each motor (left, right) during the last physics step, N.
    pub fn thrust(&self) -> [f64; 2] {
        self.thrust
    }

    /// Remaining battery charge.
    pub fn battery(&self) -> f64 {
        self.battery
    }

    /// Mean acceleration over the last control period, m/s².
    pub fn acceleration(&self) -> [f64; 2] {
        self.acceleration
    }

    /// Contact flags and the touch-down outcome.
    pub fn contact(&self) -> &ContactState {
        &self.contact
    }

    /// Landed safely on the platform (latched).
    pub fn landed(&self) -> bool {
        self.contact.landed
    }

    /// Crashed: onto the ground, or onto the platform too fast or tilted (latched).
    pub fn crashed(&self) -> bool {
        self.contact.crashed
    }

    /// The drone's centre is outside the world: not (0 < x < world_width and
    /// 0 < y < world_height).
    pub fn out_of_bounds(&self) -> bool {
        let d = self.drone();
        let p = &self.params;
        !(d.x > 0.0 && d.x < p.world_width && d.y > 0.0 && d.y < p.world_height)
    }

    /// Control periods completed since the start.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Simulated time since the start, s: whole grid steps k · physics_step (never
    /// accumulated), plus the piece of a grid step done since the last grid point.
    pub fn time(&self) -> f64 {
        self.grid_steps as f64 * self.params.physics_step + self.partial
    }

    /// Whether the instance stands on a control period boundary.
    pub fn at_period_boundary(&self) -> bool {
        !self.period_begun
    }

    /// The parameters in force.
    pub fn params(&self) -> &Lander2dParams {
        &self.params
    }

    /// Composite moment of inertia of the drone (frame and motor boxes), kg·m².
    pub fn inertia(&self) -> f64 {
        MassProps::of(&self.params).inertia
    }

    /// Sets parameter `name` and rebuilds the scene; on error nothing changes. Before the
    /// first step the start follows the new parameters (platform start, battery charge, from
    /// the same random draws); after it, the scene keeps its state (drone pose and velocities,
    /// platform position and heading, battery, RNG).
    /// `dt` and `physics_step` fix the clock, so they change only before the first step.
    pub fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let mut params = self.params.clone();
        params.set(name, value)?;
        let drone = self.drone();
        check_start(&drone)?;
        let fresh = self.time() == 0.0;
        if !fresh
            && (params.dt != self.params.dt || params.physics_step != self.params.physics_step)
        {
            return Err(ParamError::Relation {
                name: if params.dt != self.params.dt {
                    "dt"
                } else {
                    "physics_step"
                },
                requirement: "dt and physics_step can change only before the first step (they fix the instance's clock)".into(),
            });
        }
        let platform_x = if fresh {
            self.platform_direction = self.draws.platform_heading;
            self.battery = params.initial_battery;
            self.draws.platform_start_x(&params)
        } else {
            self.platform_x()
        };
        let platform_vx = self.platform_direction * params.platform_speed;
        self.wind_force = self.draws.wind_force(&params);
        let wind = self.wind_force();
        self.scene = Scene::new(&params, &drone, platform_x, platform_vx, wind);
        self.params = params;
        Ok(())
    }
}

/// The random draws that shape an episode, kept so that a parameter change before the first
/// step re-derives the start from the same numbers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct EpisodeDraws {
    /// Wind direction if random, rad in [0, 2π).
    wind_angle: f64,
    /// Start heading of a moving platform, +1 or −1.
    platform_heading: f64,
    /// Uniform in [0, 1): the platform's start within its travel, if random.
    platform_start: f64,
}

impl EpisodeDraws {
    fn wind_force(&self, p: &Lander2dParams) -> [f64; 2] {
        let angle = if p.wind_direction_random {
            self.wind_angle
        } else {
            p.wind_direction
        };
        let magnitude = p.wind_force_magnitude();
        [magnitude * angle.cos(), magnitude * angle.sin()]
    }

    fn platform_start_x(&self, p: &Lander2dParams) -> f64 {
        if p.platform_random_start_x {
            let (lo, hi) = p.platform_travel();
            lo + (hi - lo) * self.platform_start
        } else {
            p.platform_start_x
        }
    }
}

/// Format tag of a Lander2d snapshot (name and version; 03 put the physics on its own grid:
/// whole grid steps, the grid step's noise draws and charge, whether a period has begun;
/// 04 keeps a rapier world only within reach of a contact).
const SNAPSHOT_TAG: &[u8; 8] = b"FLYL2D04";

/// How far a communication point may miss a grid point (of the physics grid or of the
/// control periods) and still count as on it, as a fraction of the smaller grid step:
/// t0 + n·h, k · dt and k · physics_step agree only up to rounding.
const GRID_SLACK: f64 = 1e-6;

impl Lander2d {
    /// The whole state as bytes: the drone in free flight or the rapier world (bodies,
    /// colliders, islands, broad and narrow phase with their warm-start impulses), RNG,
    /// battery, counters and contact flags.
    pub fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        snapshot::encode(SNAPSHOT_TAG, self)
    }

    /// An instance from [`Lander2d::save`] bytes; it continues exactly as the saved one would.
    /// Foreign or damaged bytes are an error, never a panic.
    pub fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        let lander: Lander2d = snapshot::decode(SNAPSHOT_TAG, "Lander2D", bytes)?;
        lander.check_restored()?;
        Ok(lander)
    }

    /// Checks a decoded instance before anything indexes its world.
    pub(crate) fn check_restored(&self) -> Result<(), SnapshotError> {
        let lander = self;
        lander
            .params
            .validate()
            .map_err(|e| SnapshotError::Invalid(e.to_string()))?;
        if !lander.scene.is_valid() {
            return Err(SnapshotError::Invalid(
                "body or collider handles do not match the world".into(),
            ));
        }
        let d = lander.draws;
        let numbers = [
            lander.battery,
            lander.platform_direction,
            d.wind_angle,
            d.platform_start,
        ]
        .into_iter()
        .chain(lander.command)
        .chain(lander.external_wind_force)
        .chain(lander.wind_force)
        .chain(lander.thrust)
        .chain(lander.noise)
        .chain(lander.period_start_velocity);
        if numbers.into_iter().any(|v| !v.is_finite()) {
            return Err(SnapshotError::Invalid(
                "a command, force or the battery is not finite".into(),
            ));
        }
        if !(0.0..lander.params.physics_step).contains(&lander.partial) {
            return Err(SnapshotError::Invalid(
                "the time inside the physics grid step is off its grid".into(),
            ));
        }
        Ok(())
    }
}

/// The drone's start must be finite numbers (rapier would quarantine the body).
fn check_start(drone: &DroneState) -> Result<(), ParamError> {
    let values = [
        ("initial_x", drone.x),
        ("initial_y", drone.y),
        ("initial_angle", drone.angle),
        ("initial_vx", drone.vx),
        ("initial_vy", drone.vy),
        ("initial_angular_velocity", drone.angular_velocity),
    ];
    for (name, value) in values {
        if !value.is_finite() {
            return Err(ParamError::Relation {
                name,
                requirement: format!("the drone's start must be finite, got {value}"),
            });
        }
    }
    Ok(())
}
