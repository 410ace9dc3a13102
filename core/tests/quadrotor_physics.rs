//! Analytic checks of the quadrotor dynamics: equilibrium, free fall, torque signs, motor
//! lag, conservation laws, drag, determinism (ground contact: quadrotor_ground.rs). "The
//! reference" below is seed 001's environment (docs/reference/quadrotor.md).

// Helpers are test code too: a failed setup is a failed test.

use flyloop_core::SimRng;
use flyloop_core::quadrotor::{BodyState, Quadrotor, QuadrotorParams};
use nalgebra::Vector3;

const DT: f64 = 0.01;

fn still_air() -> QuadrotorParams {
    QuadrotorParams {
        wind_enabled: false,
        ..Default::default()
    }
}

fn vehicle(params: QuadrotorParams, body: BodyState) -> Quadrotor {
    Quadrotor::new(params, body, SimRng::new(1)).unwrap()
}

fn fly(quad: &mut Quadrotor, command: [f64; 4], seconds: f64) {
    quad.set_command(command).unwrap();
    for _ in 0..(seconds / DT).round() as usize {
        quad.step(DT);
    }
}

#[test]
fn hover_equilibrium_at_the_analytic_command_holds_altitude() {
    let params = still_air();
    let hover = params.hover_motor_state().unwrap();
    assert!((hover - 0.49523).abs() < 1e-5);

    let start = Vector3::new(0.0, 0.0, 1.5);
    let mut quad = vehicle(
        params.clone(),
        BodyState::at_rest(start, 0.0, 0.0, 0.0, hover),
    );
    fly(&mut quad, [hover; 4], 10.0);
    assert!(
        (quad.body.position - start).norm() < 1e-9,
        "{:?}",
        quad.body.position
    );
    assert!(quad.body.velocity.norm() < 1e-9);
    assert!(quad.body.body_rates.norm() < 1e-12);
    let (acceleration, angular) = quad.accelerations();
    assert!(acceleration.norm() < 1e-9 && angular.norm() < 1e-12);

    // The rounded command 0.49523 carries 1.1e-4 N too much: 5.6 mm in 10 s, ½·(ΔT/m)·t².
    let mut quad = vehicle(params, BodyState::at_rest(start, 0.0, 0.0, 0.0, 0.49523));
    fly(&mut quad, [0.49523; 4], 10.0);
    let excess = 40.0 * 0.49523f64.powi(2) - 9.81;
    let expected_rise = 0.5 * excess * 100.0;
    assert!(
        (quad.body.position.z - 1.5 - expected_rise).abs() < 1e-4,
        "{}",
        quad.body.position.z
    );
}

#[test]
fn free_fall_matches_half_g_t_squared() {
    let params = QuadrotorParams {
        drag_area: 0.0,
        ..still_air()
    };
    let mut quad = vehicle(
        params,
        BodyState::at_rest(Vector3::new(3.0, -2.0, 100.0), 0.2, -0.1, 1.0, 0.0),
    );
    fly(&mut quad, [0.0; 4], 2.0);
    let t = 2.0;
    assert!((quad.body.position.z - (100.0 - 0.5 * 9.81 * t * t)).abs() < 1e-9);
    assert!((quad.body.velocity.z + 9.81 * t).abs() < 1e-9);
    assert!((quad.body.position.xy() - nalgebra::Vector2::new(3.0, -2.0)).norm() < 1e-12);
    assert!((quad.accelerations().0.z + 9.81).abs() < 1e-12);
}

/// Raises the right-hand motors (0 front-right, 3 rear-right) by 0.02 over hover for 0.3 s.
fn right_motors_up(yaw: f64) -> Quadrotor {
    let params = still_air();
    let h = params.hover_motor_state().unwrap();
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 5.0), 0.0, 0.0, yaw, h);
    let mut quad = vehicle(params, body);
    fly(&mut quad, [h + 0.02, h, h, h + 0.02], 0.3);
    quad
}

