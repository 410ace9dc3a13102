//! Ground contact on the landing gear: the vehicle settles level on its feet, does not creep,
//! takes off again, rights itself after a tilted touchdown, and a drop loses energy at every
//! bounce until it rests. For the default vehicle and a PX4-iris-like one, at the default
//! 10 ms step and at PX4's 4 ms step.

// Helpers are test code too: a failed setup is a failed test.

use flyloop_core::SimRng;
use flyloop_core::quadrotor::contact::{foot_heights, gear_energy, rest_height};
use flyloop_core::quadrotor::{BodyState, Quadrotor, QuadrotorParams};
use nalgebra::Vector3;

fn still_air() -> QuadrotorParams {
    QuadrotorParams {
        wind_enabled: false,
        ..Default::default()
    }
}

/// Mass, inertia and arm close to PX4's iris (airframe 10016), thrust for a 0.6 hover, feet
/// under the rotors as in sitl/presets/px4_iris.toml.
fn iris() -> QuadrotorParams {
    QuadrotorParams {
        mass: 1.5,
        arm_length: 0.25,
        inertia_xx: 0.029,
        inertia_yy: 0.029,
        inertia_zz: 0.055,
        thrust_coefficient: 10.2,
        gear_x: 0.177,
        gear_y: 0.177,
        gear_z: -0.055,
        ..still_air()
    }
}

fn vehicle(params: QuadrotorParams, body: BodyState) -> Quadrotor {
    Quadrotor::new(params, body, SimRng::new(1)).unwrap()
}

fn run(quad: &mut Quadrotor, command: [f64; 4], seconds: f64, dt: f64) {
    quad.set_command(command).unwrap();
    for _ in 0..(seconds / dt).round() as usize {
        quad.step(dt);
    }
}

/// Kinetic + rotational + potential energy + the gear's springs and bristles, J.
fn energy(q: &Quadrotor) -> f64 {
    let p = &q.params;
    let b = &q.body;
    let inertia = Vector3::new(p.inertia_xx, p.inertia_yy, p.inertia_zz);
    0.5 * p.mass * b.velocity.norm_squared()
        + 0.5 * b.body_rates.dot(&inertia.component_mul(&b.body_rates))
        + p.mass * p.gravity * b.position.z
        + gear_energy(p, b)
}

fn tilt(q: &Quadrotor) -> f64 {
    let (roll, pitch, _) = q.body.euler_angles();
    roll.abs().max(pitch.abs())
}

#[test]
fn settles_level_on_its_feet_carrying_its_weight() {
    for (name, params) in [("default", still_air()), ("iris", iris())] {
        for dt in [0.01, 0.004] {
            let rest = rest_height(&params);
            let start = Vector3::new(0.5, -0.3, rest + 0.05);
            let mut quad = vehicle(
                params.clone(),
                BodyState::at_rest(start, 0.1, -0.05, 0.7, 0.0),
            );
            run(&mut quad, [0.0; 4], 4.0, dt);
            let b = &quad.body;
            // The feet carry m·g: the centre of mass sits at −gear_z − m·g/4k, level.
            assert!(
                (b.position.z - rest).abs() < 1e-7,
                "{name} {dt}: z {}",
                b.position.z
            );
            assert!(tilt(&quad) < 1e-6, "{name} {dt}: tilt {}", tilt(&quad));
            assert!(
                b.velocity.norm() < 1e-6 && b.body_rates.norm() < 1e-5,
                "{name} {dt}"
            );
            let (linear, angular) = quad.accelerations();
            assert!(linear.norm() < 1e-4 && angular.norm() < 1e-3, "{name} {dt}");
            assert!(quad.is_grounded());
            // Every foot carries its share: all four are pressed in by m·g/4k.
            let sag = params.mass * params.gravity / (4.0 * params.gear_stiffness);
            for h in quad.foot_heights() {
                assert!((h + sag).abs() < 1e-6, "{name} {dt}: foot at {h}");
            }
        }
    }
}

