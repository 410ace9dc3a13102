//! The autopilot parameters that make PX4's or ArduPilot's mixer match the vehicle's rotor
//! table (`--print-autopilot-params px4|ardupilot`), so the simulated vehicle and the
//! autopilot always agree on where each motor is and which way it turns.
//!
//! PX4 takes any multirotor as a table (`CA_ROTORn_PX/PY/KM/CT`, body FRD, metres): the
//! core's [`px4_rotors`] of the frame (what the rate-loop model mixes for too; the quad X's are
//! PX4's stock none_iris values, which PX4 flies it with), motor n on output n (`PWM_MAIN_FUNCn = 100 + n`, which
//! PX4's simulator link sends as HIL_ACTUATOR_CONTROLS controls[n − 1]). ArduPilot mixes only
//! its own frame classes (AP_MotorsMatrix): the shipped frames are its quad X and plus, hexa X
//! and octo X, whose motor order is the table's (checked against AP_MotorsMatrix's motor
//! angles in this module's tests), and a frame it has no class for is refused.

use crate::telemetry::multirotor_mav_type;
use flyloop_core::quadrotor::{Frame, QuadrotorParams};
use flyloop_core::rate_loop::px4_rotors::{NONE_IRIS, px4_rotors};
use mavlink::dialects::common::MavType;
use std::fmt::Write;

/// Which autopilot's parameters to print.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Autopilot {
    Px4,
    Ardupilot,
}

/// PX4's MAV_TYPE for a multirotor of `rotors` rotors: the ground-station HEARTBEAT's
/// ([`multirotor_mav_type`]) where PX4's airframes name it (quad 2, hexa 13, octo 14);
/// other counts stay the quadrotor PX4 mode has always set.
fn px4_mav_type(rotors: usize) -> u8 {
    match multirotor_mav_type(rotors) {
        t @ (MavType::MAV_TYPE_HEXAROTOR | MavType::MAV_TYPE_OCTOROTOR) => t as u8,
        _ => MavType::MAV_TYPE_QUADROTOR as u8,
    }
}

/// PX4 `NAME VALUE` lines for the frame (PX4 SITL takes each at start-up as the environment
/// variable `PX4_PARAM_NAME=VALUE`).
pub fn px4(frame: &Frame, params: &QuadrotorParams) -> String {
    let mut out = String::new();
    let mut line = |name: String, value: String| {
        let _ = writeln!(out, "{name} {value}");
    };
    line("CA_AIRFRAME".into(), "0".into());
    line(
        "MAV_TYPE".into(),
        px4_mav_type(frame.rotor_count()).to_string(),
    );
    line("CA_ROTOR_COUNT".into(), frame.rotor_count().to_string());
    // The same rotors the core's rate-loop model mixes for (the quad X: PX4's stock none_iris).
    for (i, r) in px4_rotors(frame, params).iter().enumerate() {
        let iris = NONE_IRIS.get(i);
        let kept = |value: f64, iris: Option<f64>, default: f64| kept_by_px4(value, iris, default);
        line(
            format!("CA_ROTOR{i}_PX"),
            kept(r.px, iris.map(|s| s.px), 0.0),
        );
        line(
            format!("CA_ROTOR{i}_PY"),
            kept(r.py, iris.map(|s| s.py), 0.0),
        );
        line(
            format!("CA_ROTOR{i}_KM"),
            kept(r.km, iris.map(|s| s.km), 0.05),
        );
        line(format!("CA_ROTOR{i}_CT"), round(r.ct));
    }
    for n in 1..=frame.rotor_count() {
        line(format!("PWM_MAIN_FUNC{n}"), (100 + n).to_string());
    }
    out
}

/// `value` as printed so that PX4 keeps it. PX4 SITL applies its `PX4_PARAM_*` variables
/// before the airframe script and drops one equal to the firmware's default (`default`:
/// nothing to store); none_iris's `param set-default` then puts the Iris's value (`iris`) in
/// its place. Measured: a hexa's `CA_ROTOR0_PX 0` became 0.1515 and PX4 pitched on every roll
/// step. Such a value is printed one step (1e-6) off the default, which PX4 keeps; the model
/// mixes for the exact table (a 1e-6 m difference).
fn kept_by_px4(value: f64, iris: Option<f64>, default: f64) -> String {
    let printed = round(value);
    match iris {
        Some(iris) if printed == round(default) && printed != round(iris) => round(value + 1e-6),
        _ => printed,
    }
}

