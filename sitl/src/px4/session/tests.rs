//! The session against hand-made PX4 traffic: the lockstep rule, the messages and their
//! units, bad input, reconnects and determinism.

use super::*;
use crate::wire::{Encoder, frames};
use flyloop_core::quadrotor::contact::rest_height;
use mavlink::dialects::common::{
    HIL_ACTUATOR_CONTROLS_DATA, HIL_SENSOR_DATA, HilActuatorControlsFlags, MavModeFlag,
};
use nalgebra::Vector3;

pub(crate) fn session(seed: u64) -> Session {
    Session::new(&SessionOptions {
        vehicle: AutopilotVehicle::iris(),
        step_us: 4000,
        seed,
    })
    .unwrap()
}

/// PX4's HIL_ACTUATOR_CONTROLS with `value` on motors 1-4, armed, lockstep.
pub(crate) fn controls(value: f32) -> Vec<u8> {
    let mut c = [0.0f32; 16];
    c[..4].fill(value);
    let m = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        controls: c,
        mode: MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED,
        flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        ..Default::default()
    });
    let mut out = Vec::new();
    Encoder::default().push(&mut out, 1, &m);
    out
}

pub(crate) fn messages(bytes: &[u8]) -> Vec<MavMessage> {
    frames(bytes).map(|f| f.unwrap().message).collect()
}

fn sensors(bytes: &[u8]) -> Vec<HIL_SENSOR_DATA> {
    messages(bytes)
        .into_iter()
        .filter_map(|m| match m {
            MavMessage::HIL_SENSOR(s) => Some(s),
            _ => None,
        })
        .collect()
}

#[test]
fn connect_sends_sensors_at_once_and_each_controls_message_is_one_step() {
    let mut s = session(1);
    let mut out = Vec::new();
    s.connect(1_700_000_000_000_000, &mut out);
    let first = sensors(&out);
    assert_eq!(first.len(), 1);
    assert_eq!(first[0].time_usec, 4000);
    // Resting on the ground, level: −g on z, no rotation, the ISA pressure at 488 m.
    assert!((first[0].zacc + 9.81).abs() < 0.5, "{}", first[0].zacc);
    assert!(first[0].xgyro.abs() < 0.02);
    assert!(
        (first[0].abs_pressure - 955.98).abs() < 0.1,
        "{}",
        first[0].abs_pressure
    );
    assert_eq!(first[0].fields_updated.bits(), 0x1FF | 0x1A00);
    assert!(!s.is_lockstep());

    // Before PX4's first controls the simulator steps on its own.
    out.clear();
    s.free_step(&mut out);
    assert_eq!(sensors(&out)[0].time_usec, 8000);

    // Each controls message: one step, one HIL_SENSOR 4 ms later.
    out.clear();
    let mut three = controls(0.7);
    three.extend(controls(0.7));
    three.extend(controls(0.7));
    assert_eq!(s.receive(&three, &mut out), 3);
    assert!(s.is_lockstep());
    let times: Vec<u64> = sensors(&out).iter().map(|m| m.time_usec).collect();
    assert_eq!(times, vec![12_000, 16_000, 20_000]);
    assert_eq!(s.vehicle().actuators(), [0.7f32 as f64; 4]);
    assert_eq!(s.stats.steps, 4);
}

#[test]
fn gps_comes_at_10_hz_and_ground_truth_when_asked() {
    let mut s = session(2);
    let mut out = Vec::new();
    s.connect(1_000_000, &mut out);
    let ask = MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        command: MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
        param1: 115.0,
        param2: 8000.0,
        ..Default::default()
    });
    let mut bytes = Vec::new();
    Encoder::default().push(&mut bytes, 1, &ask);
    s.receive(&bytes, &mut out);
    for _ in 0..99 {
        s.free_step(&mut out);
    }
    // 0.004 … 0.400 s: fixes at 0.004, 0.104, 0.204, 0.304.
    let all = messages(&out);
    let gps: Vec<_> = all
        .iter()
        .filter_map(|m| match m {
            MavMessage::HIL_GPS(g) => Some(g),
            _ => None,
        })
        .collect();
    assert_eq!(gps.len(), 4);
    assert_eq!(gps[0].time_usec, 1_004_000);
    assert_eq!((gps[0].fix_type, gps[0].satellites_visible), (3, 12));
    assert!((gps[0].lat - 473_977_420).abs() <= 10, "{}", gps[0].lat);
    // Every other step at 8 ms.
    let states = all
        .iter()
        .filter(|m| matches!(m, MavMessage::HIL_STATE_QUATERNION(_)))
        .count();
    assert_eq!(states, 50);
}

