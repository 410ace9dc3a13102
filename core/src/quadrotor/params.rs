//! Physical parameters of the quadrotor and its initial conditions.

use crate::error::ParamError;
use crate::number::Compact;
use crate::param;
use crate::params::{ParamSpec, Parameters};
use serde::{Deserialize, Serialize};

/// Physical parameters. Defaults are the reference vehicle of seed 001 (1 kg, 10 cm arms;
/// docs/reference/quadrotor.md).
///
/// Units are SI; every field's range is in [`QuadrotorParams::specs`] and enforced by
/// [`Parameters::validate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct QuadrotorParams {
    /// Vehicle mass, kg. Default 1.0.
    pub mass: f64,
    /// Distance from the centre to each rotor, m. Default 0.10 (lever arm per axis L/√2).
    pub arm_length: f64,
    /// Principal moment of inertia about body x (forward), kg·m². Default 0.01.
    pub inertia_xx: f64,
    /// Principal moment of inertia about body y (left), kg·m². Default 0.01.
    pub inertia_yy: f64,
    /// Principal moment of inertia about body z (up), kg·m². Default 0.02.
    pub inertia_zz: f64,
    /// Gravitational acceleration, m/s². Default 9.81.
    pub gravity: f64,
    /// Thrust at full motor state: T = k·m², N. Default 10 (hover at m = 0.49523).
    pub thrust_coefficient: f64,
    /// First-order motor lag time constant, s. Default 0.08.
    pub motor_time_constant: f64,
    /// Spin reaction torque per newton of thrust, N·m/N. Default 0.02.
    pub yaw_torque_coefficient: f64,
    /// Air density, kg/m³. Default 1.225.
    pub air_density: f64,
    /// Drag coefficient times reference area, m². Default 0.02.
    pub drag_area: f64,
    /// Linear angular damping, N·m·s/rad. Default 0.02.
    pub angular_damping_linear: f64,
    /// Quadratic angular damping, N·m·s²/rad². Default 0.002.
    pub angular_damping_quadratic: f64,
    /// Non-physical "pendulum" restoring torque −c·m·g·sin(roll | pitch), m. Default 0 (off);
    /// the reference DroneEnv used 0.003.
    pub pendulum_coefficient: f64,
    /// Physics grid step, s: the state is integrated on the absolute grid k·max_substep,
    /// one RK4 step per interval in the air (see `Quadrotor::step`), so every step size
    /// that is a multiple of it gives the same bits. Default 0.005 (the tasks' 0.01 s is two
    /// intervals; PX4's 0.004 s steps are not a multiple and end in partial pieces).
    pub max_substep: f64,
    /// Whether the ground plane z = 0 holds the vehicle (on its four landing-gear feet).
    /// Default true.
    pub ground_enabled: bool,
    /// Feet at body x = ±gear_x (forward), m. Default 0.07 (under the default rotors).
    pub gear_x: f64,
    /// Feet at body y = ±gear_y (left), m. Default 0.07.
    pub gear_y: f64,
    /// Feet at body z = gear_z (up; negative = below the centre of mass), m. Default −0.05.
    pub gear_z: f64,
    /// Normal (and tangential bristle) stiffness of each foot, N/m. Default 3000: a 1 kg
    /// vehicle sags 0.8 mm, a 1.5 kg one 1.2 mm; its bounce frequency (90–110 rad/s) is
    /// resolved by `contact_substep`.
    pub gear_stiffness: f64,
    /// Normal (and tangential bristle) damping of each foot, N·s/m. Default 20 (damping ratio
    /// 0.37 at 1 kg, 0.30 at 1.5 kg: a 1 m drop bounces ~8 cm, then ~1 cm).
    pub gear_damping: f64,
    /// Coulomb friction coefficient between a foot and the ground, 1. Default 0.5.
    pub gear_friction: f64,
    /// Largest RK4 substep while a foot may touch the ground, s. Default 0.002 (ω·h ≤ 0.25
    /// for the default gear on a 1 kg vehicle).
    pub contact_substep: f64,
    /// Whether wind blows at all. Default true.
    pub wind_enabled: bool,
    /// Lower end of the per-episode mean wind speed, m/s. Default 0.
    pub wind_speed_min: f64,
    /// Upper end of the per-episode mean wind speed, m/s. Default 5.
    pub wind_speed_max: f64,
    /// Mean reversion rate θ of the Ornstein–Uhlenbeck turbulence, 1/s. Default 0.5.
    pub turbulence_theta: f64,
    /// Diffusion σ of the horizontal turbulence, m/s/√s. Default 1.0 (stationary std σ/√(2θ) = 1 m/s).
    pub turbulence_sigma: f64,
    /// Vertical turbulence σ as a fraction of the horizontal one. Default 0.2.
    pub turbulence_vertical_ratio: f64,
    /// Time between turbulence samples, s: the wind's own grid, held between samples, so the
    /// weather does not depend on the step size a caller (an FMU master, a task) chooses.
    /// Default 0.01.
    pub turbulence_dt: f64,
}

