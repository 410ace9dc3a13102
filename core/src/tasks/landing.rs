//! Landing: bring the Lander2D down onto its platform (seed 000), without the reference's bugs
//! (docs/reference/lander2d.md).
//!
//! Observation (11 × f32, 12 with a moving platform), each value clipped to [−1, 1] (battery
//! and distance to [0, 1]), with W, H the world's width and height (50 m by default):
//!
//! | index | value |
//! |---|---|
//! | 0, 1 | x/(W/2) − 1, y/(H/2) − 1 |
//! | 2, 3 | vx/15, vy/15 (m/s) |
//! | 4, 5 | wrap(angle)/π, ω/10 (rad/s) |
//! | 6 | battery / initial_battery |
//! | 7, 8 | err_x/(W/2), err_y/(H/2): drone → platform top centre |
//! | 9 | wrap(atan2(err_y, err_x) − angle)/π: bearing of the platform from the body |
//! | 10 | ‖err‖/W |
//! | 11 | platform vx / platform_speed (moving platform only) |
//!
//! The first terminal condition in this order ends the episode: landed, crashed, lost control
//! (|wrapped angle| > max_allowed_tilt_angle_rad), battery empty, out of bounds. Otherwise the
//! episode is truncated at exactly step == max_steps (the reference fired one step late).
//!
//! The reward is chosen by `reward_version` ([`super::landing_reward`]): 0 = the seed's
//! (default: on the normalised values n, 2·e^(−0.1·n10) − 0.1·(n2² + n3²) − 0.2·|n4| −
//! 0.1·|n5|, +5 on a step with platform contact; landed +100 if ‖(n2, n3)‖ < 0.1 and
//! |n5| < 0.1, else +20; failures −50; time limit −10), 1 = landing (potential-based shaping,
//! landed +100, failures and the time limit −100).

use super::landing_reward::{
    self, Ending, REWARD_LANDING, REWARD_SEED, landing_terminal_reward, seed_terminal_reward,
};
use super::{ActionError, InfoRef, InfoVisitor, StepOutcome, Task, check_action, clip_f32};
use crate::error::ParamError;
use crate::lander2d::{DroneState, Lander2d, Lander2dParams, wrap_angle};
use crate::param;
use crate::params::{ParamSpec, Parameters};
use crate::rng::SimRng;
use crate::snapshot::{self, SnapshotError};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Parameters of the Landing task (the reference's constructor arguments that are not the
/// model's own: `moving_platform` and `platform_speed` live in [`Lander2dParams`], as the FMU
/// needs them too).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LandingParams {
    /// Episode length in steps; truncation at step == max_steps. Default 1000.
    pub max_steps: u32,
    /// Half side of the square spawn zone around (spawn_x, spawn_y), m. Default 5; 0 = fixed.
    pub initial_pos_random_range_m: f64,
    /// Centre of the spawn zone, x, m. Default 25.
    pub spawn_x: f64,
    /// Centre of the spawn zone, y, m. Default 40.
    pub spawn_y: f64,
    /// Half range of the uniform spawn angle, rad. Default 0.1.
    pub initial_angle_random_range_rad: f64,
    /// |wrapped angle| beyond which control is lost, rad. Default π/2.
    pub max_allowed_tilt_angle_rad: f64,
    /// Reward: 0 = `seed` (the reference's, bit for bit; it pays for hovering near the pad),
    /// 1 = `landing` (potential-based shaping, a safe landing dominates). Default 0.
    pub reward_version: u32,
}

impl Default for LandingParams {
    fn default() -> Self {
        LandingParams {
            max_steps: 1000,
            initial_pos_random_range_m: 5.0,
            spawn_x: 25.0,
            spawn_y: 40.0,
            initial_angle_random_range_rad: 0.1,
            max_allowed_tilt_angle_rad: PI / 2.0,
            reward_version: REWARD_SEED,
        }
    }
}

