use super::file::{self, Autopilot};
use super::*;
use crate::config::AutopilotVehicle;
use crate::wire::{Encoder, StreamDecoder};
use mavlink::dialects::common::{
    HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavModeFlag,
};

fn spec(positions: &[[f64; 2]]) -> FleetSpec {
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
            while let Some(Ok(_)) = d.next_frame() {
                sensors[i] += 1;
                let value = 0.55 + 0.01 * i as f32 + if sensors[i] % 50 < 25 { 0.1 } else { 0.0 };
                let bytes = controls(value, sensors[i]);
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
    f.px4_bytes(0, &controls(0.7, 1));
    f.px4_bytes(1, &controls(0.7, 1));
    while f.advance(false).is_ok() {}
    f.px4_bytes(0, &controls(0.7, 2));
    assert_eq!(f.advance(false), Err(Hold::Waiting(1)));
    f.silence(1, std::time::Duration::from_secs(3));
    assert!(f.world().vehicle(1).command().iter().all(|&c| c == 0.0));
    let notices = f.take_notices();
    assert!(
        notices
            .iter()
            .any(|n| n.text.starts_with("px4-001: px4 silent for 3.0 s")),
        "{notices:?}"
    );
    for k in 0..10 {
        f.advance(false).unwrap();
        f.px4_bytes(0, &controls(0.7, 3 + k));
    }
    assert_eq!(f.lockstep().now_us(), 44_000);
}

#[test]
fn two_vehicles_flown_into_each_other_are_reported() {
    let mut f = Fleet::new(&spec(&[[0.0, 0.0], [0.8, 0.0]]), 0, PX4_STEP_US).unwrap();
    f.px4_connected(0);
    f.px4_connected(1);
    f.px4_bytes(0, &controls(0.0, 1));
    f.px4_bytes(1, &controls(0.0, 1));
    // Push vehicle 1 toward vehicle 0.
    f.world.vehicle_mut(1).body.velocity.x = -2.0;
    for k in 0..200 {
        let _ = f.advance(false);
        f.px4_bytes(0, &controls(0.0, 2 + k));
        f.px4_bytes(1, &controls(0.0, 2 + k));
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
