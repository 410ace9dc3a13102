//! One 10 ms step of a world of N hovering quads (wind field, broad phase, contact and
//! downwash on) against N lone vehicles stepped one by one: the price of sharing a world.
//!
//! cargo bench -p flyloop-core --bench world_step

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use flyloop_core::quadrotor::{Quadrotor, QuadrotorParams};
use flyloop_core::world::{World, WorldParams};
use nalgebra::Vector3;
use std::hint::black_box;

mod common;

/// N quads hovering on a square lattice 1 m apart, every third one 0.5 m higher.
fn fleet(n: usize) -> Vec<(String, Quadrotor)> {
    let side = (n as f64).sqrt().ceil() as usize;
    (0..n)
        .map(|k| {
            let position = Vector3::new(
                (k % side) as f64,
                (k / side) as f64,
                5.0 + 0.5 * (k % 3) as f64,
            );
            let quad = common::hovering(QuadrotorParams::default(), position, [0.0; 3], k as u64);
            (format!("v{k:04}"), quad)
        })
        .collect()
}

fn world_step(c: &mut Criterion) {
    for n in [1, 64, 1024] {
        let mut world = World::new(WorldParams::default(), 1, fleet(n)).unwrap();
        c.bench_function(&format!("world_{n}_step_10ms"), |b| {
            b.iter(|| world.step(black_box(0.01)))
        });
        let mut alone: Vec<Quadrotor> = fleet(n).into_iter().map(|(_, q)| q).collect();
        c.bench_function(&format!("lone_{n}_step_10ms"), |b| {
            b.iter(|| alone.iter_mut().for_each(|q| q.step(black_box(0.01))))
        });
    }
}

criterion_group!(benches, world_step);
criterion_main!(benches);
