//! Frames other than the quad X fly through the same core (issue 33): every shipped frame
//! hovers at its analytic motor state, a frame defined here and nowhere else hovers and
//! steers, a motor cut on a hexa yaws it the way its spin says, and a hexa's snapshot
//! continues bit for bit.

use flyloop_core::quadrotor::{
    BodyState, Frame, FrameTable, Quadrotor, QuadrotorParams, Rotor, Spin,
};
use flyloop_core::rng::SimRng;
use nalgebra::Vector3;

fn calm() -> QuadrotorParams {
    QuadrotorParams {
        wind_enabled: false,
        ground_enabled: false,
        ..QuadrotorParams::default()
    }
}

fn flying(frame: Frame, params: QuadrotorParams) -> Quadrotor {
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 10.0), 0.0, 0.0, 0.0, 0.0);
    let mut quad = Quadrotor::new(params, body, SimRng::new(5))
        .unwrap()
        .with_frame(frame);
    let hover = quad.hover_motor_state().unwrap();
    let n = quad.frame().rotor_count();
    quad.body.motors.iter_mut().for_each(|m| *m = hover);
    quad.set_command(vec![hover; n]).unwrap();
    quad
}

/// A pentacopter: five rotors on a circle, spins alternating but one pair, its own thrust
/// coefficient on one rotor. Defined in this test only.
fn pentacopter() -> Frame {
    let rotors = (0..5)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 5.0;
            let spin = if i % 2 == 0 { Spin::Cw } else { Spin::Ccw };
            Rotor {
                thrust_coefficient: (i == 4).then_some(12.0),
                ..Rotor::at(a.cos(), a.sin(), spin)
            }
        })
        .collect();
    Frame::new(FrameTable {
        name: "penta".into(),
        rotors,
    })
    .unwrap()
}

#[test]
fn every_frame_hovers_at_its_analytic_motor_state() {
    let frames = ["quad_x", "quad_plus", "hexa_x", "octo_x"]
        .map(|n| Frame::named(n).unwrap())
        .into_iter()
        .chain([pentacopter()]);
    for frame in frames {
        let name = frame.name().to_string();
        let n = frame.rotor_count();
        let mut quad = flying(frame, calm());
        assert_eq!((quad.body.motors.len(), quad.command().len()), (n, n));
        let hover = quad.hover_motor_state().unwrap();
        let (a, _) = quad.accelerations();
        assert!(a.z.abs() < 1e-12, "{name}: vertical acceleration {}", a.z);
        if name != "penta" {
            // Symmetric frames hold their height and attitude (the pentacopter's odd spin
            // count yaws it and its stronger rotor tilts it).
            for _ in 0..200 {
                quad.step(0.01);
            }
            let z = quad.body.position.z;
            assert!((z - 10.0).abs() < 1e-9, "{name}: {z}");
            let w = quad.body.body_rates;
            assert!(w.norm() < 1e-12, "{name}: {w}");
        }
        // Σk m² = m g: a hexa's rotors each carry a sixth.
        let total: f64 = quad
            .frame()
            .rotors()
            .iter()
            .map(|r| r.thrust_coefficient.unwrap_or(10.0))
            .sum();
        assert!((total * hover * hover - 9.81).abs() < 1e-12, "{name}");
    }
    let hexa = flying(Frame::named("hexa_x").unwrap(), calm());
    let expected = (9.81f64 / 60.0).sqrt();
    assert_eq!(hexa.hover_motor_state(), Some(expected));
}

#[test]
fn a_frame_defined_in_a_test_steers_by_its_table() {
    let mut quad = flying(pentacopter(), calm());
    let hover = quad.hover_motor_state().unwrap();
    // More thrust on the rotors left of the centre (y > 0) rolls the vehicle right (+x body
    // rate in FLU is left side up).
    let command: Vec<f64> = quad
        .frame()
        .rotors()
        .iter()
        .map(|r| if r.y > 0.1 { hover + 0.05 } else { hover })
        .collect();
    quad.set_command(&command).unwrap();
    for _ in 0..20 {
        quad.step(0.01);
    }
    assert!(quad.body.body_rates.x > 0.1, "{}", quad.body.body_rates);
}

#[test]
fn a_hexa_losing_one_motor_yaws_against_the_lost_spin_and_sinks() {
    let mut quad = flying(Frame::named("hexa_x").unwrap(), calm());
    let hover = quad.hover_motor_state().unwrap();
    // Rotor 0 turns clockwise: without it the counter-clockwise rotors win, the body turns
    // toward −z.
    let mut command = vec![hover; 6];
    command[0] = 0.0;
    quad.set_command(&command).unwrap();
    for _ in 0..100 {
        quad.step(0.01);
    }
    assert!(quad.body.body_rates.z < -0.1, "{}", quad.body.body_rates);
    assert!(quad.body.position.z < 9.9, "{}", quad.body.position.z);
    // A seven-value command for six rotors is refused, not truncated.
    assert!(quad.set_command([0.5; 7]).is_err());
}

#[test]
fn an_octo_snapshot_continues_bit_for_bit() {
    let params = QuadrotorParams::default();
    let mut a = flying(Frame::named("octo_x").unwrap(), params);
    let command: Vec<f64> = (0..8).map(|i| 0.3 + 0.02 * i as f64).collect();
    a.set_command(&command).unwrap();
    a.step(0.013);
    let mut b = Quadrotor::restore(&a.save().unwrap()).unwrap();
    assert_eq!(a, b);
    assert_eq!(b.frame().name(), "octo_x");
    for _ in 0..300 {
        a.step(0.004);
        b.step(0.004);
    }
    assert_eq!(a.body, b.body);
    assert!(
        a.body.body_rates.norm() > 1e-3,
        "the uneven command turns it"
    );
}