/// Regression: on the ground x/y drifted ~0.5 mm over 4 s in wind while vx, vy read 0. A
/// resting vehicle now holds its place: the wind deflects the friction bristles elastically
/// (F/4k, micrometres) and when the wind stops the vehicle is back where it stood.
#[test]
fn no_creep_on_the_ground_while_velocity_reads_zero() {
    let params = QuadrotorParams {
        wind_enabled: false,
        ..QuadrotorParams::default()
    };
    let body = BodyState::at_rest(
        Vector3::new(1.0, 2.0, rest_height(&params) + 0.01),
        0.0,
        0.0,
        0.3,
        0.0,
    );
    let mut quad = Quadrotor::new(params, body, SimRng::new(5)).unwrap();
    run(&mut quad, [0.0; 4], 1.0, 0.01);
    let settled = quad.body.position;
    // 5 m/s of wind with 1 m/s gusts for 4 s.
    quad.params.wind_enabled = true;
    quad.wind.mean = Vector3::new(4.0, 3.0, 0.0);
    let mut farthest: f64 = 0.0;
    for _ in 0..400 {
        quad.step(0.01);
        farthest = farthest.max((quad.body.position - settled).xy().norm());
    }
    assert!(farthest < 1e-4, "moved {farthest} m");
    assert!(quad.body.velocity.xy().norm() < 1e-3);
    quad.params.wind_enabled = false;
    quad.wind = Default::default();
    run(&mut quad, [0.0; 4], 1.0, 0.01);
    let moved = (quad.body.position - settled).norm();
    assert!(moved < 1e-7, "crept {moved} m");

    // A steady push: 5 m/s of wind on 0.02 m² is 0.30625 N downwind, held by the four
    // bristles (k·Σs = F, a few tens of micrometres); then no motion at all.
    let body = BodyState::at_rest(
        Vector3::new(0.0, 0.0, rest_height(&still_air())),
        0.0,
        0.0,
        0.0,
        0.0,
    );
    let mut quad = vehicle(still_air(), body);
    quad.external_wind = Vector3::new(5.0, 0.0, 0.0);
    run(&mut quad, [0.0; 4], 2.0, 0.01);
    let deflected = quad.body.position;
    let push = 0.5 * 1.225 * 0.02 * 25.0;
    let held: f64 = quad.body.gear_stretch.iter().map(|s| s[0]).sum::<f64>() * 3000.0;
    assert!((held - push).abs() < 1e-9, "{held}");
    assert!(deflected.x > 0.0 && deflected.x < 1e-4, "{}", deflected.x);
    run(&mut quad, [0.0; 4], 4.0, 0.01);
    assert!(
        (quad.body.position - deflected).norm() < 1e-9,
        "{:?}",
        quad.body.position
    );
}

#[test]
fn takes_off_when_thrust_exceeds_weight_and_stays_below_it() {
    for params in [still_air(), iris()] {
        let rest = rest_height(&params);
        let body = BodyState::at_rest(Vector3::new(0.0, 0.0, rest), 0.0, 0.0, 0.0, 0.0);
        let hover = params.hover_motor_state().unwrap();
        // 90 % of the hover state is 81 % of the weight: the feet carry the other 19 %.
        let mut quad = vehicle(params.clone(), body);
        run(&mut quad, [0.9 * hover; 4], 2.0, 0.01);
        let load = params.mass * params.gravity * (1.0 - 0.81);
        let expected = -params.gear_z - load / (4.0 * params.gear_stiffness);
        assert!(
            (quad.body.position.z - expected).abs() < 1e-7,
            "{}",
            quad.body.position.z
        );
        assert!(quad.is_grounded());
        // 120 % of it lifts off and climbs.
        run(&mut quad, [1.2 * hover; 4], 1.0, 0.01);
        assert!(quad.body.position.z > 0.5, "{}", quad.body.position.z);
        assert!(!quad.is_grounded());
        assert!(tilt(&quad) < 1e-9 && quad.body.position.xy().norm() < 1e-9);
    }
}

