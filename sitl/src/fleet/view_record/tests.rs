//! A fleet's recording and view stream read back: both vehicles at every world step, each
//! PX4's sensor samples as sent under its own system id, a collision from both vehicles and
//! the fleet's line, the same bytes for the same seed, and nothing written when off.

use super::super::tests::{answer, spec};
use super::super::{Fleet, PX4_STEP_US};
use crate::autopilot_record::AutopilotRecorder;
use crate::kinematics::Home;
use crate::view_stream::ViewStream;
use crate::wire::frames;
use mavlink::dialects::common::MavMessage;
use std::net::UdpSocket;
use std::path::PathBuf;

const HOME: Home = Home {
    latitude_deg: 47.397742,
    longitude_deg: 8.545594,
    altitude_m: 488.0,
};

fn temp_path(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("flyloop-fleet-{}-{name}.tlog", std::process::id()))
}

/// (time stamp µs, system id, message) of every frame of a telemetry log.
fn read_tlog(bytes: &[u8]) -> Vec<(u64, u8, MavMessage)> {
    let mut out = Vec::new();
    let mut rest = bytes;
    while rest.len() > 8 {
        let time = u64::from_be_bytes(rest[..8].try_into().unwrap());
        let len = 12 + usize::from(rest[9]);
        let incoming = frames(&rest[8..8 + len]).next().unwrap().unwrap();
        out.push((time, incoming.header.system_id, incoming.message));
        rest = &rest[8 + len..];
    }
    assert!(rest.is_empty(), "{} bytes left over", rest.len());
    out
}

/// Two PX4s 0.8 m apart, vehicle 1 pushed into vehicle 0, `steps` lockstep rounds; the
/// recording, and every HIL_SENSOR each PX4 was sent.
fn collide(name: &str, seed: u64, steps: usize) -> (Vec<u8>, [Vec<MavMessage>; 2]) {
    let path = temp_path(name);
    let mut f = Fleet::new(&spec(&[[0.0, 0.0], [0.8, 0.0]]), seed, PX4_STEP_US).unwrap();
    f.view_record
        .set_recording(AutopilotRecorder::create(&path, HOME).unwrap());
    let mut sent: [Vec<MavMessage>; 2] = [Vec::new(), Vec::new()];
    let mut take = |f: &mut Fleet| {
        for (i, sent) in sent.iter_mut().enumerate() {
            let out = std::mem::take(&mut f.member_mut(i).out);
            sent.extend(frames(&out).map(|r| r.unwrap().message));
        }
    };
    f.px4_connected(0);
    f.px4_connected(1);
    // What each PX4 is sent at its connection, before the world moves, is not a step's.
    f.member_mut(0).out.clear();
    f.member_mut(1).out.clear();
    answer(&mut f, 0, 0.0);
    answer(&mut f, 1, 0.0);
    f.world.vehicle_mut(1).body_mut().velocity.x = -2.0;
    for _ in 0..steps {
        let _ = f.advance(false);
        take(&mut f);
        answer(&mut f, 0, 0.0);
        answer(&mut f, 1, 0.0);
    }
    assert!(f.collisions >= 1);
    drop(f);
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    (bytes, sent)
}