static LANDING_SPECS: [ParamSpec<LandingParams>; 7] = [
    param!(integer max_steps, "", 1, i32::MAX, "Episode length in steps (truncation at step == max_steps)"),
    param!(real initial_pos_random_range_m, "m", 0.0, 1e4, "Half side of the square spawn zone"),
    param!(real spawn_x, "m", 0.0, 1e4, "Centre of the spawn zone, x"),
    param!(real spawn_y, "m", 0.0, 1e4, "Centre of the spawn zone, y"),
    param!(real initial_angle_random_range_rad, "rad", 0.0, PI, "Half range of the uniform spawn angle"),
    param!(real max_allowed_tilt_angle_rad, "rad", 0.0, PI, "|wrapped angle| beyond which control is lost"),
    param!(integer reward_version, "", 0, 1, "Reward: 0 = seed (the reference's), 1 = landing (potential-based shaping, landing pays)"),
];

impl Parameters for LandingParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &LANDING_SPECS
    }
}

/// Where a spawn may lie: one drone width inside the world's sides and top, and one drone
/// width above the platform's top, so no episode starts touching or outside.
fn spawn_box(model: &Lander2dParams) -> ((f64, f64), (f64, f64)) {
    let margin = model.drone_width;
    (
        (margin, model.world_width - margin),
        (model.platform_top() + margin, model.world_height - margin),
    )
}

/// Velocity and angular-velocity scales of the observation.
const VELOCITY_SCALE: f64 = 15.0;
const ANGULAR_VELOCITY_SCALE: f64 = 10.0;

/// Outcome flags and counters of the current episode.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct LandingStatus {
    /// Steps taken in this episode.
    pub step: u32,
    pub lost_control: bool,
    pub out_of_bounds: bool,
    pub battery_empty: bool,
    pub time_limit: bool,
    pub terminated: bool,
    pub truncated: bool,
}

/// The Landing task over one [`Lander2d`].
#[derive(Debug, Serialize, Deserialize)]
pub struct Landing {
    params: LandingParams,
    lander: Lander2d,
    status: LandingStatus,
    /// Φ of the current state (reward version 1's shaping is Φ(s′) − Φ(s)).
    #[serde(default)]
    potential: f64,
}

impl Landing {
    /// A Landing task, reset with seed 0. Both parameter sets are validated, and the spawn
    /// zone must fit the world.
    pub fn new(model: Lander2dParams, params: LandingParams) -> Result<Self, ParamError> {
        params.validate()?;
        model.validate()?;
        let ((xlo, xhi), (ylo, yhi)) = spawn_box(&model);
        if xlo > xhi || ylo > yhi {
            return Err(ParamError::Relation {
                name: "world_height",
                requirement: format!(
                    "the world leaves no room to spawn the drone: x in [{xlo}, {xhi}], y in [{ylo}, {yhi}]"
                ),
            });
        }
        let lander = Lander2d::new(model, DroneState::default(), SimRng::new(0))?;
        let mut landing = Landing {
            params,
            lander,
            status: LandingStatus::default(),
            potential: 0.0,
        };
        landing.reset(0);
        Ok(landing)
    }

    pub fn params(&self) -> &LandingParams {
        &self.params
    }

    pub fn lander(&self) -> &Lander2d {
        &self.lander
    }

    /// Mutable access for tests and front ends that place the drone by hand.
    pub fn lander_mut(&mut self) -> &mut Lander2d {
        &mut self.lander
    }

    pub fn status(&self) -> &LandingStatus {
        &self.status
    }

    /// Starts an episode with the drone in `drone` state instead of a sampled one; the
    /// episode's wind and platform are still drawn from `seed`. A non-finite state is refused.
    pub fn reset_to(&mut self, seed: u64, drone: DroneState) -> Result<(), ParamError> {
        let model = self.lander.params().clone();
        self.lander = Lander2d::new(model, drone, SimRng::new(seed))?;
        self.status = LandingStatus::default();
        self.potential = landing_reward::potential(&self.lander);
        Ok(())
    }

