//! Recordings of hand-made PX4 and ArduPilot traffic read back frame by frame: what each step
//! holds, that the sensor samples are the ones sent, and the same bytes for the same seed.

use crate::ardupilot;
use crate::ardupilot::packet::encode_16;
use crate::autopilot_record::AutopilotRecorder;
use crate::config::AutopilotVehicle;
use crate::kinematics::Home;
use crate::px4;
use crate::px4::session::tests::controls;
use crate::wire::frames;
use mavlink::dialects::common::MavMessage;
use std::path::PathBuf;

const HOME: Home = Home {
    latitude_deg: 47.397742,
    longitude_deg: 8.545594,
    altitude_m: 488.0,
};

fn temp_path(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("flyloop-{}-{name}.tlog", std::process::id()))
}

/// The (time stamp, frame bytes) of a telemetry log.
fn tlog_frames(bytes: &[u8]) -> Vec<(u64, Vec<u8>)> {
    let mut out = Vec::new();
    let mut rest = bytes;
    while rest.len() > 8 {
        let time = u64::from_be_bytes(rest[..8].try_into().unwrap());
        let len = 12 + usize::from(rest[9]);
        out.push((time, rest[8..8 + len].to_vec()));
        rest = &rest[8 + len..];
    }
    assert!(rest.is_empty(), "{} bytes left over", rest.len());
    out
}

fn decode(frame: &[u8]) -> (u8, MavMessage) {
    let incoming = frames(frame).next().unwrap().unwrap();
    (incoming.header.system_id, incoming.message)
}

/// A PX4 flight of `steps` controls at 0.7, recorded; the recording and the bytes sent.
fn px4_flight(name: &str, seed: u64, steps: usize) -> (Vec<u8>, Vec<u8>) {
    px4_flight_of(AutopilotVehicle::iris(), name, seed, steps)
}

/// [`px4_flight`] of `vehicle`.
fn px4_flight_of(
    vehicle: AutopilotVehicle,
    name: &str,
    seed: u64,
    steps: usize,
) -> (Vec<u8>, Vec<u8>) {
    let path = temp_path(name);
    let mut s = px4::session::Session::new(&px4::session::SessionOptions {
        vehicle,
        step_us: 4000,
        seed,
    })
    .unwrap();
    s.track
        .set_recording(AutopilotRecorder::create(&path, HOME).unwrap());
    let mut sent = Vec::new();
    s.connect(1_700_000_000_000_000, &mut sent);
    for _ in 0..steps {
        s.receive(&controls(0.7), &mut sent);
    }
    drop(s);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    (bytes, sent)
}

#[test]
fn a_px4_step_holds_its_controls_the_sensors_sent_the_truth_motors_and_wind() {
    let (bytes, sent) = px4_flight("px4", 1, 300);
    let tlog = tlog_frames(&bytes);
    // The sensor frames in the recording are the bytes PX4 got, in order.
    let sent_frames: Vec<&[u8]> = crate::record::frames_of(&sent).collect();
    let recorded_sensors: Vec<&[u8]> = tlog
        .iter()
        .map(|(_, f)| f.as_slice())
        .filter(|f| {
            let id = crate::record::message_id(f);
            id == crate::telemetry::id::HIL_SENSOR || id == crate::telemetry::id::HIL_GPS
        })
        .collect();
    assert_eq!(recorded_sensors, sent_frames);
    assert!(sent_frames.len() > 301, "GPS fixes among the sensors");

    let messages: Vec<(u64, u8, MavMessage)> = tlog
        .iter()
        .map(|(t, f)| {
            let (id, m) = decode(f);
            (*t, id, m)
        })
        .collect();
    assert!(matches!(messages[0].2, MavMessage::HOME_POSITION(_)));
    let mut controls = 0;
    let mut servo = 0;
    let mut lines = Vec::new();
    for (time, system_id, m) in &messages {
        if let MavMessage::STATUSTEXT(s) = m {
            assert_eq!(*system_id, super::LINES_SYSTEM);
            lines.push((*time, s.text.to_str().unwrap().to_string()));
            continue;
        }
        assert_eq!(*system_id, 1);
        match m {
            MavMessage::HIL_ACTUATOR_CONTROLS(c) => {
                // Stamped with the time of the sensors it answers: 4 ms before its step's.
                assert_eq!(*time, 4000 * (controls + 1));
                assert_eq!(c.controls[0], 0.7);
                controls += 1;
            }
            MavMessage::SERVO_OUTPUT_RAW(s) => {
                assert_eq!(u64::from(s.time_usec), *time);
                // The first state (connect) is before any controls: motors off.
                let want = if servo == 0 { 1000 } else { 1700 };
                assert_eq!([s.servo1_raw, s.servo4_raw, s.servo5_raw], [want, want, 0]);
                servo += 1;
            }
            MavMessage::HIL_STATE_QUATERNION(s) => assert_eq!(s.time_usec, *time),
            MavMessage::WIND_COV(w) => assert_eq!(w.time_usec, *time),
            MavMessage::HIL_SENSOR(s) => assert_eq!(s.time_usec, *time),
            MavMessage::HOME_POSITION(h) => assert_eq!(h.latitude, 473_977_420),
            MavMessage::HIL_GPS(_) => {}
            other => panic!("unexpected {other:?}"),
        }
    }
    let lockstep = "PX4: first controls at t=0.004 s: in lockstep";
    assert_eq!(lines, [(4000, lockstep.to_string())]);
    assert_eq!((controls, servo), (300, 301));
    // 0.7 on every motor lifts the Iris: the recorded truth climbs.
    let last_alt = messages.iter().rev().find_map(|(_, _, m)| match m {
        MavMessage::HIL_STATE_QUATERNION(s) => Some(s.alt),
        _ => None,
    });
    assert!(last_alt.unwrap() > 488_000 + 100, "{last_alt:?}");
}

