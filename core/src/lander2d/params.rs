//! Physical and world parameters of the Lander2D and its start values.

use crate::error::ParamError;
use crate::param;
use crate::params::{ParamSpec, Parameters};
use serde::{Deserialize, Serialize};

/// Physical, world and contact parameters. Defaults are the metric reference of seed 000
/// (docs/reference/lander2d.md).
///
/// The drone's three parts follow from `drone_width` (w) and `drone_height` (h): two square
/// motors of side h centred at x = ±(w − h)/2 and a frame (w − h) × h/2 between them, with
/// 20 % / 40 % / 40 % of `drone_mass`. The defaults give the reference's 0.8 × 0.1 frame and
/// 0.2 × 0.2 motors at ±0.4 m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Lander2dParams {
    /// Gravitational acceleration, m/s². Default 9.81.
    pub gravity: f64,
    /// World width; the world is x in (0, world_width), m. Default 50.
    pub world_width: f64,
    /// World height; the world is y in (0, world_height), m. Default 50.
    pub world_height: f64,
    /// Height of the ground surface, m. Default 10.
    pub ground_height: f64,
    /// Friction coefficient of the ground, 1. Default 0.8.
    pub ground_friction: f64,
    /// Total drone mass, kg. Default 1.5.
    pub drone_mass: f64,
    /// Drone width, tip to tip, m. Default 1.0.
    pub drone_width: f64,
    /// Drone height (the motors' side), m. Default 0.2.
    pub drone_height: f64,
    /// Friction coefficient of the drone's parts, 1. Default 1.0 (friction combines by product,
    /// so the pad's and the ground's own coefficients apply unchanged).
    pub drone_friction: f64,
    /// Largest thrust of one motor, N. Default 15.
    pub max_thrust: f64,
    /// Standard deviation of the Gaussian noise on each motor's thrust at full thrust, N;
    /// it scales with the commanded thrust, so a stopped motor gives none. Default 1.5
    /// (0.1 · max_thrust); 0 turns the noise off.
    pub thrust_noise_std: f64,
    /// Battery charge at the start, units. Default 100.
    pub initial_battery: f64,
    /// Battery drain per newton-second of total thrust, units/(N·s). Default 0.1.
    pub battery_consumption_rate: f64,
    /// Whether the episode's constant wind blows. Default true.
    pub wind_enabled: bool,
    /// Wind speed, m/s. Default 5.
    pub wind_speed: f64,
    /// Wind force per (m/s · m of drone width), N/(m²/s). Default 0.5 (2.5 N at the defaults).
    pub wind_force_coefficient: f64,
    /// Whether the wind direction is drawn uniformly in [0, 2π) per episode. Default true.
    pub wind_direction_random: bool,
    /// Wind direction when not random, from +x toward +y, rad. Default 0.
    pub wind_direction: f64,
    /// Landing platform width, m. Default 5.
    pub platform_width: f64,
    /// Landing platform height above the ground, m. Default 0.5.
    pub platform_height: f64,
    /// Friction coefficient of the platform, 1. Default 1.0.
    pub platform_friction: f64,
    /// Platform centre x at the start (when not random), m. Default 25.
    pub platform_start_x: f64,
    /// Whether the platform start x is drawn uniformly inside its travel range. Default false.
    pub platform_random_start_x: bool,
    /// Whether the platform moves back and forth along x. Default false.
    pub moving_platform: bool,
    /// Platform speed when moving, m/s. Default 1.5.
    pub platform_speed: f64,
    /// Largest speed relative to the platform at first contact for a safe landing, m/s.
    /// Default 1.5.
    pub max_safe_landing_speed: f64,
    /// Largest |angle| at first platform contact for a safe landing, rad. Default 0.2.
    pub max_safe_landing_angle: f64,
    /// Control period, s: what `Lander2d::step` advances by and what the mean acceleration
    /// is measured over. Default 0.02 (50 Hz).
    pub dt: f64,
    /// Physics step, s: rapier steps on the fixed grid k·physics_step from the start, with
    /// the thrust noise drawn and the battery drained once per grid step, independent of
    /// `dt`; so every `dt` or communication step that is a multiple of it gives the same bits
    /// at the shared times. Default 0.02 (one physics step per control period, as the
    /// reference).
    pub physics_step: f64,
}