impl Default for QuadrotorParams {
    fn default() -> Self {
        QuadrotorParams {
            mass: 1.0,
            arm_length: 0.10,
            inertia_xx: 0.01,
            inertia_yy: 0.01,
            inertia_zz: 0.02,
            gravity: 9.81,
            thrust_coefficient: 10.0,
            motor_time_constant: 0.08,
            yaw_torque_coefficient: 0.02,
            air_density: 1.225,
            drag_area: 0.02,
            angular_damping_linear: 0.02,
            angular_damping_quadratic: 0.002,
            pendulum_coefficient: 0.0,
            max_substep: 0.005,
            ground_enabled: true,
            gear_x: 0.07,
            gear_y: 0.07,
            gear_z: -0.05,
            gear_stiffness: 3000.0,
            gear_damping: 20.0,
            gear_friction: 0.5,
            contact_substep: 0.002,
            wind_enabled: true,
            wind_speed_min: 0.0,
            wind_speed_max: 5.0,
            turbulence_theta: 0.5,
            turbulence_sigma: 1.0,
            turbulence_vertical_ratio: 0.2,
            turbulence_dt: 0.01,
        }
    }
}

static QUADROTOR_SPECS: [ParamSpec<QuadrotorParams>; 30] = [
    param!(real mass, "kg", 1e-3, 1e4, "Vehicle mass"),
    param!(real arm_length, "m", 1e-3, 100.0, "Distance from the centre to each rotor"),
    param!(real inertia_xx, "kg.m2", 1e-7, 1e4, "Moment of inertia about body x (forward)"),
    param!(real inertia_yy, "kg.m2", 1e-7, 1e4, "Moment of inertia about body y (left)"),
    param!(real inertia_zz, "kg.m2", 1e-7, 1e4, "Moment of inertia about body z (up)"),
    param!(real gravity, "m/s2", 0.0, 100.0, "Gravitational acceleration"),
    param!(real thrust_coefficient, "N", 0.0, 1e6, "Thrust per motor at full motor state (T = k m^2)"),
    param!(real motor_time_constant, "s", 1e-4, 10.0, "First-order motor lag time constant"),
    param!(real yaw_torque_coefficient, "m", 0.0, 10.0, "Spin reaction torque per newton of thrust"),
    param!(real air_density, "kg/m3", 0.0, 100.0, "Air density"),
    param!(real drag_area, "m2", 0.0, 1e3, "Drag coefficient times reference area"),
    param!(real angular_damping_linear, "N.m.s/rad", 0.0, 1e3, "Linear angular damping"),
    param!(real angular_damping_quadratic, "N.m.s2/rad2", 0.0, 1e3, "Quadratic angular damping"),
    param!(real pendulum_coefficient, "m", 0.0, 10.0, "Non-physical restoring torque -c m g sin(roll|pitch); 0 = off"),
    param!(real max_substep, "s", 1e-6, 1.0, "Physics grid step: RK4 on the absolute grid k*max_substep, so any multiple of it as step size gives the same bits"),
    param!(boolean ground_enabled, "Ground plane z = 0 holds the vehicle on its four feet"),
    param!(boolean wind_enabled, "Wind (mean + turbulence) blows"),
    param!(real wind_speed_min, "m/s", 0.0, 100.0, "Lower end of the per-episode mean wind speed"),
    param!(real wind_speed_max, "m/s", 0.0, 100.0, "Upper end of the per-episode mean wind speed"),
    param!(real turbulence_theta, "1/s", 0.0, 100.0, "Ornstein-Uhlenbeck mean reversion rate"),
    param!(real turbulence_sigma, "m/s/s0.5", 0.0, 100.0, "Ornstein-Uhlenbeck diffusion (horizontal)"),
    param!(real turbulence_vertical_ratio, "1", 0.0, 10.0, "Vertical turbulence sigma / horizontal sigma"),
    param!(real gear_x, "m", 1e-3, 100.0, "Feet at body x = +-gear_x (forward)"),
    param!(real gear_y, "m", 1e-3, 100.0, "Feet at body y = +-gear_y (left)"),
    param!(real gear_z, "m", -100.0, 0.0, "Feet at body z = gear_z (up; below the centre of mass < 0)"),
    param!(real gear_stiffness, "N/m", 1.0, 1e9, "Normal and tangential stiffness of each foot"),
    param!(real gear_damping, "N.s/m", 1e-3, 1e9, "Normal and tangential damping of each foot"),
    param!(real gear_friction, "1", 0.0, 10.0, "Coulomb friction coefficient foot-ground"),
    param!(real contact_substep, "s", 1e-6, 1.0, "Largest RK4 substep while a foot may touch the ground (a grid interval is split into equal substeps)"),
    param!(real turbulence_dt, "s", 1e-4, 10.0, "Time between turbulence samples (the wind's own grid, independent of the step size)"),
];

