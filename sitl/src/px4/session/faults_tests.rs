//! Issue 35: faults in PX4 mode — the config file's faults in what PX4 is sent and in the
//! motors, and MAV_CMD_INJECT_FAILURE on the control link over loopback.

use super::tests::{controls, messages, session};
use super::*;
use crate::control_link::ControlLink;
use crate::wire::{Encoder, frames};
use mavlink::dialects::common::{COMMAND_ACK_DATA, MavResult};
use std::net::UdpSocket;
use std::time::Duration;

pub(super) fn faulty_session(faults: &str) -> Session {
    let text = format!("{}\n{faults}", crate::config::IRIS_PRESET);
    Session::new(&SessionOptions {
        vehicle: AutopilotVehicle::parse(&text).unwrap(),
        step_us: 4000,
        seed: 5,
    })
    .unwrap()
}

/// `steps` lockstep steps at motor command `value`; what PX4 was sent.
fn fly(s: &mut Session, steps: usize, value: f32) -> Vec<MavMessage> {
    let mut out = Vec::new();
    for _ in 0..steps {
        s.receive(&controls(value), &mut out);
    }
    messages(&out)
}

fn count_gps(sent: &[MavMessage]) -> usize {
    (sent.iter())
        .filter(|m| matches!(m, MavMessage::HIL_GPS(_)))
        .count()
}

#[test]
fn gps_off_in_the_config_stops_hil_gps_and_the_baro_sticks() {
    let mut s = faulty_session(
        "[[faults]]\nkind = \"sensor_off\"\nsensor = \"gps\"\nat = 1.0\n\
         [[faults]]\nkind = \"sensor_stuck\"\nsensor = \"baro\"\nat = 1.0",
    );
    let mut out = Vec::new();
    s.connect(1_000_000, &mut out);
    // 0.008 … 0.996 s: fixes at 10 Hz (0.104 … 0.904; the connect sent the one of 0.004).
    let before = fly(&mut s, 248, 0.0);
    assert_eq!(count_gps(&before), 9);
    let after = fly(&mut s, 500, 0.0);
    assert_eq!(count_gps(&after), 0, "no HIL_GPS once the GPS is off");
    let alts: Vec<f32> = (after.iter())
        .filter_map(|m| match m {
            MavMessage::HIL_SENSOR(h) => Some(h.pressure_alt),
            _ => None,
        })
        .collect();
    assert_eq!(alts.len(), 500);
    // The fault fires at the step starting at 1.0 s: the sample of 1.000 s is still free,
    // every one from 1.004 s repeats the stuck one.
    assert!(
        alts[1..].iter().all(|&a| a == alts[1]),
        "stuck baro: one value"
    );
    // The noise-free baro at rest varies sample to sample (1 Pa noise ≈ 8 cm).
    let free: Vec<f32> = (before.iter())
        .filter_map(|m| match m {
            MavMessage::HIL_SENSOR(h) => Some(h.pressure_alt),
            _ => None,
        })
        .collect();
    assert!(free.windows(2).any(|w| w[0] != w[1]));
}

#[test]
fn a_motor_off_in_the_config_spins_down_while_the_others_follow_px4() {
    let mut s = faulty_session("[[faults]]\nkind = \"motor_off\"\nmotor = 1\nat = 0.1");
    let mut out = Vec::new();
    s.connect(1_000_000, &mut out);
    fly(&mut s, 200, 0.3);
    let states = s.vehicle().actuator_states();
    assert!(states[0] < 1e-3, "motor 1 off: {}", states[0]);
    assert!(
        (states[1] - 0.3).abs() < 1e-3,
        "motor 2 follows: {}",
        states[1]
    );
    // What PX4 commanded stays the vehicle's command.
    assert_eq!(s.vehicle().actuators(), [0.3f32 as f64; 4]);
}

#[test]
fn without_faults_the_bits_are_the_same_as_before() {
    // An empty fault table list is no fault: the same sensor stream as the plain preset.
    let mut a = faulty_session("");
    let mut b = session(5);
    let (mut oa, mut ob) = (Vec::new(), Vec::new());
    a.connect(1_000_000, &mut oa);
    b.connect(1_000_000, &mut ob);
    assert_eq!(fly(&mut a, 300, 0.6), fly(&mut b, 300, 0.6));
}

pub(crate) fn inject(unit: f32, failure: f32, instance: f32, target: u8) -> Vec<u8> {
    let m = MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        command: MavCmd::MAV_CMD_INJECT_FAILURE,
        target_system: target,
        param1: unit,
        param2: failure,
        param3: instance,
        ..Default::default()
    });
    let mut out = Vec::new();
    Encoder::default().push(&mut out, 255, &m);
    out
}

