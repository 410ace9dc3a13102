//! Every agent's 3 nearest neighbours in a world of N vehicles spread over the plane: the
//! column grid (`all_nearest`, what the multi-agent observation uses) against a scan of all
//! the others per agent (`nearest` for each agent, what it did before).
//!
//! cargo bench -p flyloop-core --bench neighbours

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_core::SimRng;
use flyloop_core::quadrotor::{BodyState, Frame, QuadrotorParams, multirotor_at};
use flyloop_core::tasks::multi::neighbours::{all_nearest, nearest};
use flyloop_core::vehicle::AirVehicle;
use nalgebra::Vector3;
use std::hint::black_box;

/// N vehicles drawn uniformly over a square of 1 m² per vehicle, 1–3 m high.
fn spread(n: usize) -> Vec<Box<dyn AirVehicle>> {
    let half = (n as f64).sqrt() / 2.0;
    let mut rng = SimRng::new(1);
    (0..n)
        .map(|_| {
            let p = Vector3::new(
                rng.uniform(-half, half),
                rng.uniform(-half, half),
                rng.uniform(1.0, 3.0),
            );
            let body = BodyState::at_rest(p, 0.0, 0.0, 0.0, 0.0);
            let params = QuadrotorParams::default();
            multirotor_at(params, Frame::quad_x(), body, SimRng::new(0)).unwrap()
        })
        .collect()
}

fn neighbours(c: &mut Criterion) {
    for n in [64, 1024] {
        let vehicles = spread(n);
        c.bench_function(&format!("nearest_3_of_{n}_grid"), |b| {
            b.iter(|| all_nearest(black_box(&vehicles), 3))
        });
        c.bench_function(&format!("nearest_3_of_{n}_scan"), |b| {
            b.iter(|| {
                for i in 0..n {
                    black_box(nearest(black_box(&vehicles), i, 3));
                }
            })
        });
    }
}

criterion_group!(benches, neighbours);
criterion_main!(benches);