    /// The observation before narrowing to f32: each value normalised and clipped.
    pub fn normalised_observation(&self) -> ([f64; 12], usize) {
        let l = &self.lander;
        let p = l.params();
        let d = l.drone();
        let (tx, ty) = l.platform_target();
        let (half_w, half_h) = (p.world_width / 2.0, p.world_height / 2.0);
        let (ex, ey) = (tx - d.x, ty - d.y);
        let angle = wrap_angle(d.angle);
        let signed = |v: f64| v.clamp(-1.0, 1.0);
        let unsigned = |v: f64| v.clamp(0.0, 1.0);
        let battery = if p.initial_battery > 0.0 {
            l.battery() / p.initial_battery
        } else {
            0.0
        };
        let platform = if p.platform_speed > 0.0 {
            l.platform_vx() / p.platform_speed
        } else {
            0.0
        };
        let values = [
            signed(d.x / half_w - 1.0),
            signed(d.y / half_h - 1.0),
            signed(d.vx / VELOCITY_SCALE),
            signed(d.vy / VELOCITY_SCALE),
            signed(angle / PI),
            signed(d.angular_velocity / ANGULAR_VELOCITY_SCALE),
            unsigned(battery),
            signed(ex / half_w),
            signed(ey / half_h),
            signed(wrap_angle(ey.atan2(ex) - angle) / PI),
            unsigned(ex.hypot(ey) / p.world_width),
            signed(platform),
        ];
        (values, self.observation_size())
    }

    /// The whole episode as bytes (see [`Lander2d::save`]).
    pub fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        snapshot::encode(SNAPSHOT_TAG, self)
    }

    /// A task from [`Landing::save`] bytes; foreign or damaged bytes are an error.
    pub fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        let landing: Landing = snapshot::decode(SNAPSHOT_TAG, "Landing", bytes)?;
        landing
            .params
            .validate()
            .map_err(|e| SnapshotError::Invalid(e.to_string()))?;
        landing.lander.check_restored()?;
        Ok(landing)
    }
}

/// Format tag of a Landing snapshot (02: its lander is on its physics grid; 03: a FLYL2D04
/// one, with a rapier world only within reach of a contact).
const SNAPSHOT_TAG: &[u8; 8] = b"FLYLND03";

/// The seed's per-step reward on normalised observation values (module docs).
pub use landing_reward::seed_step_reward as shaping_reward;

impl Task for Landing {
    fn action_size(&self) -> usize {
        2
    }