#[test]
fn raising_the_right_motors_tilts_the_right_side_up_and_pushes_toward_plus_y() {
    // Regression: the reference's roll/pitch torques acted as if the rotors were rotated 90°.
    let quad = right_motors_up(0.0);
    let (roll, pitch, _) = quad.body.euler_angles();
    // FLU: positive roll lowers the right side, so "right side up" is negative roll.
    assert!(roll < -0.05, "roll {roll}");
    assert!(pitch.abs() < 1e-9, "pitch {pitch}");
    // The right-hand rotor arm (body −y) now points upward in the world.
    let right_rotor_world = quad.attitude() * Vector3::new(0.0, -0.1, 0.0);
    assert!(right_rotor_world.z > 0.0);
    assert!(quad.body.velocity.y > 0.01, "vy {}", quad.body.velocity.y);
    assert!(
        quad.body.velocity.x.abs() < 1e-9,
        "vx {}",
        quad.body.velocity.x
    );
}

#[test]
fn the_same_command_at_yaw_90_pushes_toward_minus_x() {
    // Regression: the reference integrated body torques as world rates, so its response did
    // not turn with the vehicle.
    let quad = right_motors_up(std::f64::consts::FRAC_PI_2);
    assert!(quad.body.velocity.x < -0.01, "vx {}", quad.body.velocity.x);
    assert!(
        quad.body.velocity.y.abs() < 1e-9,
        "vy {}",
        quad.body.velocity.y
    );
    let reference = right_motors_up(0.0);
    // Same speed, turned by 90°: the response rotates with the vehicle.
    assert!((quad.body.velocity.x + reference.body.velocity.y).abs() < 1e-12);
}

#[test]
fn front_motors_up_pitch_the_nose_up() {
    let params = still_air();
    let h = params.hover_motor_state().unwrap();
    let mut quad = vehicle(
        params,
        BodyState::at_rest(Vector3::new(0.0, 0.0, 5.0), 0.0, 0.0, 0.0, h),
    );
    fly(&mut quad, [h + 0.02, h, h + 0.02, h], 0.3);
    let (roll, pitch, _) = quad.body.euler_angles();
    // Nose up is negative pitch (positive pitch turns body x toward −z); thrust then points back.
    assert!(
        pitch < -0.05 && roll.abs() < 1e-9,
        "pitch {pitch} roll {roll}"
    );
    assert!(quad.body.velocity.x < -0.01);
}

#[test]
fn ccw_cw_imbalance_yaws_the_documented_way() {
    let params = still_air();
    let h = params.hover_motor_state().unwrap();
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 5.0), 0.0, 0.0, 0.0, h);
    // CCW rotors (0, 1) faster: their reaction turns the body clockwise seen from above (−z).
    let mut ccw = vehicle(params.clone(), body);
    fly(&mut ccw, [h + 0.05, h + 0.05, h - 0.05, h - 0.05], 0.5);
    // CW rotors (2, 3) faster: counter-clockwise (+z).
    let mut cw = vehicle(params, body);
    fly(&mut cw, [h - 0.05, h - 0.05, h + 0.05, h + 0.05], 0.5);
    assert!(ccw.body.body_rates.z < -0.1, "{}", ccw.body.body_rates.z);
    assert!(cw.body.body_rates.z > 0.1, "{}", cw.body.body_rates.z);
    assert!((ccw.body.body_rates.z + cw.body.body_rates.z).abs() < 1e-9);
    // The diagonal pairs cancel each other's roll and pitch torques.
    for quad in [&ccw, &cw] {
        let (roll, pitch, _) = quad.body.euler_angles();
        assert!(roll.abs() < 1e-12 && pitch.abs() < 1e-12, "{roll} {pitch}");
    }
    // Initial yaw acceleration = Σ spin·c·T / Izz with T from the lagged motors (all at h).
    let mut fresh = vehicle(still_air(), body);
    fresh.body.motors = [h + 0.05, h + 0.05, h - 0.05, h - 0.05].into();
    let t_fast = 10.0 * (h + 0.05f64).powi(2);
    let t_slow = 10.0 * (h - 0.05f64).powi(2);
    let expected = 0.02 * 2.0 * (t_slow - t_fast) / 0.02;
    assert!((fresh.accelerations().1.z - expected).abs() < 1e-12);
}

