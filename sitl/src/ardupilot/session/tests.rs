//! The session against hand-made ArduPilot packets: the lockstep rule, the reply's values
//! and frames, repeats, restarts and bad input.

use super::*;
use crate::ardupilot::packet::encode_16;

fn session(seed: u64) -> Session {
    Session::new(&SessionOptions {
        vehicle: AutopilotVehicle::iris(),
        seed,
    })
    .unwrap()
}

pub(super) fn addr(port: u16) -> SocketAddr {
    SocketAddr::from(([127, 0, 0, 1], port))
}

pub(super) fn servo(count: u32, pwm: u16) -> Vec<u8> {
    let mut channels = [0u16; 16];
    channels[..4].fill(pwm);
    encode_16(1200, count, &channels)
}

/// The numbers after `"key":` in a reply.
pub(super) fn field(reply: &[u8], key: &str) -> Vec<f64> {
    let text = std::str::from_utf8(reply).unwrap();
    let at = text.find(&format!("\"{key}\":")).unwrap() + key.len() + 3;
    let rest = &text[at..];
    let end = if rest.starts_with('[') {
        rest.find(']').unwrap()
    } else {
        rest.find([',', '}']).unwrap()
    };
    rest[..end]
        .trim_start_matches('[')
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect()
}

#[test]
fn each_new_frame_is_one_step_of_its_rate_and_repeats_are_answered_without_a_step() {
    let mut s = session(1);
    let ap = addr(40000);
    assert_eq!(s.receive(&servo(0, 1000), ap), Outcome::Stepped);
    let first = s.reply().to_vec();
    assert!(first.starts_with(b"\n{\"timestamp\":") && first.ends_with(b"}\n"));
    assert_eq!(field(&first, "timestamp"), vec![0.000833]);
    // At rest on its feet, level, facing north: -g on z, NED quaternion identity.
    let accel = field(&first, "accel_body");
    assert!(accel[0].abs() < 0.6 && accel[1].abs() < 0.6, "{accel:?}");
    assert!((accel[2] + 9.81).abs() < 0.6, "{accel:?}");
    let q = field(&first, "quaternion");
    assert!(
        (q[0] - 1.0).abs() < 1e-6 && q[1..].iter().all(|v| v.abs() < 1e-6),
        "{q:?}"
    );
    let p = field(&first, "position");
    assert!(
        p[0] == 0.0 && p[1] == 0.0 && (p[2] + 0.0538).abs() < 1e-3,
        "{p:?}"
    );

    // The same frame count again: the same bytes, no step.
    assert_eq!(s.receive(&servo(0, 1000), ap), Outcome::Repeated);
    assert_eq!(s.reply(), &first[..]);
    assert_eq!((s.stats.steps, s.stats.repeats), (1, 1));

    // 1199 further frames of 833 us (1/1200 s in whole microseconds).
    for k in 1..1200 {
        assert_eq!(s.receive(&servo(k, 1000), ap), Outcome::Stepped);
    }
    assert_eq!(field(s.reply(), "timestamp"), vec![0.9996]);
    assert_eq!(s.time_us(), 999_600);

    // A rate change: frames of the new length from there on.
    let mut channels = [0u16; 16];
    channels[..4].fill(1000);
    s.receive(&encode_16(400, 1200, &channels), ap);
    assert_eq!(s.time_us(), 1_002_100);
}

#[test]
fn full_throttle_lifts_off_and_the_motor_mapping_holds() {
    let mut s = session(2);
    let ap = addr(40000);
    for k in 0..600 {
        s.receive(&servo(k, 1900), ap);
    }
    assert_eq!(s.vehicle().actuators(), [0.9; 4]);
    // Thrust 4 * 10 N * 0.81 = 32 N against 14.7 N of weight: climbing after 0.5 s.
    let v = field(s.reply(), "velocity");
    let p = field(s.reply(), "position");
    assert!(v[2] < -3.0 && p[2] < -0.8, "{v:?} {p:?}");
    // The IMU feels the thrust: specific force about -32/1.5 m/s^2 less drag.
    let a = field(s.reply(), "accel_body");
    assert!(a[2] < -15.0, "{a:?}");
    // Unset outputs (0) and pulses below 1000 us are off.
    s.receive(&servo(600, 0), ap);
    assert_eq!(s.vehicle().actuators(), [0.0; 4]);
    s.receive(&servo(601, 900), ap);
    assert_eq!(s.vehicle().actuators(), [0.0; 4]);
}