    fn action_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![-1.0; 2], vec![1.0; 2])
    }

    fn observation_size(&self) -> usize {
        if self.lander.params().moving_platform {
            12
        } else {
            11
        }
    }

    fn observation_layout(&self) -> Vec<(&'static str, usize)> {
        let mut layout = vec![
            ("position", 2), // x/25 − 1, y/25 − 1
            ("velocity", 2),
            ("angle", 1),
            ("angular_velocity", 1),
            ("battery", 1),
            ("platform_offset", 2),
            ("platform_bearing", 1),
            ("platform_distance", 1),
        ];
        if self.observation_size() == 12 {
            layout.push(("platform_velocity", 1)); // vx / platform_speed
        }
        layout
    }

    fn observation_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        let n = self.observation_size();
        let mut low = vec![-1.0f32; n];
        low[6] = 0.0;
        low[10] = 0.0;
        (low, vec![1.0; n])
    }

    fn reset(&mut self, seed: u64) {
        let mut rng = SimRng::new(seed);
        let model = self.lander.params().clone();
        let p = &self.params;
        let r = p.initial_pos_random_range_m;
        let a = p.initial_angle_random_range_rad;
        let x = p.spawn_x + rng.uniform(-r, r);
        let y = p.spawn_y + rng.uniform(-r, r);
        let angle = rng.uniform(-a, a);
        let ((xlo, xhi), (ylo, yhi)) = spawn_box(&model);
        let drone = DroneState {
            x: x.clamp(xlo, xhi),
            y: y.clamp(ylo, yhi),
            angle,
            ..Default::default()
        };
        self.lander = Lander2d::new_unchecked(model, drone, rng);
        self.status = LandingStatus::default();
        self.potential = landing_reward::potential(&self.lander);
    }

    fn step(&mut self, action: &[f64]) -> Result<StepOutcome, ActionError> {
        check_action(action, 2)?;
        let command = [action[0].clamp(-1.0, 1.0), action[1].clamp(-1.0, 1.0)];
        self.lander
            .set_command(command)
            .map_err(|e| ActionError::NotFinite {
                index: e.index,
                value: e.value,
            })?;
        self.lander.step();
        self.status.step = self.status.step.saturating_add(1);

        let (n, _) = self.normalised_observation();
        let l = &self.lander;
        let s = &mut self.status;
        s.lost_control = wrap_angle(l.drone().angle).abs() > self.params.max_allowed_tilt_angle_rad;
        s.battery_empty = l.battery() <= 0.0;
        s.out_of_bounds = l.out_of_bounds();
        let ending = if l.landed() {
            Some(Ending::Landed {
                calm: n[2].hypot(n[3]) < 0.1 && n[5].abs() < 0.1,
            })
        } else if l.crashed() || s.lost_control || s.battery_empty || s.out_of_bounds {
            Some(Ending::Failed)
        } else if s.step >= self.params.max_steps {
            Some(Ending::TimeLimit)
        } else {
            None
        };
        s.time_limit = ending == Some(Ending::TimeLimit);
        s.terminated = ending.is_some() && !s.time_limit;
        s.truncated = s.time_limit;
        let reward = if self.params.reward_version == REWARD_LANDING {
            let potential = landing_reward::potential(l);
            let shaping = potential - self.potential;
            self.potential = potential;
            shaping - landing_reward::control_cost(command)
                + ending.map_or(0.0, landing_terminal_reward)
        } else {
            shaping_reward(&n, l.contact().touched_platform)
                + ending.map_or(0.0, seed_terminal_reward)
        };
        Ok(StepOutcome {
            reward,
            terminated: s.terminated,
            truncated: s.truncated,
        })
    }

    fn write_observation(&self, out: &mut [f32]) {
        let (values, n) = self.normalised_observation();
        for (i, slot) in out.iter_mut().enumerate().take(n) {
            let low = if i == 6 || i == 10 { 0.0 } else { -1.0 };
            *slot = clip_f32(values[i], low, 1.0);
        }
    }

    fn visit_info(&self, visit: &mut InfoVisitor<'_>) {
        let l = &self.lander;
        let d = l.drone();
        let (tx, ty) = l.platform_target();
        let s = &self.status;
        let c = l.contact();
        visit("position", InfoRef::Vector(&[d.x, d.y]));
        visit("velocity", InfoRef::Vector(&[d.vx, d.vy]));
        visit("angle", InfoRef::Real(wrap_angle(d.angle)));
        visit("angular_velocity", InfoRef::Real(d.angular_velocity));
        visit("battery", InfoRef::Real(l.battery()));
        visit("thrust", InfoRef::Vector(&l.thrust()));
        visit("wind_force", InfoRef::Vector(&l.wind_force()));
        visit("platform_position", InfoRef::Vector(&[tx, ty]));
        visit("distance", InfoRef::Real((tx - d.x).hypot(ty - d.y)));
        visit("landed", InfoRef::Flag(l.landed()));
        visit("crashed", InfoRef::Flag(l.crashed()));
        visit("lost_control", InfoRef::Flag(s.lost_control));
        visit("out_of_bounds", InfoRef::Flag(s.out_of_bounds));
        visit("battery_empty", InfoRef::Flag(s.battery_empty));
        visit("time_limit", InfoRef::Flag(s.time_limit));
        visit("platform_contact", InfoRef::Flag(c.touched_platform));
        visit("touchdown_speed", InfoRef::Real(c.touchdown_speed));
        visit("step", InfoRef::Integer(i64::from(s.step)));
    }

    fn dt(&self) -> f64 {
        self.lander.params().dt
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{assert_every_bound_is_enforced, assert_table_is_consistent};

    #[test]
    fn table_is_consistent_and_every_bound_is_enforced() {
        assert_table_is_consistent::<LandingParams>();
        assert_every_bound_is_enforced::<LandingParams>();
    }

    #[test]
    fn named_errors_for_the_classic_mistakes() {
        let cases = [
            (
                "max_steps",
                0.0,
                "parameter `max_steps` = 0 is out of range",
            ),
            ("max_steps", 10.5, "`max_steps` = 10.5 is not an integer"),
            (
                "initial_pos_random_range_m",
                -1.0,
                "`initial_pos_random_range_m` = -1 m",
            ),
            (
                "max_allowed_tilt_angle_rad",
                f64::NAN,
                "`max_allowed_tilt_angle_rad` = NaN",
            ),
        ];
        for (name, value, expected) in cases {
            let mut p = LandingParams::default();
            let err = p.set(name, value).unwrap_err().to_string();
            assert!(err.contains(expected), "{err}");
            assert_eq!(p, LandingParams::default());
        }
        let p = LandingParams::from_toml_str("max_steps = 1500\ninitial_pos_random_range_m = 10.0")
            .unwrap();
        assert_eq!((p.max_steps, p.initial_pos_random_range_m), (1500, 10.0));
    }
}