#[test]
fn nan_controls_are_counted_and_skipped_but_time_goes_on() {
    let mut s = session(3);
    let mut out = Vec::new();
    s.connect(0, &mut out);
    s.receive(&controls(0.4), &mut out);
    out.clear();
    assert_eq!(s.receive(&controls(f32::NAN), &mut out), 1);
    assert_eq!(s.stats.refused_controls, 1);
    assert_eq!(s.vehicle().actuators(), [0.4f32 as f64; 4]);
    assert_eq!(sensors(&out)[0].time_usec, 12_000);
}

#[test]
fn garbage_and_truncated_frames_are_counted_and_good_frames_still_step() {
    let mut s = session(4);
    let mut out = Vec::new();
    s.connect(0, &mut out);
    let good = controls(0.5);
    let mut bytes = vec![0x01, 0x02, 0x03];
    bytes.extend(&good);
    bytes.extend(&good[..10]); // cut: waits for the rest
    assert_eq!(s.receive(&bytes, &mut out), 1);
    assert_eq!(s.stats.garbage, 1);
    assert_eq!(s.receive(&good[10..], &mut out), 1);
    assert_eq!(s.stats.steps, 2);
}

#[test]
fn a_new_connection_starts_from_the_start_state() {
    let mut s = session(5);
    let mut out = Vec::new();
    s.connect(0, &mut out);
    for _ in 0..200 {
        s.receive(&controls(0.9), &mut out);
    }
    assert!(s.vehicle().kinematics().position.z > 1.0);
    out.clear();
    s.connect(0, &mut out);
    assert_eq!(s.time_us(), 4000);
    assert!(!s.is_lockstep());
    // Standing on its landing gear again: the centre of mass at the rest height.
    let standing = Vector3::new(0.0, 0.0, rest_height(&AutopilotVehicle::iris().quadrotor));
    assert!((s.vehicle().kinematics().position - standing).norm() < 1e-12);
    assert_eq!(s.vehicle().actuators(), [0.0; 4]);
}

#[test]
fn same_seed_same_bytes() {
    let run = |seed| {
        let mut s = session(seed);
        let mut out = Vec::new();
        s.connect(0, &mut out);
        for k in 0..300 {
            s.receive(&controls(0.5 + 0.001 * k as f32), &mut out);
        }
        out
    };
    assert_eq!(run(7), run(7));
    assert_ne!(run(7), run(8));
}

/// Issue 33: a frame given in full in a config file (five rotors, defined here only) is the
/// vehicle PX4 flies: controls[0..5] drive its five motors, the sixth output is not a motor,
/// and at full command it climbs off its gear.
#[test]
fn a_frame_from_a_config_file_flies_on_its_own_rotor_count() {
    let mut text = String::from("mass = 1.5\n[frame]\nname = \"penta\"\n");
    for i in 0..5 {
        let a = std::f64::consts::TAU * f64::from(i) / 5.0;
        let spin = if i % 2 == 0 { "cw" } else { "ccw" };
        text += &format!(
            "[[frame.rotor]]\nx = {}\ny = {}\nspin = \"{spin}\"\n",
            a.cos(),
            a.sin()
        );
    }
    let vehicle = AutopilotVehicle::parse(&text).unwrap();
    let mut s = Session::new(&SessionOptions {
        vehicle,
        step_us: 4000,
        seed: 3,
    })
    .unwrap();
    let mut out = Vec::new();
    s.connect(1_000_000, &mut out);
    let mut c = [0.0f32; 16];
    c[..5].fill(1.0);
    c[5] = 0.3;
    let m = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        controls: c,
        mode: MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED,
        flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        ..Default::default()
    });
    let mut bytes = Vec::new();
    let mut encoder = Encoder::default();
    for _ in 0..250 {
        encoder.push(&mut bytes, 1, &m);
    }
    assert_eq!(s.receive(&bytes, &mut out), 250);
    assert_eq!(s.vehicle().actuators(), [1.0; 5]);
    assert_eq!(s.vehicle().actuator_states().len(), 5);
    assert!(
        s.vehicle().kinematics().position.z > 1.0,
        "{}",
        s.vehicle().kinematics().position.z
    );
    assert_eq!(s.stats.refused_controls, 0);
}
