//! Flies the Hover task with a small cascaded PD controller and prints the flight.
//!
//! cargo run --release -p flyloop-core --example hover [-- SEED]
//!
//! The controller reads the vehicle's true state (world ENU, body FLU), asks for a tilt that
//! accelerates it toward the target, and mixes collective thrust and body torques into the
//! four PX4 quad-X motors (0 front-right, 1 rear-left, 2 front-left, 3 rear-right).

use flyloop_core::quadrotor::{BodyState, QuadrotorParams};
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::hover::Hover;
use flyloop_core::tasks::{InfoValue, Task};
use nalgebra::Vector3;
use std::process::ExitCode;

/// Motor commands that steer `body` toward `target` and hold it there.
fn pd_controller(p: &QuadrotorParams, body: &BodyState, target: &Vector3<f64>) -> [f64; 4] {
    let error = target - body.position;
    let v = body.velocity;
    // Desired acceleration (world), limited so the demanded tilt stays small.
    let ax = (1.2 * error.x - 1.8 * v.x).clamp(-3.0, 3.0);
    let ay = (1.2 * error.y - 1.8 * v.y).clamp(-3.0, 3.0);
    let az = (2.0 * error.z - 2.0 * v.z).clamp(-4.0, 4.0);
    let (roll, pitch, yaw) = body.euler_angles();
    // Rotate the horizontal demand into the yaw frame: +pitch accelerates forward, +roll
    // accelerates to the right (−y).
    let (s, c) = yaw.sin_cos();
    let forward = c * ax + s * ay;
    let left = -s * ax + c * ay;
    let pitch_wanted = (forward / p.gravity).clamp(-0.35, 0.35);
    let roll_wanted = (-left / p.gravity).clamp(-0.35, 0.35);
    let w = body.body_rates;
    let torque = Vector3::new(
        p.inertia_xx * (60.0 * (roll_wanted - roll) - 12.0 * w.x),
        p.inertia_yy * (60.0 * (pitch_wanted - pitch) - 12.0 * w.y),
        p.inertia_zz * (4.0 * (0.0 - yaw) - 3.0 * w.z),
    );
    let tilt = (roll.cos() * pitch.cos()).max(0.5);
    let thrust = p.mass * (p.gravity + az) / tilt;
    // Squared motor states from thrust and torques (inverse of the quad-X mixing).
    let k = p.thrust_coefficient;
    let lever = p.arm_length * std::f64::consts::FRAC_1_SQRT_2;
    let base = thrust / (4.0 * k);
    let r = torque.x / (4.0 * k * lever);
    let q = torque.y / (4.0 * k * lever);
    let y = torque.z / (4.0 * k * p.yaw_torque_coefficient);
    let squares = [
        base - r - q - y,
        base + r + q - y,
        base + r - q + y,
        base - r + q + y,
    ];
    squares.map(|s| s.max(0.0).sqrt().clamp(0.0, 1.0))
}

fn main() -> ExitCode {
    let seed = match std::env::args().nth(1).map(|s| s.parse::<u64>()) {
        None => 0,
        Some(Ok(seed)) => seed,
        Some(Err(e)) => {
            eprintln!("error: the seed must be a non-negative integer ({e})");
            return ExitCode::FAILURE;
        }
    };
    let flight = FlightParams {
        max_steps: 1500,
        ..FlightParams::default()
    };
    let mut task = match Hover::new(QuadrotorParams::default(), flight) {
        Ok(task) => task,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    task.reset(seed);
    println!(
        "Hover task, seed {seed}, PD controller, dt = {} s",
        task.dt()
    );
    println!(
        "{:>6} {:>22} {:>22} {:>8} {:>7} {:>6}",
        "t [s]", "position ENU [m]", "target [m]", "dist [m]", "reward", "wind"
    );
    let mut episode_return = 0.0;
    let mut step = 0u32;
    loop {
        let quad = task.air_vehicle();
        let action = pd_controller(quad.params(), quad.body(), &task.target());
        let outcome = match task.step(&action) {
            Ok(outcome) => outcome,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        };
        episode_return += outcome.reward;
        step += 1;
        if step % 100 == 0 || outcome.terminated || outcome.truncated {
            let quad = task.air_vehicle();
            let (p, t) = (quad.body().position, task.target());
            println!(
                "{:>6.2} {:>6.2} {:>7.2} {:>7.2} {:>6.2} {:>7.2} {:>7.2} {:>8.3} {:>7.3} {:>6.2}",
                f64::from(step) * task.dt(),
                p.x,
                p.y,
                p.z,
                t.x,
                t.y,
                t.z,
                (t - p).norm(),
                outcome.reward,
                quad.wind_velocity().norm(),
            );
        }
        if outcome.terminated || outcome.truncated {
            let crashed = task
                .info()
                .iter()
                .any(|(name, value)| *name == "crashed" && *value == InfoValue::Flag(true));
            println!(
                "episode over after {step} steps: return {episode_return:.1}, {}",
                if outcome.terminated {
                    if crashed { "crashed" } else { "out of bounds" }
                } else {
                    "time limit reached"
                }
            );
            return ExitCode::SUCCESS;
        }
    }
}