#[test]
fn motor_lag_reaches_63_percent_in_tau() {
    let params = QuadrotorParams {
        ground_enabled: false,
        ..still_air()
    };
    let tau = params.motor_time_constant;
    let mut quad = vehicle(
        params,
        BodyState::at_rest(Vector3::zeros(), 0.0, 0.0, 0.0, 0.0),
    );
    fly(&mut quad, [1.0; 4], tau);
    let expected = 1.0 - (-1.0f64).exp();
    for m in quad.body.motors {
        assert!(
            (m - expected).abs() < 1e-6,
            "motor {m}, expected {expected}"
        );
    }
}

#[test]
fn torque_free_spin_conserves_energy_and_angular_momentum() {
    // No drag, no damping, motors off: only the gyroscopic term ω × Iω acts.
    let params = QuadrotorParams {
        inertia_xx: 0.01,
        inertia_yy: 0.015,
        inertia_zz: 0.02,
        drag_area: 0.0,
        angular_damping_linear: 0.0,
        angular_damping_quadratic: 0.0,
        ground_enabled: false,
        ..still_air()
    };
    let inertia = Vector3::new(0.01, 0.015, 0.02);
    let mut body = BodyState::at_rest(Vector3::zeros(), 0.3, -0.2, 0.5, 0.0);
    let w0 = Vector3::new(3.0, 0.5, 2.0);
    body.body_rates = w0;
    let mut quad = vehicle(params, body);
    let energy = |q: &Quadrotor| {
        0.5 * q
            .body
            .body_rates
            .dot(&inertia.component_mul(&q.body.body_rates))
    };
    let momentum = |q: &Quadrotor| q.attitude() * inertia.component_mul(&q.body.body_rates);
    let (e0, l0) = (energy(&quad), momentum(&quad));
    fly(&mut quad, [0.0; 4], 10.0);
    let (e1, l1) = (energy(&quad), momentum(&quad));
    assert!((e1 - e0).abs() / e0 < 1e-6, "energy {e0} -> {e1}");
    assert!(
        (l1 - l0).norm() / l0.norm() < 1e-6,
        "momentum {l0:?} -> {l1:?}"
    );
    // The body rates did change: the gyroscopic term is really there.
    assert!(
        (quad.body.body_rates - w0).norm() > 0.5,
        "{:?}",
        quad.body.body_rates
    );
    assert!((quad.body.attitude.norm() - 1.0).abs() < 1e-12);
}

#[test]
fn finer_substeps_converge_to_the_same_trajectory() {
    let run = |max_substep: f64| {
        let params = QuadrotorParams {
            max_substep,
            ..still_air()
        };
        let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 5.0), 0.1, -0.1, 0.3, 0.5);
        let mut quad = vehicle(params, body);
        fly(&mut quad, [0.6, 0.4, 0.55, 0.45], 1.0);
        quad.body
    };
    let coarse = run(0.01);
    let fine = run(0.001);
    assert!((coarse.position - fine.position).norm() < 1e-6);
    assert!((coarse.body_rates - fine.body_rates).norm() < 1e-6);
}

#[test]
fn wind_acts_through_drag_on_the_air_relative_velocity() {
    let params = still_air();
    let h = params.hover_motor_state().unwrap();
    let mut quad = vehicle(
        params,
        BodyState::at_rest(Vector3::new(0.0, 0.0, 2.0), 0.0, 0.0, 0.0, h),
    );
    quad.set_command([h; 4]).unwrap();
    quad.external_wind = Vector3::new(5.0, 0.0, 0.0);
    // ½ ρ CdA |v_rel| v_rel / m with v_rel = −5 m/s east: 0.30625 m/s² toward +x.
    let a = quad.accelerations().0;
    assert!((a.x - 0.5 * 1.225 * 0.02 * 25.0).abs() < 1e-12, "{a:?}");
    assert!(a.y.abs() < 1e-15 && a.z.abs() < 1e-12);
}

#[test]
fn pendulum_torque_is_off_by_default_and_restoring_when_on() {
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 5.0), 0.3, -0.2, 0.0, 0.0);
    let off = vehicle(still_air(), body);
    assert_eq!(off.accelerations().1, Vector3::zeros());
    let on = vehicle(
        QuadrotorParams {
            pendulum_coefficient: 0.003,
            ..still_air()
        },
        body,
    );
    let (roll, pitch, _) = body.euler_angles();
    let alpha = on.accelerations().1;
    assert!((alpha.x + 0.003 * 9.81 * roll.sin() / 0.01).abs() < 1e-12);
    assert!((alpha.y + 0.003 * 9.81 * pitch.sin() / 0.01).abs() < 1e-12);
}