/// A landing at 0.5 m/s that meets the ground tilted by half a radian (lowest foot 5 mm up):
/// the low feet touch first, the vehicle tips onto all four and ends level.
#[test]
fn a_touchdown_tilted_half_a_radian_rights_itself() {
    for (name, params) in [("default", still_air()), ("iris", iris())] {
        for (roll, pitch) in [(0.5, 0.0), (0.0, -0.5), (0.35, 0.35)] {
            let mut body = BodyState::at_rest(Vector3::zeros(), roll, pitch, 0.2, 0.0);
            let lowest = foot_heights(&params, &body)
                .into_iter()
                .fold(f64::MAX, f64::min);
            body.position.z = 0.005 - lowest;
            body.velocity.z = -0.5;
            let mut quad = vehicle(params.clone(), body);
            run(&mut quad, [0.0; 4], 3.0, 0.01);
            let t = tilt(&quad);
            assert!(t < 1e-5, "{name} {roll} {pitch}: tilt {t}");
            let z = quad.body.position.z;
            assert!(
                (z - rest_height(&params)).abs() < 1e-6,
                "{name} {roll} {pitch}: z {z}"
            );
        }
    }
}

#[test]
fn a_dropped_vehicle_bounces_lower_each_time_and_comes_to_rest() {
    for (params, dt) in [(still_air(), 0.002), (still_air(), 0.004), (iris(), 0.002)] {
        // Feet 1 m above the ground.
        let start = Vector3::new(0.0, 0.0, 1.0 - params.gear_z);
        let mut quad = vehicle(
            params.clone(),
            BodyState::at_rest(start, 0.0, 0.0, 0.0, 0.0),
        );
        let mut previous = energy(&quad);
        let mut apexes = Vec::new();
        let mut rising = false;
        for _ in 0..(3.0 / dt) as usize {
            let vz = quad.body.velocity.z;
            quad.step(dt);
            let e = energy(&quad);
            assert!(e <= previous + 1e-9, "energy rose from {previous} to {e}");
            previous = e;
            if rising && quad.body.velocity.z <= 0.0 && vz > 0.0 {
                apexes.push(quad.body.position.z - rest_height(&params));
            }
            rising = quad.body.velocity.z > 0.0;
        }
        // Bounces that rise above the rest height by more than 0.1 mm, each lower.
        let bounces: Vec<f64> = apexes.into_iter().filter(|a| *a > 1e-4).collect();
        assert!(bounces.len() >= 2, "{bounces:?}");
        assert!(bounces[0] < 0.2, "first bounce {}", bounces[0]);
        for pair in bounces.windows(2) {
            assert!(pair[1] < 0.5 * pair[0], "{bounces:?}");
        }
        let b = &quad.body;
        assert!((b.position.z - rest_height(&params)).abs() < 1e-7);
        assert!(b.velocity.norm() < 1e-6 && tilt(&quad) < 1e-9);
        // At rest only the weight's sag is left: E = m·g·z + 4·½k·sag².
        let sag = params.mass * params.gravity / (4.0 * params.gear_stiffness);
        let rest_energy =
            params.mass * params.gravity * b.position.z + 2.0 * params.gear_stiffness * sag * sag;
        assert!((energy(&quad) - rest_energy).abs() < 1e-6);
    }
}

#[test]
fn standing_starts_level_at_the_origin_facing_north_with_the_gear_carrying_it() {
    for params in [still_air(), iris()] {
        let q = Quadrotor::standing(params.clone(), 4).unwrap();
        assert_eq!(
            q.body.position,
            Vector3::new(0.0, 0.0, rest_height(&params))
        );
        let (roll, pitch, yaw) = q.attitude().euler_angles();
        assert!(roll.abs() < 1e-12 && pitch.abs() < 1e-12, "{roll} {pitch}");
        assert!((yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12, "{yaw}");
        let (linear, _) = q.accelerations();
        assert!(linear.norm() < 1e-9, "the feet carry m·g: {linear}");
    }
    let windy = Quadrotor::standing(QuadrotorParams::default(), 4).unwrap();
    assert_eq!(windy.air_velocity(), -windy.wind_velocity(), "at rest");
}