#[test]
fn the_same_seed_and_controls_give_the_same_recording() {
    let (a, _) = px4_flight("same-a", 7, 100);
    let (b, _) = px4_flight("same-b", 7, 100);
    assert_eq!(a, b);
    let (c, _) = px4_flight("same-c", 8, 100);
    assert_ne!(a, c, "the seed reaches the sensor noise");
}

#[test]
fn the_lockstep_line_and_a_fault_that_fires_and_clears_are_statustext_from_system_250() {
    let faults = "[[faults]]\nkind = \"motor_off\"\nmotor = 1\nat = 0.1\nduration = 0.2";
    let text = format!("{}\n{faults}", crate::config::IRIS_PRESET);
    let vehicle = AutopilotVehicle::parse(&text).unwrap();
    let (bytes, _) = px4_flight_of(vehicle, "lines", 1, 100);
    let lines: Vec<(u64, u8, String)> = tlog_frames(&bytes)
        .iter()
        .filter_map(|(t, f)| match decode(f) {
            (id, MavMessage::STATUSTEXT(s)) => Some((*t, id, s.text.to_str().unwrap().to_string())),
            _ => None,
        })
        .collect();
    let expect = [
        (4000, "PX4: first controls at t=0.004 s: in lockstep"),
        (100_000, "fault fired: motor_off:1 at 0.100 s"),
        (300_000, "fault cleared: motor_off:1 at 0.300 s"),
    ];
    let got: Vec<(u64, &str)> = lines.iter().map(|(t, _, s)| (*t, s.as_str())).collect();
    assert_eq!(got, expect);
    assert!(lines.iter().all(|(_, id, _)| *id == super::LINES_SYSTEM));
    let (same, _) = px4_flight_of(AutopilotVehicle::parse(&text).unwrap(), "lines-2", 1, 100);
    assert_eq!(bytes, same, "the same seed and controls: the same bytes");
}

#[test]
fn an_ardupilot_step_holds_its_imu_the_motor_pwm_truth_and_wind() {
    let path = temp_path("ardupilot");
    let mut s = ardupilot::session::Session::new(&ardupilot::session::SessionOptions {
        vehicle: AutopilotVehicle::iris(),
        seed: 1,
    })
    .unwrap();
    s.track
        .set_recording(AutopilotRecorder::create(&path, HOME).unwrap());
    let from = std::net::SocketAddr::from(([127, 0, 0, 1], 40000));
    let mut channels = [0u16; 16];
    channels[..4].fill(1500);
    let mut replies = Vec::new();
    for count in 0..50 {
        s.receive(&encode_16(1200, count, &channels), from);
        replies.push(s.reply().to_vec());
    }
    drop(s);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    let messages: Vec<(u64, MavMessage)> = tlog_frames(&bytes)
        .iter()
        .map(|(t, f)| (*t, decode(f).1))
        .collect();
    let (mut steps, mut imu) = (0u64, 0);
    for (time, m) in &messages {
        match m {
            MavMessage::SERVO_OUTPUT_RAW(s) => {
                steps += 1;
                assert_eq!(*time, 833 * steps);
                assert_eq!([s.servo1_raw, s.servo4_raw, s.servo5_raw], [1500, 1500, 0]);
            }
            MavMessage::HIL_SENSOR(h) => {
                // The IMU of the JSON line sent at that step, to f32.
                let line = std::str::from_utf8(&replies[imu]).unwrap();
                let want = format!("\"accel_body\":[{},{},{}]", h.xacc, h.yacc, h.zacc);
                assert!(line.contains(&want), "{line} lacks {want}");
                assert_eq!(h.fields_updated.bits(), 0x3F);
                imu += 1;
            }
            MavMessage::HIL_STATE_QUATERNION(_)
            | MavMessage::WIND_COV(_)
            | MavMessage::HOME_POSITION(_) => {}
            MavMessage::STATUSTEXT(s) => {
                assert_eq!(
                    (*time, s.text.to_str().unwrap()),
                    (0, "ArduPilot: connection 1: in lockstep")
                );
            }
            other => panic!("unexpected {other:?}"),
        }
    }
    assert_eq!((steps, imu), (50, 50));
}