impl Parameters for QuadrotorParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &QUADROTOR_SPECS
    }

    fn check_relations(&self) -> Result<(), ParamError> {
        if self.wind_speed_min > self.wind_speed_max {
            return Err(ParamError::Relation {
                name: "wind_speed_min",
                requirement: format!(
                    "wind_speed_min ({}) must not exceed wind_speed_max ({})",
                    Compact(self.wind_speed_min),
                    Compact(self.wind_speed_max)
                ),
            });
        }
        Ok(())
    }
}

impl QuadrotorParams {
    /// Motor state at which the four rotors of a quad together carry the weight: √(m g / 4k)
    /// (any frame: `Quadrotor::hover_motor_state`).
    /// Returns `None` when no motor state in [0, 1] can hover.
    pub fn hover_motor_state(&self) -> Option<f64> {
        let m = (self.mass * self.gravity / (4.0 * self.thrust_coefficient)).sqrt();
        (m.is_finite() && m <= 1.0).then_some(m)
    }
}

/// Initial conditions of a free-standing quadrotor (the FMU's start values). The gym tasks
/// sample their own starts instead.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct QuadrotorInitial {
    /// Seed of the instance's random generator (wind). Default 0.
    pub seed: u32,
    /// Initial position east, m. Default 0.
    pub initial_x: f64,
    /// Initial position north, m. Default 0.
    pub initial_y: f64,
    /// Initial height, m. Default 1.5.
    pub initial_z: f64,
    /// Initial velocity east, m/s. Default 0.
    pub initial_vx: f64,
    /// Initial velocity north, m/s. Default 0.
    pub initial_vy: f64,
    /// Initial velocity up, m/s. Default 0.
    pub initial_vz: f64,
    /// Initial roll (about body x, right side down positive), rad. Default 0.
    pub initial_roll: f64,
    /// Initial pitch (about body y, nose down positive), rad. Default 0.
    pub initial_pitch: f64,
    /// Initial yaw (from east toward north), rad. Default 0.
    pub initial_yaw: f64,
    /// Initial body rate about x, rad/s. Default 0.
    pub initial_wx: f64,
    /// Initial body rate about y, rad/s. Default 0.
    pub initial_wy: f64,
    /// Initial body rate about z, rad/s. Default 0.
    pub initial_wz: f64,
    /// Initial state of all four motors, 1. Default 0.
    pub initial_motor: f64,
}

impl Default for QuadrotorInitial {
    fn default() -> Self {
        QuadrotorInitial {
            seed: 0,
            initial_x: 0.0,
            initial_y: 0.0,
            initial_z: 1.5,
            initial_vx: 0.0,
            initial_vy: 0.0,
            initial_vz: 0.0,
            initial_roll: 0.0,
            initial_pitch: 0.0,
            initial_yaw: 0.0,
            initial_wx: 0.0,
            initial_wy: 0.0,
            initial_wz: 0.0,
            initial_motor: 0.0,
        }
    }
}

const FAR: f64 = 1e6;
const FAST: f64 = 1e3;
const PI: f64 = std::f64::consts::PI;

