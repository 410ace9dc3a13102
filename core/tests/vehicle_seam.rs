//! The vehicle seam (flyloop_core::vehicle::Vehicle) over both models: the multirotor and
//! the lander driven only through the trait behave as driven directly, refuse bad commands
//! whole, and fall as free bodies do.

use flyloop_core::CommandError;
use flyloop_core::lander2d::{DroneState, Lander2d, Lander2dParams};
use flyloop_core::quadrotor::{Quadrotor, QuadrotorParams};
use flyloop_core::rng::SimRng;
use flyloop_core::vehicle::{Kinematics, Vehicle};

/// No thrust noise, no wind: the lander as a deterministic free body.
fn quiet_lander(y: f64) -> Lander2d {
    let params = Lander2dParams {
        thrust_noise_std: 0.0,
        wind_enabled: false,
        ..Default::default()
    };
    let start = DroneState {
        x: 10.0,
        y,
        ..Default::default()
    };
    Lander2d::new(params, start, SimRng::new(7)).unwrap()
}

/// `seconds` of `command` in steps of `dt`, through the seam only.
fn fly<V: Vehicle>(vehicle: &mut V, command: &[f64], dt: f64, seconds: f64) -> Kinematics {
    vehicle.set_actuators(command).unwrap();
    for _ in 0..(seconds / dt).round() as usize {
        vehicle.advance(dt);
    }
    vehicle.kinematics()
}

fn bits(k: &Kinematics) -> Vec<u64> {
    (k.position.iter())
        .chain(k.velocity.iter())
        .chain(k.attitude.coords.iter())
        .chain(k.body_rates.iter())
        .map(|v| v.to_bits())
        .collect()
}

#[test]
fn the_lander_through_the_seam_is_the_lander_stepped_directly_bit_for_bit() {
    let mut direct = quiet_lander(30.0);
    direct.set_command([0.3, 0.1]).unwrap();
    for _ in 0..100 {
        direct.step();
    }
    let mut seam = quiet_lander(30.0);
    let dt = seam.params().dt;
    let through = fly(&mut seam, &[0.3, 0.1], dt, 100.0 * dt);
    assert_eq!(bits(&through), bits(&direct.kinematics()));
    assert_eq!(seam.actuators(), vec![0.3, 0.1]);
    // The rolled lander turned: the seam's attitude is not level.
    assert!(through.attitude.angle() > 1e-3);
}

#[test]
fn both_models_fall_freely_through_the_seam() {
    // Engines off, 0.5 s from rest, high above the ground: v = -g t (the quad's drag at
    // under 5 m/s and its motors spinning down leave it within 2 %).
    let mut lander = quiet_lander(40.0);
    let k = fly(&mut lander, &[-1.0, -1.0], 0.02, 0.5);
    let g = k.gravity;
    assert!((k.velocity.z + g * 0.5).abs() < 1e-9, "{}", k.velocity.z);
    assert!((k.specific_force_frd().norm()) < 1e-9);
    assert!(!lander.is_grounded() && lander.is_finite());

    let mut quad = Quadrotor::standing(QuadrotorParams::default(), 3).unwrap();
    quad.body.position.z = 50.0;
    let motors = vec![0.0; quad.actuator_count()];
    let k = fly(&mut quad, &motors, 0.004, 0.5);
    assert!(
        (k.velocity.z + k.gravity * 0.5).abs() < 0.02 * k.gravity * 0.5,
        "{}",
        k.velocity.z
    );
    assert!(!quad.is_grounded() && quad.is_finite());
}

#[test]
fn a_bad_command_is_refused_whole_by_both_models() {
    let mut lander = quiet_lander(30.0);
    lander.set_actuators(&[0.2, 0.4]).unwrap();
    let err = lander.set_actuators(&[0.1, 0.2, 0.3]).unwrap_err();
    assert_eq!(
        err,
        CommandError::WrongLength {
            what: "motor command",
            expected: 2,
            got: 3
        }
    );
    assert!(err.to_string().contains("takes 2"), "{err}");
    let err = lander.set_actuators(&[0.1, f64::NAN]).unwrap_err();
    assert!(err.to_string().contains("motor command 1"), "{err}");
    assert_eq!(lander.actuators(), vec![0.2, 0.4]);

    let mut quad = Quadrotor::standing(QuadrotorParams::default(), 3).unwrap();
    assert!(matches!(
        quad.set_actuators(&[0.5; 2]),
        Err(CommandError::WrongLength {
            expected: 4,
            got: 2,
            ..
        })
    ));
}

#[test]
fn a_lander_saved_through_the_seam_continues_bit_for_bit() {
    let mut a = quiet_lander(30.0);
    fly(&mut a, &[0.4, 0.2], 0.02, 0.3);
    let saved = a.save().unwrap();
    let mut b = Lander2d::restore(&saved).unwrap();
    let ka = fly(&mut a, &[0.1, 0.5], 0.02, 0.4);
    let kb = fly(&mut b, &[0.1, 0.5], 0.02, 0.4);
    assert_eq!(bits(&ka), bits(&kb));
}

#[test]
fn a_lander_at_rest_on_the_ground_is_grounded() {
    // Dropped from 2 m above the ground (at 10 m), engines off, beside the platform.
    let mut lander = quiet_lander(12.0);
    assert!(!lander.is_grounded());
    fly(&mut lander, &[-1.0, -1.0], 0.02, 3.0);
    assert!(
        lander.is_grounded(),
        "{:?} {:?}",
        lander.drone(),
        lander.contact()
    );
    assert!(lander.kinematics().velocity.norm() < 0.05);
}