#[test]
fn same_seed_gives_a_bit_identical_trajectory() {
    let run = |seed: u64| {
        let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 3.0), 0.05, 0.0, 0.0, 0.5);
        let mut quad = Quadrotor::new(QuadrotorParams::default(), body, SimRng::new(seed)).unwrap();
        let mut commands = SimRng::new(99);
        let mut trace = Vec::new();
        for _ in 0..2000 {
            let c = [0.0; 4].map(|_: f64| commands.uniform(0.45, 0.55));
            quad.set_command(c).unwrap();
            quad.step(DT);
            let b = &quad.body;
            trace.extend([
                b.position.x,
                b.position.y,
                b.position.z,
                b.attitude.w,
                b.attitude.i,
            ]);
            trace.extend(quad.wind_velocity().iter());
        }
        trace.into_iter().map(f64::to_bits).collect::<Vec<u64>>()
    };
    assert_eq!(run(7), run(7));
    assert_ne!(run(7), run(8));
}

#[test]
fn a_snapshot_continues_bit_identically() {
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 3.0), 0.05, 0.0, 0.0, 0.5);
    let mut quad = Quadrotor::new(QuadrotorParams::default(), body, SimRng::new(3)).unwrap();
    fly(&mut quad, [0.5, 0.49, 0.51, 0.5], 1.0);
    let saved = serde_json::to_string(&quad).unwrap();
    fly(&mut quad, [0.5, 0.49, 0.51, 0.5], 1.0);
    let mut restored: Quadrotor = serde_json::from_str(&saved).unwrap();
    fly(&mut restored, [0.5, 0.49, 0.51, 0.5], 1.0);
    assert_eq!(
        serde_json::to_string(&quad).unwrap(),
        serde_json::to_string(&restored).unwrap()
    );
}

#[test]
fn saved_bytes_restore_an_instance_that_continues_bit_identically() {
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 3.0), 0.05, 0.0, 0.0, 0.5);
    let mut quad = Quadrotor::new(QuadrotorParams::default(), body, SimRng::new(4)).unwrap();
    fly(&mut quad, [0.5, 0.49, 0.51, 0.5], 0.5);
    let bytes = quad.save().unwrap();
    fly(&mut quad, [0.52, 0.49, 0.51, 0.5], 1.0);
    let mut restored = Quadrotor::restore(&bytes).unwrap();
    fly(&mut restored, [0.52, 0.49, 0.51, 0.5], 1.0);
    assert_eq!(quad.save().unwrap(), restored.save().unwrap());
    assert!(Quadrotor::restore(b"not a snapshot at all").is_err());
    let mut damaged = bytes.clone();
    damaged[20] ^= 0x10;
    assert!(Quadrotor::restore(&damaged).is_err());
}

#[test]
fn non_finite_commands_are_refused_and_out_of_range_ones_clamped() {
    let mut quad = vehicle(
        still_air(),
        BodyState::at_rest(Vector3::zeros(), 0.0, 0.0, 0.0, 0.0),
    );
    quad.set_command([0.2, 0.3, 0.4, 0.5]).unwrap();
    let err = quad.set_command([0.1, f64::NAN, 0.1, 0.1]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "motor command 1 is NaN, not a finite number"
    );
    assert_eq!(quad.command(), [0.2, 0.3, 0.4, 0.5]);
    // Regression (issue 33): a command vector of the wrong length is refused whole, never
    // truncated or padded.
    let err = quad.set_command([0.9; 6]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "motor command has 6 values, the vehicle takes 4"
    );
    assert!(quad.set_command([0.9; 3]).is_err());
    assert_eq!(quad.command(), [0.2, 0.3, 0.4, 0.5]);
    assert!(quad.set_command([f64::INFINITY, 0.0, 0.0, 0.0]).is_err());
    quad.set_command([-1.0, 2.0, 0.5, 1.0]).unwrap();
    assert_eq!(quad.command(), [0.0, 1.0, 0.5, 1.0]);
}