#[test]
fn a_restarted_ardupilot_gets_the_start_state_and_time_from_zero() {
    let mut s = session(3);
    let first = addr(40000);
    let mut replies = Vec::new();
    for k in 0..400 {
        s.receive(&servo(k, 1800), first);
        if k < 3 {
            replies.push(s.reply().to_vec());
        }
    }
    assert!(field(s.reply(), "position")[2] < -0.2);
    // A new ArduPilot (frame count from 0, another port): reset, the same first replies.
    let second = addr(40001);
    for (k, expected) in replies.iter().enumerate() {
        assert_eq!(s.receive(&servo(k as u32, 1800), second), Outcome::Stepped);
        assert_eq!(s.reply(), &expected[..], "frame {k}");
    }
    assert_eq!(s.stats.connections, 2);
    // The same ArduPilot going back in its count (a restart on the same port) too.
    s.receive(&servo(0, 1800), second);
    assert_eq!(s.reply(), &replies[0][..]);
    assert_eq!(s.stats.connections, 3);
    // The same count from a new sender is a restart, not a repeat.
    s.receive(&servo(0, 1800), addr(40002));
    assert_eq!((s.stats.connections, s.stats.repeats), (4, 0));
}

#[test]
fn bad_packets_are_skipped_and_counted_and_absurd_pwm_holds_the_command() {
    let mut s = session(4);
    let ap = addr(40000);
    s.receive(&servo(0, 1500), ap);
    let good = servo(1, 1500);
    let mut wrong_magic = good.clone();
    wrong_magic[0] ^= 0xff;
    let mut bad_rate = good.clone();
    bad_rate[2..4].fill(0);
    let mut long_16 = good.clone();
    long_16.extend_from_slice(&[0; 32]);
    for bad in [
        &good[..20],
        &[][..],
        &wrong_magic[..],
        &bad_rate[..],
        &long_16[..],
        b"{\"json\":1}\n",
    ] {
        assert_eq!(s.receive(bad, ap), Outcome::Skipped);
    }
    assert_eq!(
        (
            s.stats.bad_length,
            s.stats.bad_magic,
            s.stats.bad_frame_rate
        ),
        (3, 2, 1)
    );
    assert_eq!(s.stats.steps, 1);
    // The lockstep goes on with the next good frame.
    assert_eq!(s.receive(&good, ap), Outcome::Stepped);
    // A motor at 40000 us: counted, the previous command holds, the frame still answered.
    let mut channels = [1500u16; 16];
    channels[2] = 40_000;
    assert_eq!(
        s.receive(&encode_16(1200, 2, &channels), ap),
        Outcome::Stepped
    );
    assert_eq!(s.vehicle().actuators(), [0.5; 4]);
    assert_eq!((s.stats.absurd_pwm, s.stats.steps), (1, 3));
    // A valid 32-channel packet flies.
    let mut p32 = servo(3, 1600);
    p32[..2].copy_from_slice(&packet::MAGIC_32.to_le_bytes());
    p32.extend_from_slice(&[0; 32]);
    assert_eq!(s.receive(&p32, ap), Outcome::Stepped);
    assert_eq!(s.vehicle().actuators(), [0.6; 4]);
    // A frame count skipping ahead is stepped once and counted.
    assert_eq!(s.receive(&servo(10, 1600), ap), Outcome::Stepped);
    assert_eq!(s.stats.gaps, 1);
    assert_eq!(s.stats.bad_input(), 7);
}

#[test]
fn the_same_seed_and_frames_give_the_same_bytes() {
    let run = |seed| {
        let mut s = session(seed);
        let mut all = Vec::new();
        for k in 0..300 {
            s.receive(&servo(k, 1000 + (k as u16 % 700)), addr(40000));
            all.extend_from_slice(s.reply());
        }
        all
    };
    assert_eq!(run(5), run(5));
    assert_ne!(run(5), run(6));
}

#[test]
fn gyro_and_attitude_are_frd_and_ned() {
    let mut s = session(7);
    let ap = addr(40000);
    // Spin up, then the left motors (rear-left 1, front-left 2) above the right: roll right.
    for k in 0..600 {
        s.receive(&servo(k, 1700), ap);
    }
    let mut channels = [0u16; 16];
    channels[..4].copy_from_slice(&[1650, 1750, 1750, 1650]);
    for k in 600..700 {
        s.receive(&encode_16(1200, k, &channels), ap);
    }
    let gyro = field(s.reply(), "gyro");
    assert!(
        gyro[0] > 0.5,
        "FRD roll rate to the right is positive: {gyro:?}"
    );
    assert!((gyro[0] - s.true_gyro().x).abs() < 0.05);
    let q = field(s.reply(), "quaternion");
    // Rolled right: the quaternion's x part positive (rotation about +x forward).
    assert!(q[1] > 0.01, "{q:?}");
}
