//! One 20 ms env step of the Landing task (physics, contacts, reward, termination and the
//! 11-value observation): in flight (the drone integrated alone), resting on the pad (in a
//! rapier world, contacts active) and with a moving platform; plus an episode reset and a
//! whole-state save/restore.
//!
//! cargo bench -p flyloop-core --bench lander2d_step

// Setup failures should stop a benchmark loudly; there is no user input here.
#![allow(clippy::expect_used, clippy::unwrap_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_core::lander2d::{DroneState, Lander2d, Lander2dParams};
use flyloop_core::tasks::Task;
use flyloop_core::tasks::landing::{Landing, LandingParams};
use std::hint::black_box;

mod common;

fn run(
    c: &mut Criterion,
    name: &str,
    model: Lander2dParams,
    start: Option<DroneState>,
    action: [f64; 2],
) {
    let mut task = Landing::new(model, LandingParams::default()).expect("valid defaults");
    let restart = |task: &mut Landing| match start {
        Some(drone) => task.reset_to(0, drone).expect("finite start"),
        None => task.reset(0),
    };
    restart(&mut task);
    common::task_steps(c, name, &mut task, &action, restart);
}

fn lander2d_step(c: &mut Criterion) {
    let p = Lander2dParams::default();
    let hover = p.command_for_thrust(p.hover_thrust()).unwrap_or(0.0);
    // In flight: hover with thrust noise and wind (the drone drifts; episodes run ~1000 steps).
    run(
        c,
        "landing_task_step_20ms_in_flight",
        p.clone(),
        None,
        [hover, hover],
    );

    // Resting on the pad: a 0.1 m drop, then contact every step. The task terminates at the
    // touch-down, so drive the model directly here.
    let mut resting = Lander2d::new(
        Lander2dParams {
            wind_enabled: false,
            ..p.clone()
        },
        DroneState {
            x: 25.0,
            y: 10.7,
            ..Default::default()
        },
        flyloop_core::SimRng::new(0),
    )
    .expect("valid defaults");
    resting.set_command([-0.5, -0.5]).expect("finite command");
    for _ in 0..50 {
        resting.step();
    }
    c.bench_function("lander2d_model_step_20ms_on_pad", |b| {
        b.iter(|| resting.step())
    });

    let moving = Lander2dParams {
        moving_platform: true,
        ..p.clone()
    };
    run(
        c,
        "landing_task_step_20ms_moving_platform",
        moving,
        None,
        [hover, hover],
    );

    let mut task = Landing::new(p.clone(), LandingParams::default()).expect("valid defaults");
    let mut seed = 0;
    c.bench_function("landing_task_reset", |b| {
        b.iter(|| {
            seed += 1;
            task.reset(black_box(seed));
        })
    });
    let lander = Lander2d::new(
        p,
        DroneState {
            x: 25.0,
            y: 40.0,
            ..Default::default()
        },
        flyloop_core::SimRng::new(1),
    )
    .expect("valid defaults");
    c.bench_function("lander2d_save_and_restore", |b| {
        b.iter(|| {
            let bytes = lander.save().expect("encodes");
            black_box(Lander2d::restore(&bytes).expect("decodes"));
        })
    });
}

criterion_group!(benches, lander2d_step);
criterion_main!(benches);
