//! The turbulence lives on its own time grid (`turbulence_dt`): the step size a caller picks
//! changes neither the wind samples nor, beyond integration accuracy, the path.

// Helpers are test code too: a failed setup is a failed test.

use flyloop_core::SimRng;
use flyloop_core::quadrotor::{BodyState, Quadrotor, QuadrotorParams};
use nalgebra::Vector3;

/// A windy vehicle (seed 11) at hover command, high above the ground, slightly tilted, so
/// the wind carries it and drag couples the path to the wind; the same for every run.
fn windy() -> Quadrotor {
    let params = QuadrotorParams {
        wind_speed_min: 2.0,
        wind_speed_max: 4.0,
        turbulence_sigma: 2.0,
        ..Default::default()
    };
    let hover = params.hover_motor_state().unwrap();
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 100.0), 0.02, -0.01, 0.2, hover);
    let mut quad = Quadrotor::new(params, body, SimRng::new(11)).unwrap();
    quad.set_command([hover; 4]).unwrap();
    quad
}

/// Flies `seconds` in steps of `h` (times n·h, never summed) and returns, at every multiple
/// of `every`, the wind and the position.
fn fly(h: f64, seconds: f64, every: f64) -> Vec<(f64, Vector3<f64>, Vector3<f64>)> {
    let mut quad = windy();
    let mut out = Vec::new();
    let steps = (seconds / h).round() as usize;
    let mut next = 0.0;
    for n in 0..=steps {
        let t = n as f64 * h;
        if (t - next).abs() < 1e-9 {
            out.push((t, quad.wind_velocity(), quad.body.position));
            next += every;
        }
        if n < steps {
            quad.step(h);
        }
    }
    out
}

#[test]
fn the_wind_samples_are_the_same_for_every_step_size() {
    let reference = fly(0.01, 5.0, 0.04);
    assert_eq!(reference.len(), 126);
    for h in [0.005, 0.02, 0.04] {
        let run = fly(h, 5.0, 0.04);
        assert_eq!(run.len(), reference.len(), "h = {h}");
        for (a, b) in reference.iter().zip(&run) {
            assert_eq!(a.1, b.1, "wind at t = {} with h = {h}", a.0);
        }
    }
    // The turbulence does move: it is not the same sample all along.
    let spread = (reference[0].1 - reference[100].1).norm();
    assert!(spread > 0.1, "turbulence moved {spread} m/s in 4 s");
}

#[test]
fn paths_for_different_step_sizes_agree_to_integration_accuracy() {
    let reference = fly(0.01, 5.0, 0.04);
    let moved = (reference[125].2 - reference[0].2).norm();
    assert!(moved > 0.3, "the wind carried the vehicle {moved} m");
    for h in [0.005, 0.02, 0.04] {
        let run = fly(h, 5.0, 0.04);
        let worst = reference
            .iter()
            .zip(&run)
            .map(|(a, b)| (a.2 - b.2).norm())
            .fold(0.0, f64::max);
        assert!(worst < 1e-6, "h = {h}: {worst} m from the h = 0.01 path");
    }
}

#[test]
fn a_step_size_off_the_grid_sees_the_same_weather() {
    // 0.0123 s never lands on the 0.01 s grid except at 1.23 s, 2.46 s, ...: the step is cut
    // at every sample time it crosses.
    let mut quad = windy();
    let mut reference = windy();
    for n in 1..=400 {
        quad.step(0.0123);
        let t = n as f64 * 0.0123;
        if n % 100 == 0 {
            // 1.23 s = 123 grid steps.
            for _ in 0..123 {
                reference.step(0.01);
            }
            assert_eq!(quad.wind_velocity(), reference.wind_velocity(), "t = {t}");
            let off = (quad.body.position - reference.body.position).norm();
            assert!(off < 1e-6, "t = {t}: {off} m");
        }
    }
}

#[test]
fn a_coarser_grid_is_a_parameter_and_holds_the_wind_between_samples() {
    let mut quad = windy();
    quad.params.turbulence_dt = 0.1;
    let start = quad.wind_velocity();
    for _ in 0..9 {
        quad.step(0.01);
        assert_eq!(quad.wind_velocity(), start, "held before the first sample");
    }
    quad.step(0.01);
    assert_ne!(quad.wind_velocity(), start, "sampled at 0.1 s");
}

#[test]
fn a_snapshot_keeps_the_position_on_the_wind_grid() {
    let mut quad = windy();
    quad.step(0.004);
    let bytes = quad.save().unwrap();
    let mut restored = Quadrotor::restore(&bytes).unwrap();
    for _ in 0..50 {
        quad.step(0.007);
        restored.step(0.007);
    }
    assert_eq!(quad, restored);
    assert_eq!(quad.wind_velocity(), restored.wind_velocity());
}