impl Default for Lander2dParams {
    fn default() -> Self {
        Lander2dParams {
            gravity: 9.81,
            world_width: 50.0,
            world_height: 50.0,
            ground_height: 10.0,
            ground_friction: 0.8,
            drone_mass: 1.5,
            drone_width: 1.0,
            drone_height: 0.2,
            drone_friction: 1.0,
            max_thrust: 15.0,
            thrust_noise_std: 1.5,
            initial_battery: 100.0,
            battery_consumption_rate: 0.1,
            wind_enabled: true,
            wind_speed: 5.0,
            wind_force_coefficient: 0.5,
            wind_direction_random: true,
            wind_direction: 0.0,
            platform_width: 5.0,
            platform_height: 0.5,
            platform_friction: 1.0,
            platform_start_x: 25.0,
            platform_random_start_x: false,
            moving_platform: false,
            platform_speed: 1.5,
            max_safe_landing_speed: 1.5,
            max_safe_landing_angle: 0.2,
            dt: 0.02,
            physics_step: 0.02,
        }
    }
}

const TAU: f64 = std::f64::consts::TAU;
const PI: f64 = std::f64::consts::PI;
const LARGE: f64 = 1e4;

static LANDER_SPECS: [ParamSpec<Lander2dParams>; 29] = [
    param!(real gravity, "m/s2", 0.0, 100.0, "Gravitational acceleration"),
    param!(real world_width, "m", 1.0, LARGE, "World width (x in (0, world_width))"),
    param!(real world_height, "m", 1.0, LARGE, "World height (y in (0, world_height))"),
    param!(real ground_height, "m", 0.0, LARGE, "Height of the ground surface"),
    param!(real ground_friction, "1", 0.0, 10.0, "Friction coefficient of the ground"),
    param!(real drone_mass, "kg", 1e-3, LARGE, "Total drone mass (20 % frame, 40 % each motor)"),
    param!(real drone_width, "m", 1e-2, 100.0, "Drone width, tip to tip"),
    param!(real drone_height, "m", 1e-3, 100.0, "Drone height (side of each square motor)"),
    param!(real drone_friction, "1", 0.0, 10.0, "Friction coefficient of the drone's parts"),
    param!(real max_thrust, "N", 0.0, 1e6, "Largest thrust of one motor"),
    param!(real thrust_noise_std, "N", 0.0, 1e6, "Standard deviation of the Gaussian thrust noise per motor at full thrust (it scales with the commanded thrust: none when stopped)"),
    param!(real initial_battery, "1", 0.0, 1e9, "Battery charge at the start"),
    param!(real battery_consumption_rate, "1/(N.s)", 0.0, 1e9, "Battery drain per newton-second of total thrust"),
    param!(boolean wind_enabled, "The episode's constant wind blows"),
    param!(real wind_speed, "m/s", 0.0, 100.0, "Wind speed"),
    param!(real wind_force_coefficient, "N.s/m2", 0.0, 100.0, "Wind force per (m/s of wind x m of drone width)"),
    param!(boolean wind_direction_random, "Wind direction drawn uniformly in [0, 2 pi) per episode"),
    param!(real wind_direction, "rad", 0.0, TAU, "Wind direction when not random, from +x toward +y"),
    param!(real platform_width, "m", 1e-2, LARGE, "Landing platform width"),
    param!(real platform_height, "m", 1e-2, LARGE, "Landing platform height above the ground"),
    param!(real platform_friction, "1", 0.0, 10.0, "Friction coefficient of the platform"),
    param!(real platform_start_x, "m", 0.0, LARGE, "Platform centre x at the start (when not random)"),
    param!(boolean platform_random_start_x, "Platform start x drawn uniformly inside its travel range"),
    param!(boolean moving_platform, "The platform moves back and forth along x"),
    param!(real platform_speed, "m/s", 0.0, 100.0, "Platform speed when moving"),
    param!(real max_safe_landing_speed, "m/s", 0.0, 100.0, "Largest speed relative to the platform at first contact for a safe landing"),
    param!(real max_safe_landing_angle, "rad", 0.0, PI, "Largest |angle| at first platform contact for a safe landing"),
    param!(real dt, "s", 1e-4, 1.0, "Control period (what a step advances by; the mean acceleration's window)"),
    param!(real physics_step, "s", 1e-4, 1.0, "Physics grid step: rapier steps, thrust noise and battery drain on the absolute grid k*physics_step, so any multiple of it as step size gives the same bits"),
];

fn relation(name: &'static str, requirement: String) -> ParamError {
    ParamError::Relation { name, requirement }
}

