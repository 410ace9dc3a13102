//! AttitudeController.fmu closes Quadrotor.fmu + RateController.fmu, all three wired by name
//! and stepped on the rate loop's 4 ms grid as a master that respects direct feedthrough
//! does it (plant outputs → attitude controller → rate controller → plant): it holds a hover,
//! follows a yaw step and a position step, holds a roll target with the position loop off, and
//! refuses bad inputs naming them.
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_fmu::fmi2_types::fmi2Status::{fmi2Error, fmi2OK};
use support::{Fmu, Model};

const TICK: f64 = 0.004;
const HOVER: f64 = 0.495_227_220_576_575_4; // √(9.81 / 40)
const PLANT_OUT: [&str; 9] = ["x", "y", "z", "vx", "vy", "vz", "roll", "pitch", "yaw"];
const SETPOINT: [&str; 4] = ["thrust", "roll_rate", "pitch_rate", "yaw_rate"];
const RATES: [&str; 3] = ["wx", "wy", "wz"];

struct Loop {
    plant: Fmu,
    rates: Fmu,
    attitude: Fmu,
}

impl Loop {
    fn new(attitude: &[(&str, f64)]) -> Loop {
        let plant = Fmu::started(
            Model::Quadrotor,
            0.0,
            &[
                ("seed", 1.0),
                ("initial_z", 1.0),
                ("initial_motor", HOVER),
                ("wind_enabled", 0.0),
            ],
        );
        let rates = Fmu::started(Model::RateController, 0.0, &[]);
        let attitude = Fmu::started(Model::AttitudeController, 0.0, attitude);
        Loop {
            plant,
            rates,
            attitude,
        }
    }

    /// Runs until `end` s.
    fn run(&self, end: f64) {
        let mut t = self.plant.time();
        while t < end - 1e-9 {
            for name in PLANT_OUT {
                assert_eq!(self.attitude.set(name, self.plant.get(name)), fmi2OK);
            }
            for name in SETPOINT {
                assert_eq!(self.rates.set(name, self.attitude.get(name)), fmi2OK);
            }
            for name in RATES {
                assert_eq!(self.rates.set(name, self.plant.get(name)), fmi2OK);
            }
            for i in 0..4 {
                let name = format!("motor_command_{i}");
                assert_eq!(self.plant.set(&name, self.rates.get(&name)), fmi2OK);
            }
            for fmu in [&self.plant, &self.rates, &self.attitude] {
                assert_eq!(fmu.do_step(t, TICK), fmi2OK);
            }
            t = self.plant.time();
        }
    }

    fn get(&self, name: &str) -> f64 {
        self.plant.get(name)
    }
}

#[test]
fn holds_a_hover_and_follows_a_yaw_step() {
    let l = Loop::new(&[("target_yaw", 0.5), ("step_time", 2.0)]);
    l.run(2.0);
    let level = [l.get("x"), l.get("y"), l.get("yaw")];
    assert!(
        level.iter().all(|v| v.abs() < 1e-9),
        "level hover at 2 s: {level:?}"
    );
    // PX4's PWM step (output_quantum 0.001) rounds the hover command down: a PD without an
    // integrator settles a little low (0.1 thrust per metre: ~2.4 mm).
    let sag = 1.0 - l.get("z");
    assert!(sag > 0.0 && sag < 5e-3, "height at 2 s: {}", l.get("z"));
    l.run(6.0);
    assert!((l.get("yaw") - 0.5).abs() < 1e-3, "yaw {}", l.get("yaw"));
    let still = [l.get("x"), l.get("y"), l.get("z") - 1.0];
    assert!(
        still.iter().all(|v| v.abs() < 1e-2),
        "position at 6 s: {still:?}"
    );
}

#[test]
fn flies_to_a_position_target() {
    // 1 m east and 0.5 m north, facing 1 rad off east: the tilt is turned into the body.
    let l = Loop::new(&[("target_x", 1.0), ("target_y", 0.5), ("target_yaw", 1.0)]);
    l.run(10.0);
    let error = [l.get("x") - 1.0, l.get("y") - 0.5, l.get("z") - 1.0];
    assert!(
        error.iter().all(|v| v.abs() < 0.02),
        "position error at 10 s: {error:?}"
    );
}

#[test]
fn holds_a_roll_target_with_the_position_loop_off() {
    let l = Loop::new(&[
        ("position_p", 0.0),
        ("position_d", 0.0),
        ("target_roll", 0.1),
    ]);
    l.run(1.0);
    assert!((l.get("roll") - 0.1).abs() < 2e-3, "roll {}", l.get("roll"));
    // Rolled right (FLU roll > 0), the vehicle accelerates toward −y (right of east-facing).
    assert!(l.get("vy") < -0.3, "vy {}", l.get("vy"));
}

#[test]
fn bad_inputs_and_parameters_are_refused_naming_them() {
    let c = Fmu::started(Model::AttitudeController, 0.0, &[]);
    assert_eq!(c.set("z", f64::NAN), fmi2Error);
    assert!(
        c.last_message().contains("`z` = NaN"),
        "{}",
        c.last_message()
    );
    let fresh = Fmu::new(Model::AttitudeController);
    assert_eq!(fresh.set("target_roll", 2.0), fmi2Error);
    let message = fresh.last_message();
    assert!(message.contains("`target_roll` = 2 rad"), "{message}");
}
