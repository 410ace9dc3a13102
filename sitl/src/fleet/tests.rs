use super::file::{self, Autopilot};
use super::*;
use crate::config::AutopilotVehicle;
use crate::wire::{Encoder, StreamDecoder};
use mavlink::dialects::common::{
    HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavModeFlag,
};

pub(crate) fn spec(positions: &[[f64; 2]]) -> FleetSpec {
    let base = "127.0.0.1:4560".parse().unwrap();
    let mut s = file::row(
        Autopilot::Px4,
        positions.len(),
        base,
        3.0,
        &AutopilotVehicle::iris(),
    )
    .unwrap();
    for (v, p) in s.vehicles.iter_mut().zip(positions) {
        v.position = *p;
    }
    s
}

/// Controls answering PX4 i's last sensors.
pub(crate) fn answer(f: &mut Fleet, i: usize, value: f32) {
    let t = f.lockstep().slot(i).time_us.max(1);
    f.px4_bytes(i, &controls(value, t));
}

fn controls(value: f32, t: u64) -> Vec<u8> {
    let mut out = Vec::new();
    let mut c = [0.0f32; 16];
    c[..4].fill(value);
    let m = MavMessage::HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA {
        time_usec: t,
        flags: HilActuatorControlsFlags::from_bits_truncate(1),
        controls: c,
        mode: MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED,
    });
    Encoder::default().push(&mut out, 1, &m);
    out
}

use mavlink::dialects::common::MavMessage;

/// Three PX4s answering every HIL_SENSOR with a command that depends only on the vehicle
/// and the sensor count, in the answer order `order` gives per round.
fn fly(order: impl Fn(u64) -> Vec<usize>) -> Vec<u8> {
    let mut f = Fleet::new(&spec(&[[0.0, 0.0], [0.8, 0.0], [5.0, 0.0]]), 7, PX4_STEP_US).unwrap();
    for i in 0..3 {
        f.px4_connected(i);
    }
    let mut sensors = [0u64; 3];
    for round in 0..2000u64 {
        for i in order(round) {
            let m = &mut f.members[i];
            let mut d = StreamDecoder::default();
            d.push(&m.out);
            while let Some(Ok(frame)) = d.next_frame() {
                let MavMessage::HIL_SENSOR(h) = frame.message else {
                    continue;
                };
                sensors[i] += 1;
                let value = 0.55 + 0.01 * i as f32 + if sensors[i] % 50 < 25 { 0.1 } else { 0.0 };
                let bytes = controls(value, h.time_usec);
                f.member_mut(i).out.clear();
                f.px4_bytes(i, &bytes);
            }
            f.member_mut(i).out.clear();
            // Round 0: every PX4 joins the lockstep (its first controls) before the world
            // moves, as a fleet started together does; then the world steps between any
            // two answers the barrier lets it.
            if round > 0 {
                while f.advance(false).is_ok() {}
            }
        }
    }
    assert!(
        f.lockstep().now_us() > 4_000_000,
        "flew {} µs",
        f.lockstep().now_us()
    );
    f.world().save().unwrap()
}

#[test]
fn same_answers_in_any_arrival_order_give_the_same_world_bits() {
    let a = fly(|_| vec![0, 1, 2]);
    let b = fly(|_| vec![2, 1, 0]);
    let c = fly(|r| {
        if r % 2 == 0 {
            vec![1, 2, 0]
        } else {
            vec![0, 2, 1]
        }
    });
    assert_eq!(a, b);
    assert_eq!(a, c);
}

#[test]
fn vehicles_spawned_inside_each_other_are_refused_by_name() {
    let e = Fleet::new(&spec(&[[0.0, 0.0], [0.2, 0.0]]), 0, PX4_STEP_US).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("`px4-000` and `px4-001` start inside each other"),
        "{text}"
    );
}

#[test]
fn a_silent_px4_stops_its_motors_and_the_others_fly_on() {
    let mut f = Fleet::new(&spec(&[[0.0, 0.0], [5.0, 0.0]]), 0, PX4_STEP_US).unwrap();
    f.px4_connected(0);
    f.px4_connected(1);
    answer(&mut f, 0, 0.7);
    answer(&mut f, 1, 0.7);
    while f.advance(false).is_ok() {}
    answer(&mut f, 0, 0.7);
    assert_eq!(f.advance(false), Err(Hold::Waiting(1)));
    f.silence(1, std::time::Duration::from_secs(3));
    assert!(f.world().vehicle(1).actuators().iter().all(|&c| c == 0.0));
    let notices = f.take_notices();
    assert!(
        notices
            .iter()
            .any(|n| n.text.starts_with("px4-001: px4 silent for 3.0 s")),
        "{notices:?}"
    );
    for _ in 0..10 {
        f.advance(false).unwrap();
        answer(&mut f, 0, 0.7);
    }
    assert_eq!(f.lockstep().now_us(), 44_000);
}

#[test]
fn two_vehicles_flown_into_each_other_are_reported() {
    let mut f = Fleet::new(&spec(&[[0.0, 0.0], [0.8, 0.0]]), 0, PX4_STEP_US).unwrap();
    f.px4_connected(0);
    f.px4_connected(1);
    answer(&mut f, 0, 0.0);
    answer(&mut f, 1, 0.0);
    // Push vehicle 1 toward vehicle 0.
    f.world.vehicle_mut(1).body_mut().velocity.x = -2.0;
    for _ in 0..200 {
        let _ = f.advance(false);
        answer(&mut f, 0, 0.0);
        answer(&mut f, 1, 0.0);
    }
    assert!(f.collisions >= 1);
    let notices = f.take_notices();
    assert!(
        notices
            .iter()
            .any(|n| n.text.starts_with("collision px4-000 px4-001")),
        "{notices:?}"
    );
}

#[test]
fn only_the_answer_to_the_last_sensors_is_a_step() {
    let mut f = Fleet::new(&spec(&[[0.0, 0.0]]), 0, PX4_STEP_US).unwrap();
    f.px4_connected(0);
    // Free: the world gives it sensors at 4, 8, 12 ms before its first controls.
    for _ in 0..3 {
        f.advance(true).unwrap();
    }
    f.px4_bytes(0, &controls(0.5, 1)); // answers the first sensors: joins the lockstep
    f.advance(false).unwrap(); // its step under way ends at 16 ms
    assert_eq!(f.lockstep().now_us(), 16_000);
    // The answers to 4, 8, 12 ms arrive late: stale, no steps in flight from them.
    for t in [4000, 8000, 12_000] {
        f.px4_bytes(0, &controls(0.5, t));
    }
    assert_eq!(f.stale_controls, 3);
    assert_eq!(f.advance(false), Err(Hold::Waiting(0)));
    f.px4_bytes(0, &controls(0.6, 16_000));
    f.px4_bytes(0, &controls(0.6, 16_000)); // the same answer again: stale
    assert_eq!(f.stale_controls, 4);
    f.advance(false).unwrap();
    assert_eq!(
        f.advance(false),
        Err(Hold::Waiting(0)),
        "one step per answer"
    );
}