impl Parameters for Lander2dParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &LANDER_SPECS
    }

    fn check_relations(&self) -> Result<(), ParamError> {
        if self.drone_height >= self.drone_width {
            return Err(relation(
                "drone_height",
                format!(
                    "drone_height ({}) must be less than drone_width ({}): the motors sit at the tips",
                    self.drone_height, self.drone_width
                ),
            ));
        }
        let platform_top = self.ground_height + self.platform_height;
        if platform_top >= self.world_height {
            return Err(relation(
                "ground_height",
                format!(
                    "ground_height + platform_height ({platform_top}) must be below world_height ({})",
                    self.world_height
                ),
            ));
        }
        if self.platform_width > self.world_width {
            return Err(relation(
                "platform_width",
                format!(
                    "platform_width ({}) must not exceed world_width ({})",
                    self.platform_width, self.world_width
                ),
            ));
        }
        let (lo, hi) = self.platform_travel();
        if !(self.platform_start_x >= lo && self.platform_start_x <= hi) {
            return Err(relation(
                "platform_start_x",
                format!(
                    "platform_start_x ({}) must keep the platform inside the world: [{lo}, {hi}]",
                    self.platform_start_x
                ),
            ));
        }
        Ok(())
    }
}

impl Lander2dParams {
    /// Range of the platform centre: it stays inside the world. At the defaults this is the
    /// reference's reversal points, 2.5 m and 47.5 m.
    pub fn platform_travel(&self) -> (f64, f64) {
        let half = self.platform_width / 2.0;
        (half, self.world_width - half)
    }

    /// Height of the platform's top surface, m.
    pub fn platform_top(&self) -> f64 {
        self.ground_height + self.platform_height
    }

    /// Magnitude of the wind force when the wind is on, N.
    pub fn wind_force_magnitude(&self) -> f64 {
        if self.wind_enabled {
            self.wind_speed * self.wind_force_coefficient * self.drone_width
        } else {
            0.0
        }
    }

    /// Thrust per motor that carries the weight in a level hover, N.
    pub fn hover_thrust(&self) -> f64 {
        self.drone_mass * self.gravity / 2.0
    }

    /// The normalised motor command in [-1, 1] of a thrust, or `None` when out of reach.
    pub fn command_for_thrust(&self, thrust: f64) -> Option<f64> {
        let a = 2.0 * thrust / self.max_thrust - 1.0;
        (a.is_finite() && (-1.0..=1.0).contains(&a)).then_some(a)
    }
}

/// Start values of a free-standing lander (the FMU's start values). The Landing task samples
/// its own start instead.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Lander2dInitial {
    /// Seed of the instance's random generator (thrust noise, wind and platform draws).
    /// Default 0.
    pub seed: u32,
    /// Initial x of the drone's centre, m. Default 25.
    pub initial_x: f64,
    /// Initial y of the drone's centre, m. Default 40.
    pub initial_y: f64,
    /// Initial angle, counter-clockwise, rad. Default 0.
    pub initial_angle: f64,
    /// Initial velocity along x, m/s. Default 0.
    pub initial_vx: f64,
    /// Initial velocity along y, m/s. Default 0.
    pub initial_vy: f64,
    /// Initial angular velocity, counter-clockwise, rad/s. Default 0.
    pub initial_angular_velocity: f64,
}

impl Default for Lander2dInitial {
    fn default() -> Self {
        Lander2dInitial {
            seed: 0,
            initial_x: 25.0,
            initial_y: 40.0,
            initial_angle: 0.0,
            initial_vx: 0.0,
            initial_vy: 0.0,
            initial_angular_velocity: 0.0,
        }
    }
}

const FAR: f64 = 1e6;
const FAST: f64 = 1e3;

static INITIAL_SPECS: [ParamSpec<Lander2dInitial>; 7] = [
    param!(integer seed, "", 0, i32::MAX, "Seed of the random generator (thrust noise, wind, platform)"),
    param!(real initial_x, "m", -FAR, FAR, "Initial x of the drone's centre"),
    param!(real initial_y, "m", -FAR, FAR, "Initial y of the drone's centre"),
    param!(real initial_angle, "rad", -PI, PI, "Initial angle, counter-clockwise"),
    param!(real initial_vx, "m/s", -FAST, FAST, "Initial velocity along x"),
    param!(real initial_vy, "m/s", -FAST, FAST, "Initial velocity along y"),
    param!(real initial_angular_velocity, "rad/s", -FAST, FAST, "Initial angular velocity, counter-clockwise"),
];

impl Parameters for Lander2dInitial {
    fn specs() -> &'static [ParamSpec<Self>] {
        &INITIAL_SPECS
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{assert_every_bound_is_enforced, assert_table_is_consistent};