/// The control link's answers to one command: the ack and the STATUSTEXT's text.
pub(crate) fn answer(client: &UdpSocket) -> (COMMAND_ACK_DATA, String) {
    let mut buf = [0u8; 1024];
    let n = client.recv(&mut buf).unwrap();
    let mut ack = None;
    let mut text = String::new();
    for f in frames(&buf[..n]) {
        match f.unwrap().message {
            MavMessage::COMMAND_ACK(a) => ack = Some(a),
            MavMessage::STATUSTEXT(t) => {
                text.push_str(
                    std::str::from_utf8(&t.text.to_vec())
                        .unwrap()
                        .trim_end_matches('\0'),
                );
            }
            _ => {}
        }
    }
    (ack.unwrap(), text)
}

#[test]
fn inject_failure_on_the_control_link_is_acked_and_acts() {
    let mut s = session(7);
    let link = ControlLink::new(UdpSocket::bind("127.0.0.1:0").unwrap()).unwrap();
    let addr = link.local_addr().unwrap();
    s.set_control(link);
    let client = UdpSocket::bind("127.0.0.1:0").unwrap();
    client
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    client.connect(addr).unwrap();
    let mut out = Vec::new();
    s.connect(1_000_000, &mut out);
    fly(&mut s, 10, 0.4);

    // Motor 2 off (PX4's numbering): accepted, named, and the motor spins down.
    client.send(&inject(101.0, 1.0, 2.0, 1)).unwrap();
    std::thread::sleep(Duration::from_millis(50));
    fly(&mut s, 3, 0.4);
    let (ack, text) = answer(&client);
    assert_eq!(ack.result, MavResult::MAV_RESULT_ACCEPTED);
    assert_eq!(ack.command, MavCmd::MAV_CMD_INJECT_FAILURE);
    assert_eq!(text, "fault injected: motor_off:2");
    fly(&mut s, 200, 0.4);
    let m = s.vehicle().actuator_states();
    assert!(m[1] < 1e-3 && (m[0] - 0.4).abs() < 1e-3, "{m:?}");

    // A motor the quad lacks: UNSUPPORTED naming the instance; a code that is no integer:
    // DENIED naming the parameter.
    client.send(&inject(101.0, 1.0, 5.0, 1)).unwrap();
    std::thread::sleep(Duration::from_millis(50));
    fly(&mut s, 3, 0.4);
    let (ack, text) = answer(&client);
    assert_eq!(ack.result, MavResult::MAV_RESULT_UNSUPPORTED);
    assert!(
        text.contains("instance 5: the frame has motors 1 to 4"),
        "{text}"
    );
    client.send(&inject(101.5, 1.0, 1.0, 1)).unwrap();
    std::thread::sleep(Duration::from_millis(50));
    fly(&mut s, 3, 0.4);
    let (ack, text) = answer(&client);
    assert_eq!(ack.result, MavResult::MAV_RESULT_DENIED);
    assert!(text.contains("param1 (failure_unit) = 101.5"), "{text}");

    // GPS off at run time: no HIL_GPS from then on.
    client.send(&inject(4.0, 1.0, 0.0, 1)).unwrap();
    std::thread::sleep(Duration::from_millis(50));
    fly(&mut s, 3, 0.4);
    assert_eq!(answer(&client).1, "fault injected: sensor_off:gps");
    assert_eq!(count_gps(&fly(&mut s, 100, 0.4)), 0);
}

#[test]
fn the_track_says_which_fault_fired_and_cleared_when() {
    let path = std::env::temp_dir().join(format!("flyloop-fault-track-{}.csv", std::process::id()));
    let mut s = faulty_session(
        "[[faults]]\nkind = \"motor_off\"\nmotor = 1\nat = 0.1\nduration = 0.2\n\
         [[faults]]\nkind = \"link_loss\"\nat = 0.25\nduration = 0.1",
    );
    s.track
        .set(crate::track::Track::create(&path, 20_000, 4).unwrap());
    let mut out = Vec::new();
    s.connect(1_000_000, &mut out);
    fly(&mut s, 150, 0.5);
    s.track.flush();
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    let mut lines = text.lines();
    assert!(lines.next().unwrap().ends_with(",grounded,p,q,r,faults"));
    let events: Vec<(u64, &str)> = lines
        .filter_map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let last = *cells.last().unwrap();
            (!last.is_empty()).then(|| (cells[1].parse().unwrap(), last))
        })
        .collect();
    // Each event in the first row at or after it (rows every 20 ms of simulation time).
    assert_eq!(
        events,
        [
            (104_000, "+motor_off:1@0.100"),
            (264_000, "+link_loss@0.252"),
            (304_000, "-motor_off:1@0.300"),
            (364_000, "-link_loss@0.352"),
        ]
    );
}