#[test]
fn a_fleet_recording_holds_every_vehicle_its_sensors_and_the_collision() {
    let (bytes, sent) = collide("collide", 0, 200);
    let frames = read_tlog(&bytes);
    let states = |s: u8| -> Vec<u64> {
        (frames.iter())
            .filter(|(_, id, m)| *id == s && matches!(m, MavMessage::HIL_STATE_QUATERNION(_)))
            .map(|(t, _, _)| *t)
            .collect()
    };
    // Both vehicles at every world step (4 ms apart, both PX4s on one grid).
    let (one, two) = (states(1), states(2));
    assert_eq!(one, two);
    assert_eq!(one.len(), 200);
    assert!(one.windows(2).all(|w| w[1] - w[0] == PX4_STEP_US));
    for s in [1u8, 2] {
        let homes = (frames.iter())
            .filter(|(_, id, m)| *id == s && matches!(m, MavMessage::HOME_POSITION(_)))
            .count();
        assert_eq!(homes, 1, "system {s}");
        let servo = (frames.iter())
            .filter(|(_, id, m)| *id == s && matches!(m, MavMessage::SERVO_OUTPUT_RAW(_)))
            .count();
        assert_eq!(servo, 200, "system {s}");
    }
    // Each PX4's sensor samples as it was sent them.
    for (i, sent) in sent.iter().enumerate() {
        let recorded: Vec<&MavMessage> = (frames.iter())
            .filter(|(_, id, m)| {
                usize::from(*id) == i + 1
                    && matches!(m, MavMessage::HIL_SENSOR(_) | MavMessage::HIL_GPS(_))
            })
            .map(|(_, _, m)| m)
            .collect();
        let sent: Vec<&MavMessage> = sent.iter().collect();
        assert_eq!(recorded, sent, "vehicle {i}");
    }
    // The collision: its speed from both vehicles, the fleet's line.
    let hits: Vec<(u8, f32)> = (frames.iter())
        .filter_map(|(_, id, m)| match m {
            MavMessage::NAMED_VALUE_FLOAT(v) if v.name.to_str().unwrap() == "collision" => {
                Some((*id, v.value))
            }
            _ => None,
        })
        .collect();
    assert!(!hits.is_empty() && hits.len() % 2 == 0, "{hits:?}");
    for pair in hits.chunks(2) {
        assert_eq!((pair[0].0, pair[1].0), (1, 2), "{hits:?}");
        assert_eq!(pair[0].1, pair[1].1);
    }
    assert!(hits[0].1 > 1.0, "closing at 2 m/s: {hits:?}");
    let texts: Vec<String> = (frames.iter())
        .filter_map(|(_, id, m)| match m {
            MavMessage::STATUSTEXT(s) if *id == super::FLEET_SYSTEM => {
                Some(s.text.to_str().unwrap().to_string())
            }
            _ => None,
        })
        .collect();
    assert!(
        texts
            .iter()
            .any(|t| t.starts_with("collision px4-000 px4-")),
        "{texts:?}"
    );
    assert!(
        texts
            .iter()
            .any(|t| t.starts_with("px4-001: PX4 connected"))
    );
}

#[test]
fn the_same_seed_records_the_same_bytes() {
    let (a, _) = collide("same-a", 5, 100);
    let (b, _) = collide("same-b", 5, 100);
    let (c, _) = collide("other", 6, 100);
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn the_view_gets_every_vehicle_every_interval_with_its_motors() {
    let view = UdpSocket::bind("127.0.0.1:0").unwrap();
    view.set_read_timeout(Some(std::time::Duration::from_secs(2)))
        .unwrap();
    let mut f = Fleet::new(&spec(&[[0.0, 0.0], [5.0, 0.0]]), 0, PX4_STEP_US).unwrap();
    let stream = ViewStream::new(view.local_addr().unwrap(), HOME).unwrap();
    f.view_record.set_view(stream);
    f.px4_connected(0);
    f.px4_connected(1);
    answer(&mut f, 0, 0.6);
    answer(&mut f, 1, 0.6);
    for _ in 0..25 {
        f.advance(false).unwrap();
        answer(&mut f, 0, 0.6);
        answer(&mut f, 1, 0.6);
    }
    // 100 ms of world time: states at 4, 24, 44, 64, 84 ms, each from both vehicles.
    let mut got: Vec<(u8, &'static str, u64)> = Vec::new();
    let mut buf = [0u8; 65536];
    while let Ok(n) = view.recv(&mut buf) {
        for frame in frames(&buf[..n]) {
            let frame = frame.unwrap();
            let id = frame.header.system_id;
            match frame.message {
                MavMessage::HIL_STATE_QUATERNION(s) => got.push((id, "state", s.time_usec)),
                MavMessage::SERVO_OUTPUT_RAW(s) => {
                    assert_eq!(s.servo1_raw, 1600);
                    got.push((id, "servo", u64::from(s.time_usec)))
                }
                MavMessage::STATUSTEXT(_) => assert_eq!(id, super::FLEET_SYSTEM),
                _ => {}
            }
        }
        if got.len() == 20 {
            break;
        }
    }
    let states: Vec<(u8, u64)> = (got.iter())
        .filter(|g| g.1 == "state")
        .map(|g| (g.0, g.2))
        .collect();
    let want: Vec<(u8, u64)> = [4000, 24_000, 44_000, 64_000, 84_000]
        .iter()
        .flat_map(|&t| [(1, t), (2, t)])
        .collect();
    assert_eq!(states, want);
    assert_eq!(got.iter().filter(|g| g.1 == "servo").count(), 10);
}
