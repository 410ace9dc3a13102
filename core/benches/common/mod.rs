//! Set-up the core's benches share: a quadrotor holding hover, and a task stepped in a loop.

// Each bench uses some of these; a failed setup is a failed benchmark.
#![allow(dead_code, clippy::expect_used)]

use criterion::Criterion;
use flyloop_core::SimRng;
use flyloop_core::quadrotor::{BodyState, Quadrotor, QuadrotorParams};
use flyloop_core::tasks::Task;
use nalgebra::Vector3;
use std::hint::black_box;

/// A quad X of `params` at `position` (world ENU, m) with attitude `[roll, pitch, yaw]` (rad),
/// at rest, its motors spinning and commanded at the hover state (0.5 if it cannot hover).
pub fn hovering(
    params: QuadrotorParams,
    position: Vector3<f64>,
    [roll, pitch, yaw]: [f64; 3],
    seed: u64,
) -> Quadrotor {
    let hover = params.hover_motor_state().unwrap_or(0.5);
    let body = BodyState::at_rest(position, roll, pitch, yaw, hover);
    let mut quad = Quadrotor::new(params, body, SimRng::new(seed)).expect("valid parameters");
    quad.set_command([hover; 4]).expect("finite command");
    quad
}

/// Benchmarks `name`: one step of `task` with `action` and the writing of its observation;
/// an episode that ends starts again through `restart`.
pub fn task_steps<T: Task>(
    c: &mut Criterion,
    name: &str,
    task: &mut T,
    action: &[f64],
    restart: impl Fn(&mut T),
) {
    let mut obs = vec![0f32; task.observation_size()];
    c.bench_function(name, |b| {
        b.iter(|| {
            let out = task.step(black_box(action)).expect("valid action");
            if out.terminated || out.truncated {
                restart(task);
            }
            task.write_observation(&mut obs);
            black_box(&obs);
        })
    });
}