/// A number as PX4's float parameters print it: six decimals at most, no trailing zeros.
fn round(v: f64) -> String {
    let s = format!("{:.6}", v + 0.0);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// ArduPilot's FRAME_CLASS and FRAME_TYPE of the shipped frames.
const ARDUPILOT_CLASSES: [(&str, u8, u8, &str); 4] = [
    ("quad_x", 1, 1, "quad X"),
    ("quad_plus", 1, 0, "quad plus"),
    ("hexa_x", 2, 1, "hexa X"),
    ("octo_x", 3, 1, "octo X"),
];

/// ArduPilot `.parm` lines for the frame, or why ArduPilot cannot mix it.
pub fn ardupilot(frame: &Frame) -> Result<String, String> {
    let shipped = Frame::named(frame.name()).ok();
    let class = ARDUPILOT_CLASSES
        .iter()
        .find(|(name, ..)| *name == frame.name())
        .filter(|_| shipped.is_some_and(|s| s.rotors() == frame.rotors()));
    let Some((_, class, kind, text)) = class else {
        return Err(format!(
            "ArduPilot mixes only its own frame classes; frame `{}` is not one of flyloop's frames it has a class for ({})",
            frame.name(),
            ARDUPILOT_CLASSES.map(|c| c.0).join(", ")
        ));
    };
    let mut out = format!(
        "# ArduPilot's {text} (AP_MotorsMatrix): motor n on servo output n is flyloop's rotor n - 1.\n\
         FRAME_CLASS {class}\nFRAME_TYPE {kind}\n"
    );
    // Servo functions 33..40 are motors 1..8; a hexa's outputs 5 and 6 are not motors in
    // copter.parm's quad defaults.
    for n in 1..=frame.rotor_count() {
        let _ = writeln!(out, "SERVO{n}_FUNCTION {}", 32 + n);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// PX4's own airframe tables, for the geometry only (positions scaled to unit arm
    /// length, FRD): 6001 hexa_x and 8001 octo_x (PX4 v1.16.0), 5001 quad_+.
    #[test]
    fn px4_rotor_tables_match_px4s_airframes_in_order_and_spin() {
        let unit = QuadrotorParams {
            arm_length: 1.0,
            ..QuadrotorParams::default()
        };
        let hexa = px4(&Frame::named("hexa_x").unwrap(), &unit);
        // (px, py, km sign) per rotor from PX4's 6001_hexa_x (PY 0.5 there = arm 0.5).
        let expected = [
            (0.0, 1.0, -1.0),
            (0.0, -1.0, 1.0),
            (0.866025, -0.5, -1.0),
            (-0.866025, 0.5, 1.0),
            (0.866025, 0.5, 1.0),
            (-0.866025, -0.5, -1.0),
        ];
        check(&hexa, &expected);
        let c = 0.92388;
        let s = 0.382683;
        let octo = px4(&Frame::named("octo_x").unwrap(), &unit);
        check(
            &octo,
            &[
                (c, s, -1.0),
                (-c, -s, -1.0),
                (s, c, 1.0),
                (-c, s, 1.0),
                (c, -s, 1.0),
                (-s, -c, 1.0),
                (s, -c, -1.0),
                (-s, c, -1.0),
            ],
        );
        let plus = px4(&Frame::named("quad_plus").unwrap(), &unit);
        check(
            &plus,
            &[
                (0.0, 1.0, 1.0),
                (0.0, -1.0, 1.0),
                (1.0, 0.0, -1.0),
                (-1.0, 0.0, -1.0),
            ],
        );
        assert!(octo.contains("MAV_TYPE 14\n") && octo.contains("PWM_MAIN_FUNC8 108\n"));
        assert!(hexa.contains("CA_ROTOR_COUNT 6\n") && hexa.contains("CA_ROTOR5_CT 10\n"));
    }

    /// The quad X is what PX4 flies it with: its stock none_iris rotors (the numbers the
    /// core's rate-loop model mixes for).
    #[test]
    fn the_quad_x_prints_px4s_none_iris_rotors() {
        let text = px4(&Frame::quad_x(), &QuadrotorParams::default());
        for line in [
            "CA_ROTOR_COUNT 4",
            "CA_ROTOR0_PX 0.1515",
            "CA_ROTOR0_PY 0.245",
            "CA_ROTOR0_KM 0.05",
            "CA_ROTOR1_PY -0.1875",
            "CA_ROTOR3_KM -0.05",
            "CA_ROTOR3_CT 6.5",
        ] {
            assert!(text.contains(&format!("{line}\n")), "{line} in {text}");
        }
    }

    /// Regression (issue 33): PX4 drops a `PX4_PARAM_` value equal to its firmware default
    /// and none_iris then re-defaults it (a hexa's rotor 0 flew with the Iris's x = 0.1515 m):
    /// such values print one step off the default; values none_iris shares stay as they are.
    #[test]
    fn values_px4_would_drop_for_none_iris_defaults_print_one_step_off() {
        let hexa = px4(
            &Frame::named("hexa_x").unwrap(),
            &QuadrotorParams::default(),
        );
        assert!(
            hexa.contains("CA_ROTOR0_PX 0.000001\n") && hexa.contains("CA_ROTOR1_PX 0.000001\n")
        );
        // Rotors past none_iris's four keep their exact values.
        let plus = px4(
            &Frame::named("quad_plus").unwrap(),
            &QuadrotorParams::default(),
        );
        assert!(plus.contains("CA_ROTOR2_PY 0.000001\n"), "{plus}");
        let km = QuadrotorParams {
            yaw_torque_coefficient: 0.05,
            ..QuadrotorParams::default()
        };
        let hexa = px4(&Frame::named("hexa_x").unwrap(), &km);
        // Rotor 1 turns counter-clockwise: KM 0.05 is the default and none_iris's rotor 1 too.
        assert!(hexa.contains("CA_ROTOR1_KM 0.05\n") && hexa.contains("CA_ROTOR3_KM 0.050001\n"));
        assert!(hexa.contains("CA_ROTOR4_KM 0.05\n"), "{hexa}");
    }

    fn check(text: &str, expected: &[(f64, f64, f64)]) {
        let value = |name: String| -> f64 {
            let line = text.lines().find(|l| l.split(' ').next() == Some(&name));
            line.and_then(|l| l.split(' ').nth(1)?.parse().ok())
                .unwrap()
        };
        for (i, (px, py, km)) in expected.iter().enumerate() {
            assert!(
                (value(format!("CA_ROTOR{i}_PX")) - px).abs() < 1e-5,
                "{i} {text}"
            );
            assert!(
                (value(format!("CA_ROTOR{i}_PY")) - py).abs() < 1e-5,
                "{i} {text}"
            );
            assert_eq!(value(format!("CA_ROTOR{i}_KM")).signum(), *km, "{i}");
        }
    }

    /// AP_MotorsMatrix's motor angles (degrees clockwise from forward) and spins for hexa X
    /// and octo X (ArduCopter 4.6): motor n must be the table's rotor n − 1.
    #[test]
    fn ardupilot_motor_order_is_the_tables() {
        let cw = 1.0;
        let ccw = -1.0;
        let hexa = [
            (90.0, cw),
            (-90.0, ccw),
            (-30.0, cw),
            (150.0, ccw),
            (30.0, ccw),
            (-150.0, cw),
        ];
        let octo = [
            (22.5, cw),
            (-157.5, cw),
            (67.5, ccw),
            (157.5, ccw),
            (-22.5, ccw),
            (-112.5, ccw),
            (-67.5, cw),
            (112.5, cw),
        ];
        let quad_x = [(45.0, ccw), (-135.0, ccw), (-45.0, cw), (135.0, cw)];
        let plus = [(90.0, ccw), (-90.0, ccw), (0.0, cw), (180.0, cw)];
        for (name, motors) in [
            ("hexa_x", &hexa[..]),
            ("octo_x", &octo[..]),
            ("quad_x", &quad_x[..]),
            ("quad_plus", &plus[..]),
        ] {
            let f = Frame::named(name).unwrap();
            for (r, (angle, spin)) in f.rotors().iter().zip(motors) {
                let a: f64 = f64::to_radians(*angle);
                // FLU: x forward = cos, y left = −sin (the angle turns toward the right).
                let (x, y) = (a.cos(), -a.sin());
                let norm = r.x.hypot(r.y);
                assert!(
                    (r.x / norm - x).abs() < 1e-9 && (r.y / norm - y).abs() < 1e-9,
                    "{name}"
                );
                assert_eq!(r.spin.sign(), *spin, "{name}");
            }
            assert!(
                ardupilot(&f)
                    .unwrap()
                    .contains(&format!("SERVO{}_FUNCTION", f.rotor_count()))
            );
        }
        let hexa = ardupilot(&Frame::named("hexa_x").unwrap()).unwrap();
        assert!(hexa.contains("FRAME_CLASS 2\nFRAME_TYPE 1\n"), "{hexa}");
    }

    #[test]
    fn ardupilot_refuses_a_frame_it_has_no_class_for() {
        let mut table = Frame::named("hexa_x").unwrap().table().clone();
        table.rotors[0].x = 0.2;
        let e = ardupilot(&Frame::new(table).unwrap()).unwrap_err();
        assert!(
            e.starts_with("ArduPilot mixes only its own frame classes; frame `hexa_x`"),
            "{e}"
        );
    }
}
