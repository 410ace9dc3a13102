//! One 4 ms PX4 step of flyloop's own work in the core: the quadrotor's physics step plus one
//! sample of every sensor (IMU, magnetometer, barometer) and the GPS check; and the sensor
//! sample alone.
//!
//! cargo bench -p flyloop-core --bench sensors_step

// Helpers are test code too: a failed setup is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_core::quadrotor::QuadrotorParams;
use flyloop_core::sensors::{SensorParams, Sensors};
use flyloop_core::vehicle::Vehicle;
use nalgebra::Vector3;
use std::hint::black_box;

mod common;

const DT: f64 = 0.004;

fn sensors_step(c: &mut Criterion) {
    let params = QuadrotorParams {
        wind_enabled: false,
        ..QuadrotorParams::default()
    };
    let mut quad = common::hovering(params, Vector3::new(0.0, 0.0, 5.0), [0.05, -0.03, 0.1], 1);
    let mut sensors = Sensors::new(SensorParams::default(), 1).unwrap();
    c.bench_function("sensors_sample", |b| {
        b.iter(|| black_box(sensors.sample(black_box(&quad.kinematics()), DT)))
    });
    let mut t = 0.0;
    c.bench_function("px4_step_physics_and_sensors_4ms", |b| {
        b.iter(|| {
            quad.step(DT);
            t += DT;
            let r = sensors.sample(&quad.kinematics(), DT);
            black_box((r, sensors.gps(&quad.kinematics(), t)))
        })
    });
}

criterion_group!(benches, sensors_step);
criterion_main!(benches);