    #[test]
    fn tables_are_consistent() {
        assert_table_is_consistent::<Lander2dParams>();
        assert_table_is_consistent::<Lander2dInitial>();
    }

    #[test]
    fn every_bad_parameter_gets_its_error() {
        assert_every_bound_is_enforced::<Lander2dParams>();
        assert_every_bound_is_enforced::<Lander2dInitial>();
    }

    #[test]
    fn named_errors_for_the_classic_mistakes() {
        let cases = [
            (
                "drone_mass",
                -1.0,
                "parameter `drone_mass` = -1 kg is out of range: it must be in [0.001, 10000] kg",
            ),
            ("drone_mass", 0.0, "parameter `drone_mass` = 0 kg"),
            ("dt", 0.0, "parameter `dt` = 0 s is out of range"),
            ("dt", -0.02, "`dt` = -0.02 s"),
            (
                "physics_step",
                0.0,
                "parameter `physics_step` = 0 s is out of range: it must be in [0.0001, 1] s",
            ),
            ("physics_step", 2.0, "`physics_step` = 2 s is out of range"),
            ("gravity", f64::NAN, "`gravity` = NaN"),
            ("max_thrust", f64::INFINITY, "`max_thrust` = inf"),
            ("wind_direction", 7.0, "`wind_direction` = 7 rad"),
        ];
        for (name, value, expected) in cases {
            let mut p = Lander2dParams::default();
            let err = p.set(name, value).unwrap_err().to_string();
            assert!(err.contains(expected), "{err}");
            assert_eq!(
                p,
                Lander2dParams::default(),
                "a refused set changed the parameters"
            );
        }
    }

    #[test]
    fn relations_keep_the_platform_and_drone_consistent() {
        let e = Lander2dParams::from_toml_str("drone_height = 1.0").unwrap_err();
        assert!(e.to_string().contains("`drone_height`"), "{e}");
        let e = Lander2dParams::from_toml_str("platform_start_x = 1.0").unwrap_err();
        assert!(
            e.to_string().contains(
                "platform_start_x (1) must keep the platform inside the world: [2.5, 47.5]"
            ),
            "{e}"
        );
        let e = Lander2dParams::from_toml_str("platform_width = 60.0").unwrap_err();
        assert!(e.to_string().contains("`platform_width`"), "{e}");
        let e = Lander2dParams::from_toml_str("ground_height = 49.8").unwrap_err();
        assert!(
            e.to_string()
                .contains("ground_height + platform_height (50.3)"),
            "{e}"
        );
        let p = Lander2dParams::from_toml_str("world_width = 100\nplatform_start_x = 90").unwrap();
        assert_eq!(p.platform_travel(), (2.5, 97.5));
    }

    #[test]
    fn derived_quantities_are_the_reference_numbers() {
        let p = Lander2dParams::default();
        assert_eq!(p.wind_force_magnitude(), 2.5);
        assert_eq!(p.platform_top(), 10.5);
        assert_eq!(p.platform_travel(), (2.5, 47.5));
        assert!((p.hover_thrust() - 7.3575).abs() < 1e-12);
        assert_eq!(p.command_for_thrust(7.5), Some(0.0));
        assert_eq!(p.command_for_thrust(16.0), None);
        let calm = Lander2dParams {
            wind_enabled: false,
            ..Default::default()
        };
        assert_eq!(calm.wind_force_magnitude(), 0.0);
    }

    #[test]
    fn files_load_and_name_their_mistakes() {
        let p =
            Lander2dParams::from_toml_str("moving_platform = true\nplatform_speed = 2.5").unwrap();
        assert!(p.moving_platform);
        assert_eq!(p.platform_speed, 2.5);
        let p = Lander2dParams::from_json_str(r#"{"wind_enabled": false, "physics_step": 0.005}"#)
            .unwrap();
        assert!(!p.wind_enabled);
        assert_eq!(p.physics_step, 0.005);
        // The old parameter is gone by name, not silently ignored.
        let e = Lander2dParams::from_toml_str("physics_substeps = 4").unwrap_err();
        assert_eq!(e.to_string(), "unknown parameter `physics_substeps`");
        let e = Lander2dParams::from_toml_str("drone_mas = 2").unwrap_err();
        assert_eq!(e.to_string(), "unknown parameter `drone_mas`");
        let e = Lander2dInitial::from_toml_str("seed = -1").unwrap_err();
        assert!(e.to_string().contains("`seed` = -1"), "{e}");
    }
}
