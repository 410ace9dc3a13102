//! The seam's air part (`flyloop_core::vehicle::AirVehicle`): what the world and the flight
//! tasks hold their vehicles through. A boxed air vehicle is plain data — it clones, compares
//! and round-trips through serde as its snapshot bytes, continuing bit for bit — and a task
//! holding one snapshots mid-episode as it did when it held the model itself.

use flyloop_core::quadrotor::{BodyState, Frame, QuadrotorParams, multirotor_at};
use flyloop_core::rng::SimRng;
use flyloop_core::tasks::Task;
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::hover::Hover;
use flyloop_core::vehicle::{AirVehicle, air};
use nalgebra::Vector3;

fn bits(v: &dyn AirVehicle) -> Vec<u64> {
    let b = v.body();
    (b.position.iter().chain(&b.velocity))
        .chain(b.attitude.coords.iter())
        .chain(&b.body_rates)
        .chain(b.motors.iter())
        .map(|x| x.to_bits())
        .collect()
}

fn flying_hexa() -> Box<dyn AirVehicle> {
    let body = BodyState::at_rest(Vector3::new(0.0, 0.0, 20.0), 0.1, -0.05, 0.3, 0.55);
    let mut v = multirotor_at(
        QuadrotorParams::default(),
        Frame::named("hexa_x").unwrap(),
        body,
        SimRng::new(8),
    )
    .unwrap();
    v.set_actuators(&[0.6, 0.5, 0.55, 0.6, 0.5, 0.58]).unwrap();
    v.advance(0.37);
    v
}

#[test]
fn a_boxed_air_vehicle_clones_and_round_trips_bit_for_bit() {
    let mut a = flying_hexa();
    let mut cloned = a.clone();
    let mut restored = air::restore(&a.save().unwrap()).unwrap();
    let json = serde_json::to_string(&a).unwrap();
    let mut from_json: Box<dyn AirVehicle> = serde_json::from_str(&json).unwrap();
    for v in [&cloned, &restored, &from_json] {
        assert!(a.same_as(v.as_ref()));
    }
    assert_eq!(restored.actuator_count(), 6);
    for v in [&mut a, &mut cloned, &mut restored, &mut from_json] {
        v.advance(0.41);
    }
    let want = bits(a.as_ref());
    assert!(want.iter().any(|&b| b != 0));
    for v in [&cloned, &restored, &from_json] {
        assert_eq!(bits(v.as_ref()), want);
    }
    // Another state is another vehicle.
    cloned.body_mut().velocity.x += 1.0;
    assert!(!a.same_as(cloned.as_ref()));
}

#[test]
fn foreign_or_damaged_bytes_are_an_error_not_a_vehicle() {
    assert!(air::restore(b"not a vehicle").is_err());
    let mut bytes = flying_hexa().save().unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    let err = air::restore(&bytes).unwrap_err();
    assert!(err.to_string().contains("damaged"), "{err}");
}

#[test]
fn a_hover_task_snapshotted_through_serde_continues_bit_for_bit() {
    let mut a = Hover::new(QuadrotorParams::default(), FlightParams::default()).unwrap();
    a.reset(12);
    let action = [0.62, 0.6, 0.61, 0.6];
    for _ in 0..30 {
        a.step(&action).unwrap();
    }
    let mut b: Hover = postcard::from_bytes(&postcard::to_stdvec(&a).unwrap()).unwrap();
    assert!(a == b);
    for _ in 0..50 {
        let (ra, rb) = (a.step(&action).unwrap(), b.step(&action).unwrap());
        assert_eq!(ra.reward.to_bits(), rb.reward.to_bits());
    }
    assert_eq!(bits(a.air_vehicle()), bits(b.air_vehicle()));
    assert_eq!(a.observation(), b.observation());
}