static INITIAL_SPECS: [ParamSpec<QuadrotorInitial>; 14] = [
    param!(integer seed, "", 0, i32::MAX, "Seed of the random generator (wind)"),
    param!(real initial_x, "m", -FAR, FAR, "Initial position east"),
    param!(real initial_y, "m", -FAR, FAR, "Initial position north"),
    param!(real initial_z, "m", -FAR, FAR, "Initial height"),
    param!(real initial_vx, "m/s", -FAST, FAST, "Initial velocity east"),
    param!(real initial_vy, "m/s", -FAST, FAST, "Initial velocity north"),
    param!(real initial_vz, "m/s", -FAST, FAST, "Initial velocity up"),
    param!(real initial_roll, "rad", -PI, PI, "Initial roll"),
    param!(real initial_pitch, "rad", -PI / 2.0, PI / 2.0, "Initial pitch"),
    param!(real initial_yaw, "rad", -PI, PI, "Initial yaw"),
    param!(real initial_wx, "rad/s", -FAST, FAST, "Initial body rate about x (forward)"),
    param!(real initial_wy, "rad/s", -FAST, FAST, "Initial body rate about y (left)"),
    param!(real initial_wz, "rad/s", -FAST, FAST, "Initial body rate about z (up)"),
    param!(real initial_motor, "1", 0.0, 1.0, "Initial state of all four motors"),
];

impl Parameters for QuadrotorInitial {
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
        assert_table_is_consistent::<QuadrotorParams>();
        assert_table_is_consistent::<QuadrotorInitial>();
    }

    #[test]
    fn every_bad_parameter_gets_its_error() {
        assert_every_bound_is_enforced::<QuadrotorParams>();
        assert_every_bound_is_enforced::<QuadrotorInitial>();
    }

    #[test]
    fn named_errors_for_the_classic_mistakes() {
        let cases = [
            (
                "mass",
                -1.0,
                "parameter `mass` = -1 kg is out of range: it must be in [0.001, 10000] kg",
            ),
            ("mass", 0.0, "parameter `mass` = 0 kg"),
            ("inertia_zz", 0.0, "`inertia_zz`"),
            (
                "motor_time_constant",
                0.0,
                "`motor_time_constant` = 0 s is out of range",
            ),
            ("max_substep", -0.01, "`max_substep`"),
            ("gravity", f64::NAN, "`gravity` = NaN"),
        ];
        for (name, value, expected) in cases {
            let mut p = QuadrotorParams::default();
            let err = p.set(name, value).unwrap_err().to_string();
            assert!(err.contains(expected), "{err}");
            assert_eq!(
                p,
                QuadrotorParams::default(),
                "a refused set changed the parameters"
            );
        }
    }

    #[test]
    fn wind_range_must_be_ordered() {
        let err = QuadrotorParams::from_toml_str("wind_speed_min = 6.0").unwrap_err();
        assert!(
            err.to_string()
                .contains("wind_speed_min (6) must not exceed wind_speed_max (5)")
        );
        let ok =
            QuadrotorParams::from_toml_str("wind_speed_min = 6.0\nwind_speed_max = 8.0").unwrap();
        assert_eq!(ok.wind_speed_min, 6.0);
    }

    #[test]
    fn files_load_and_name_their_mistakes() {
        let p = QuadrotorParams::from_toml_str("mass = 2\nground_enabled = false").unwrap();
        assert_eq!(p.mass, 2.0);
        assert!(!p.ground_enabled);
        let p = QuadrotorParams::from_json_str(r#"{"arm_length": 0.2, "wind_enabled": false}"#)
            .unwrap();
        assert_eq!(p.arm_length, 0.2);
        assert!(!p.wind_enabled);
        let e = QuadrotorParams::from_toml_str("mas = 2").unwrap_err();
        assert_eq!(e.to_string(), "unknown parameter `mas`");
        let e = QuadrotorParams::from_toml_str("mass = \"heavy\"").unwrap_err();
        assert!(e.to_string().contains("`mass` must be a number"), "{e}");
        let e = QuadrotorParams::from_toml_str("mass = ").unwrap_err();
        assert!(e.to_string().starts_with("invalid parameter file"), "{e}");
        let e = QuadrotorInitial::from_toml_str("seed = 1.5").unwrap_err();
        assert!(
            e.to_string().contains("`seed` = 1.5 is not an integer"),
            "{e}"
        );
    }

    #[test]
    fn hover_motor_state_is_the_analytic_value() {
        let m = QuadrotorParams::default().hover_motor_state().unwrap();
        assert!((m - 0.49523).abs() < 5e-6, "{m}");
        let heavy = QuadrotorParams {
            mass: 10.0,
            ..Default::default()
        };
        assert_eq!(heavy.hover_motor_state(), None);
    }
}
