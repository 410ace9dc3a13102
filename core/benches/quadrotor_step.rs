//! One 10 ms control step of the quadrotor (default substep: one RK4 step) in flight and
//! resting on the ground, and one Hover task step (physics + reward + termination + 33-value
//! observation).
//!
//! cargo bench -p flyloop-core --bench quadrotor_step

// Helpers are test code too: a failed setup is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_core::SimRng;
use flyloop_core::quadrotor::{BodyState, Frame, Quadrotor, QuadrotorParams};
use flyloop_core::tasks::Task;
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::hover::Hover;
use nalgebra::Vector3;
use std::hint::black_box;

mod common;

fn quadrotor_step(c: &mut Criterion) {
    let params = QuadrotorParams::default();
    let hover = params.hover_motor_state().unwrap_or(0.5);
    let (position, attitude) = (Vector3::new(0.0, 0.0, 1.5), [0.05, -0.03, 0.1]);
    let mut quad = common::hovering(params, position, attitude, 1);
    c.bench_function("quadrotor_control_step_10ms", |b| {
        b.iter(|| {
            quad.step(black_box(0.01));
        })
    });

    let still = QuadrotorParams {
        wind_enabled: false,
        ..QuadrotorParams::default()
    };
    let mut calm = common::hovering(still, position, attitude, 1);
    c.bench_function("quadrotor_control_step_10ms_no_wind", |b| {
        b.iter(|| {
            calm.step(black_box(0.01));
        })
    });
    // Resting on the landing gear in wind: the contact path (5 substeps of 2 ms).
    let rest = flyloop_core::quadrotor::contact::rest_height(&QuadrotorParams::default());
    let standing = BodyState::at_rest(Vector3::new(0.0, 0.0, rest), 0.0, 0.0, 0.1, 0.0);
    let mut ground =
        Quadrotor::new(QuadrotorParams::default(), standing, SimRng::new(1)).expect("valid");
    c.bench_function("quadrotor_control_step_10ms_on_ground", |b| {
        b.iter(|| {
            ground.step(black_box(0.01));
        })
    });
    // Other frames (issue 33): the same flight, six and eight rotors at their hover state.
    for name in ["hexa_x", "octo_x"] {
        let frame = Frame::named(name).expect("shipped frame");
        let quad = common::hovering(QuadrotorParams::default(), position, attitude, 1);
        let mut multi = quad.with_frame(frame);
        let h = multi.hover_motor_state().unwrap_or(0.5);
        multi
            .set_command(vec![h; multi.frame().rotor_count()])
            .expect("finite command");
        c.bench_function(&format!("quadrotor_control_step_10ms_{name}"), |b| {
            b.iter(|| {
                multi.step(black_box(0.01));
            })
        });
    }
    let mut rng = SimRng::new(3);
    c.bench_function("normal_draw", |b| b.iter(|| black_box(rng.normal())));

    let mut task =
        Hover::new(QuadrotorParams::default(), FlightParams::default()).expect("valid defaults");
    let action = [hover; 4];
    let restart = |task: &mut Hover| task.reset(0);
    common::task_steps(
        c,
        "hover_task_step_with_observation",
        &mut task,
        &action,
        restart,
    );
}

criterion_group!(benches, quadrotor_step);
criterion_main!(benches);
